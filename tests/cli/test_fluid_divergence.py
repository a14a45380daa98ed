#!/usr/bin/python3
"""A transient flow whose Newton solve fails stops with the step and the residual history,
keeps the last good state, and never writes the failed state (`problem: navier_stokes`,
FlowProblem::keep_last_good_state).

- Blow-up: DFG 2D-2 (level 0, steps of 0.02 s, VTK every step) with the inflow multiplied by a
  table factor that jumps from 1 at t = 0.05 s to 1e300 at t = 0.06 s, so the residual of
  step 3 is not finite. On 1, 2 and 3 ranks: exit status 1; one error line on standard error,
  naming step 3, the non-finite residual and its history; summary.json "status": "failed"
  with that reason, last_good_step 2 and last_good_time 0.04; series.csv holds the two good
  steps, all finite; solution.pvd has the times 0.02 and 0.04 only, and VTK's own reader finds
  no non-finite value in them; the checkpoint holds step 2. `--restart` from the failed run
  with the factor put back to 1 gives steps 3..5 of series.csv and the benchmark bit for bit as
  the run of 5 steps straight through with that factor (same 2 ranks, the deterministic
  solver of cli_common): what the run kept is the committed state, not the failed trial.
- No convergence: the same case with fluid.newton.max_iterations 1 (the first step needs 2)
  fails at step 1 with "no convergence in 1 iterations" and the residual history, and keeps
  the initial state (last_good_step 0, the VTK of t = 0 and a checkpoint of step 0).
- The fluid's `reaction` field: in the straight run's VTK of every step (2 ranks), its sum over
  the cylinder's vertices is the cylinder's force of that step's row of series.csv (c_D, c_L
  times rho U^2 D / 2) to 1e-9 relative, and it is zero away from prescribed velocities: the
  force written is the committed step's (FluidModel::force_level).
"""

import json
import math
import subprocess

from cli_common import DETERMINISTIC_FLUID, Runner, parse_arguments, read_json, read_rows

BASE = ["--set", "mesh.level=0", "--set", "time.step=0.02", "--set", "time.end_time=0.1",
        "--set", "output.vtk_interval=1", "--set", "boundary[2].waveform.type=table",
        "--set", "boundary[2].waveform.times=[0,0.05,0.06,1]"]
BLOW_UP = ["--set", "boundary[2].waveform.values=[1,1,1e300,1e300]"]
HARMLESS = ["--set", "boundary[2].waveform.values=[1,1,1,1]"]


def vtk_steps(r, pvd):
    """(times, non-finite count over every array) of a .pvd, read by tools/vtk_read.py."""
    reader = subprocess.run(["/usr/bin/python3", str(r.source / "tools" / "vtk_read.py"), str(pvd),
                             "--summary"], capture_output=True, text=True)
    if reader.returncode != 0:
        r.expect(False, f"tools/vtk_read.py reads {pvd.name}", reader.stderr)
        return [], -1
    steps = json.loads(reader.stdout)["steps"]
    bad = sum(array["non_finite"] for step in steps for kind in ("point_data", "cell_data")
              for array in step[kind])
    return [step["time"] for step in steps], bad


def check_reactions(r, out, rows):
    """The `reaction` field summed over the cylinder (centre (0.2, 0.2), radius 0.05) against
    series.csv's forces of the same steps; zero at the vertices inside the channel."""
    reader = subprocess.run(["/usr/bin/python3", str(r.source / "tools" / "vtk_read.py"),
                             str(out / "solution.pvd")], capture_output=True, text=True)
    if reader.returncode != 0:
        r.expect(False, "tools/vtk_read.py reads the straight run", reader.stderr)
        return
    steps = json.loads(reader.stdout)["steps"]
    r.expect(len(steps) == len(rows), "the straight run: a VTK file per step", f"{len(steps)} files")
    scale = 2.0 / (1.0 * 1.0**2 * 0.1)  # c = 2 F / (rho U^2 D)
    worst, stray = 0.0, 0.0
    for step, row in zip(steps, rows):
        points = step["points"]["values"]
        reaction = next(a for a in step["point_data"] if a["name"] == "reaction")
        ids = next(a for a in step["point_data"] if a["name"] == "global_id")["values"]
        c = reaction["components"]  # vectors are written with 3 components
        seen, force = set(), [0.0, 0.0]
        for k in range(step["n_points"]):
            if ids[k] in seen:  # a vertex in both ranks' pieces
                continue
            seen.add(ids[k])
            x, y = points[3 * k], points[3 * k + 1]
            f = reaction["values"][c * k:c * k + 2]
            if math.hypot(x - 0.2, y - 0.2) <= 0.05 + 1e-9:
                force = [force[0] + f[0], force[1] + f[1]]
            elif 1e-9 < x < 2.2 - 1e-9 and 1e-9 < y < 0.41 - 1e-9:
                stray = max(stray, abs(f[0]), abs(f[1]))
        for value, column in zip(force, ("drag_coefficient", "lift_coefficient")):
            expected = float(row[column])
            worst = max(worst, abs(scale * value - expected) / abs(expected))
    r.expect(worst < 1e-9 and stray == 0.0,
             f"reaction summed over the cylinder = the step's force in series.csv (worst {worst:.1e} "
             f"relative), zero inside the channel (largest {stray:.1e})")


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    case = r.source / "cases" / "dfg" / "2d2.yaml"

    for ranks in (1, 2, 3):
        out = r.work / f"blow-up-np{ranks}"
        result = r.run("run", case, "--output", out, *BASE, *BLOW_UP, "--", *DETERMINISTIC_FLUID,
                       ranks=ranks)
        name = f"blow-up on {ranks} rank(s)"
        r.expect(result.returncode == 1, f"{name}: exit status 1", result.stdout[-2000:] + result.stderr)
        errors = [line for line in result.stderr.splitlines() if line.startswith("coapt: run failed:")]
        r.expect(len(errors) == 1 and "step 3 (t = 0.06 s)" in errors[0] and "non-finite residual" in errors[0]
                 and "history" in errors[0], f"{name}: one error line naming step 3 and its residual history",
                 result.stderr)
        r.expect("the last good state (step 2, t = 0.04 s)" in result.stdout,
                 f"{name}: the log says where the last good state is", result.stdout[-2000:])
        summary = read_json(out / "summary.json")
        r.expect(summary.get("status") == "failed" and "step 3" in summary.get("reason", ""),
                 f"{name}: summary.json says failed, with the reason", json.dumps(summary)[:2000])
        r.expect(summary.get("last_good_step") == 2 and abs(summary.get("last_good_time", 0) - 0.04) < 1e-15,
                 f"{name}: last good step 2 at t = 0.04 s", json.dumps(summary)[:2000])
        rows = read_rows(out / "series.csv")
        r.expect(len(rows) == 2 and all(math.isfinite(float(v)) for row in rows for v in row.values()),
                 f"{name}: series.csv holds the two good steps, finite", str(rows))
        times, bad = vtk_steps(r, out / "solution.pvd")
        r.expect(len(times) == 2 and abs(times[0] - 0.02) < 1e-12 and abs(times[1] - 0.04) < 1e-12 and bad == 0,
                 f"{name}: VTK of t = 0.02 and 0.04 only, all values finite", f"times {times}, non-finite {bad}")
        state = read_json(out / "checkpoint" / "state.json")["state"]
        r.expect(state["fluid"]["steps"] == 2, f"{name}: the checkpoint holds step 2", json.dumps(state)[:500])

    # The kept state restarts as the committed state of a straight run (bit for bit, 2 ranks).
    straight = r.work / "straight"
    again = r.work / "again"
    first = r.run("run", case, "--output", straight, *BASE, *HARMLESS, "--", *DETERMINISTIC_FLUID, ranks=2)
    second = r.run("run", case, "--output", again, *BASE, *HARMLESS, "--restart", r.work / "blow-up-np2",
                   "--", *DETERMINISTIC_FLUID, ranks=2)
    r.expect(first.returncode == 0 and second.returncode == 0, "the straight run and the restart succeed",
             first.stderr + second.stdout[-2000:] + second.stderr)
    if first.returncode == 0 and second.returncode == 0:
        reference = read_rows(straight / "series.csv")
        restarted = read_rows(again / "series.csv")
        r.expect(len(reference) == 5 and restarted == reference[2:],
                 "restarted from the failed run: steps 3..5 bit for bit as the straight run",
                 f"{len(restarted)} rows restarted, {len(reference)} straight")
        r.expect(read_json(straight / "summary.json")["benchmark"] == read_json(again / "summary.json")["benchmark"],
                 "restarted from the failed run: the benchmark bit for bit")
        check_reactions(r, straight, reference)

    # A Newton iteration that runs out of iterations at the first step keeps the initial state.
    out = r.work / "no-convergence"
    result = r.run("run", case, "--output", out, *BASE, *HARMLESS, "--set", "fluid.newton.max_iterations=1")
    errors = [line for line in result.stderr.splitlines() if line.startswith("coapt: run failed:")]
    r.expect(result.returncode == 1 and len(errors) == 1 and "step 1 (t = 0.02 s)" in errors[0]
             and "no convergence in 1 iterations" in errors[0] and "residual history" in errors[0],
             "no convergence: exit status 1, one error line naming step 1 and the residual history",
             result.stdout[-2000:] + result.stderr)
    summary = read_json(out / "summary.json")
    r.expect(summary.get("status") == "failed" and summary.get("last_good_step") == 0
             and summary.get("last_good_time") == 0,
             "no convergence: failed, last good step 0 at t = 0", json.dumps(summary)[:2000])
    times, bad = vtk_steps(r, out / "solution.pvd")
    r.expect(times == [0] and bad == 0, "no convergence: the VTK of the initial state only, finite",
             f"times {times}, non-finite {bad}")
    r.expect((out / "checkpoint" / "state.json").is_file(), "no convergence: a checkpoint of step 0")
    r.finish()


if __name__ == "__main__":
    main()
