#!/usr/bin/env python3
"""molremesh on molecular surfaces it was never tuned on: generated here, from the shared structures.

The ten shared meshes are what the pipeline was developed and tested on. This runner makes other
surfaces of the shared structures (../shared/data/structures) with the generators Debian ships, in
settings the shared meshes do not cover (INPUTS): EDTSurf's marching cubes and vertex-connected
marching cubes of its four surface kinds at four grid scales; PyMOL's SES at surface qualities -1
to 2, probe radii 1.0, 1.4 and 2.0 Å, with and without cavity mode, exported as OBJ and WRL soups
(one vertex per triangle corner), of single chains and of the multi-chain complexes, whose sheets
interpenetrate; and marching cubes of a Gaussian density (TMSmesh's kind of surface), which face
inward. Then it runs the full pipeline (`molremesh remesh IN OUT`, the CLI's defaults) on each and,
with --stage3, the first half (`--stages clean,cvt,segment,rar`), and with --meshlabserver the
plugin's Full Pipeline filter through the build's sandboxed meshlabserver
(meshlabserver_scripts/full_pipeline.mlx), and tabulates per input the
defects in, the verdict out, angles, obtuse faces, V567, the volume and area change and Hausdorff
distance against the union the input encloses, the volumetric rebuild, TetGen, time and peak memory.

Run it with the system interpreter (/usr/bin/python3: Debian's python3-pymol, python3-skimage).
Needs edtsurf, python3-pymol, python3-skimage (scripts/install_deps.sh --unseen) and tetgen, and
the build targets molremesh, mesh_convert, mesh_distance and volumetric_rebuild (and
meshlabserver_sandbox for --meshlabserver). Writes
docs/results/RESULTS-unseen.md (--out) and the raw figures (--json, by default under the build
folder).
"""

import argparse
import datetime
import gzip
import json
import os
import shutil
import shlex
import sys
import tempfile
import types

from run_benchmarks import REPO, Tools, format_peak, run_json, run_measured

DEFAULT_OUT = os.path.join(REPO, "docs", "results", "RESULTS-unseen.md")

MESHLABSERVER = "full pipeline through meshlabserver"
STRUCTURES = os.path.normpath(os.path.join(REPO, "..", "shared", "data", "structures"))


def edtsurf(*args):
    return ("edtsurf", list(args))


def pymol(quality, cavity=0, probe=1.4, ext="obj"):
    return ("pymol", {"quality": quality, "cavity": cavity, "probe": probe, "ext": ext})


def gaussian(grid, decay, level=1.0):
    return ("gaussian", {"grid": grid, "decay": decay, "level": level})


# name -> (structure, generator, settings). EDTSurf: -t 1 MC / 2 VCMC, -s 1 VWS / 2 SAS / 3 MS /
# 4 SES, -f grid scale (per Å), -p probe radius, -c color mode. PyMOL: surface_quality,
# surface_cavity_mode, solvent_radius (Å), export format (OBJ and WRL are soups: one vertex per
# triangle corner). Gaussian: marching cubes of scikit-image over a Gaussian density of the heavy
# atoms (scripts/make_broken_surfaces.py: grid spacing Å, decay, level), which faces inward.
# 1HPV, 1MAH, 1TII and 4JSV are multi-chain complexes; 1UBQ, BPTI and lysozyme single chains.
INPUTS = [
    ("1TII_edtsurf_mc_ses_f1", "1TII", *edtsurf("-t", "1", "-s", "4", "-f", "1")),
    ("1TII_edtsurf_vcmc_ms_f1", "1TII", *edtsurf("-t", "2", "-s", "3", "-f", "1")),
    ("1TII_edtsurf_mc_ses", "1TII", *edtsurf("-t", "1", "-s", "4")),
    ("1MAH_edtsurf_mc_vws_f1", "1MAH", *edtsurf("-t", "1", "-s", "1", "-f", "1")),
    ("1HPV_edtsurf_mc_sas_f1", "1HPV", *edtsurf("-t", "1", "-s", "2", "-f", "1")),
    ("4JSV_edtsurf_vcmc_ses_f1", "4JSV", *edtsurf("-t", "2", "-s", "4", "-f", "1")),
    ("1UBQ_edtsurf_mc_ses_p05", "1UBQ", *edtsurf("-t", "1", "-s", "4", "-p", "0.5")),
    ("1UBQ_edtsurf_mc_ses_f3", "1UBQ", *edtsurf("-t", "1", "-s", "4", "-f", "3")),
    ("1UBQ_edtsurf_vcmc_ms_f15", "1UBQ", *edtsurf("-t", "2", "-s", "3", "-c", "2", "-f", "1.5")),
    ("1UBQ_edtsurf_vcmc_vws_f2", "1UBQ", *edtsurf("-t", "2", "-s", "1", "-f", "2")),
    ("1UBQ_pymol_ses_qm1", "1UBQ", *pymol(-1)),
    ("1UBQ_pymol_ses_q1", "1UBQ", *pymol(1)),
    ("1UBQ_pymol_ses_q2", "1UBQ", *pymol(2)),
    ("bpti_pymol_ses_q1_r10", "bpti_1bpi", *pymol(1, probe=1.0)),
    ("lysozyme_pymol_ses_q0_r20", "lysozyme_Lys1", *pymol(0, probe=2.0)),
    ("1HPV_pymol_ses_q0", "1HPV", *pymol(0)),
    ("1HPV_pymol_ses_q1", "1HPV", *pymol(1)),
    ("1HPV_pymol_ses_q1_r10", "1HPV", *pymol(1, probe=1.0)),
    ("1HPV_pymol_ses_q0_cavity", "1HPV", *pymol(0, cavity=1)),
    ("1HPV_pymol_ses_q0_wrl", "1HPV", *pymol(0, ext="wrl")),
    ("1MAH_pymol_ses_qm1", "1MAH", *pymol(-1)),
    ("1MAH_pymol_ses_q0", "1MAH", *pymol(0)),
    ("1MAH_pymol_ses_q1", "1MAH", *pymol(1)),
    ("1MAH_pymol_ses_q0_r20", "1MAH", *pymol(0, probe=2.0)),
    ("1MAH_pymol_ses_q0_cavity", "1MAH", *pymol(0, cavity=1)),
    ("1MAH_pymol_ses_q1_cavity", "1MAH", *pymol(1, cavity=1)),
    ("1TII_pymol_ses_q0", "1TII", *pymol(0)),
    ("1TII_pymol_ses_q1", "1TII", *pymol(1)),
    ("1TII_pymol_ses_q0_cavity", "1TII", *pymol(0, cavity=1)),
    ("4JSV_pymol_ses_qm1", "4JSV", *pymol(-1)),
    ("4JSV_pymol_ses_q0", "4JSV", *pymol(0)),
    ("4JSV_pymol_ses_q0_cavity", "4JSV", *pymol(0, cavity=1)),
    ("1HPV_gaussian_g05_d1", "1HPV", *gaussian(0.5, 1.0)),
    ("1MAH_gaussian_g04_d05", "1MAH", *gaussian(0.4, 0.5)),
    ("1TII_gaussian_g03_d075", "1TII", *gaussian(0.3, 0.75)),
    ("4JSV_gaussian_g05_d1", "4JSV", *gaussian(0.5, 1.0)),
]

# argv: structure, output, surface_quality [, surface_cavity_mode [, solvent_radius]].
PYMOL_SCRIPT = """
import sys
from pymol import cmd
cmd.load(sys.argv[1], 'm')
cmd.remove('solvent')
cmd.remove('hydro')
cmd.set('surface_quality', int(sys.argv[3]))
if len(sys.argv) > 4:
    cmd.set('surface_cavity_mode', int(sys.argv[4]))
if len(sys.argv) > 5:
    cmd.set('solvent_radius', float(sys.argv[5]))
cmd.set('surface_type', 0)
cmd.show('surface')
cmd.save(sys.argv[2])
"""


def structure_file(name, work):
    """The PDB (or PQR) file of a shared structure, unzipped into work when it is gzipped."""
    for ext in (".pdb", ".pqr"):
        plain = os.path.join(STRUCTURES, name + ext)
        if os.path.exists(plain):
            return plain
        if os.path.exists(plain + ".gz"):
            unzipped = os.path.join(work, name + ext)
            if not os.path.exists(unzipped):
                with gzip.open(plain + ".gz", "rb") as src, open(unzipped, "wb") as dst:
                    shutil.copyfileobj(src, dst)
            return unzipped
    raise FileNotFoundError("no structure %s in %s" % (name, STRUCTURES))


def describe(entry):
    """The generator and its settings, as the table shows them."""
    _, structure, generator, settings = entry
    if generator == "edtsurf":
        return "EDTSurf " + " ".join(settings)
    if generator == "pymol":
        return "PyMOL SES q%d%s, probe %.1f, %s" % (settings["quality"], ", cavity mode %d" % settings["cavity"]
                                                   if settings["cavity"] else "", settings["probe"],
                                                   settings["ext"].upper())
    return "Gaussian MC, grid %.1f, decay %.2f (inward)" % (settings["grid"], settings["decay"])


def generate(entry, work, timeout):
    """Makes the input surface; returns its path, or None with the reason printed."""
    name, structure, generator, settings = entry
    pdb = structure_file(structure, work)
    if generator == "edtsurf":
        path = os.path.join(work, name + ".ply")
        argv = ["EDTSurf", "-i", pdb, "-o", os.path.join(work, name)] + settings
    elif generator == "pymol":
        path = os.path.join(work, "%s.%s" % (name, settings["ext"]))
        script = os.path.join(work, "pymol_surface.py")
        with open(script, "w") as f:
            f.write(PYMOL_SCRIPT)
        # Debian's python3-pymol lives in the system interpreter, whatever python3 is first on PATH.
        argv = ["/usr/bin/python3", script, pdb, path, str(settings["quality"]), str(settings["cavity"]),
                str(settings["probe"])]
    else:
        path = os.path.join(work, name + ".obj")
        argv = ["/usr/bin/python3", os.path.join(REPO, "scripts", "make_broken_surfaces.py"), "--gaussian",
                pdb, path, str(settings["grid"]), str(settings["decay"]), str(settings["level"])]
    if not os.path.exists(path):
        r = run_measured(argv, timeout)
        if not r.ok or not os.path.exists(path):
            print("  %s: the generator failed: %s" % (name, r.why()), file=sys.stderr)
            return None
    return path


def remesh(tools, mesh, output, stages, timeout):
    """Runs the CLI; returns the row of figures (input and output reports, verdict, run)."""
    json_path = output + ".json"
    argv = [tools.molremesh, "remesh", mesh, output, "--quiet", "--json", json_path] + tools.remesh_args
    if stages:
        argv += ["--stages", stages]
    r = run_measured(argv, timeout)
    row = {"exit": r.code, "seconds": r.seconds, "peak_mb": r.peak_mb,
           "warnings": [l for l in r.stderr.splitlines() if l.startswith("molremesh: warning:")]}
    if r.code in (0, 3) and os.path.exists(json_path):
        with open(json_path) as f:
            data = json.load(f)
        row["input"], row["output"] = data["input"], data["output"]
        row["cleaned"] = data["stages"][0]["after"]
        row["clean_summary"] = data["stages"][0].get("summary", "")
        row["verdict"] = data.get("verdict")
        row["rebuild_retry"] = data.get("rebuild_retry") or {}
        row["tetgen"] = tools.tetgen_check(output, os.path.dirname(output))
    else:
        row["error"] = r.why().replace(os.path.dirname(mesh) + os.sep, "")  # no machine path in the table
    return row


def remesh_meshlabserver(tools, mesh, output, timeout):
    """Runs the plugin's Full Pipeline with its script's defaults through the sandboxed
    meshlabserver; its output is judged from outside: welded defects (validity), report, TetGen."""
    mlx = os.path.join(REPO, "meshlabserver_scripts", "full_pipeline.mlx")
    log = output + ".log"
    row = {"warnings": []}
    if mesh.endswith(".obj"):
        # MeshLab 2020.09 as Debian builds it aborts on opening any OBJ file (an assertion in
        # vcglib's OBJ importer, Debian bug #1054006): it gets the same vertices and faces as PLY.
        ply = os.path.splitext(mesh)[0] + ".mls-input.ply"
        converted = run_measured([tools.mesh_convert, mesh, ply], timeout)
        if not converted.ok:
            return dict(row, exit=converted.code, seconds=0, peak_mb=None, error="conversion: " + converted.why())
        mesh, row["converted"] = ply, True
    r = run_measured([tools.meshlab, "-l", log, "-i", mesh, "-o", output, "-s", mlx], timeout)
    row.update({"exit": r.code, "seconds": r.seconds, "peak_mb": r.peak_mb})
    if not r.ok or not os.path.exists(output):
        row["error"] = r.why().replace(os.path.dirname(mesh) + os.sep, "")
        return row
    report, rr = run_json([tools.molremesh, "report", output, "--json"], timeout=timeout)
    row["defects_out"] = welded_defects(tools, output, timeout)
    if report is None or row["defects_out"] is None:
        row["error"] = "the written mesh could not be measured: " + rr.why()
        return row
    row["output"] = report
    row["tetgen"] = tools.tetgen_check(output, os.path.dirname(output))
    return row


def welded_defects(tools, mesh, timeout):
    """The input's defects as a mesh welded at equal coordinates (benchmarks/volumetric_rebuild)."""
    data, r = run_json([tools.volumetric_rebuild, mesh, "--defects-only"], timeout=timeout)
    if data is None:
        print("  defects of %s: %s" % (mesh, r.why()), file=sys.stderr)
        return None
    return data["input_welded"]


def is_valid_surface(d):
    return (d["non_manifold_edges"] == d["non_manifold_vertices"] == d["boundary_edges"] == 0 and
            d["degenerate_faces"] == d["si_pairs"] == d["adjacent_overlap_pairs"] == d["misoriented_edges"] == 0
            and d["volume"] > 0)


def union_reference(tools, mesh, defects, work, name, timeout):
    """What the output is compared with: the input itself when it is already a valid closed
    surface, else the union of the regions it encloses rebuilt from a volume by
    benchmarks/volumetric_rebuild (its default voxel, half the input's mean edge: the clean stage's
    fallback rebuilds the same way, so for those inputs the figures measure the remeshing only).
    Returns (path, volume, area, how)."""
    if defects and is_valid_surface(defects):
        return mesh, defects["volume"], defects["area"], "input"
    if defects and defects["si_pairs"] == defects["adjacent_overlap_pairs"] == defects["misoriented_edges"] == 0 \
            and defects["non_manifold_edges"] == 0 and defects["volume"] > 0:
        # Only cracks: a flood fill from outside leaks through them, so the rebuild would not be its
        # union; the input itself is the reference (its volume closed by cones over the cracks).
        return mesh, defects["volume"], defects["area"], "input (open)"
    path = os.path.join(work, name + ".union.ply")
    argv = [tools.volumetric_rebuild, mesh, path, "--threads", "2"]
    data, r = run_json(argv, timeout=timeout)
    if data is None or not data.get("ok"):
        print("  union of %s: %s" % (name, r.why() if data is None else data.get("message")), file=sys.stderr)
        return None, None, None, "failed"
    if defects["boundary_edges"] and data["volume_out"] < 0.5 * abs(defects["volume"]):
        # The flood fill from outside leaked through the cracks: what is left is not the union. The
        # input itself is the reference then (its volume closed by cones over the cracks; where its
        # sheets overlap, that volume counts the overlap twice).
        return mesh, abs(defects["volume"]), defects["area"], "input (open; the rebuild leaks)"
    return path, data["volume_out"], data["area_out"], "rebuilt at %.3g Å" % data["voxel_size"]


def compare(tools, row, output, reference, timeout):
    """Volume and area change of the output against the reference, and their Hausdorff distance."""
    path, volume, area, how = reference
    row["reference"] = how
    if path is None or "output" not in row:
        return
    o = row["output"]
    row["volume_change_percent"] = 100.0 * (o["volume"] - volume) / volume if volume else None
    row["area_change_percent"] = 100.0 * (o["area"] - area) / area if area else None
    data, r = run_json([tools.mesh_distance, output, path, "--threads", "2"], timeout=timeout)
    row["hausdorff"] = data["hausdorff"] if data else None


def rebuilt(row):
    """'yes (area A of B)' when the clean stage rebuilt the surface from a volume, else 'no'."""
    if "defects_out" in row:
        return "–"  # meshlabserver: the filter's summary is in its log only
    summary = row.get("clean_summary", "")
    if "volumetric fallback: rebuilt" not in summary:
        return "no"
    figures = dict(line.split(": ", 1) for line in summary.splitlines() if ": " in line)
    retry = ""
    if row.get("rebuild_retry", {}).get("kept"):
        retry = "; rebuilt first, see Goals" if rebuilt_first(row) else "; second run, see Goals"
    return "yes (%s of %s Å²%s)" % (figures.get("rebuilt area in", "?"), "%.0f" % row["input"]["area"], retry)


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
    if work:
        out["warnings"] = [w.replace(work.rstrip("/") + "/", "") for w in out.get("warnings", [])]
    return out


def defects_text(d):
    if d is None:
        return "?"
    return "%d / %d / %d / %d" % (d["non_manifold_edges"], d["boundary_edges"], d["si_pairs"] + d["adjacent_overlap_pairs"],
                                  d["misoriented_edges"]) + ("" if d["volume"] > 0 else ", inward")


def validity(row):
    if "defects_out" in row:  # meshlabserver: judged on the written mesh
        return "valid" if row["defects_out"] and is_valid_surface(row["defects_out"]) else \
            "**not valid** (%s)" % defects_text(row["defects_out"])
    v = row.get("verdict") or {}
    if v.get("valid") and row["exit"] in (0,):
        return "valid"
    return "**not valid** (exit %d)" % row["exit"]


def percent(x):
    return "–" if x is None else "%+.2f" % x


def cells(entry, row):
    name = entry[0]
    if "output" in row and "input" not in row:  # meshlabserver without a CLI row: the welded input's faces
        row = dict(row, input={"faces": row["defects"]["faces"]} if row.get("defects") else {"faces": 0})
    if "output" not in row:
        return [name, describe(entry), "–", defects_text(row.get("defects")), "failed: " + row.get("error", "?")] + \
            ["–"] * (len(HEADER) - 5)
    i, o = row["input"], row["output"]
    hausdorff = row.get("hausdorff")
    return [name, describe(entry), "%d → %d" % (i["faces"], o["faces"]), defects_text(row.get("defects")),
            validity(row), "%.1f–%.1f" % (o["angle_min_deg"], o["angle_max_deg"]), "%.2f" % o["obtuse_percent"],
            "%.2f" % o["v567_percent"], percent(row.get("volume_change_percent")),
            percent(row.get("area_change_percent")), "–" if hausdorff is None else "%.2f" % hausdorff,
            row.get("reference", "–"), rebuilt(row), "%d" % o["components"], row.get("tetgen") or "n/a",
            "%.1f" % row["seconds"], "%.0f" % (1e6 * row["seconds"] / max(i["faces"], 1)),
            format_peak(row["peak_mb"])]


HEADER = ["input", "generator, settings", "faces in → out", "defects in: NM edges / boundary / SI / misoriented",
          "out", "θ out", "obtuse %", "V567 %", "ΔV %", "ΔA %", "Hausdorff Å", "union from", "rebuilt",
          "components out", "TetGen -pq1.4", "s", "µs / face in", "peak MB"]


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
    p.add_argument("--meshlabserver", action="store_true",
                   help="also run the plugin's Full Pipeline through the build's sandboxed meshlabserver")
    p.add_argument("--keep-from", metavar="JSON",
                   help="a previous run's --json: the rows of the inputs not run now (see --only) are taken "
                        "from it, so a change that touches a few inputs is measured on those alone")
    p.add_argument("--table-from", metavar="JSON",
                   help="write the tables from a previous run's --json (with the same --meshlabserver and "
                        "--stage3) without running anything")
    p.add_argument("--remesh-args", default="",
                   help="more options for every molremesh remesh run, as one string after an equals sign "
                        "(--remesh-args=--volumetric-rebuild); give --out and --json elsewhere then")
    p.add_argument("--timeout", type=float, default=3600)
    p.add_argument("--tetgen-timeout", type=float, default=1200)
    p.add_argument("--out", default=DEFAULT_OUT,
                   help="Markdown file written with the tables (%(default)s)")
    p.add_argument("--json", help="JSON file written with the raw figures (default: "
                                  "BUILD/benchmarks/RESULTS-unseen.json; raw figures are not committed)")
    args = p.parse_args()
    if args.table_from:
        return table_from(args)
    if args.json is None:
        args.json = os.path.join(args.build_dir, "benchmarks", "RESULTS-unseen.json")
    for tool in ("EDTSurf", "tetgen"):
        if not shutil.which(tool):
            print("unseen_inputs: %s not found (Debian packages edtsurf, tetgen: scripts/install_deps.sh "
                  "--unseen)" % tool, file=sys.stderr)
    tools = Tools(types.SimpleNamespace(build_dir=args.build_dir, tetgen_timeout=args.tetgen_timeout))
    tools.volumetric_rebuild = os.path.join(os.path.abspath(args.build_dir), "benchmarks", "volumetric_rebuild")
    tools.remesh_args = shlex.split(args.remesh_args)
    for path in (tools.molremesh, tools.mesh_convert, tools.mesh_distance, tools.volumetric_rebuild):
        if not os.access(path, os.X_OK):
            sys.exit("unseen_inputs: build the targets molremesh, mesh_convert, mesh_distance and "
                     "volumetric_rebuild in %s first" % args.build_dir)
    if args.meshlabserver and not os.access(tools.meshlab, os.X_OK):
        sys.exit("unseen_inputs: build the target meshlabserver_sandbox in %s first" % args.build_dir)
    work = args.work or tempfile.mkdtemp(prefix="molremesh_unseen_")
    os.makedirs(work, exist_ok=True)
    modes = run_modes(args)
    results, tables = [], {mode: [] for mode, _ in modes}
    for entry in INPUTS:
        if args.only and not any(part in entry[0] for part in args.only):
            continue
        print("%s: generating ..." % entry[0], file=sys.stderr, flush=True)
        path = generate(entry, work, args.timeout)
        if path is None:
            continue
        defects = welded_defects(tools, path, args.timeout)
        reference = union_reference(tools, path, defects, work, entry[0], args.timeout)
        for mode, stages in modes:
            suffix = "mls" if stages is None else "s3" if stages else "full"
            output = os.path.join(work, "%s.%s.ply" % (entry[0], suffix))
            print("%s: %s ..." % (entry[0], mode), file=sys.stderr, flush=True)
            if stages is None:
                row = remesh_meshlabserver(tools, path, output, args.timeout)
                if "input" in results[-1] and "output" in row:
                    row["input"] = {"faces": results[-1]["input"]["faces"]}  # the CLI's reading of the input
            else:
                row = remesh(tools, path, output, stages, args.timeout)
            row["defects"] = defects
            compare(tools, row, output, reference, args.timeout)
            results.append({"name": entry[0], "generator": entry[2], "settings": entry[3], "mode": mode, **row})
            tables[mode].append(cells(entry, row))
    if args.keep_from:
        keep_rows(args.keep_from, results, tables)
    write_results(args, results, tables, modes, work)


def run_modes(args):
    """(table title, --stages value or None for meshlabserver) of each kind of run asked for."""
    return [("full pipeline", "")] + ([("clean, CVT, segment, RAR", "clean,cvt,segment,rar")] if args.stage3 else []) \
        + ([(MESHLABSERVER, None)] if args.meshlabserver else [])


def table_from(args):
    """Writes the tables of a previous run's JSON (--table-from) again, with this script's text."""
    modes = run_modes(args)
    tables = {mode: [] for mode, _ in modes}
    args.keep_from = None  # every row is the JSON's; its file is written again only to --json
    results = []
    keep_rows(args.table_from, results, tables)
    write_results(args, results, tables, modes, "")


def keep_rows(path, results, tables):
    """Adds the rows of a previous run for the inputs and modes this run has no row of, in INPUTS order."""
    entry_of = {entry[0]: entry for entry in INPUTS}
    run = {(r["name"], r["mode"]) for r in results}
    with open(path) as f:
        kept = [r for r in json.load(f) if (r["name"], r["mode"]) not in run and r["mode"] in tables
                and r["name"] in entry_of]
    results += kept
    for r in kept:
        tables[r["mode"]].append(cells(entry_of[r["name"]], r))
    order = {entry[0]: i for i, entry in enumerate(INPUTS)}
    results.sort(key=lambda r: (order[r["name"]], r["mode"] != "full pipeline"))
    for rows in tables.values():
        rows.sort(key=lambda cell_list: order[cell_list[0]])


def goals(results):
    """The issue's goals counted over the full-pipeline rows."""
    rows = [r for r in results if r["mode"] == "full pipeline"]
    valid = [r for r in rows if validity(r) == "valid" and (r.get("tetgen") or "").startswith("yes")]
    bounds = [r for r in rows if "output" in r and r["output"]["angle_min_deg"] >= 30 - 1e-9 and
              r["output"]["angle_max_deg"] <= 90 + 1e-9 and r["output"]["v567_percent"] >= 99.9]
    return ["- valid and TetGen-ready: %d of %d" % (len(valid), len(rows)),
            "- every angle in [30°, 90°] and V567 ≥ 99.9 %%: %d of %d (%.0f %%)" %
            (len(bounds), len(rows), 100.0 * len(bounds) / max(len(rows), 1)),
            "- not in bounds: " + (", ".join("%s (θ %.1f–%.1f°, V567 %.2f %%)" % (
                r["name"], r["output"]["angle_min_deg"], r["output"]["angle_max_deg"], r["output"]["v567_percent"])
                for r in rows if "output" in r and r not in bounds) or "none")] + retry_goals(rows) + \
        meshlabserver_goals(results)


def rebuilt_first(row):
    """Whether the run on the rebuilt surface was made before any other (the JSON's rebuild_retry.first;
    a JSON written before that key existed tells it by the note, which then opens with the narrow gaps)."""
    retry = row.get("rebuild_retry", {})
    if "first" in retry:
        return retry["first"]
    return "faces the surface again" in retry.get("message", "")


def retry_goals(rows):
    """The runs on the surface rebuilt from a volume that the pipeline made on its own, with the CLI's note."""
    tried = [r for r in rows if r.get("rebuild_retry", {}).get("tried")]
    first = [r for r in tried if rebuilt_first(r)]
    second = [r for r in tried if r not in first]
    lines = ["- remeshed from the surface rebuilt from a volume before any other run, because more than "
             "0.02 %% of the cleaned input's area faces the surface again within L/2 (narrow crevices): "
             "%d of %d%s" % (len(first), len(rows), ":" if first else "")]
    lines += ["  - %s: %s" % (r["name"], r["rebuild_retry"]["message"]) for r in first]
    lines += ["- remeshed a second time from the surface rebuilt from a volume, because the first remesh's "
              "angles missed [30°, 90°]: %d of %d%s" % (len(second), len(rows), ":" if second else "")]
    return lines + ["  - %s: %s" % (r["name"], r["rebuild_retry"]["message"]) for r in second]


def meshlabserver_goals(results):
    rows = [r for r in results if r["mode"] == MESHLABSERVER]
    if not rows:
        return []
    valid = [r for r in rows if validity(r) == "valid" and (r.get("tetgen") or "").startswith("yes")]
    return ["- through meshlabserver (the plugin's Full Pipeline), valid and TetGen-ready: %d of %d%s" % (
        len(valid), len(rows), "" if len(valid) == len(rows) else "; not: " + ", ".join(
            "%s (%s)" % (r["name"], r.get("error") or validity(r)) for r in rows if r not in valid))]


def kept_note(args):
    if not args.keep_from:
        return ""
    return ("; the rows of the inputs other than %s are those of an earlier run of the same command "
            "(`--only ... --keep-from JSON`)" % ", ".join(args.only or []))


def write_results(args, results, tables, modes, work):
    text = ["# molremesh on generated inputs it was not developed on", "",
            "Made by `/usr/bin/python3 benchmarks/unseen_inputs.py --build-dir build%s` on %s (2 shared cores)%s. "
            "Inputs: the shared structures through Debian's EDTSurf and PyMOL and marching cubes of a "
            "Gaussian density (settings in the script); each run is one process of the CLI with its "
            "defaults%s. *Defects in* are counted on the input welded at equal "
            "coordinates (*SI* includes pairs of faces sharing a vertex that also meet elsewhere; "
            "*inward*: negative enclosed volume). *out* is the CLI's verdict: valid = closed, 2-manifold, "
            "consistently oriented outward, no degenerate face, no self-intersecting pair. θ, obtuse %%, "
            "V567 are the output's. ΔV, ΔA and the Hausdorff distance compare the output with the union "
            "of the regions the input encloses: the input itself when it is already a valid surface, else "
            "that union rebuilt from a volume (`benchmarks/volumetric_rebuild`, voxel half the input's mean "
            "edge, the same rebuild the clean stage falls back to: on those rows they measure the "
            "remeshing). *rebuilt*: the clean stage rebuilt the surface from a volume (area of the input "
            "it replaced; *rebuilt first*: on the CLI's run on the rebuilt surface made before any other, "
            "because the cleaned input has narrow crevices; *second run*: on the CLI's second run, made "
            "because the first remesh's angles missed [30°, 90°]; the Goals list these runs with the CLI's "
            "note). *µs / face in*: the run's time per input face. The meshlabserver rows (with "
            "--meshlabserver) run the plugin's Full Pipeline with `meshlabserver_scripts/full_pipeline.mlx` "
            "through the build's sandboxed meshlabserver (Xvfb start-up and file input/output included); "
            "*out* there is judged on the written mesh welded at equal coordinates. MeshLab 2020.09 as "
            "Debian builds it aborts on opening any OBJ file (an assertion in vcglib's OBJ importer, "
            "Debian bug #1054006), so the OBJ inputs reach it as PLY files with the same vertices and "
            "faces (`mesh_convert`, not timed)."
            % ((" --meshlabserver" if args.meshlabserver else "")
               + (" --remesh-args=\"%s\"" % args.remesh_args if args.remesh_args else "")
               + (" --only " + " ".join(args.only) if args.only and not args.keep_from else "")
               + (" --out " + os.path.relpath(args.out, REPO) if args.out != DEFAULT_OUT else ""),
               datetime.date.today().isoformat(), kept_note(args),
               " and `%s`" % args.remesh_args if args.remesh_args else " (`molremesh remesh IN OUT`)"),
            ""]
    text += ["## Goals", ""] + goals(results) + [""]
    for mode, _ in modes:
        text += ["## " + mode, "", table(tables[mode]), ""]
    text += ["## Warnings", ""]
    for r in results:
        for w in r.get("warnings", []):
            text.append("- %s (%s): %s" % (r["name"], r["mode"], w.split(": ", 2)[-1].split(" ", 1)[-1]))
    with open(args.out, "w") as f:
        f.write("\n".join(text) + "\n")
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
        with open(args.json, "w") as f:
            json.dump([compact(r, work) for r in results], f, indent=1)
    print("\n".join(text))


if __name__ == "__main__":
    main()
