#!/usr/bin/env python3
"""Structure to surface: molremesh's extraction and its whole chain beside EDTSurf and PyMOL.

usage: surface_speed.py [--build-dir build] [--structures 4JSV 1HPV] [--out docs/results/RESULTS-surface-speed.md]

For each shared structure, in the same run on the same machine: EDTSurf's molecular surface at its
defaults (`EDTSurf -i PDB -o OUT`: vertex-connected marching cubes of the SES, probe 1.4 Å), PyMOL's
SES at its default quality (surface_quality 0, waters and hydrogens removed), `molremesh surface
--no-remesh` (the raw level-set SES, probe 1.4 Å, grid 0.4 Å) and `molremesh surface` (extraction and
the full pipeline at L = 1 Å). Each run is one process: wall-clock seconds and peak resident memory
(os.wait4), then the faces, area and validity of what it wrote (`molremesh report`, not timed). The
ratios are against EDTSurf's extraction measured in the same run: these machines are shared and noisy.
"""
import argparse
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_benchmarks import REPO, format_peak, run_json, run_measured  # noqa: E402
from unseen_inputs import PYMOL_SCRIPT, structure_file  # noqa: E402


def measure(name, argv, output, molremesh, timeout):
    """One generator run: seconds, peak MB and the report of its output."""
    run = run_measured(argv, timeout)
    row = {"method": name, "seconds": run.seconds, "peak_mb": run.peak_mb, "ok": run.ok and os.path.exists(output)}
    if not row["ok"]:
        row["why"] = run.why()
        return row
    report, _ = run_json([molremesh, "report", "--json", output], timeout)
    row["report"] = report
    return row


def bench(structure, molremesh, work, timeout):
    pdb = structure_file(structure, work)
    base = os.path.join(work, structure)
    pymol_script = os.path.join(work, "pymol_surface.py")
    with open(pymol_script, "w") as f:
        f.write(PYMOL_SCRIPT)
    runs = [
        ("EDTSurf (MS, VCMC, defaults)", ["EDTSurf", "-i", pdb, "-o", base + "_edtsurf"], base + "_edtsurf.ply"),
        # Debian's python3-pymol lives in the system interpreter, whatever python3 is first on PATH.
        ("PyMOL SES (surface_quality 0)", ["/usr/bin/python3", pymol_script, pdb, base + "_pymol.obj", "0"],
         base + "_pymol.obj"),
        ("molremesh surface --no-remesh", [molremesh, "surface", pdb, base + "_raw.ply", "--no-remesh", "--quiet"],
         base + "_raw.ply"),
        ("molremesh surface (extraction + remesh)", [molremesh, "surface", pdb, base + "_full.ply", "--quiet"],
         base + "_full.ply"),
    ]
    return [measure(name, argv, output, molremesh, timeout) for name, argv, output in runs]


def table(structure, rows):
    reference = rows[0]["seconds"] if rows[0]["ok"] else None
    lines = ["### %s" % structure, "",
             "| method | seconds | × EDTSurf | peak | faces | area (Å²) | θmin / θmax | SI | closed |",
             "|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        if not row["ok"]:
            lines.append("| %s | failed: %s | | | | | | | |" % (row["method"], row["why"]))
            continue
        r = row["report"] or {}
        ratio = "%.2f" % (row["seconds"] / reference) if reference else "n/a"
        closed = "yes" if r.get("boundary_edges") == 0 and r.get("non_manifold_edges") == 0 else "no"
        intersections = r.get("self_intersecting_pairs")
        if r.get("vertices") == 3 * r.get("faces", -1):
            # PyMOL's OBJ export: one vertex copy per corner, so no edge is shared and every corner
            # touch counts as a crossing; what it would be welded is the clean stage's business.
            closed, intersections = "soup", "n/a (soup)"
        lines.append("| %s | %.1f | %s | %s | %s | %.0f | %.1f° / %.1f° | %s | %s |" % (
            row["method"], row["seconds"], ratio, format_peak(row["peak_mb"]), r.get("faces"),
            r.get("area", float("nan")), r.get("angle_min_deg", float("nan")), r.get("angle_max_deg", float("nan")),
            intersections, closed))
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build-dir", default=os.path.join(REPO, "build"))
    parser.add_argument("--structures", nargs="+", default=["4JSV"])
    parser.add_argument("--timeout", type=float, default=3600)
    parser.add_argument("--out", default=os.path.join(REPO, "docs", "results", "RESULTS-surface-speed.md"))
    args = parser.parse_args()
    molremesh = os.path.join(os.path.abspath(args.build_dir), "cli", "molremesh")
    if not os.access(molremesh, os.X_OK):
        sys.exit("surface_speed: %s not found: build the target molremesh" % molremesh)
    text = ["# Structure to surface beside EDTSurf and PyMOL", "",
            "`python3 benchmarks/surface_speed.py --structures %s` (the method: the script's docstring). "
            "Seconds are wall-clock of one process each, in one run on this machine (2 cores, shared); "
            "× EDTSurf is against EDTSurf's extraction in the same run." % " ".join(args.structures), ""]
    with tempfile.TemporaryDirectory(prefix="molremesh_surface_speed_") as work:
        for structure in args.structures:
            print("surface_speed: %s ..." % structure, file=sys.stderr)
            text.append(table(structure, bench(structure, molremesh, work, args.timeout)))
    with open(args.out, "w") as f:
        f.write("\n".join(text))
    print("\n".join(text))


if __name__ == "__main__":
    main()
