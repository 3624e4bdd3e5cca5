#!/usr/bin/python3
"""Broken molecular surfaces for the volumetric rebuild, made from the shared structures.

The surfaces users make most often for large complexes are the ones the local clean-up cannot
repair: PyMOL's solvent-excluded surface (SES) of multi-chain structures at low quality
(interpenetrating and overlapping sheets, non-manifold edges, open cracks), with cavity mode on
(the buried voids as extra closed sheets), PyMOL's exports (triangle soups: three vertex copies per
triangle), and marching cubes of a Gaussian density with scikit-image's default gradient direction
(the whole mesh faces inward). This script writes them, one file per entry of INPUTS, into the
folder given on the command line; the meshes are not kept in the repository, only these settings.

usage: /usr/bin/python3 scripts/make_broken_surfaces.py OUTDIR [--only NAME ...]
       /usr/bin/python3 scripts/make_broken_surfaces.py --fixtures OUTDIR
       /usr/bin/python3 scripts/make_broken_surfaces.py --gaussian PDB OUT.obj GRID DECAY LEVEL
--fixtures writes the small test fixtures of tests/data (FIXTURES) instead; --gaussian one Gaussian
surface of any structure file (for benchmarks/unseen_inputs.py).
Needs Debian's python3-pymol and python3-skimage (the system interpreter, /usr/bin/python3).
"""

import argparse
import os
import subprocess
import sys
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STRUCTURES = os.path.normpath(os.path.join(REPO, "..", "shared", "data", "structures"))
sys.path.insert(0, os.path.join(REPO, "benchmarks"))
from unseen_inputs import structure_file  # noqa: E402  (the PDB of a shared structure, gunzipped)

# name -> (structure, generator, settings). pymol: surface_quality, surface_cavity_mode, file type
# of the export; gaussian: grid spacing (A), decay (the d of exp(-d (|x - c|^2 / r^2 - 1))), level.
MULTI_CHAIN = ["1TII", "4JSV", "1HPV", "1MAH"]
INPUTS = []
for s in MULTI_CHAIN:
    INPUTS.append(("%s_pymol_ses_q0" % s, s, "pymol", {"quality": 0, "cavity": 0, "ext": "obj"}))
    INPUTS.append(("%s_pymol_ses_q1" % s, s, "pymol", {"quality": 1, "cavity": 0, "ext": "obj"}))
    INPUTS.append(("%s_pymol_ses_q0_cavity" % s, s, "pymol", {"quality": 0, "cavity": 1, "ext": "obj"}))
INPUTS += [
    ("1MAH_pymol_ses_q1_cavity", "1MAH", "pymol", {"quality": 1, "cavity": 1, "ext": "obj"}),
    ("1HPV_pymol_ses_q0_wrl", "1HPV", "pymol", {"quality": 0, "cavity": 0, "ext": "wrl"}),
    ("1HPV_gaussian_g05_d1", "1HPV", "gaussian", {"grid": 0.5, "decay": 1.0, "level": 1.0}),
    ("1MAH_gaussian_g04_d05", "1MAH", "gaussian", {"grid": 0.4, "decay": 0.5, "level": 1.0}),
]

PYMOL_SCRIPT = """
import sys
from pymol import cmd
cmd.load(sys.argv[1], 'm')
cmd.remove('solvent')
cmd.remove('hydro')
cmd.set('surface_quality', int(sys.argv[3]))
cmd.set('surface_cavity_mode', int(sys.argv[4]))
cmd.set('surface_type', 0)
cmd.show('surface')
cmd.save(sys.argv[2])
"""

# The test fixtures (tests/data, each < 150 KB): PyMOL SES of two small selections of the HIV
# protease dimer 1HPV that interpenetrate at its dimer interface (the catalytic Asp25 of each chain
# and its neighbours), each a closed sheet exported as a soup, and the inward Gaussian surface of one.
FIXTURE_SELECTIONS = {"a": "chain A and resi 25-27", "b": "chain B and resi 25-27"}

PYMOL_FIXTURE_SCRIPT = """
import sys
from pymol import cmd
cmd.load(sys.argv[1], 'm')
cmd.remove('solvent or hydro')
cmd.set('surface_quality', 0)
cmd.set('surface_type', 0)
cmd.create('part', sys.argv[3])
cmd.hide('everything')
cmd.show('surface', 'part')
cmd.save(sys.argv[2])
"""

RADII = {"C": 1.7, "N": 1.55, "O": 1.52, "S": 1.8, "P": 1.8, "H": 1.1}


def heavy_atoms(pdb, select=None):
    """Centers and radii of the non-water heavy atoms of a PDB file (select: (chain, first residue,
    last residue) to keep only those)."""
    centers, radii = [], []
    with open(pdb) as f:
        for line in f:
            if not line.startswith(("ATOM", "HETATM")) or line[17:20] in ("HOH", "WAT"):
                continue
            element = (line[76:78].strip() or line[12:14].strip().lstrip("0123456789"))[:1].upper()
            if element == "H":
                continue
            if select and (line[21] != select[0] or not select[1] <= int(line[22:26]) <= select[2]):
                continue
            centers.append((float(line[30:38]), float(line[38:46]), float(line[46:54])))
            radii.append(RADII.get(element, 1.8))
    return centers, radii


def gaussian_surface(pdb, path, grid, decay, level, select=None):
    """Marching cubes of sum_i exp(-decay (|x - c_i|^2 / r_i^2 - 1)) at the level, as scikit-image
    returns it (default gradient direction: the triangles face the inside)."""
    import numpy as np
    from skimage import measure

    centers, radii = heavy_atoms(pdb, select)
    c, r = np.array(centers), np.array(radii)
    lo, hi = c.min(axis=0) - 6.0, c.max(axis=0) + 6.0
    shape = np.ceil((hi - lo) / grid).astype(int) + 1
    density = np.zeros(shape, dtype=np.float32)
    for center, radius in zip(c, r):
        reach = radius * np.sqrt(1.0 + 9.0 / decay)  # where the term falls below exp(-9)
        a = np.maximum(np.floor((center - reach - lo) / grid).astype(int), 0)
        b = np.minimum(np.ceil((center + reach - lo) / grid).astype(int) + 1, shape)
        axes = [lo[k] + grid * np.arange(a[k], b[k]) - center[k] for k in range(3)]
        d2 = axes[0][:, None, None] ** 2 + axes[1][None, :, None] ** 2 + axes[2][None, None, :] ** 2
        density[a[0]:b[0], a[1]:b[1], a[2]:b[2]] += np.exp(-decay * (d2 / radius ** 2 - 1.0))
    verts, faces, _, _ = measure.marching_cubes(density, level=level, spacing=(grid, grid, grid))
    verts += lo
    with open(path, "w") as f:
        f.write("# marching cubes of a Gaussian density (grid %g, decay %g, level %g)\n" % (grid, decay, level))
        for v in verts:
            f.write("v %.5f %.5f %.5f\n" % tuple(v))
        for t in faces:
            f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))


def generate(entry, out, timeout):
    """Makes one surface; returns its path, or None with the reason printed."""
    name, structure, generator, settings = entry
    pdb = structure_file(structure, out)
    if generator == "pymol":
        path = os.path.join(out, "%s.%s" % (name, settings["ext"]))
        script = os.path.join(out, "pymol_surface.py")
        with open(script, "w") as f:
            f.write(PYMOL_SCRIPT)
        argv = ["/usr/bin/python3", script, pdb, path, str(settings["quality"]), str(settings["cavity"])]
        try:
            subprocess.run(argv, check=True, timeout=timeout, stdout=subprocess.DEVNULL)
        except (subprocess.SubprocessError, OSError) as e:
            print("  %s: PyMOL failed: %s" % (name, e), file=sys.stderr)
            return None
    else:
        path = os.path.join(out, name + ".obj")
        gaussian_surface(pdb, path, settings["grid"], settings["decay"], settings["level"])
    return path if os.path.exists(path) else None


def make_fixtures(out):
    """The fixtures of tests/data (see FIXTURE_SELECTIONS)."""
    pdb = structure_file("1HPV", out)
    script = os.path.join(out, "pymol_fixture.py")
    with open(script, "w") as f:
        f.write(PYMOL_FIXTURE_SCRIPT)
    for key, selection in sorted(FIXTURE_SELECTIONS.items()):
        path = os.path.join(out, "1hpv_pymol_asp25_%s.obj" % key)
        subprocess.run(["/usr/bin/python3", script, pdb, path, selection], check=True, stdout=subprocess.DEVNULL)
        print(path)
    path = os.path.join(out, "1hpv_gaussian_inward_asp25_a.obj")
    gaussian_surface(pdb, path, 0.6, 1.0, 1.0, ("A", 25, 27))
    print(path)


def main():
    if len(sys.argv) == 7 and sys.argv[1] == "--gaussian":
        pdb, path, grid, decay, level = sys.argv[2:]
        gaussian_surface(pdb, path, float(grid), float(decay), float(level))
        return
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", help="folder the surfaces are written to (outside the repository)")
    p.add_argument("--fixtures", action="store_true", help="write the test fixtures of tests/data instead")
    p.add_argument("--only", nargs="*", help="names (or parts of names) of the inputs to make")
    p.add_argument("--timeout", type=float, default=1800)
    args = p.parse_args()
    out = os.path.abspath(args.out)
    if out == REPO or out.startswith(REPO + os.sep):
        sys.exit("make_broken_surfaces: write the surfaces outside the repository")
    os.makedirs(out, exist_ok=True)
    if args.fixtures:
        make_fixtures(out)
        return
    for entry in INPUTS:
        if args.only and not any(part in entry[0] for part in args.only):
            continue
        start = time.time()
        path = generate(entry, out, args.timeout)
        if path:
            print("%s: %s (%.0f s)" % (entry[0], path, time.time() - start), flush=True)


if __name__ == "__main__":
    main()
