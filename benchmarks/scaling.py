#!/usr/bin/env python3
"""How molremesh's cost per face grows with the input, beside CGAL's isotropic remeshing.

Makes a family of raw solvent-excluded surfaces from the shared structures with `molremesh surface
--no-remesh` (the level set's own triangles, before any remeshing) at grid spacings that span about
10k to 2.5M faces, adds the meshes given with --meshes, and remeshes every input at its own mean edge
length L:

  molremesh   `molremesh remesh IN OUT` (the full pipeline, all cores), and with --one-thread also
              `--threads 1` (the serial efficiency)
  cgal        benchmarks/cgal_isotropic_remesh, 10 iterations at L (CGAL is serial)

Each run is one process, timed with the wall clock, its peak resident memory from os.wait4. The
machine's parallel throughput is measured before and after (2.00 = two cores). Every molremesh output
is checked with `molremesh report --json` (angles, V567, self-intersections).

Writes a Markdown table to --out (default docs/results/RESULTS-scaling.md), a picture of seconds and
KB per input face against input faces to --plot (default docs/images/scaling.png; needs
python3-matplotlib) and the raw figures to --json (default <build>/benchmarks/RESULTS-scaling.json).
"""

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run_benchmarks as rb  # noqa: E402  (the process runner and the throughput probe)

STRUCTURES = os.path.normpath(os.path.join(rb.REPO, "..", "shared", "data", "structures"))

# (name, structure, grid spacing in Å): raw SES level sets from about 10k to 2.5M faces.
FAMILY = [
    ("1UBQ_ses_h1.0", "1UBQ.pqr", 1.0),
    ("1UBQ_ses_h0.5", "1UBQ.pqr", 0.5),
    ("1HPV_ses_h0.4", "1HPV.pqr", 0.4),
    ("4JSV_ses_h0.8", "4JSV.pqr.gz", 0.8),
    ("4JSV_ses_h0.5", "4JSV.pqr.gz", 0.5),
    ("4JSV_ses_h0.36", "4JSV.pqr.gz", 0.36),
]


def make_input(tools, name, structure, grid, work, timeout):
    """The raw SES of `structure` at `grid` as a PLY in work (made once, reused when present)."""
    out = os.path.join(work, name + ".ply")
    if os.path.exists(out):
        return out
    source = os.path.join(STRUCTURES, structure)
    if not os.path.exists(source):
        print("scaling: %s not found, %s skipped" % (source, name), file=sys.stderr)
        return None
    argv = [tools.molremesh, "surface", source, out, "--no-remesh", "--grid", str(grid), "--quiet"]
    run = rb.run_measured(argv, timeout)
    if not run.ok:
        print("scaling: making %s failed: %s" % (name, run.why()), file=sys.stderr)
        return None
    return out


def output_figures(tools, mesh):
    report = tools.report(mesh)
    if not report:
        return {}
    keys = ("faces", "angle_min_deg", "angle_max_deg", "v567_percent", "self_intersecting_pairs", "obtuse_faces")
    return {k: report.get(k) for k in keys}


def measure(tools, args, argv, output, work, label):
    run = rb.run_measured(argv, args.timeout, log_prefix=os.path.join(work, label))
    row = {"seconds": round(run.seconds, 2), "peak_mb": round(run.peak_mb or 0.0, 1), "ok": run.ok}
    if not run.ok:
        row["why"] = run.why()
    elif output and args.check_outputs:
        row.update(output_figures(tools, output))
    print("  %-14s %8.1f s %8.0f MB%s" % (label, run.seconds, run.peak_mb or 0, "" if run.ok else "  " + run.why()),
          flush=True)
    return row


def bench_input(tools, args, mesh, work):
    report = tools.report(mesh)
    if not report:
        return None
    faces, length = report["faces"], report["mean_edge_length"]
    name = os.path.splitext(os.path.basename(mesh))[0]
    print("%s: %d faces, L = %.4f" % (name, faces, length), flush=True)
    result = {"mesh": rb.portable_path(mesh), "faces_in": faces, "target_edge_length": length}
    out = os.path.join(work, name + "_molremesh.ply")
    result["molremesh"] = measure(tools, args, [tools.molremesh, "remesh", mesh, out, "--quiet"], out, work,
                                  name + "_molremesh")
    if args.one_thread:
        out1 = os.path.join(work, name + "_molremesh_t1.ply")
        argv = [tools.molremesh, "remesh", mesh, out1, "--quiet", "--threads", "1"]
        result["molremesh_t1"] = measure(tools, args, argv, None, work, name + "_molremesh_t1")
    if not args.skip_cgal:
        outc = os.path.join(work, name + "_cgal.ply")
        argv = [tools.cgal, mesh, outc, "--target", "%.9g" % length, "--iterations", "10"]
        result["cgal"] = measure(tools, args, argv, None, work, name + "_cgal")
    return result


METHODS = (("molremesh", "molremesh"), ("molremesh_t1", "molremesh 1 thread"), ("cgal", "CGAL"))


def per_face(row, faces):
    """Microseconds and KB per input face of one run."""
    return 1e6 * row["seconds"] / faces, 1024.0 * row["peak_mb"] / faces


def ratio(results, key):
    a, b = results.get(key), results.get("cgal")
    if not a or not b or not a["ok"] or not b["ok"]:
        return "n/a", "n/a"
    return "%.2f" % (a["seconds"] / b["seconds"]), "%.2f" % (a["peak_mb"] / b["peak_mb"])


def markdown(results, header):
    lines = header + ["", "| input | faces in | method | s | MB | µs/face | KB/face | ×CGAL time | ×CGAL memory "
                      "| θmin–θmax | V567 % | SI |", "|---|---:|---|---:|---:|---:|---:|---:|---:|---|---:|---:|"]
    for r in results:
        for key, label in METHODS:
            row = r.get(key)
            if not row:
                continue
            us, kb = per_face(row, r["faces_in"])
            t, m = ratio(r, key) if key != "cgal" else ("1", "1")
            quality = "n/a", "n/a", "n/a"
            if row.get("angle_min_deg") is not None:
                quality = ("%.1f–%.1f" % (row["angle_min_deg"], row["angle_max_deg"]), "%.2f" % row["v567_percent"],
                           str(row["self_intersecting_pairs"]))
            lines.append("| %s | %d | %s | %.1f | %.0f | %.1f | %.2f | %s | %s | %s | %s | %s |" % (
                os.path.basename(r["mesh"]), r["faces_in"], label, row["seconds"], row["peak_mb"], us, kb, t, m,
                *quality) if row["ok"] else "| %s | %d | %s | failed: %s | | | | | | | | |" % (
                os.path.basename(r["mesh"]), r["faces_in"], label, row.get("why", "")))
    return "\n".join(lines) + "\n"


def plot(results, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("scaling: matplotlib not found (Debian package python3-matplotlib): no plot", file=sys.stderr)
        return
    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(10, 4))
    for key, label in METHODS:
        rows = sorted((r["faces_in"], r[key]) for r in results if r.get(key) and r[key]["ok"])
        if not rows:
            continue
        faces = [f for f, _ in rows]
        ax_t.plot(faces, [per_face(row, f)[0] for f, row in rows], "o-", label=label)
        ax_m.plot(faces, [per_face(row, f)[1] for f, row in rows], "o-", label=label)
    for ax, what in ((ax_t, "wall µs per input face"), (ax_m, "peak KB per input face")):
        ax.set_xscale("log")
        ax.set_xlabel("input faces")
        ax.set_ylabel(what)
        ax.set_ylim(bottom=0)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle("molremesh full pipeline and CGAL isotropic remeshing (10 iterations), same machine and run")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("scaling: plot written to %s" % path)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build-dir", default=os.path.join(rb.REPO, "build"), help="CMake build folder (%(default)s)")
    p.add_argument("--meshes", nargs="*", default=[], help="more input meshes (e.g. the shared 1HPV and 4JSV)")
    p.add_argument("--only", nargs="*", help="only these inputs of the generated family (names)")
    p.add_argument("--no-family", action="store_true", help="only the --meshes, no generated surfaces")
    p.add_argument("--one-thread", action="store_true", help="also run molremesh on one thread")
    p.add_argument("--skip-cgal", action="store_true")
    p.add_argument("--no-check", dest="check_outputs", action="store_false",
                   help="skip the quality report of molremesh's outputs")
    p.add_argument("--work-dir", help="inputs, outputs and logs (default: a temporary folder, removed)")
    p.add_argument("--timeout", type=float, default=3600, help="seconds allowed to each run (%(default)s)")
    p.add_argument("--out", default=os.path.join(rb.REPO, "docs", "results", "RESULTS-scaling.md"))
    p.add_argument("--plot", default=os.path.join(rb.REPO, "docs", "images", "scaling.png"))
    p.add_argument("--json")
    p.add_argument("--from-json", help="only render the table and the plot of an earlier run's JSON")
    args = p.parse_args()
    if args.from_json:
        with open(args.from_json) as f:
            data = json.load(f)
        render(data["results"], data["throughput_before"], data["throughput_after"], data.get("date"), args)
        return
    tools = rb.Tools(args)
    needed = [tools.molremesh] + ([] if args.skip_cgal else [tools.cgal])
    for path in needed:
        if not os.access(path, os.X_OK):
            sys.exit("scaling: %s not found: build the targets molremesh and cgal_isotropic_remesh "
                     "(libcgal-dev: scripts/install_deps.sh --benchmarks)" % path)
    work = os.path.abspath(args.work_dir) if args.work_dir else tempfile.mkdtemp(prefix="molremesh_scaling_")
    os.makedirs(work, exist_ok=True)
    rb.MEMORY_FLOOR_MB[0] = rb.run_measured([sys.executable, "-c", "pass"], 60).peak_mb or 0.0

    inputs = [os.path.abspath(m) for m in args.meshes]
    if not args.no_family:
        for name, structure, grid in FAMILY:
            if args.only and name not in args.only:
                continue
            made = make_input(tools, name, structure, grid, work, args.timeout)
            if made:
                inputs.append(made)
    before = rb.parallel_throughput()
    results = [r for r in (bench_input(tools, args, m, work) for m in inputs) if r]
    after = rb.parallel_throughput()
    results.sort(key=lambda r: r["faces_in"])

    data = {"date": datetime.date.today().isoformat(), "throughput_before": before, "throughput_after": after,
            "results": results}
    json_path = args.json or os.path.join(os.path.abspath(args.build_dir), "benchmarks", "RESULTS-scaling.json")
    os.makedirs(os.path.dirname(json_path), exist_ok=True)
    with open(json_path, "w") as f:
        json.dump(data, f, indent=1)
    render(results, before, after, data["date"], args)


def render(results, before, after, date, args):
    header = ["# Cost per face against input size", "",
              "Generated by `benchmarks/scaling.py` on %s (%s, %d cores); see docs/benchmarks.md#scaling." % (
                  date or "an unrecorded date", platform.machine(), os.cpu_count() or 0),
              rb.describe_throughput("before", before), rb.describe_throughput("after", after),
              "- Every run is one whole process (reading and writing included); molremesh uses all cores, CGAL "
              "is serial. Ratios are molremesh's over CGAL's on the same input in the same run."]
    table = markdown(results, header)
    print(table)
    with open(args.out, "w") as f:
        f.write(table)
    if args.plot:
        plot(results, args.plot)

if __name__ == "__main__":
    main()
