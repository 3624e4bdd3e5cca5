#!/usr/bin/python3
"""The batch workflow (workflows/Snakefile) on three shared structures with --cores 2, plus a broken
structure beside them: a row per structure in the summary, the three remeshed within the pipeline's
bounds and meshed by TetGen, the broken one failed with its reason, and the others not stopped.

Usage: test_workflow.py MOLREMESH SOURCE_DIR SHARED_DATA_DIR. Exit 77 (skipped) without snakemake,
tetgen or the shared structures."""
import csv
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SKIPPED = 77
STRUCTURES = ["1UBQ.pqr", "bpti_1bpi.pqr", "lysozyme_Lys1.pqr"]


def main(molremesh, source_dir, shared_dir):
    structures = [Path(shared_dir) / "structures" / s for s in STRUCTURES]
    for tool in ("snakemake", "tetgen"):
        if not shutil.which(tool):
            print(f"skipped: {tool} not found")
            return SKIPPED
    if not all(s.exists() for s in structures):
        print(f"skipped: shared structures not found in {shared_dir}/structures")
        return SKIPPED
    failures = []

    def check(condition, what):
        if not condition:
            failures.append(what)
            print("FAILED:", what)

    with tempfile.TemporaryDirectory(prefix="molremesh_workflow_") as tmp:
        broken = Path(tmp) / "broken.pqr"
        broken.write_text("ATOM 1 C ALA A 1 0.0 0.0\n")  # a truncated record
        out = Path(tmp) / "results"
        files = ",".join(f'"{f}"' for f in [*map(str, structures), str(broken)])
        start = time.monotonic()
        run = subprocess.run(["snakemake", "-s", str(Path(source_dir) / "workflows" / "Snakefile"),
                              "--cores", "2", "--directory", tmp, "--quiet", "--config",
                              f"structures=[{files}]", f"out_dir={out}", f"molremesh={molremesh}"],
                             capture_output=True, text=True)
        seconds = time.monotonic() - start
        check(run.returncode == 0, f"snakemake exit status {run.returncode}:\n{run.stdout}{run.stderr}")
        if run.returncode != 0:
            return 1
        rows = {row["structure"]: row for row in csv.DictReader(open(out / "summary.csv"))}
        markdown = (out / "summary.md").read_text()
        print(markdown)
        print(f"workflow: {seconds:.1f} s")
        check(sorted(rows) == sorted(s.replace(".", "_") for s in [*STRUCTURES, "broken.pqr"]),
              f"summary rows {sorted(rows)}")
        for name in STRUCTURES:
            row = rows.get(name.replace(".", "_"), {})
            check(row.get("status") == "ok", f"{name}: {row}")
            if row.get("status") != "ok":
                continue
            check(int(row["atoms"]) > 500 and row["surface"] == "ses", f"{name}: atoms, surface {row}")
            check(int(row["faces"]) > 1000, f"{name}: faces {row['faces']}")
            # 30° is the target; lysozyme misses it (29.0°, a warning, exit status 0), as README says.
            check(float(row["theta_min"]) >= 25.0, f"{name}: theta_min {row['theta_min']}")
            check(float(row["theta_max"]) <= 120.0, f"{name}: theta_max {row['theta_max']}")
            check(float(row["v567_percent"]) >= 99.0, f"{name}: V567 {row['v567_percent']}")
            check(row["self_intersections"] == "0", f"{name}: SI {row['self_intersections']}")
            check(row["tetgen_ok"] == "true" and int(row["tetrahedra"]) > 0, f"{name}: TetGen {row}")
            check(f"| {name.replace('.', '_')} | {row['atoms']} | ses | {row['faces']} |" in markdown,
                  f"{name}: Markdown row")
        bad = rows.get("broken_pqr", {})
        check(bad.get("status") == "failed" and bad.get("tetgen_ok") == "false", f"broken: {bad}")
        check("bad input" in bad.get("failure", "") and "molremesh: error:" in bad.get("failure", ""),
              f"broken: failure {bad.get('failure')}")
        check("4 structures, 3 ok, 1 failed." in markdown, "Markdown count line")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(*(str(Path(a).resolve()) for a in sys.argv[1:4])))
