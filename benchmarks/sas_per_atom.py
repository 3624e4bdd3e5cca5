#!/usr/bin/env python3
"""Where the raw SAS mesh's area falls short of freesasa's: atom by atom.

usage: sas_per_atom.py STRUCTURE.pdb[.gz] [--build-dir build] [--grid 0.4] [--probe 1.4]

Builds the raw SAS (`molremesh surface --type sas --no-remesh`) and runs Debian's freesasa command
(Lee-Richards, ProtOr radii, HETATM kept, the same probe) with `--format=pdb`, which writes each atom's
radius and SASA. Each mesh face goes to the atom whose sphere (radius + probe) its centroid lies on;
the atoms are then split by where their faces are: only on the outer (largest) component, on a cavity
(any other component), or nowhere (freesasa gives them area, the mesh has none). The table gives per
group the mesh's area, freesasa's and the difference, in Å² and in % of freesasa's total. Needs
python3-numpy and python3-scipy.
"""
import argparse
import gzip
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_benchmarks import REPO  # noqa: E402


def read_binary_ply(path):
    """Vertices and triangles of a binary little-endian PLY (float or double coordinates)."""
    with open(path, "rb") as f:
        vertices = faces = 0
        kind = "<f8"
        while True:
            line = f.readline().decode().strip()
            if line.startswith("element vertex"):
                vertices = int(line.split()[2])
            elif line.startswith("element face"):
                faces = int(line.split()[2])
            elif line == "property float x":
                kind = "<f4"
            elif line == "end_header":
                break
        size = np.dtype(kind).itemsize
        points = np.frombuffer(f.read(vertices * 3 * size), dtype=kind).reshape(vertices, 3).astype(float)
        record = np.dtype([("n", "u1"), ("i", "<i4", 3)])
        triangles = np.frombuffer(f.read(faces * record.itemsize), dtype=record)["i"]
    return points, triangles


WATERS = {"HOH", "WAT", "DOD", "H2O"}


def freesasa_atoms(structure, probe, workdir):
    """Centres, radii and SASA of freesasa's atoms (its PDB output: radius as occupancy, SASA as B)."""
    opener = gzip.open if structure.endswith(".gz") else open
    pdb = os.path.join(workdir, "structure.pdb")
    with opener(structure, "rt") as src, open(pdb, "w") as dst:  # waters skipped, as molremesh does
        dst.writelines(line for line in src if line[17:20] not in WATERS)
    out = os.path.join(workdir, "freesasa.pdb")
    subprocess.run(["freesasa", "--hetatm", "--lee-richards", "--resolution=100", f"--probe-radius={probe}",
                    "--format=pdb", f"--output={out}", "--no-warnings", pdb], check=True)
    centres, radii, sasa = [], [], []
    for line in open(out):
        if line.startswith(("ATOM", "HETATM")):
            centres.append([float(line[30:38]), float(line[38:46]), float(line[46:54])])
            radii.append(float(line[54:60]))
            sasa.append(float(line[60:66]))
    return np.array(centres), np.array(radii), np.array(sasa)


def face_components(triangles, vertices):
    rows = np.concatenate([triangles[:, 0], triangles[:, 1]])
    cols = np.concatenate([triangles[:, 1], triangles[:, 2]])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(vertices, vertices))
    return connected_components(graph, directed=False)[1][triangles[:, 0]]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("structure")
    p.add_argument("--build-dir", default=os.path.join(REPO, "build"))
    p.add_argument("--grid", type=float, default=0.4)
    p.add_argument("--probe", type=float, default=1.4)
    a = p.parse_args()
    with tempfile.TemporaryDirectory() as work:
        mesh = os.path.join(work, "sas.ply")
        figures = os.path.join(work, "sas.json")
        subprocess.run([os.path.join(a.build_dir, "cli", "molremesh"), "surface", a.structure, mesh, "--type", "sas",
                        "--no-remesh", "--grid", str(a.grid), "--probe", str(a.probe), "--quiet", "--json", figures],
                       check=True)
        points, triangles = read_binary_ply(mesh)
        centres, radii, sasa = freesasa_atoms(a.structure, a.probe, work)
        atoms = json.load(open(figures))["structure"]["atoms"]
    if atoms != len(centres):
        sys.exit(f"sas_per_atom: molremesh used {atoms} atoms, freesasa {len(centres)}: not the same atoms")
    radii = radii + a.probe
    corners = points[triangles]
    area = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    centroid = corners.mean(axis=1)
    distance, near = cKDTree(centres).query(centroid, k=min(24, len(centres)))
    near = near.reshape(len(centroid), -1)
    distance = distance.reshape(len(centroid), -1)
    atom = near[np.arange(len(centroid)), np.abs(distance - radii[near]).argmin(axis=1)]
    mesh_area = np.bincount(atom, weights=area, minlength=len(centres))
    component = face_components(triangles, len(points))
    outer = np.bincount(component, weights=area).argmax()
    on_cavity = np.zeros(len(centres), bool)
    on_cavity[atom[component != outer]] = True
    missed = (sasa > 0) & (mesh_area == 0)
    total = sasa.sum()
    print(f"| {os.path.basename(a.structure)}, grid {a.grid} Å | atoms | mesh (Å²) | freesasa (Å²) | difference |")
    print("|---|---|---|---|---|")
    groups = [("outer surface only", ~on_cavity & ~missed), ("on a cavity", on_cavity), ("no mesh area", missed),
              ("all", np.ones(len(centres), bool))]
    for name, chosen in groups:
        m, s = mesh_area[chosen].sum(), sasa[chosen].sum()
        print(f"| {name} | {chosen.sum()} | {m:.1f} | {s:.1f} | {m - s:+.1f} Å² ({100 * (m - s) / total:+.2f} %) |")
    print(f"\ncavities: {len(np.unique(component)) - 1}, their area {area[component != outer].sum():.1f} Å²")


if __name__ == "__main__":
    main()
