#!/usr/bin/env python3
"""Writes the CGAL reference figures the tests compare with (tests/data/cgal_reference.json).

The tests never read benchmark results: this script extracts, from the JSON of a benchmark run
(benchmarks/run_baselines.py or any file of that layout: a list of {"mesh", "rows": [{"method",
"status", "report", ...}]}), the row of CGAL's isotropic remeshing on each shared mesh and keeps
the figures the tests need. Numbers are copied unchanged (full double precision), so a test that
compares with them asserts exactly what it asserted against the benchmark file.

usage: make_cgal_reference.py BENCHMARK_JSON [--out tests/data/cgal_reference.json]
"""
import argparse
import json
import sys

# Figures of CGAL's quality report the tests use, under the same names.
REPORT_KEYS = ("obtuse_percent", "angle_min_deg", "angle_max_deg", "q_min", "v567_percent")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("benchmark_json", help="JSON written by a benchmark run")
    parser.add_argument("--out", default="tests/data/cgal_reference.json", help="reference file to write")
    args = parser.parse_args()
    with open(args.benchmark_json) as f:
        runs = json.load(f)
    reference = {}
    for entry in runs:
        for row in entry.get("rows", []):
            if row.get("method") == "cgal" and row.get("status") == "ok":
                figures = {key: row["report"][key] for key in REPORT_KEYS}
                if "hausdorff_over_L" in row:
                    figures["hausdorff_over_L"] = row["hausdorff_over_L"]
                reference[entry["mesh"]] = figures
                break
    if not reference:
        sys.exit("make_cgal_reference: no successful CGAL row in " + args.benchmark_json)
    with open(args.out, "w") as f:
        json.dump(dict(sorted(reference.items())), f, indent=2)
        f.write("\n")
    print("make_cgal_reference: %d meshes -> %s" % (len(reference), args.out))


if __name__ == "__main__":
    main()
