#!/usr/bin/env python3
"""Molecular remeshing of IN into OUT in PyMeshLab (the Full Pipeline filter of molremesh).

usage: full_pipeline.py IN OUT [--target-length L] [--min-angle A] [--max-angle A]
                        [--surface-lift S] [--seed N] [--threads N] [--memory-limit MB] [--quiet]
Prints the quality figures of the result (the filter's output values), one "name value" a line.
"""
import argparse
import sys

import molremesh_pymeshlab as molremesh


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--target-length", type=float, default=0.0,
                        help="edge length (mesh units); 0 = the input's mean edge length")
    parser.add_argument("--min-angle", type=float, default=30.0)
    parser.add_argument("--max-angle", type=float, default=120.0)
    parser.add_argument("--surface-lift", type=float, default=0.5)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--memory-limit", type=float, default=0.0,
                        help="MB; 0 = the memory available, -1 = no check")
    parser.add_argument("--quiet", action="store_true", help="print nothing")
    args = parser.parse_args()

    pymeshlab = molremesh.load()
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(args.input)
    try:
        figures = ms.apply_filter(molremesh.FULL_PIPELINE,
                                  targetlength=molremesh.length_value(pymeshlab, args.target_length),
                                  minangle=args.min_angle, maxangle=args.max_angle,
                                  surfacelift=args.surface_lift, seed=args.seed, threads=args.threads,
                                  memorylimit=args.memory_limit, newlayer=False)
    except pymeshlab.PyMeshLabException as error:
        sys.exit(f"full_pipeline: {error}")
    ms.save_current_mesh(args.output, save_vertex_color=False, save_vertex_normal=False,
                         save_face_color=False)
    if not args.quiet:
        molremesh.print_figures(figures)
    return 0 if figures.get("valid", True) else 2


if __name__ == "__main__":
    sys.exit(main())
