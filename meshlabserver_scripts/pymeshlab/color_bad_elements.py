#!/usr/bin/env python3
"""Colors the triangles and vertices the remeshing removes (molremesh's Color Bad Elements) and
saves IN with the colors and qualities into OUT.

usage: color_bad_elements.py IN OUT [--small-angle A] [--obtuse-angle A]
Prints the counts (the filter's output values), one "name value" a line.
"""
import argparse
import sys

import molremesh_pymeshlab as molremesh


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--small-angle", type=float, default=30.0)
    parser.add_argument("--obtuse-angle", type=float, default=90.0)
    args = parser.parse_args()

    pymeshlab = molremesh.load()
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(args.input)
    try:
        counts = ms.apply_filter(molremesh.COLOR_BAD_ELEMENTS, smallangle=args.small_angle,
                                 obtuseangle=args.obtuse_angle)
    except pymeshlab.PyMeshLabException as error:
        sys.exit(f"color_bad_elements: {error}")
    ms.save_current_mesh(args.output, save_vertex_color=True, save_face_color=True,
                         save_vertex_quality=True, save_face_quality=True)
    molremesh.print_figures(counts)
    return 0


if __name__ == "__main__":
    sys.exit(main())
