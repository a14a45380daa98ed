"""Shared helpers of the command-line tests: argument parsing, running coapt under mpirun,
and small assertions with readable failures."""

import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path


def parse_arguments():
    parser = argparse.ArgumentParser()
    parser.add_argument("--coapt", required=True, help="the coapt executable")
    parser.add_argument("--mpiexec", default="mpirun")
    parser.add_argument("--source", required=True, help="the source tree (for cases/, tools/)")
    parser.add_argument("--workdir", required=True, help="scratch folder for this test")
    arguments = parser.parse_args()
    work = Path(arguments.workdir)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    return arguments


class Runner:
    """Runs coapt (optionally under mpirun) and keeps the output for messages."""

    def __init__(self, arguments):
        self.coapt = arguments.coapt
        self.mpiexec = arguments.mpiexec
        self.source = Path(arguments.source)
        self.work = Path(arguments.workdir)
        self.failures = 0
        self.passed = 0

    def run(self, *args, ranks=1, timeout=900, check=False):
        command = [self.mpiexec, "--oversubscribe", "--bind-to", "none", "-np", str(ranks), self.coapt]
        command += [str(a) for a in args]
        environment = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                           OMP_NUM_THREADS="1")
        result = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=environment)
        if check and result.returncode != 0:
            raise AssertionError(f"{' '.join(command)} failed ({result.returncode}):\n{result.stdout}\n{result.stderr}")
        return result

    def expect(self, condition, what, detail=""):
        if condition:
            self.passed += 1
            print(f"ok: {what}")
        else:
            self.failures += 1
            print(f"FAILED: {what}\n{detail}")

    def finish(self):
        print(f"{self.passed} passed, {self.failures} failed")
        sys.exit(1 if self.failures else 0)


# PETSc's own LU of the gathered matrix without a Krylov wrapper, for tests that compare runs
# bit for bit: MUMPS LU on 2 ranks is not bitwise reproducible from run to run (two identical
# 2-rank runs of DFG 2D-2 differ by ~1e-15 relative from the 4th step on).
DETERMINISTIC_FLUID = ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "redundant",
                       "-fluid_redundant_pc_type", "lu"]
DETERMINISTIC_SOLID = ["-solid_pc_type", "redundant", "-solid_redundant_pc_type", "lu"]


def read_rows(path):
    """The rows of a CSV file (series.csv) as dicts of strings."""
    with open(path) as f:
        return list(csv.DictReader(f))


def read_json(path):
    with open(path) as f:
        return json.load(f)


def run_with_series(runner, case, name, *arguments, ranks=1):
    """Runs `coapt run case --output work/name arguments...`; expects it to complete and returns
    (summary.json, series.csv rows as floats), or (None, None) after a failed expectation."""
    out = runner.work / name
    result = runner.run("run", case, "--output", out, *arguments, ranks=ranks)
    summary = read_json(out / "summary.json") if (out / "summary.json").is_file() else {}
    ok = result.returncode == 0 and summary.get("status") == "completed"
    runner.expect(ok, f"{name} on {ranks} rank(s) runs", result.stdout[-3000:] + result.stderr)
    if not ok:
        return None, None
    with open(out / "series.csv") as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    return summary, rows
