#!/usr/bin/env python3
"""Whether a remeshed output's faces out of the angle bounds sit on thin parts of its input.

usage: thin_parts.py INPUT OUTPUT [--target-length L] [--build-dir build] [--random 400] [--seed 1]

A part of a surface thinner than the target edge length L (a neck of a Gaussian level set near a
critical level, a fin or tunnel of a coarse marching-cubes surface, a void pinched at its ends) has
an opposing sheet within L: a face of the input whose normal points the other way (cosine below
-0.3). For every output face with an angle below 30 or above 90 degrees, and for as many random
output faces, the script measures that gap from the face's centroid (the closest input face
centroid, then opposing input faces within 3 L of it) and prints both distributions in units of L.
L defaults to the `target_edge_length` of OUTPUT's `.json` report beside it (`molremesh remesh
--json OUTPUT.json`). Reads any format the CLI reads through the build's `mesh_convert`. Needs
python3-numpy and python3-scipy.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sas_per_atom import read_binary_ply  # noqa: E402


def load(path, build_dir, scratch):
    """Vertices and triangles of any mesh the CLI reads (converted to binary PLY by mesh_convert)."""
    out = os.path.join(scratch, os.path.basename(path) + ".ply")
    subprocess.run([os.path.join(build_dir, "benchmarks", "mesh_convert"), path, out], check=True)
    return read_binary_ply(out)


def face_angles(vertices, faces):
    """Smallest and largest angle of every triangle, in degrees."""
    p = vertices[faces]
    angles = []
    for k in range(3):
        u = p[:, (k + 1) % 3] - p[:, k]
        w = p[:, (k + 2) % 3] - p[:, k]
        cos = (u * w).sum(1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(w, axis=1) + 1e-300)
        angles.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
    angles = np.stack(angles, 1)
    return angles.min(1), angles.max(1)


class OpposingSheets:
    """Gap from a point to the input's opposing sheet, through the input's face centroids."""

    def __init__(self, vertices, faces, L):
        normals = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
        self.normals = normals / (np.linalg.norm(normals, axis=1)[:, None] + 1e-300)
        self.centroids = vertices[faces].mean(1)
        self.tree = cKDTree(self.centroids)
        self.L = L

    def gap(self, point):
        _, nearest = self.tree.query(point)
        facing = self.normals[nearest]
        best = np.inf
        for j in self.tree.query_ball_point(point, 3 * self.L):
            if self.normals[j] @ facing < -0.3:
                best = min(best, np.linalg.norm(self.centroids[j] - self.centroids[nearest]))
        return best / self.L


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--target-length", type=float, default=0)
    parser.add_argument("--build-dir", default="build")
    parser.add_argument("--random", type=int, default=400)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    L = args.target_length
    if not L > 0:
        with open(os.path.splitext(args.output)[0] + ".json") as f:
            L = json.load(f)["target_edge_length"]
    with tempfile.TemporaryDirectory() as scratch:
        vin, fin = load(args.input, args.build_dir, scratch)
        vout, fout = load(args.output, args.build_dir, scratch)
    sheets = OpposingSheets(vin, fin, L)
    lo, hi = face_angles(vout, fout)
    bad = np.where((lo < 30.0) | (hi > 90.0 + 1e-6))[0]
    rng = np.random.default_rng(args.seed)
    sample = rng.choice(len(fout), min(args.random, len(fout)), replace=False)
    centroids = vout[fout].mean(1)
    print("L = %.4f; quantiles 10/25/50/75/90 %% of the gap to the input's opposing sheet, in L" % L)
    for name, faces in (("out-of-bounds faces", bad), ("random faces", sample)):
        if len(faces) == 0:
            print("%-20s none" % name)
            continue
        gaps = np.array([sheets.gap(centroids[f]) for f in faces])
        # No opposing sheet within 3 L: reported as ">3".
        quantiles = " ".join("%.2f" % q if q < 3 else ">3" for q in np.quantile(np.minimum(gaps, 3.0), [0.1, 0.25, 0.5, 0.75, 0.9]))
        print("%-20s %6d  within 1 L: %5.1f %%  quantiles: %s" % (name, len(faces), 100 * np.mean(gaps < 1), quantiles))


if __name__ == "__main__":
    main()
