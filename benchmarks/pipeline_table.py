#!/usr/bin/env python3
"""Runs `molremesh remesh` (the full pipeline, or --stages) on the shared meshes and prints Markdown
tables of what each stage reached, from the CLI's --json report:

  * the full pipeline, before (raw input) and after, per mesh: faces, θmin, θmax, Qmin, V567,
    % obtuse, % < 30°, self-intersecting pairs, genus, volume change against the cleaned input,
    time and peak memory of the whole run, TetGen on the output (optional);
  * the valence stage: V567 and irregular vertices after CVT and after valence optimization, the
    stage's time against the CVT stage's;
  * per-stage wall times.

usage: pipeline_table.py [--build-dir BUILD] [--meshes a.ply,b.ply] [--stages LIST] [--out FILE]
                         [--json FILE] [--tetgen]

The tables go to docs/results/pipeline-<stages>.md (--out); the raw stage reports only with --json
(raw figures are not committed: give a path outside the source tree, such as build/benchmarks/).
"""
import argparse
import json
import os
import shutil
import sys
import tempfile

from run_benchmarks import run_measured  # the benchmark runner's timing (os.wait4)

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESHES = os.path.join(REPO, "..", "shared", "data", "meshes")


def run(argv, timeout=3600):
    """Runs argv; returns (exit code, stdout, stderr, wall seconds, peak MB of this child)."""
    r = run_measured(argv, timeout)
    return (124 if r.timed_out else r.code), r.stdout, r.stderr, r.seconds, r.peak_mb


def tetgen_ok(build, mesh_file, work):
    """'yes (N tets)' or 'no (...)': tetgen -pq1.4 on an OFF copy (benchmark_tools' mesh_convert)."""
    tetgen = shutil.which("tetgen")
    convert = os.path.join(build, "benchmarks", "mesh_convert")
    if not tetgen or not os.path.exists(convert):
        return "n/a"
    off = os.path.join(work, "surface.off")
    code, _, err, _, _ = run([convert, mesh_file, off])
    if code != 0:
        return "no (conversion: %s)" % err.strip()[:60]
    code, out, err, wall, _ = run([tetgen, "-pq1.4", "-Q", off], timeout=1800)
    ele = os.path.join(work, "surface.1.ele")
    if code != 0 or not os.path.exists(ele):
        return "no (exit %d)" % code
    with open(ele) as f:
        tets = int(f.readline().split()[0])
    return "yes (%d tets, %.0f s)" % (tets, wall)


def fmt(x, digits=2):
    return "n/a" if x is None else ("%.*f" % (digits, x))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build-dir", default=os.path.join(REPO, "build"))
    ap.add_argument("--meshes", default="", help="comma-separated file names in ../shared/data/meshes")
    ap.add_argument("--stages", default="", help="--stages of molremesh remesh (default: all)")
    ap.add_argument("--out", help="Markdown file written with the tables (default: "
                                  "docs/results/pipeline-<stages>.md, pipeline-full.md without --stages); "
                                  "'-' to print them only")
    ap.add_argument("--json", default="", help="also write every stage report to this file")
    ap.add_argument("--tetgen", action="store_true", help="run tetgen -pq1.4 on every output")
    args = ap.parse_args()
    if args.out is None:
        name = "pipeline-%s.md" % (args.stages.replace(",", "-") if args.stages else "full")
        args.out = os.path.join(REPO, "docs", "results", name)

    cli = os.path.join(args.build_dir, "cli", "molremesh")
    if not os.path.exists(cli):
        sys.exit("pipeline_table: %s not found (build first)" % cli)
    names = [m for m in args.meshes.split(",") if m] or sorted(f for f in os.listdir(MESHES) if f.endswith(".ply"))
    results = []
    with tempfile.TemporaryDirectory(prefix="molremesh_table_") as work:
        for name in names:
            out_mesh = os.path.join(work, "out.ply")
            out_json = os.path.join(work, "out.json")
            argv = [cli, "remesh", "--quiet", os.path.join(MESHES, name), out_mesh, "--json", out_json]
            if args.stages:
                argv += ["--stages", args.stages]
            code, out, err, wall, peak = run(argv)
            entry = {"mesh": name, "exit": code, "wall_s": wall, "peak_mb": peak}
            if code == 0:
                with open(out_json) as f:
                    entry["run"] = json.load(f)
                if args.tetgen:
                    entry["tetgen"] = tetgen_ok(args.build_dir, out_mesh, work)
            else:
                entry["error"] = err.strip().splitlines()[-1] if err.strip() else "exit %d" % code
            print("pipeline_table: %s %s (%.1f s)" % (name, "ok" if code == 0 else entry["error"], wall),
                  file=sys.stderr)
            results.append(entry)

    lines = []
    lines.append("| mesh | faces in → out | θmin | θmax | Qmin | V567 % | obtuse % | % < 30° | SI pairs | "
                 "genus | volume vs cleaned % | time s | peak MB | TetGen |")
    lines.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for e in results:
        if "run" not in e:
            lines.append("| %s | failed: %s |" % (e["mesh"], e.get("error", "")))
            continue
        i = e["run"]["input"]
        stages = e["run"]["stages"]
        o = stages[-1]["after"]
        cleaned = next((s["after"] for s in stages if s["name"] == "clean"), i)
        dv = 100.0 * (o["volume"] / cleaned["volume"] - 1.0) if cleaned.get("volume") else None
        pair = lambda key, d=2: "%s → %s" % (fmt(i.get(key), d), fmt(o.get(key), d))
        genus = lambda r: "n/a" if r.get("genus") is None or r.get("genus", -1) < 0 else str(r["genus"])
        lines.append("| %s | %d → %d | %s | %s | %s | %s | %s | %s | %d → %d | %s → %s | %s | %.1f | %.0f | %s |" % (
            e["mesh"].replace(".ply", ""), i["faces"], o["faces"], pair("angle_min_deg"), pair("angle_max_deg"),
            pair("q_min", 3), pair("v567_percent"), pair("obtuse_percent"), pair("small_angle_percent"),
            i["self_intersecting_pairs"], o["self_intersecting_pairs"], genus(i), genus(o), fmt(dv, 3),
            e["wall_s"], e["peak_mb"], e.get("tetgen", "not run")))
    lines.append("")
    names_of = lambda e: [s["name"] for s in e["run"]["stages"]] if "run" in e else []
    if any("valence" in names_of(e) and "cvt" in names_of(e) for e in results):
        lines.append("| mesh | V567 % after CVT | after valence | irregular vertices | valence s | CVT s | valence / CVT |")
        lines.append("|---|---|---|---|---|---|---|")
        for e in results:
            if "valence" not in names_of(e):
                continue
            st = {s["name"]: s for s in e["run"]["stages"]}
            c, v = st["cvt"]["after"], st["valence"]["after"]
            irr = lambda r: r["interior_vertices"] - r["regular_vertices"]
            lines.append("| %s | %.2f | %.2f | %d → %d | %.2f | %.2f | %.1f %% |" % (
                e["mesh"].replace(".ply", ""), c["v567_percent"], v["v567_percent"], irr(c), irr(v),
                st["valence"]["seconds"], st["cvt"]["seconds"], 100 * st["valence"]["seconds"] / st["cvt"]["seconds"]))
        lines.append("")
    stage_names = []
    for e in results:
        for n in names_of(e):
            if n not in stage_names:
                stage_names.append(n)
    lines.append("| mesh | " + " | ".join(stage_names) + " | total s |")
    lines.append("|---|" + "---|" * (len(stage_names) + 1))
    for e in results:
        if "run" not in e:
            continue
        st = {s["name"]: s["seconds"] for s in e["run"]["stages"]}
        lines.append("| %s | %s | %.1f |" % (e["mesh"].replace(".ply", ""),
                                             " | ".join(fmt(st.get(n)) for n in stage_names), e["run"]["seconds"]))
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out != "-":
        with open(args.out, "w") as f:
            f.write(text)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
