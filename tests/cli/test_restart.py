#!/usr/bin/python3
"""Checkpoint and restart (`coapt run CASE --restart DIR`, src/coapt/run/checkpoint.hpp), on the
Newmark free vibration (cases/solid/vibration.yaml, 40 steps):

- a run of 20 steps writing a checkpoint at step 20, restarted to step 40 on the same 2 ranks,
  gives steps 21..40 of series.csv and the summary's benchmark bit for bit as the run of 40
  steps straight through;
- restarted on 1 and 3 ranks (another partition), the same to 1e-9 relative (solver tolerance);
- the ball in a box (cases/ball_in_box.yaml, contact-stabilized Newmark with mortar contact)
  checkpointed at step 260, inside its first impact (7 active nodes), and restarted to step
  300 on 1 rank gives steps 261..300 (active nodes, active-set changes, contact force, energy)
  and the impact benchmark bit for bit: the active set and the complementarity constant come
  back with the Newmark state;
- a step whose Newton fails (the strip Neo-Hookean with a large velocity, at most 3 Newton
  iterations: step 2 needs 4) stops with exit status 1 and one error line with the step's time
  and |R| history, and keeps the last good state (step 1: its VTK and a checkpoint); restarted
  from that folder with the default Newton settings, steps 2..5 are the straight run's bit for
  bit (1 rank);
- a missing checkpoint folder, a checkpoint of another mesh and a quasi-static case are refused
  with one error line naming the folder, exit 2."""

from cli_common import Runner, parse_arguments, read_json, read_rows

CASE = "solid/vibration.yaml"


def main():
    arguments = parse_arguments()
    runner = Runner(arguments)
    work = runner.work
    case = runner.source / "cases" / CASE
    every = ["--set", "output.checkpoint_interval=20"]

    def run(output, end_time, *extra, ranks=2):
        return runner.run("run", case, "--output", work / output, "--set",
                          f"time.end_time={end_time}", *every, *extra, ranks=ranks)

    straight = run("straight", 0.4)
    first = run("first", 0.2)
    again = run("again", 0.4, "--restart", work / "first")
    for name, result in [("straight", straight), ("first", first), ("restarted", again)]:
        runner.expect(result.returncode == 0, f"{name} run succeeds", result.stdout + result.stderr)
    if runner.failures:
        runner.finish()
    runner.expect((work / "first" / "checkpoint" / "state.json").exists(),
                  "the first run wrote a checkpoint")
    reference = {row["step"]: row for row in read_rows(work / "straight" / "series.csv")}
    restarted = read_rows(work / "again" / "series.csv")
    runner.expect([row["step"] for row in restarted] == [str(k) for k in range(21, 41)],
                  "the restarted series holds steps 21..40",
                  str([row["step"] for row in restarted]))
    identical = all(row == reference[row["step"]] for row in restarted)
    runner.expect(identical, "same ranks: steps 21..40 bit for bit as the straight run")
    benchmark = read_json(work / "straight" / "summary.json")["benchmark"]
    restarted_benchmark = read_json(work / "again" / "summary.json")["benchmark"]
    runner.expect(benchmark == restarted_benchmark, "same ranks: the benchmark bit for bit",
                  f"{benchmark}\n{restarted_benchmark}")

    for ranks in (1, 3):
        result = run(f"again{ranks}", 0.4, "--restart", work / "first", ranks=ranks)
        runner.expect(result.returncode == 0, f"restart on {ranks} rank(s) succeeds",
                      result.stdout + result.stderr)
        if result.returncode != 0:
            continue
        last = read_rows(work / f"again{ranks}" / "series.csv")[-1]
        worst = 0.0
        for key in ("tip_displacement_y", "kinetic_energy", "total_energy"):
            a, b = float(last[key]), float(reference["40"][key])
            worst = max(worst, abs(a - b) / abs(b))
        runner.expect(worst < 1e-9, f"restart on {ranks} rank(s): step 40 agrees to 1e-9",
                      f"largest relative difference {worst:.3e}")

    ball = runner.source / "cases" / "ball_in_box.yaml"

    def run_ball(output, end_time, *extra):
        return runner.run("run", ball, "--output", work / output, "--set", "output.vtk=false",
                          "--set", f"time.end_time={end_time}", "--set",
                          "output.checkpoint_interval=130", *extra, ranks=1)

    results = [run_ball("ball", 30), run_ball("ball-first", 26)]
    results.append(run_ball("ball-again", 30, "--restart", work / "ball-first"))
    runner.expect(all(result.returncode == 0 for result in results), "ball in a box runs succeed",
                  "\n".join(result.stderr for result in results))
    if all(result.returncode == 0 for result in results):
        reference = read_rows(work / "ball" / "series.csv")
        restarted = read_rows(work / "ball-again" / "series.csv")
        runner.expect(int(float(reference[260]["contact_active_nodes"])) > 0,
                      "the ball is in contact at the checkpoint (step 260)")
        runner.expect(restarted == reference[261:],
                      "ball in a box: steps 261..300 bit for bit as the straight run",
                      f"{len(restarted)} rows restarted")
        runner.expect(read_json(work / "ball" / "summary.json")["benchmark"] ==
                      read_json(work / "ball-again" / "summary.json")["benchmark"],
                      "ball in a box: the benchmark (impacts, contact) bit for bit")

    # A step whose Newton fails keeps the last good state: the Neo-Hookean strip with a large
    # velocity needs 4 Newton iterations from step 2 on; with at most 3, step 2 fails.
    hyperelastic = ["--set", "bodies[0].material.model=neo_hookean", "--set",
                    "time.initial_velocity=[0,1]", "--set", "output.vtk=true", "--set",
                    "output.vtk_interval=2"]
    failed = run("fails", 0.05, *hyperelastic, "--set", "newton.max_iterations=3", ranks=1)
    summary = read_json(work / "fails" / "summary.json")
    errors = [line for line in failed.stderr.splitlines() if line.startswith("coapt: run failed:")]
    runner.expect(failed.returncode == 1 and len(errors) == 1 and "t = 0.02 s" in errors[0]
                  and "|R| = [" in errors[0] and summary.get("status") == "failed"
                  and summary.get("last_good_step") == 1,
                  "a failed step: exit 1, one error line with the step's time and |R| history, "
                  "last good step 1", failed.stdout[-2000:] + failed.stderr)
    pvd = (work / "fails" / "solid.pvd").read_text() if (work / "fails" / "solid.pvd").is_file() else ""
    runner.expect('timestep="0.01"' in pvd and 'timestep="0.02"' not in pvd,
                  "a failed step: the VTK of the last good step (0.01 s), not of the failed one", pvd)
    results = [run("smooth", 0.05, *hyperelastic, ranks=1),
               run("resumed", 0.05, *hyperelastic, "--restart", work / "fails", ranks=1)]
    runner.expect(all(result.returncode == 0 for result in results),
                  "the straight run and the restart from the failed run succeed",
                  "\n".join(result.stderr for result in results))
    if all(result.returncode == 0 for result in results):
        runner.expect(read_rows(work / "resumed" / "series.csv") ==
                      read_rows(work / "smooth" / "series.csv")[2:],
                      "restarted from the failed run's last good state: steps 2..5 bit for bit")

    def refused(result, what, needle):
        errors = [line for line in result.stderr.splitlines() if "error:" in line]
        runner.expect(result.returncode == 2 and len(errors) == 1 and needle in errors[0],
                      f"refused: {what}", result.stdout + result.stderr)

    refused(run("bad1", 0.4, "--restart", work / "nowhere"), "a folder without a checkpoint",
            "nowhere")
    refused(run("bad2", 0.4, "--restart", work / "first", "--set", "mesh.cells=[12, 2]"),
            "a checkpoint of another mesh", "checkpoint")
    refused(runner.run("run", runner.source / "cases" / "cook" / "linear.yaml", "--output",
                       work / "bad3", "--restart", work / "first", ranks=1),
            "a quasi-static case", "first")
    runner.finish()


if __name__ == "__main__":
    main()
