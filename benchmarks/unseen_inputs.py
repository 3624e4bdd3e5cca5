#!/usr/bin/env python3
"""molremesh on molecular surfaces it was never tuned on: generated here, from the shared structures.

The ten shared meshes are what the pipeline was developed and tested on. This runner makes other
surfaces of the shared PDB files (../shared/data/structures) with the generators Debian ships,
in settings the shared meshes do not cover: EDTSurf's marching cubes (-t 1) and vertex-connected
marching cubes (-t 2) on its van der Waals (-s 1), solvent-accessible (-s 2), molecular (-s 3) and
solvent-excluded (-s 4) surfaces at several grid scales, and PyMOL's SES at surface qualities -1,
0 and 1 (saved as OBJ, one vertex copy per triangle corner: the clean stage welds them). Then it
runs the full pipeline (`molremesh remesh IN OUT`) on each and, with --stage3, the first half
(`--stages clean,cvt,segment,rar`), and tabulates what the outputs keep of the promises: angles,
V567, obtuse faces, self-intersections, boundary, components, genus, TetGen, the exit status and
the CLI's warnings (its verdict), time and peak memory.

Needs Debian's edtsurf and python3-pymol (scripts/install_deps.sh --unseen) and tetgen for the
TetGen column. Writes docs/results/RESULTS-unseen.md (--out) and the raw figures (--json, by
default under the build folder).
"""

import argparse
import datetime
import gzip
import json
import os
import shutil
import subprocess
import sys
import tempfile
import types

from run_benchmarks import REPO, Tools, format_peak, run_measured

STRUCTURES = os.path.normpath(os.path.join(REPO, "..", "shared", "data", "structures"))

# name -> (structure, generator, arguments). EDTSurf: -t 1 MC / 2 VCMC, -s 1 VWS / 2 SAS / 3 MS /
# 4 SES, -f grid scale, -p probe radius. PyMOL: surface_quality.
INPUTS = [
    ("1TII_edtsurf_mc_ses_f1", "1TII", "edtsurf", ["-t", "1", "-s", "4", "-f", "1"]),
    ("1TII_edtsurf_vcmc_ms_f1", "1TII", "edtsurf", ["-t", "2", "-s", "3", "-f", "1"]),
    ("1TII_edtsurf_mc_ses", "1TII", "edtsurf", ["-t", "1", "-s", "4"]),
    ("1MAH_edtsurf_mc_vws_f1", "1MAH", "edtsurf", ["-t", "1", "-s", "1", "-f", "1"]),
    ("1HPV_edtsurf_mc_sas_f1", "1HPV", "edtsurf", ["-t", "1", "-s", "2", "-f", "1"]),
    ("4JSV_edtsurf_vcmc_ses_f1", "4JSV", "edtsurf", ["-t", "2", "-s", "4", "-f", "1"]),
    ("1UBQ_edtsurf_mc_ses_p05", "1UBQ", "edtsurf", ["-t", "1", "-s", "4", "-p", "0.5"]),
    ("1UBQ_edtsurf_mc_ses_f3", "1UBQ", "edtsurf", ["-t", "1", "-s", "4", "-f", "3"]),
    ("1UBQ_edtsurf_vcmc_ms_f15", "1UBQ", "edtsurf", ["-t", "2", "-s", "3", "-c", "2", "-f", "1.5"]),
    ("1UBQ_edtsurf_vcmc_vws_f2", "1UBQ", "edtsurf", ["-t", "2", "-s", "1", "-f", "2"]),
    ("1HPV_pymol_ses_q0", "1HPV", "pymol", ["0"]),
    ("1TII_pymol_ses_q0", "1TII", "pymol", ["0"]),
    ("1UBQ_pymol_ses_q1", "1UBQ", "pymol", ["1"]),
    ("1MAH_pymol_ses_qm1", "1MAH", "pymol", ["-1"]),
]

PYMOL_SCRIPT = """
import sys
from pymol import cmd
cmd.load(sys.argv[1], 'm')
cmd.remove('solvent')
cmd.remove('hydro')
cmd.set('surface_quality', int(sys.argv[3]))
cmd.set('surface_type', 0)
cmd.show('surface')
cmd.save(sys.argv[2])
"""


def structure_file(name, work):
    """The PDB file of a shared structure (unzipped into work when it is gzipped)."""
    plain = os.path.join(STRUCTURES, name + ".pdb")
    if os.path.exists(plain):
        return plain
    unzipped = os.path.join(work, name + ".pdb")
    if not os.path.exists(unzipped):
        with gzip.open(plain + ".gz", "rb") as src, open(unzipped, "wb") as dst:
            shutil.copyfileobj(src, dst)
    return unzipped


def generate(entry, work, timeout):
    """Makes the input surface; returns its path, or None with the reason printed."""
    name, structure, generator, extra = entry
    pdb = structure_file(structure, work)
    if generator == "edtsurf":
        path = os.path.join(work, name + ".ply")
        argv = ["EDTSurf", "-i", pdb, "-o", os.path.join(work, name)] + extra
    else:
        path = os.path.join(work, name + ".obj")
        script = os.path.join(work, "pymol_surface.py")
        with open(script, "w") as f:
            f.write(PYMOL_SCRIPT)
        # Debian's python3-pymol lives in the system interpreter, whatever python3 is first on PATH.
        argv = ["/usr/bin/python3", script, pdb, path] + extra
    if not os.path.exists(path):
        r = run_measured(argv, timeout)
        if not r.ok or not os.path.exists(path):
            print("  %s: the generator failed: %s" % (name, r.why()), file=sys.stderr)
            return None
    return path


def remesh(tools, mesh, output, stages, timeout):
    """Runs the CLI; returns the row of figures (input and output reports, verdict, run)."""
    json_path = output + ".json"
    argv = [tools.molremesh, "remesh", mesh, output, "--quiet", "--json", json_path]
    if stages:
        argv += ["--stages", stages]
    r = run_measured(argv, timeout)
    row = {"exit": r.code, "seconds": r.seconds, "peak_mb": r.peak_mb,
           "warnings": [l for l in r.stderr.splitlines() if l.startswith("molremesh: warning:")]}
    if r.code in (0, 3) and os.path.exists(json_path):
        with open(json_path) as f:
            data = json.load(f)
        row["input"], row["output"] = data["input"], data["stages"][-1]["after"]
        row["cleaned"] = data["stages"][0]["after"]
        row["verdict"] = data.get("verdict")
        row["tetgen"] = tools.tetgen_check(output, os.path.dirname(output))
    else:
        row["error"] = r.why()
    return row


def compact(result, work):
    """The result as committed: reports without their per-component and valence lists (a PyMOL soup
    has one component per triangle) and paths relative to the work folder."""
    out = dict(result)
    for key in ("input", "cleaned", "output"):
        if key in out:
            report = dict(out[key])
            genera = sorted((c.get("genus") for c in report.pop("component_info", [])),
                            key=lambda g: (g is None, g or 0))
            report["component_genera"] = genera if len(genera) <= 50 else "%d components" % len(genera)
            report.pop("valence_histogram", None)
            out[key] = report
    out["warnings"] = [w.replace(work.rstrip("/") + "/", "") for w in out.get("warnings", [])]
    return out


def genus_kept(row):
    """'yes' when the output's components have the genera of the cleaned input's (the components the
    clean stage kept), else both lists."""
    def genera(report):
        return sorted((c.get("genus") for c in report.get("component_info", [])), key=lambda g: (g is None, g or 0))

    out, kept = genera(row["output"]), genera(row["cleaned"])
    return "yes" if out == kept else "%s → %s" % (kept, out)


def cells(name, row):
    if "output" not in row:
        return [name, "–", "failed: " + row.get("error", "?")] + ["–"] * 11
    i, o = row["input"], row["output"]
    return [name, "%d → %d" % (i["faces"], o["faces"]),
            "%.1f–%.1f" % (o["angle_min_deg"], o["angle_max_deg"]), "%.2f" % o["v567_percent"],
            "%d" % o["obtuse_faces"],
            "%d → %d" % (i["self_intersecting_pairs"], o["self_intersecting_pairs"]),
            "%d → %d" % (i["boundary_edges"], o["boundary_edges"]),
            "%d → %d" % (i["components"], o["components"]), genus_kept(row),
            row.get("tetgen") or "n/a", "%d" % row["exit"], "%d" % len(row["warnings"]),
            "%.1f" % row["seconds"], format_peak(row["peak_mb"])]


HEADER = ["input", "faces", "θ out", "V567 %", "obtuse", "SI pairs", "boundary edges", "components",
          "genus kept", "TetGen", "exit", "warnings", "s", "peak MB"]


def table(rows):
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build-dir", default=os.path.join(REPO, "build"))
    p.add_argument("--work", help="folder for the generated inputs and the outputs (default: a temporary one)")
    p.add_argument("--only", nargs="*", help="names (or parts of names) of the inputs to run")
    p.add_argument("--stage3", action="store_true", help="also run clean,cvt,segment,rar")
    p.add_argument("--timeout", type=float, default=3600)
    p.add_argument("--tetgen-timeout", type=float, default=1200)
    p.add_argument("--out", default=os.path.join(REPO, "docs", "results", "RESULTS-unseen.md"),
                   help="Markdown file written with the tables (%(default)s)")
    p.add_argument("--json", help="JSON file written with the raw figures (default: "
                                  "BUILD/benchmarks/RESULTS-unseen.json; raw figures are not committed)")
    args = p.parse_args()
    if args.json is None:
        args.json = os.path.join(args.build_dir, "benchmarks", "RESULTS-unseen.json")
    for tool in ("EDTSurf", "tetgen"):
        if not shutil.which(tool):
            print("unseen_inputs: %s not found (Debian packages edtsurf, tetgen: scripts/install_deps.sh "
                  "--unseen)" % tool, file=sys.stderr)
    tools = Tools(types.SimpleNamespace(build_dir=args.build_dir, tetgen_timeout=args.tetgen_timeout))
    if not os.access(tools.molremesh, os.X_OK) or not os.access(tools.mesh_convert, os.X_OK):
        sys.exit("unseen_inputs: build the targets molremesh and mesh_convert in %s first" % args.build_dir)
    work = args.work or tempfile.mkdtemp(prefix="molremesh_unseen_")
    os.makedirs(work, exist_ok=True)
    modes = [("full pipeline", "")] + ([("clean, CVT, segment, RAR", "clean,cvt,segment,rar")] if args.stage3 else [])
    results, tables = [], {mode: [] for mode, _ in modes}
    for entry in INPUTS:
        if args.only and not any(part in entry[0] for part in args.only):
            continue
        path = generate(entry, work, args.timeout)
        if path is None:
            continue
        for mode, stages in modes:
            output = os.path.join(work, "%s.%s.ply" % (entry[0], "s3" if stages else "full"))
            print("%s: %s ..." % (entry[0], mode), file=sys.stderr, flush=True)
            row = remesh(tools, path, output, stages, args.timeout)
            results.append({"name": entry[0], "generator": entry[2], "arguments": entry[3], "mode": mode,
                            **row})
            tables[mode].append(cells(entry[0], row))
    text = ["# molremesh on generated inputs it was not developed on", "",
            "Made by `benchmarks/unseen_inputs.py` on %s. Inputs: the shared structures through Debian's "
            "EDTSurf and PyMOL (settings in the script); each run is one process of the CLI with its "
            "defaults. θ, V567, obtuse faces and SI pairs are the output's; *warnings* counts the CLI's "
            "`molremesh: warning:` lines (its verdict on the promises), *exit* 3 = written but not valid."
            % datetime.date.today().isoformat(), ""]
    for mode, _ in modes:
        text += ["## " + mode, "", table(tables[mode]), ""]
    text += ["## Warnings", ""]
    for r in results:
        for w in r.get("warnings", []):
            text.append("- %s (%s): %s" % (r["name"], r["mode"], w.split(": ", 2)[-1].split(" ", 1)[-1]))
    with open(args.out, "w") as f:
        f.write("\n".join(text) + "\n")
    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    with open(args.json, "w") as f:
        json.dump([compact(r, work) for r in results], f, indent=1)
    print("\n".join(text))


if __name__ == "__main__":
    main()
