"""A run writes case.yaml (resolved), series.csv, summary.json, a .pvd of .pvtu files with one
.vtu piece per rank, and log.txt; a failed run says so in summary.json."""

import csv
import json
import subprocess

from cli_common import Runner, parse_arguments, read_json


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    case = r.source / "cases" / "poisson" / "mms2d.yaml"
    out = r.work / "run"
    result = r.run("run", case, "--output", out, "--set", "mesh.level=1", ranks=2)
    r.expect(result.returncode == 0, "poisson 2D on 2 ranks runs", result.stdout + result.stderr)

    resolved = (out / "case.yaml").read_text() if (out / "case.yaml").exists() else ""
    r.expect("level: 1" in resolved and "partitioner: metis" in resolved,
             "case.yaml holds the --set value and the defaults", resolved)
    summary = read_json(out / "summary.json") if (out / "summary.json").exists() else {}
    r.expect(summary.get("status") == "completed", "summary.json: status completed", json.dumps(summary))
    r.expect(summary.get("ranks") == 2, "summary.json: ranks 2")
    r.expect(summary.get("benchmark", {}).get("l2_error", 1) < 1e-2, "summary.json: benchmark.l2_error present and small",
             json.dumps(summary.get("benchmark")))
    r.expect("assemble" in summary.get("stages", {}) and "solve" in summary.get("stages", {}),
             "summary.json: wall time per stage", json.dumps(summary.get("stages")))
    rows = list(csv.DictReader(open(out / "series.csv"))) if (out / "series.csv").exists() else []
    r.expect(len(rows) == 1 and "l2_error" in rows[0], "series.csv: one row with l2_error", str(rows))
    log = (out / "log.txt").read_text() if (out / "log.txt").exists() else ""
    r.expect("L2 error" in log, "log.txt holds the run's log", log[-2000:])

    # Read the written VTK back with VTK's own readers and compare with the exact field.
    reader = subprocess.run(["/usr/bin/python3", str(r.source / "tools" / "vtk_read.py"), str(out / "solution.pvd")],
                            capture_output=True, text=True)
    r.expect(reader.returncode == 0, "tools/vtk_read.py reads solution.pvd", reader.stderr)
    if reader.returncode == 0:
        data = json.loads(reader.stdout)
        step = data["steps"][0]
        arrays = {a["name"]: a for a in step["point_data"]}
        u, exact = arrays["u"]["values"], arrays["u_exact"]["values"]
        worst = max(abs(a - b) for a, b in zip(u, exact))
        r.expect(step["n_cells"] == 2 * 16 * 16, "VTK: every cell written once over the pieces", str(step["n_cells"]))
        r.expect(len(set(step["cell_data_values"]["rank"])) == 2 if "cell_data_values" in step else
                 sorted(set(int(v) for v in {a["name"]: a for a in step["cell_data"]}["rank"]["values"])) == [0, 1],
                 "VTK: one piece per rank")
        r.expect(worst < 0.02, f"VTK: u matches u_exact at the vertices (max difference {worst:.2e})")

    # A solver that does not converge: the run fails, summary.json says why.
    failed = r.work / "failed"
    result = r.run("run", case, "--output", failed, "--", "-poisson_ksp_max_it", "1", "-poisson_pc_type", "none", ranks=2)
    summary = read_json(failed / "summary.json") if (failed / "summary.json").exists() else {}
    r.expect(result.returncode == 1, "non-converging solve -> exit 1", result.stderr)
    r.expect(summary.get("status") == "failed" and "did not converge" in summary.get("reason", ""),
             "summary.json: status failed with the reason", json.dumps(summary))
    r.expect(result.stderr.count("coapt: run failed:") == 1, "one failure message", result.stderr)

    # A misspelt PETSc option is reported; with --strict-options it fails the run.
    result = r.run("run", case, "--output", r.work / "typo", "--strict-options", "--", "-poison_ksp_type", "cg")
    r.expect(result.returncode == 2 and "poison_ksp_type" in result.stderr, "unused PETSc option fails a strict run",
             result.stdout + result.stderr)
    r.finish()


if __name__ == "__main__":
    main()
