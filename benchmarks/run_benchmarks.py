#!/usr/bin/env python3
"""Benchmark molremesh against the remeshers it must beat, on real molecular meshes.

For every mesh (default: all of ../shared/data/meshes) the target edge length L is the input's
mean edge length, and each method remeshes the input at L:

  cgal      CGAL 5.5 Polygon_mesh_processing::isotropic_remeshing, 10 iterations
            (benchmarks/cgal_isotropic_remesh, built when libcgal-dev is installed)
  meshlab   MeshLab 2020.09's builtin "Remeshing: Isotropic Explicit Remeshing", 10 iterations,
            absolute target length L, other parameters at MeshLab's defaults, through the
            sandboxed meshlabserver of the build (<build>/meshlabserver/run_meshlabserver.sh)
  molremesh the command template given by --molremesh-cmd (a method whose command fails is
            reported as n/a, not as an error)

Each method runs as its own process, timed (wall clock) and measured (peak resident memory of
the process and the children it waited for, from os.wait4). Its output is then measured with
`molremesh report --json` (angles, quality, valence, self-intersections, boundary, volume), with
benchmarks/mesh_distance (symmetric Hausdorff distance to the input, divided by L) and with
TetGen (`tetgen -pq1.4` on an OFF copy, with a timeout): "TetGen ok" means TetGen could build a
quality tetrahedral mesh bounded by the surface.

Prints one Markdown table per mesh and a summary table per method, and writes them to --out
(default docs/results/RESULTS.md, the committed result tables); the raw figures go to --json
(default <build-dir>/benchmarks/<name of --out>.json, outside the source tree, where --reuse-json
and --from-json can read them back). Python 3 standard library only.
"""

import argparse
import datetime
import json
import os
import platform
import shlex
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_DATA = os.path.normpath(os.path.join(REPO, "..", "shared", "data", "meshes"))


def portable_path(path):
    """The path as committed result files keep it: relative to the repository for the shared data
    beside it (../shared/...), else only the file name (outputs live in a temporary work folder)."""
    if not path:
        return path
    relative = os.path.relpath(os.path.abspath(path), REPO)
    if relative.startswith(os.path.join("..", "shared") + os.sep):
        return relative
    return os.path.basename(path)


def portable_results(results):
    """Every file path of the results made portable (no machine paths in committed JSON)."""
    for result in results:
        result["file"] = portable_path(result.get("file"))
        for row in result.get("rows", []):
            report = row.get("report")
            if isinstance(report, dict) and "file" in report:
                report["file"] = portable_path(report["file"])
    return results
DEFAULT_MOLREMESH_CMD = "{molremesh} remesh {input} {output} --stages clean,cvt,segment,rar"
METHODS = ("cgal", "meshlab", "molremesh")
# Opt-in (--equal-resolution): molremesh again, its target length set to the mean edge length of CGAL's
# output on the same mesh. CGAL's output at target L is finer than L, molremesh's CVT hits L, so at the
# same target the two differ in resolution as well as in method; this row compares them at the same one.
EQUAL_RESOLUTION = "molremesh_at_cgal_edge"
METHOD_LABELS = {"input": "input", "cgal": "CGAL isotropic", "meshlab": "MeshLab isotropic", "molremesh": "molremesh",
                 EQUAL_RESOLUTION: "molremesh at CGAL's output edge"}

MESHLAB_MLX = """<!DOCTYPE FilterScript>
<FilterScript>
 <filter name="Remeshing: Isotropic Explicit Remeshing">
  <Param type="RichInt" value="{iterations}" name="Iterations"/>
  <Param type="RichBool" value="false" name="Adaptive"/>
  <Param type="RichBool" value="false" name="SelectedOnly"/>
  <Param type="RichAbsPerc" value="{target:.9g}" min="0" max="{diag:.9g}" name="TargetLen"/>
  <Param type="RichFloat" value="30" name="FeatureDeg"/>
  <Param type="RichBool" value="false" name="CheckSurfDist"/>
  <Param type="RichAbsPerc" value="{maxdist:.9g}" min="0" max="{diag:.9g}" name="MaxSurfDist"/>
  <Param type="RichBool" value="true" name="SplitFlag"/>
  <Param type="RichBool" value="true" name="CollapseFlag"/>
  <Param type="RichBool" value="true" name="SwapFlag"/>
  <Param type="RichBool" value="true" name="SmoothFlag"/>
  <Param type="RichBool" value="true" name="ReprojectFlag"/>
 </filter>
</FilterScript>
"""


# --- Running and measuring processes ----------------------------------------------------------


class Run:
    """Outcome of one process: exit code (128+signal when killed), wall seconds, peak RSS in MB."""

    def __init__(self, code, seconds, peak_mb, timed_out, stdout, stderr, stage_peaks=None):
        self.code, self.seconds, self.peak_mb = code, seconds, peak_mb
        self.timed_out, self.stdout, self.stderr = timed_out, stdout, stderr
        self.stage_peaks = stage_peaks or {}  # stage name -> peak resident MB sampled while it ran

    @property
    def ok(self):
        return self.code == 0 and not self.timed_out

    def why(self):
        """One line saying why the run failed."""
        if self.timed_out:
            return "timed out after %.0f s" % self.seconds
        lines = [l.strip() for l in (self.stderr + "\n" + self.stdout).splitlines() if l.strip()]
        last = lines[-1] if lines else ""
        return "exit %d%s" % (self.code, (": " + last[:160]) if last else "")


_RUNNING = set()  # process groups to kill if the runner itself is stopped


def _stop(signum, frame):
    for pgid in list(_RUNNING):
        try:
            os.killpg(pgid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    sys.exit(128 + signum)


def _read_rss_mb(pid):
    """Current resident size of pid in MB (VmRSS of /proc/PID/status), None when gone."""
    try:
        with open("/proc/%d/status" % pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except (OSError, ValueError, IndexError):
        return None
    return None


def _stage_monitor(pid, err_path, peaks, stop, interval=0.02):
    """Samples pid's resident size every `interval` s and charges each sample to the pipeline
    stage running then, read from the `molremesh: stage NAME ...` lines of its stderr ("load"
    before the first stage, "save" after the last "done")."""
    current = "load"
    offset = 0
    while not stop.is_set():
        try:
            with open(err_path, errors="replace") as f:
                f.seek(offset)
                chunk = f.read()
                offset = f.tell()
        except OSError:
            chunk = ""
        for line in chunk.splitlines():
            words = line.split()
            if len(words) >= 4 and words[0] == "molremesh:" and words[1] == "stage":
                if words[3] == "...":
                    current = words[2]
                elif words[3] == "done":
                    current = "save"
        rss = _read_rss_mb(pid)
        if rss is not None:
            peaks[current] = max(peaks.get(current, 0.0), rss)
        stop.wait(interval)


def run_measured(argv, timeout, cwd=None, log_prefix=None, monitor_stages=False):
    """Runs argv in its own process group; wall time and peak memory come from os.wait4.

    The group is killed when the timeout passes. stdout/stderr go to files (no pipe can fill up),
    kept as log_prefix.out/.err when log_prefix is given. monitor_stages: also sample the
    process's resident size (20 ms) per molremesh pipeline stage (Run.stage_peaks; a sampled
    peak, so it can miss a spike shorter than the interval).
    """
    tmp = tempfile.mkdtemp(prefix="molremesh_run_")
    out_path = (log_prefix + ".out") if log_prefix else os.path.join(tmp, "out")
    err_path = (log_prefix + ".err") if log_prefix else os.path.join(tmp, "err")
    timed_out = threading.Event()
    start = time.monotonic()
    try:
        with open(out_path, "wb") as out, open(err_path, "wb") as err:
            try:
                proc = subprocess.Popen(argv, stdout=out, stderr=err, stdin=subprocess.DEVNULL, cwd=cwd,
                                        start_new_session=True)
            except OSError as e:
                return Run(127, 0.0, None, False, "", str(e))

            def kill():
                timed_out.set()
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass

            _RUNNING.add(proc.pid)
            timer = threading.Timer(timeout, kill) if timeout else None
            if timer:
                timer.start()
            stage_peaks, stop_monitor = {}, threading.Event()
            monitor = None
            if monitor_stages:
                monitor = threading.Thread(target=_stage_monitor, args=(proc.pid, err_path, stage_peaks, stop_monitor),
                                           daemon=True)
                monitor.start()
            try:
                _, status, usage = os.wait4(proc.pid, 0)
            finally:
                _RUNNING.discard(proc.pid)
                if timer:
                    timer.cancel()
                stop_monitor.set()
                if monitor:
                    monitor.join()
            proc.returncode = os.waitstatus_to_exitcode(status)
            seconds = time.monotonic() - start
        code = proc.returncode if proc.returncode >= 0 else 128 - proc.returncode
        with open(out_path, errors="replace") as f:
            stdout = f.read()
        with open(err_path, errors="replace") as f:
            stderr = f.read()
        return Run(code, seconds, usage.ru_maxrss / 1024.0, timed_out.is_set(), stdout, stderr, stage_peaks)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


# A child exec'd from this process inherits, in ru_maxrss, the resident size of the runner at the
# time of the fork (Linux keeps the old image's high-water mark across exec). Peaks at or below
# this floor only say "at most the floor"; main() measures it with a process that does nothing.
MEMORY_FLOOR_MB = [0.0]


def format_peak(mb):
    if mb is None:
        return "n/a"
    if mb <= MEMORY_FLOOR_MB[0] + 1.0:
        return "≤%.0f" % (MEMORY_FLOOR_MB[0] + 1.0)
    return "%.0f" % mb


def run_json(argv, timeout=600):
    """Runs a command that prints one JSON object; returns (dict or None, Run)."""
    r = run_measured(argv, timeout)
    if not r.ok:
        return None, r
    try:
        return json.loads(r.stdout), r
    except ValueError:
        r.code = 1
        r.stderr += "\nnot JSON: " + r.stdout[:200]
        return None, r


# --- The tools ------------------------------------------------------------------------------


class Tools:
    def __init__(self, args):
        b = os.path.abspath(args.build_dir)
        self.molremesh = os.path.join(b, "cli", "molremesh")
        self.mesh_distance = os.path.join(b, "benchmarks", "mesh_distance")
        self.mesh_convert = os.path.join(b, "benchmarks", "mesh_convert")
        self.cgal = os.path.join(b, "benchmarks", "cgal_isotropic_remesh")
        self.meshlab = os.path.join(b, "meshlabserver", "run_meshlabserver.sh")
        self.tetgen = shutil.which("tetgen")
        self.args = args

    def check(self, skip):
        """Names of the methods that cannot run, with the reason; exits when a must-have is missing."""
        for path, what in ((self.molremesh, "cli/molremesh"), (self.mesh_distance, "benchmarks/mesh_distance"),
                           (self.mesh_convert, "benchmarks/mesh_convert")):
            if not os.access(path, os.X_OK):
                sys.exit("run_benchmarks: %s not found in the build dir %s: build the targets molremesh, "
                         "mesh_distance and mesh_convert" % (what, self.args.build_dir))
        missing = {}
        if "cgal" not in skip and not os.access(self.cgal, os.X_OK):
            missing["cgal"] = "cgal_isotropic_remesh not built (install libcgal-dev, rebuild)"
        if "meshlab" not in skip and not os.access(self.meshlab, os.X_OK):
            missing["meshlab"] = "no sandboxed meshlabserver (build the target meshlabserver_sandbox)"
        if not self.tetgen:
            print("run_benchmarks: tetgen not found (Debian package tetgen): TetGen column is n/a", file=sys.stderr)
        return missing

    def report(self, mesh):
        data, r = run_json([self.molremesh, "report", "--json", mesh], timeout=self.args.timeout)
        if data is None:
            print("  report of %s failed: %s" % (os.path.basename(mesh), r.why()), file=sys.stderr)
        return data

    def stats(self, mesh):
        data, r = run_json([self.mesh_distance, "--stats", mesh])
        if data is None:
            print("  mesh_distance --stats %s failed: %s" % (mesh, r.why()), file=sys.stderr)
            return None
        return data["a"]

    def distance(self, a, b):
        argv = [self.mesh_distance, a, b, "--threads", str(self.args.threads)]
        if self.args.samples:
            argv += ["--samples", str(self.args.samples)]
        data, r = run_json(argv, timeout=self.args.timeout)
        if data is None:
            print("  mesh_distance failed: %s" % r.why(), file=sys.stderr)
        return data

    def tetgen_check(self, mesh, work):
        """'yes (N tets)', 'no (...)', 'timeout' or None when TetGen is not installed."""
        if not self.tetgen:
            return None
        folder = tempfile.mkdtemp(prefix="tetgen_", dir=work)
        try:
            off = os.path.join(folder, "surface.off")
            conv = run_measured([self.mesh_convert, mesh, off], timeout=600)
            if not conv.ok:
                return "no (conversion: %s)" % conv.why()
            # Unbuffered, so that the phase TetGen was in survives an abort.
            stdbuf = shutil.which("stdbuf")
            argv = ([stdbuf, "-o0"] if stdbuf else []) + [self.tetgen, "-pq1.4", off]
            r = run_measured(argv, timeout=self.args.tetgen_timeout, cwd=folder)
            if r.timed_out:
                return "timeout (%.0f s)" % self.args.tetgen_timeout
            if r.code != 0:
                # Debian's tetgen reports errors by throwing an int nobody catches: SIGABRT (134).
                phases = [l.strip().rstrip(".") for l in r.stdout.splitlines() if l.strip().endswith("...")]
                errors = [l.strip() for l in (r.stdout + r.stderr).splitlines()
                          if "intersect" in l.lower() or "error" in l.lower()]
                reason = {1: "out of memory", 2: "internal error", 3: "self-intersections",
                          4: "very small input feature", 5: "very close facets",
                          10: "input error"}.get(r.code)
                if reason is None:
                    reason = ("aborted" if r.code == 134 else "exit %d" % r.code)
                    if phases:
                        reason += " in %s" % phases[-1].lower()
                if errors:
                    reason += ": " + errors[0][:80]
                return "no (%s)" % reason
            tets = None
            for line in r.stdout.splitlines():
                if line.strip().startswith("Mesh tetrahedra:"):
                    tets = int(line.split(":")[1])
            if not tets:
                # TetGen removes every tetrahedron outside the surface: an open surface leaves none.
                return "no (0 tets: not closed)"
            return "yes (%d tets, %.0f s)" % (tets, r.seconds)
        finally:
            shutil.rmtree(folder, ignore_errors=True)


# --- Methods ------------------------------------------------------------------------------------


def format_template(template, **values):
    """Fills {name} placeholders with shell-quoted values and splits the result into argv."""
    quoted = {k: shlex.quote(str(v)) for k, v in values.items()}
    return shlex.split(template.format(**quoted))


def method_argv(method, tools, args, mesh, output, target, diag, work, length=None):
    """argv of one method; `length`: the --target-length of the equal-resolution row."""
    if method == "cgal":
        return [tools.cgal, mesh, output, "--target", "%.9g" % target, "--iterations", str(args.iterations)]
    if method == "meshlab":
        mlx = os.path.join(work, "isotropic_remeshing.mlx")
        with open(mlx, "w") as f:
            f.write(MESHLAB_MLX.format(iterations=args.iterations, target=target, diag=diag, maxdist=0.01 * diag))
        log = os.path.join(work, "meshlab.log")
        return [tools.meshlab, "-l", log, "-i", mesh, "-o", output, "-s", mlx]
    argv = format_template(args.molremesh_cmd, molremesh=tools.molremesh, input=mesh, output=output,
                           target="%.9g" % target, iterations=args.iterations)
    if method == EQUAL_RESOLUTION:
        argv += ["--target-length", "%.9g" % length]
    if "--json" not in argv and os.path.basename(argv[0]) == "molremesh" and "remesh" in argv:
        argv += ["--json", os.path.join(work, "molremesh_stages.json")]  # per-stage wall times
    if os.path.basename(argv[0]) == "molremesh" and "remesh" in argv and "--quiet" not in argv \
            and "--verbose" not in argv:
        argv += ["--verbose"]  # the per-stage progress lines the stage monitor reads
    return argv


def algorithm_seconds(method, run, tools, args, mesh, work):
    """Time of the remeshing alone: CGAL prints it; for MeshLab it is estimated as the run's time
    minus that of a meshlabserver run that only loads and saves the input (Xvfb start-up included)."""
    if method == "cgal":
        try:
            return float(json.loads(run.stdout)["remesh_seconds"])
        except (ValueError, KeyError):
            return None
    if method in ("molremesh", EQUAL_RESOLUTION):
        # The pipeline's own stage timers (quality reports between stages, load and save excluded).
        try:
            with open(os.path.join(work, "molremesh_stages.json")) as f:
                return float(sum(s["seconds"] for s in json.load(f)["stages"]))
        except (OSError, ValueError, KeyError, TypeError):
            return None
    if method == "meshlab":
        # meshlabserver does not log filter times: subtract a run that only loads and saves.
        io_only = os.path.join(work, "meshlab_io_only.ply")
        argv = [tools.meshlab, "-i", mesh, "-o", io_only]
        baseline = run_measured(argv, args.timeout, cwd=work)
        if baseline.ok:
            return max(0.0, run.seconds - baseline.seconds)
    return None


# --- Measuring one mesh -----------------------------------------------------------------------


def add_changes(row, input_report, cleaned_report):
    """Area and volume change of the row's output against the raw input and against the cleaned one
    (the surface molremesh remeshes: the pipeline bounds the volume change against it)."""
    out = row.get("report") or {}
    for key, column in (("area", "area_change"), ("volume", "volume_change")):
        for reference, suffix in ((input_report, "_percent"), (cleaned_report, "_cleaned_percent")):
            before, after = (reference or {}).get(key), out.get(key)
            if before and after is not None:
                row[column + suffix] = 100.0 * (after - before) / abs(before)


def measure_output(row, tools, output, mesh, input_report, target, work, args):
    report = tools.report(output)
    if report is None:
        row["status"] = "n/a (output not readable)"
        return
    row["report"] = report
    dist = tools.distance(output, mesh)
    if dist is not None:
        row["hausdorff"] = dist["hausdorff"]
        row["hausdorff_over_L"] = dist["hausdorff"] / target
        row["mean_distance_over_L"] = 0.5 * (dist["a_to_b"]["mean"] + dist["b_to_a"]["mean"]) / target
    cleaned = getattr(args, "_cleaned", {}).get(mesh)
    if cleaned:
        dist = tools.distance(output, cleaned)
        if dist is not None:
            row["hausdorff_cleaned_over_L"] = dist["hausdorff"] / target
    add_changes(row, input_report, getattr(args, "_cleaned_report", {}).get(mesh))
    if not args.skip_tetgen:
        row["tetgen"] = tools.tetgen_check(output, work)


def bench_mesh(mesh, tools, args, methods, unavailable, work_root):
    name = os.path.splitext(os.path.basename(mesh))[0]
    print("== %s" % name, file=sys.stderr)
    work = os.path.join(work_root, name)
    os.makedirs(work, exist_ok=True)
    input_report = tools.report(mesh)
    stats = tools.stats(mesh)
    if stats is None:
        return None
    target = (input_report or {}).get("mean_edge_length") or stats["mean_edge_length"]
    result = {"mesh": name, "file": mesh, "target_edge_length": target, "bbox_diagonal": stats["bbox_diagonal"],
              "rows": []}
    # The input after molremesh's stage 0 alone (`--stages clean`: repairs, hole filling, small
    # components dropped): a second yardstick for the distance, the surface molremesh remeshes.
    cleaned = os.path.join(work, "%s_cleaned.ply" % name)
    clean_run = run_measured([tools.molremesh, "remesh", mesh, cleaned, "--stages", "clean"], args.timeout, cwd=work)
    if clean_run.ok and os.path.exists(cleaned):
        args._cleaned = getattr(args, "_cleaned", {})
        args._cleaned[mesh] = cleaned
        args._cleaned_report = getattr(args, "_cleaned_report", {})
        args._cleaned_report[mesh] = tools.report(cleaned)
    row = {"method": "input", "status": "ok", "report": input_report}
    if (name, "input") in getattr(args, "_reused", {}):
        row["tetgen"] = args._reused[(name, "input")].get("tetgen")  # the input's TetGen run is the slow one
    elif not args.skip_tetgen:
        row["tetgen"] = tools.tetgen_check(mesh, work)
    result["rows"].append(row)

    reused = getattr(args, "_reused", {})
    for method in methods:
        row = {"method": method}
        result["rows"].append(row)
        if (name, method) in reused:
            # From an earlier run (--reuse-json): same program, input and parameters.
            row.update(reused[(name, method)])
            row["reused"] = True
            add_changes(row, input_report, getattr(args, "_cleaned_report", {}).get(mesh))
            print("  %s: taken from %s" % (method, args.reuse_json), file=sys.stderr)
            continue
        if method in unavailable:
            row["status"] = "n/a (%s)" % unavailable[method]
            continue
        if method == EQUAL_RESOLUTION:
            cgal = next((r for r in result["rows"] if r["method"] == "cgal" and r.get("status") == "ok"), None)
            edge = ((cgal or {}).get("report") or {}).get("mean_edge_length")
            if not edge:
                row["status"] = "n/a (no CGAL output to take the edge length from)"
                continue
            row["target_edge_length"] = edge
        output = os.path.join(work, "%s_%s.ply" % (name, method))
        argv = method_argv(method, tools, args, mesh, output, target, stats["bbox_diagonal"], work,
                           row.get("target_edge_length"))
        print("  %s: %s" % (method, " ".join(shlex.quote(a) for a in argv)), file=sys.stderr)
        run = run_measured(argv, args.timeout, cwd=work, log_prefix=os.path.join(work, method),
                           monitor_stages=method in ("molremesh", EQUAL_RESOLUTION))
        row.update(seconds=run.seconds, peak_mb=run.peak_mb, algorithm_seconds=None)
        if method in ("molremesh", EQUAL_RESOLUTION):
            row["stage_peak_mb"] = run.stage_peaks
            stages_json = os.path.join(work, "molremesh_stages.json")
            try:
                with open(stages_json) as f:
                    row["stage_seconds"] = {s["name"]: s["seconds"] for s in json.load(f).get("stages", [])}
            except (OSError, ValueError, KeyError, TypeError):
                row["stage_seconds"] = {}
        if not run.ok or not os.path.exists(output) or os.path.getsize(output) == 0:
            row["status"] = "n/a (%s)" % (run.why() if not run.ok else "no output written")
            print("    failed: %s" % row["status"], file=sys.stderr)
            continue
        row["status"] = "ok"
        row["algorithm_seconds"] = algorithm_seconds(method, run, tools, args, mesh, work)
        measure_output(row, tools, output, mesh, input_report, target, work, args)
        print("    %.1f s, %.0f MB, %s faces" % (run.seconds, run.peak_mb or 0,
                                                  (row.get("report") or {}).get("faces", "?")), file=sys.stderr)
    return result


# --- Tables -------------------------------------------------------------------------------------

COLUMNS = ["method", "faces in", "faces out", "time s", "remesh s", "peak MB", "θmin", "θmax", "Qmin", "V567 %",
           "obtuse %", "% < 30°", "SI pairs", "boundary edges", "Hausdorff/L", "Hausdorff/L cleaned",
           "area change %", "area change % cleaned", "volume change %", "volume change % cleaned", "TetGen ok"]
STAGE_ORDER = ["load", "clean", "cvt", "valence", "segment", "rar", "small", "obtuse", "smooth", "polish", "save"]


def fmt(value, spec):
    if value is None:
        return "n/a"
    if isinstance(value, str):
        return value
    return format(value, spec)


def row_cells(row, faces_in):
    r = row.get("report") or {}
    ok = row.get("status") == "ok"
    if not ok:
        cells = [METHOD_LABELS[row["method"]], fmt(faces_in, "d")] + ["n/a"] * (len(COLUMNS) - 2)
        return cells
    tet = row.get("tetgen")
    return [
        METHOD_LABELS[row["method"]],
        fmt(faces_in, "d"),
        fmt(r.get("faces"), "d"),
        fmt(row.get("seconds"), ".1f") if row["method"] != "input" else "",
        fmt(row.get("algorithm_seconds"), ".1f") if row["method"] != "input" else "",
        format_peak(row.get("peak_mb")) if row["method"] != "input" else "",
        fmt(r.get("angle_min_deg"), ".1f"),
        fmt(r.get("angle_max_deg"), ".1f"),
        fmt(r.get("q_min"), ".3f"),
        fmt(r.get("v567_percent"), ".2f"),
        fmt(r.get("obtuse_percent"), ".2f"),
        fmt(r.get("small_angle_percent"), ".2f"),
        fmt(r.get("self_intersecting_pairs"), "d"),
        fmt(r.get("boundary_edges"), "d"),
        fmt(row.get("hausdorff_over_L"), ".3f") if row["method"] != "input" else "",
        fmt(row.get("hausdorff_cleaned_over_L"), ".3f") if row["method"] != "input" else "",
        fmt(row.get("area_change_percent"), "+.2f") if row["method"] != "input" else "",
        fmt(row.get("area_change_cleaned_percent"), "+.2f") if row["method"] != "input" else "",
        fmt(row.get("volume_change_percent"), "+.2f") if row["method"] != "input" else "",
        fmt(row.get("volume_change_cleaned_percent"), "+.2f") if row["method"] != "input" else "",
        "n/a" if tet is None else tet,
    ]


def markdown_table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(cells) + " |" for cells in rows]
    return "\n".join(lines)


def mesh_table(result):
    faces_in = ((result["rows"][0].get("report")) or {}).get("faces")
    return markdown_table(COLUMNS, [row_cells(row, faces_in) for row in result["rows"]])


def stage_table(result):
    """molremesh per stage: wall time (the pipeline's timers) and sampled peak resident MB."""
    rows = [r for r in result["rows"] if r["method"] == "molremesh" and r.get("status") == "ok"]
    if not rows:
        return None
    row = rows[0]
    secs, peaks = row.get("stage_seconds") or {}, row.get("stage_peak_mb") or {}
    names = [n for n in STAGE_ORDER if n in secs or n in peaks] + \
        sorted(n for n in set(secs) | set(peaks) if n not in STAGE_ORDER)
    cells = [[n, fmt(secs.get(n), ".2f") if n in secs else "", fmt(peaks.get(n), ".0f") if n in peaks else "n/a"]
             for n in names]
    cells.append(["whole process", fmt(row.get("seconds"), ".2f"), format_peak(row.get("peak_mb"))])
    return markdown_table(["molremesh stage", "wall s", "peak MB"], cells)


def summary_table(results, methods):
    """One row per method over all meshes: sums, worst cases and medians (see the legend)."""
    header = ["method", "meshes ok", "faces in", "faces out", "time s", "peak MB", "θmin", "θmax", "Qmin",
              "V567 %", "obtuse %", "% < 30°", "SI pairs", "boundary edges", "Hausdorff/L", "Hausdorff/L cleaned",
              "max abs area change %", "max abs area change % cleaned", "max abs volume change %",
              "max abs volume change % cleaned",
              "TetGen ok"]
    rows = []
    for method in ("input",) + tuple(methods):
        picked = [(res, row) for res in results for row in res["rows"] if row["method"] == method]
        good = [(res, row) for res, row in picked if row.get("status") == "ok" and row.get("report")]
        if not good:
            rows.append([METHOD_LABELS[method], "0/%d" % len(picked)] + ["n/a"] * (len(header) - 2))
            continue
        reps = [row["report"] for _, row in good]

        def values(key, source="report"):
            out = [(row["report"] if source == "report" else row).get(key) for _, row in good]
            return [v for v in out if v is not None]

        def agg(vals, fn, spec):
            return fmt(fn(vals), spec) if vals else "n/a"

        faces_in = sum((res["rows"][0].get("report") or {}).get("faces", 0) for res, _ in good)
        tet = [row.get("tetgen") for _, row in good]
        tet_known = [t for t in tet if t is not None]
        is_input = method == "input"
        rows.append([
            METHOD_LABELS[method],
            "%d/%d" % (len(good), len(picked)),
            str(faces_in),
            str(sum(r.get("faces", 0) for r in reps)),
            "" if is_input else agg(values("seconds", "row"), sum, ".1f"),
            "" if is_input else (format_peak(max(values("peak_mb", "row"))) if values("peak_mb", "row") else "n/a"),
            agg(values("angle_min_deg"), min, ".1f"),
            agg(values("angle_max_deg"), max, ".1f"),
            agg(values("q_min"), min, ".3f"),
            agg(values("v567_percent"), statistics.median, ".2f"),
            agg(values("obtuse_percent"), statistics.median, ".2f"),
            agg(values("small_angle_percent"), statistics.median, ".2f"),
            agg(values("self_intersecting_pairs"), sum, "d"),
            agg(values("boundary_edges"), sum, "d"),
            "" if is_input else agg(values("hausdorff_over_L", "row"), max, ".3f"),
            "" if is_input else agg(values("hausdorff_cleaned_over_L", "row"), max, ".3f"),
            "" if is_input else agg([abs(v) for v in values("area_change_percent", "row")], max, ".2f"),
            "" if is_input else agg([abs(v) for v in values("area_change_cleaned_percent", "row")], max, ".2f"),
            "" if is_input else agg([abs(v) for v in values("volume_change_percent", "row")], max, ".2f"),
            "" if is_input else agg([abs(v) for v in values("volume_change_cleaned_percent", "row")], max, ".2f"),
            ("%d/%d" % (sum(1 for t in tet_known if t.startswith("yes")), len(tet_known))) if tet_known else "n/a",
        ])
    return markdown_table(header, rows)


def describe_run(args, methods):
    lines = [
        "Generated by `benchmarks/run_benchmarks.py` on %s (%s, %d cores)." % (
            datetime.date.today().isoformat(), platform.machine(), os.cpu_count() or 0),
        "",
        "Target edge length L = mean edge length of the input; %d iterations for every method." % args.iterations,
        "",
    ]
    if "cgal" in methods:
        lines.append("- **CGAL isotropic**: CGAL 5.5 `Polygon_mesh_processing::isotropic_remeshing`, input read as a "
                     "polygon soup, `repair_polygon_soup` + `orient_polygon_soup` + `polygon_soup_to_polygon_mesh`, "
                     "nothing protected (`benchmarks/cgal_isotropic_remesh`).")
    if "meshlab" in methods:
        lines.append("- **MeshLab isotropic**: MeshLab 2020.09 \"Remeshing: Isotropic Explicit Remeshing\" through "
                     "meshlabserver, TargetLen = L (absolute), crease angle 30°, refine/collapse/swap/smooth/reproject "
                     "on, adaptive and surface distance check off (MeshLab's defaults otherwise).")
    if "molremesh" in methods:
        lines.append("- **molremesh**: `%s`." % args.molremesh_cmd.replace("|", "\\|"))
    if EQUAL_RESOLUTION in methods:
        lines += ["- **molremesh at CGAL's output edge**: the same command with `--target-length` set to the mean "
                  "edge length of CGAL's output on that mesh (CGAL's output at target L is finer than L, molremesh's "
                  "CVT hits L); its Hausdorff distances are still over L."]
    lines += [
        "",
        "Columns: *time s* = wall time of the whole process (load, remesh, save; for MeshLab also Xvfb start-up); "
        "*remesh s* = the remeshing alone (CGAL: measured around the call; MeshLab: estimated as time s minus "
        "the time of a meshlabserver run that only loads and saves the input); *peak MB* = peak resident memory "
        "(ru_maxrss from os.wait4; ≤N = below what a child inherits from the runner itself); "
        "θmin/θmax = smallest/largest triangle angle; Qmin = min of Q = 6/√3·A/(p·h); V567 % = interior vertices "
        "of valence 5–7; obtuse % = faces with an angle ≥ 90°; % < 30° = faces with an angle < 30°; SI pairs = "
        "self-intersecting face pairs sharing no vertex; Hausdorff/L = symmetric Hausdorff distance output↔input "
        "(vertices plus one area-uniform sample per face, both ways) over L; Hausdorff/L cleaned = the same "
        "against the input after molremesh's stage 0 alone (`molremesh remesh IN OUT --stages clean`: repaired, "
        "holes closed, components under 1 % of the faces dropped), for every method; area change = surface area, "
        "output vs input; volume change = signed enclosed volume, output vs input; *cleaned* beside them = the "
        "same against that cleaned input (the surface molremesh remeshes; the pipeline bounds its volume change "
        "against it); TetGen ok = `tetgen -pq1.4` builds a tetrahedral mesh of the output (timeout "
        "{timeout} s). "
        "Quality figures come from `molremesh report --json`.".replace("{timeout}", "%.0f" % args.tetgen_timeout),
    ]
    return "\n".join(lines)


# --- Machine calibration ----------------------------------------------------------------------------

# A fixed CPU-bound loop (no memory traffic), run by a child Python process.
_SPIN = "import time\nt = time.perf_counter()\ns = 0\nfor i in range(%d): s += i\nprint(time.perf_counter() - t)"


def parallel_throughput(loops=15000000):
    """How much two CPU-bound processes get done together, relative to one alone: 2.0 on two real cores,
    1.0 when the two 'cores' share one. The figure moves during a run on a shared virtual machine, so it is
    measured before and after the methods run; it says how far the parallel stages could help."""
    code = _SPIN % loops

    def spin(count):
        procs = [subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
                 for _ in range(count)]
        return [float(p.communicate()[0]) for p in procs]

    try:
        alone = min(spin(1)[0] for _ in range(2))
        together = spin(2)
    except (OSError, ValueError) as e:  # a calibration failure must not stop the benchmark
        print("run_benchmarks: parallel throughput not measured: %s" % e, file=sys.stderr)
        return None
    return round(2.0 * alone / max(together), 2), round(alone, 2), [round(t, 2) for t in together]


def describe_throughput(label, measured):
    if measured is None:
        return "- Parallel throughput %s: not measured." % label
    factor, alone, together = measured
    return ("- Parallel throughput %s: %.2f (one CPU-bound process %.2f s alone, two at once %s s; 2.00 = two "
            "cores, 1.00 = one shared core)." % (label, factor, alone, " and ".join("%.2f" % t for t in together)))


# --- Main -----------------------------------------------------------------------------------------


def resolve_meshes(names, data_dir):
    if not names:
        if not os.path.isdir(data_dir):
            sys.exit("run_benchmarks: no mesh folder %s (pass meshes or --data-dir)" % data_dir)
        return sorted(os.path.join(data_dir, f) for f in os.listdir(data_dir)
                      if os.path.splitext(f)[1].lower() in (".ply", ".off", ".obj", ".stl"))
    out = []
    for n in names:
        path = n if os.path.exists(n) else os.path.join(data_dir, n)
        if not os.path.exists(path) and os.path.exists(path + ".ply"):
            path += ".ply"
        if not os.path.exists(path):
            sys.exit("run_benchmarks: mesh not found: %s" % n)
        out.append(os.path.abspath(path))
    return out


def run_all(args, skip, methods):
    meshes = resolve_meshes(args.mesh_args + args.meshes, args.data_dir)
    tools = Tools(args)
    unavailable = tools.check(skip)
    for m, why in unavailable.items():
        print("run_benchmarks: %s: %s" % (m, why), file=sys.stderr)
    work_root = os.path.abspath(args.work_dir) if args.work_dir else tempfile.mkdtemp(prefix="molremesh_bench_")
    os.makedirs(work_root, exist_ok=True)
    results = []
    try:
        for mesh in meshes:
            res = bench_mesh(mesh, tools, args, methods, unavailable, work_root)
            if res is None:
                continue
            results.append(res)
            print("\n### %s (L = %.4f)\n\n%s\n" % (res["mesh"], res["target_edge_length"], mesh_table(res)))
            stages = stage_table(res)
            if stages:
                print(stages + "\n")
            sys.stdout.flush()
    finally:
        if not args.work_dir:
            shutil.rmtree(work_root, ignore_errors=True)
    return results


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("mesh_args", nargs="*", metavar="MESH", help="meshes (paths, or names in --data-dir)")
    p.add_argument("--meshes", nargs="+", default=[], help="meshes (same as the positional arguments)")
    p.add_argument("--data-dir", default=DEFAULT_DATA, help="folder of the default meshes (%(default)s)")
    p.add_argument("--build-dir", default=os.path.join(REPO, "build"), help="CMake build folder (%(default)s)")
    p.add_argument("--out", default=os.path.join(REPO, "docs", "results", "RESULTS.md"),
                   help="Markdown file written with the tables (%(default)s); '-' for none")
    p.add_argument("--json", help="JSON file written with the raw figures (default: BUILD/benchmarks/ and the "
                                  "name of --out with .json; raw figures are not committed); '-' for none")
    p.add_argument("--skip-cgal", action="store_true")
    p.add_argument("--skip-meshlab", action="store_true")
    p.add_argument("--skip-molremesh", action="store_true")
    p.add_argument("--skip-tetgen", action="store_true", help="leave the TetGen column out (it is the slowest)")
    p.add_argument("--equal-resolution", action="store_true",
                   help="also run molremesh with the target length set to the mean edge length of CGAL's output "
                        "(needs the CGAL method)")
    p.add_argument("--molremesh-cmd", default=DEFAULT_MOLREMESH_CMD,
                   help="command template of the molremesh method; placeholders {molremesh} {input} {output} "
                        "{target} {iterations} (default: %(default)s)")
    p.add_argument("--iterations", type=int, default=10, help="iterations of CGAL and MeshLab (%(default)s)")
    p.add_argument("--timeout", type=float, default=1800, help="seconds allowed to each remeshing (%(default)s)")
    p.add_argument("--tetgen-timeout", type=float, default=600, help="seconds allowed to TetGen (%(default)s)")
    p.add_argument("--samples", type=int, default=0,
                   help="face samples per side for the Hausdorff distance (0 = one per face)")
    p.add_argument("--threads", type=int, default=1, help="threads of mesh_distance (%(default)s)")
    p.add_argument("--work-dir", help="keep outputs and logs here (default: a temporary folder, removed)")
    p.add_argument("--from-json", help="run nothing: print and write the tables of a file written by --json")
    p.add_argument("--reuse-json", help="take the rows of --reuse-methods from this earlier --json file instead of "
                                        "running them again (their programs have not changed)")
    p.add_argument("--reuse-methods", nargs="+", default=["meshlab"], help="methods taken from --reuse-json "
                                                                           "(%(default)s; 'input': the input's "
                                                                           "TetGen result)")
    args = p.parse_args()
    json_by_default = args.json is None
    if json_by_default:
        stem = os.path.splitext(os.path.basename(args.out))[0] if args.out != "-" else "RESULTS"
        args.json = os.path.join(args.build_dir, "benchmarks", stem + ".json")
    signal.signal(signal.SIGTERM, _stop)
    signal.signal(signal.SIGINT, _stop)

    skip = {m for m in METHODS if getattr(args, "skip_" + m)}
    args._reused = {}
    if args.reuse_json:
        with open(args.reuse_json) as f:
            for res in json.load(f):
                for row in res["rows"]:
                    if row["method"] in args.reuse_methods and (row["method"] == "input" or row["method"] not in skip):
                        args._reused[(res["mesh"], row["method"])] = {k: v for k, v in row.items() if k != "method"}
    methods = [m for m in METHODS if m not in skip]
    if args.equal_resolution:
        if "cgal" not in methods or "molremesh" not in methods:
            sys.exit("run_benchmarks: --equal-resolution needs the CGAL and molremesh methods")
        methods.append(EQUAL_RESOLUTION)
    floor = run_measured(["true"], 60)
    MEMORY_FLOOR_MB[0] = floor.peak_mb or 0.0
    if args.from_json:
        with open(args.from_json) as f:
            results = json.load(f)
        if EQUAL_RESOLUTION not in methods and any(r["method"] == EQUAL_RESOLUTION for res in results
                                                   for r in res["rows"]):
            methods.append(EQUAL_RESOLUTION)
        for res in results:
            print("\n### %s (L = %.4f)\n\n%s\n" % (res["mesh"], res["target_edge_length"], mesh_table(res)))
    else:
        throughput = [describe_throughput("before the run", parallel_throughput())]
        print(throughput[0])
        results = run_all(args, skip, methods)
        throughput.append(describe_throughput("after the run", parallel_throughput()))
        print(throughput[1])

    summary = summary_table(results, methods)
    print("\n### Summary over %d meshes\n\n%s\n" % (len(results), summary))
    legend = ("Summary: faces, time, SI pairs and boundary edges are sums over the meshes that ran; peak MB, "
              "θmax, Hausdorff/L and the absolute area and volume changes the largest; θmin and Qmin the smallest; the "
              "percentages are medians; TetGen ok counts successes.")
    if args.out != "-":
        parts = ["# molremesh benchmark results", "", describe_run(args, methods), ""]
        if not args.from_json:
            parts += ["Machine:", ""] + throughput + [""]
        parts += ["## Summary", "", summary, "", legend, ""]
        for res in results:
            parts += ["## %s" % res["mesh"], "",
                      "L = %.4f, bounding-box diagonal %.2f." % (res["target_edge_length"], res["bbox_diagonal"]),
                      "", mesh_table(res), ""]
            stages = stage_table(res)
            if stages:
                parts += [stages, ""]
            notes = [(METHOD_LABELS[r["method"]], r["status"]) for r in res["rows"] if r.get("status", "ok") != "ok"]
            if notes:
                parts += ["Not measured: " + "; ".join("%s: %s" % n for n in notes), ""]
            reused = [METHOD_LABELS[r["method"]] for r in res["rows"] if r.get("reused")]
            if reused:
                parts += ["Rows not re-run (taken from an earlier run's JSON, same programs and parameters): " +
                          ", ".join(reused) + ".", ""]
        with open(args.out, "w") as f:
            f.write("\n".join(parts))
        print("run_benchmarks: tables written to %s" % args.out, file=sys.stderr)
    if args.json != "-" and not (args.from_json and json_by_default):
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
        with open(args.json, "w") as f:
            json.dump(portable_results(results), f, indent=1)
        print("run_benchmarks: raw figures written to %s" % args.json, file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
