#!/usr/bin/env python3
"""Quality report of a mesh in PyMeshLab (the Quality Report filter of molremesh).

usage: report.py IN [--no-self-intersections]
Prints the figures (the filter's output values), one "name value" a line.
"""
import argparse
import sys

import molremesh_pymeshlab as molremesh


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input")
    parser.add_argument("--no-self-intersections", action="store_true",
                        help="skip the self-intersection count (the slowest figure)")
    args = parser.parse_args()

    pymeshlab = molremesh.load()
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(args.input)
    try:
        figures = ms.apply_filter(molremesh.QUALITY_REPORT,
                                  selfintersections=not args.no_self_intersections)
    except pymeshlab.PyMeshLabException as error:
        sys.exit(f"report: {error}")
    molremesh.print_figures(figures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
