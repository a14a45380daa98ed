#!/usr/bin/python3
"""Runs coapt-bench's measurements on 1 and 2 ranks and prints their JSON lines and a
Markdown table to paste into bench/RESULTS.md (with the date and the machine).

    /usr/bin/python3 tools/run_benchmarks.py --bench build/coapt-bench [--only assembly]
"""

import argparse
import datetime
import json
import os
import platform
import subprocess

RUNS = {
    "assembly": [["assembly", "--n", "32"], ["assembly", "--n", "64"]],
}


def machine():
    model = ""
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{os.cpu_count()} cores, {model}, {platform.system()} {platform.release()}"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--bench", default="build/coapt-bench")
    parser.add_argument("--only", choices=sorted(RUNS), action="append")
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    args = parser.parse_args()
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1")
    print(f"date: {datetime.date.today()}  machine: {machine()}")
    for name in args.only or sorted(RUNS):
        for run in RUNS[name]:
            for ranks in args.ranks:
                command = ["mpirun", "--oversubscribe", "--bind-to", "none", "-np", str(ranks), args.bench, *run]
                result = subprocess.run(command, capture_output=True, text=True, env=env, check=True)
                figures = json.loads(result.stdout.strip().splitlines()[-1])
                print(f"`{' '.join(command[5:])}` on {ranks} rank(s): {json.dumps(figures)}", flush=True)


if __name__ == "__main__":
    main()
