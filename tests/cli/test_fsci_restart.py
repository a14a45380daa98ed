#!/usr/bin/python3
"""Checkpoint and restart of the immersed coupling (`coapt run CASE --restart DIR`,
coupling/fsci_problem.cpp write_checkpoint), on the 2D valve (cases/valve2d.yaml as committed,
level 0, pressure reversed from the start as in test_fsci_valve.py, steps of 2 ms to
t = 0.047 s): leaflets by contact-stabilized Newmark with mortar contact, IQN-ILS reusing the
last 4 steps' columns, the continuity of the cells the leaflets cover wholly scaled
(fluid.covered_continuity_factor 0.01).

- 22 steps writing a checkpoint at step 22 (t = 0.043 s), when the coaptation faces are in
  contact (they touch at t = 0.041 s, step 21), restarted to step 24 on the same 2 ranks, gives
  the rows of steps 23..24 of series.csv (forces, coupling iterations and changes, opening,
  contact nodes, pressure and penetration, flows) and the summary's benchmark bit for bit as
  the run of 24 steps straight through: the fluid's BDF2 history, the leaflets' Newmark state,
  the applied force that starts a step, the constrained fluid nodes, the covered cells scaled
  (from the constrained nodes, the walls and the cells' covered fractions), the contact active
  set and the complementarity constant and the IQN-ILS columns all come back; the step to
  t = 0.034 s (step 17) is retried with 1 ms before the checkpoint, and the steps go on at 2 ms
  after the restart as they do straight through;
- restarted on 1 rank (another partition), step 24 agrees to 1e-5 relative in the opening and
  the inlet flow (the coupling stops at a relative change of 1e-3, so its iterates differ by
  round-off from the 2-rank run's);
- a rigid body translating through the fluid (cases/dfg/2d1_immersed.yaml made transient, the
  cylinder moving at 0.1 m/s, 4 steps of 0.05 s; the constrained set changes every step):
  2 + 2 steps on 1 rank give steps 3..4 and the benchmark bit for bit (the body's position
  comes back from the checkpoint);
- a step that fails (the same body, its inflow times a factor jumping to 1e300 at t = 0.15 s,
  no retries) stops with exit status 1 and keeps the last good state (step 2) as a checkpoint:
  restarted from the failed run's folder with the factor 1, steps 3..4 are the straight run's
  bit for bit;
- a step of the leaflets in contact that fails (restarted from the checkpoint at step 22, the
  pressure jumping to -1000 times 20 Pa over step 23, no retries) leaves a checkpoint that is,
  file for file and bit for bit, the one it started from: the failed try's constrained nodes,
  force, contact state and forgotten IQN-ILS columns are put back;
- a checkpoint of a flow run and a checkpoint with other solids are refused with one error
  line naming the folder, exit 2.
The fluid and the solid are solved by PETSc's own LU of the gathered matrix (ksp_type
preonly, pc_type redundant; test_fluid_restart.py): the default MUMPS LU is not bitwise
reproducible on 2 ranks (two identical runs differ by ~1e-15 relative), so no restart could
be."""

from cli_common import (DETERMINISTIC_FLUID, DETERMINISTIC_SOLID, Runner, parse_arguments,
                        read_json, read_rows)

VALVE = ["--set", "output.vtk=false", "--set", "fluid.outlets[0].waveform.times=[0,0.03,1]",
         "--set", "fluid.outlets[0].waveform.values=[0,-1.5,-1.5]",
         "--set", "output.checkpoint_interval=22"]
DETERMINISTIC = ["--", *DETERMINISTIC_FLUID, *DETERMINISTIC_SOLID]


def main():
    arguments = parse_arguments()
    runner = Runner(arguments)
    work = runner.work
    case = runner.source / "cases" / "valve2d.yaml"

    def run(output, end_time, *extra, ranks=2):
        return runner.run("run", case, "--output", work / output, "--set",
                          f"time.end_time={end_time}", *VALVE, *extra, *DETERMINISTIC,
                          ranks=ranks)

    runs = {"straight": run("straight", 0.047), "first": run("first", 0.043)}
    runs["again"] = run("again", 0.047, "--restart", work / "first")
    for name, result in runs.items():
        runner.expect(result.returncode == 0, f"valve {name} run succeeds",
                      result.stdout[-3000:] + result.stderr)
    if runner.failures:
        runner.finish()
    state = read_json(work / "first" / "checkpoint" / "state.json")["state"]
    print(f"checkpoint at step {state['step']}: IQN-ILS columns per kept step {state['iqn_columns']}, "
          f"constrained fluid nodes restored, complementarity constant "
          f"{state['solid0_contact']['complementarity_constant']:.4g}")
    runner.expect(sum(state["iqn_columns"]) > 0, "the checkpoint holds IQN-ILS columns to reuse")
    reference = read_rows(work / "straight" / "series.csv")
    again = read_rows(work / "again" / "series.csv")
    active = [int(float(row["contact_active_nodes_leaflets"])) for row in reference]
    tries = [int(float(row["coupling_tries"])) for row in reference]
    print(f"active contact nodes per step from step 18: {active[17:]}; steps retried: "
          f"{[i + 1 for i, n in enumerate(tries) if n > 1]}")
    runner.expect(len(reference) == 24 and active[21] > 0 and min(active[22:]) > 0,
                  f"the checkpoint (step 22) and the restarted steps are in contact "
                  f"({active[21] if len(active) > 21 else '-'} active nodes at step 22)")
    runner.expect(len(reference) == 24 and again == reference[22:],
                  "same ranks: steps 23..24 bit for bit as the straight run",
                  f"{len(again)} rows restarted, {len(reference)} straight\n"
                  + "\n".join(f"{k}: {a[k]} vs {b[k]}" for a, b in zip(again, reference[22:])
                              for k in a if a[k] != b[k]))
    a = read_json(work / "straight" / "summary.json")["benchmark"]
    b = read_json(work / "again" / "summary.json")["benchmark"]
    runner.expect(a == b, "same ranks: the benchmark bit for bit", f"{a}\n{b}")

    result = run("again1", 0.047, "--restart", work / "first", ranks=1)
    runner.expect(result.returncode == 0, "restart on 1 rank succeeds",
                  result.stdout[-3000:] + result.stderr)
    if result.returncode == 0:
        last, expected = read_rows(work / "again1" / "series.csv")[-1], reference[-1]
        worst = max(abs(float(last[k]) / float(expected[k]) - 1)
                    for k in ("opening_leaflets", "outlet_flow_inlet"))
        runner.expect(last["time"] == expected["time"] and worst < 1e-5,
                      f"restart on 1 rank: step 24 agrees to 1e-5 (largest relative difference "
                      f"{worst:.2e})")

    # A step of the leaflets that fails keeps the last good state, all of it: restarted from
    # the checkpoint at step 22 (in contact) with the pressure jumping to -1000 (in units of
    # the case's 20 Pa) over step 23 and no retries, the step fails (the fluid's Newton
    # diverges inside the coupling). Its try moves the leaflets, the constrained fluid nodes,
    # the force B^T lambda and the contact state, and the failure forgets the IQN-ILS columns;
    # the checkpoint it leaves must be, file for file and bit for bit, the one it started from.
    jump = ["--set", "fluid.outlets[0].waveform.times=[0,0.03,0.043,0.045,1]",
            "--set", "fluid.outlets[0].waveform.values=[0,-1.5,-1.5,-1000,-1000]",
            "--set", "coupling.iteration.retries=0"]
    failed = run("fails", 0.047, *jump, "--restart", work / "first")
    summary = read_json(work / "fails" / "summary.json")
    runner.expect(failed.returncode == 1 and summary.get("status") == "failed"
                  and summary.get("last_good_step") == 22,
                  f"leaflets: the step with the jump fails, exit 1, last good step 22 "
                  f"(measured {summary.get('last_good_step')})",
                  failed.stdout[-2000:] + failed.stderr[-2000:])
    if failed.returncode == 1:
        files = sorted(path.name for path in (work / "first" / "checkpoint").glob("*.bin"))
        differ = [name for name in files
                  if (work / "first" / "checkpoint" / name).read_bytes()
                  != (work / "fails" / "checkpoint" / name).read_bytes()]
        states = [read_json(work / name / "checkpoint" / "state.json")["state"]
                  for name in ("first", "fails")]
        differ += [key for key in states[0] if states[0][key] != states[1].get(key)]
        print(f"checkpoint after the failed step: {len(files)} files, IQN-ILS columns "
              f"{states[1]['iqn_columns']}, {active[21]} active contact node(s); differing from "
              f"the last good step's: {differ or 'none'}")
        runner.expect(len(files) > 0 and not differ and sum(states[1]["iqn_columns"]) > 0,
                      "leaflets: the failed run's checkpoint is the last good step's bit for bit "
                      "(fluid, leaflets, constrained nodes, force, contact, IQN-ILS columns)")

    rigid = runner.source / "cases" / "dfg" / "2d1_immersed.yaml"
    moving = ["--set", "output.vtk=false", "--set", "time.steady=false", "--set", "time.step=0.05",
              "--set", "solids[0].velocity=[0.1, 0]", "--set", "output.checkpoint_interval=2"]

    def run_rigid(output, end_time, *extra):
        return runner.run("run", rigid, "--output", work / output, "--set",
                          f"time.end_time={end_time}", *moving, *extra, ranks=1)

    results = [run_rigid("rigid", 0.2), run_rigid("rigid-first", 0.1)]
    results.append(run_rigid("rigid-again", 0.2, "--restart", work / "rigid-first"))
    runner.expect(all(result.returncode == 0 for result in results), "moving rigid body runs succeed",
                  "\n".join(result.stderr[-2000:] for result in results))
    if all(result.returncode == 0 for result in results):
        reference = read_rows(work / "rigid" / "series.csv")
        again = read_rows(work / "rigid-again" / "series.csv")
        runner.expect(len(again) == 2 and again == reference[-2:],
                      "moving rigid body: steps 3..4 bit for bit as the straight run")
        runner.expect(reference[-1]["constrained_cylinder"] != reference[-3]["constrained_cylinder"],
                      "moving rigid body: the constrained set changed over the restarted steps")
        runner.expect(read_json(work / "rigid" / "summary.json")["benchmark"] ==
                      read_json(work / "rigid-again" / "summary.json")["benchmark"],
                      "moving rigid body: the benchmark bit for bit")

    # A step that fails keeps the last good state as a checkpoint: the inflow times a factor
    # that jumps to 1e300 at t = 0.15 s (step 3), no retries; restarted from the failed run's
    # folder with the factor 1, steps 3..4 are the straight run's bit for bit.
    blow_up = ["--set", "fluid.boundary[1].waveform.type=table",
               "--set", "fluid.boundary[1].waveform.times=[0,0.125,0.15,1]",
               "--set", "coupling.iteration.retries=0"]
    failed = run_rigid("rigid-fails", 0.2, *blow_up, "--set", "fluid.boundary[1].waveform.values=[1,1,1e300,1e300]")
    summary = read_json(work / "rigid-fails" / "summary.json")
    runner.expect(failed.returncode == 1 and summary.get("status") == "failed"
                  and summary.get("last_good_step") == 2 and "the last good state (step 2, t = 0.1 s)" in failed.stdout,
                  "a failed step: exit 1, summary failed, last good step 2 and where it is",
                  failed.stdout[-2000:] + failed.stderr)
    resumed = run_rigid("rigid-resumed", 0.2, *blow_up, "--set", "fluid.boundary[1].waveform.values=[1,1,1,1]",
                        "--restart", work / "rigid-fails")
    runner.expect(resumed.returncode == 0, "restart from the failed run succeeds", resumed.stderr[-2000:])
    if resumed.returncode == 0 and (work / "rigid" / "series.csv").is_file():
        runner.expect(read_rows(work / "rigid-resumed" / "series.csv") == read_rows(work / "rigid" / "series.csv")[2:],
                      "restarted from the failed run's last good state: steps 3..4 bit for bit")

    def refused(result, what, needle):
        errors = [line for line in result.stderr.splitlines() if "error:" in line]
        runner.expect(result.returncode == 2 and len(errors) == 1 and needle in errors[0],
                      f"refused: {what}", result.stdout + result.stderr)

    flow = runner.run("run", runner.source / "cases" / "dfg" / "2d2.yaml", "--output", work / "flow",
                      "--set", "time.end_time=0.01", "--set", "time.step=0.01", "--set",
                      "output.vtk=false", "--set", "output.checkpoint_interval=1", ranks=1)
    runner.expect(flow.returncode == 0, "a flow run writing a checkpoint succeeds", flow.stderr)
    refused(run("bad1", 0.047, "--restart", work / "flow"), "a checkpoint of a flow run", "flow")
    refused(run("bad2", 0.047, "--set", "solids[0].name=valve", "--set", "benchmark.solid=valve",
                "--restart", work / "first"), "a checkpoint with other solids", "first")
    runner.finish()


if __name__ == "__main__":
    main()
