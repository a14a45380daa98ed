#!/usr/bin/python3
"""Two soft leaflets pressed together (cases/contact/leaflets2d.yaml, docs/verification/
contact.md): contact between two deformable, slender bodies that bend and slide while in
contact, on level 0.
 - with `contact.linearisation: finite_difference` (the case as committed) on 1, 2 and 3 ranks
   the run completes: every load step converges, in at most 12 Newton iterations (the step in
   which contact begins searches the active set) and in at most 6 on average over the steps
   after it (measured 12 and 4.9: the contact rows' tangent includes the derivative of the
   mortar geometry, so Newton converges quadratically once the active set holds);
 - at every load step: contact (at least one active node), no penetration beyond the gap
   tolerance, pressure >= 0 on the active set and none left off it (complementarity: max |p g|
   below 1e-12 Pa m, pressures are ~10-200 Pa and gaps ~1e-5 m where open);
 - 2 and 3 ranks agree with 1 rank at the last step (lower tip displacement, contact force) to
   1e-8 relative;
 - the same case with the frozen geometry (`linearisation: frozen`) on the first 4 load steps
   reaches the same solution (tip displacement to 1e-7 relative, the Newton tolerance's
   reach), with more iterations per step than the finite-difference tangent (linear
   convergence: measured 16, 12, 14, 19 against 12, 4, 4, 6);
 - a `linearisation` other than frozen or finite_difference is an input error naming the key."""

from cli_common import Runner, parse_arguments, run_with_series

CASE = ("cases", "contact", "leaflets2d.yaml")


def main():
    r = Runner(parse_arguments())
    case = r.source.joinpath(*CASE)
    last = {}
    for ranks in (1, 2, 3):
        summary, rows = run_with_series(r, case, f"leaflets-np{ranks}", "--set", "output.vtk=false",
                                        ranks=ranks)
        if summary is None:
            continue
        its = [int(row["newton_iterations"]) for row in rows]
        tolerance = summary["benchmark"].get("contact_gap_tolerance", 0.0)
        print(f"{ranks} rank(s): Newton iterations per load step {its}")
        r.expect(max(its) <= 12, f"{ranks} rank(s): at most 12 Newton iterations per load step ({max(its)})")
        later = its[1:]
        r.expect(sum(later) <= 6 * len(later),
                 f"{ranks} rank(s): at most 6 on average after the first step ({sum(later) / len(later):.2f})")
        r.expect(all(row["contact_active_nodes"] >= 1 for row in rows), f"{ranks} rank(s): contact at every step")
        penetration = max(row["contact_max_penetration"] for row in rows)
        r.expect(penetration <= max(tolerance, 1e-12),
                 f"{ranks} rank(s): no penetration beyond the gap tolerance ({penetration:.1e} m)")
        r.expect(all(row["contact_min_active_pressure"] >= 0 for row in rows),
                 f"{ranks} rank(s): pressure >= 0 on the active set at every step")
        open_pressure = max(row["contact_max_open_pressure"] for row in rows)
        complementarity = max(row["contact_max_complementarity"] for row in rows)
        r.expect(open_pressure < 1e-6 * max(row["contact_max_pressure"] for row in rows),
                 f"{ranks} rank(s): no pressure off the active set ({open_pressure:.1e} Pa)")
        r.expect(complementarity < 1e-12, f"{ranks} rank(s): max |p g| {complementarity:.1e} < 1e-12 Pa m")
        last[ranks] = rows[-1]
    if 1 in last:
        for ranks in (2, 3):
            if ranks not in last:
                continue
            difference = max(abs(last[ranks][k] / last[1][k] - 1)
                             for k in ("lower_tip_displacement_y", "contact_force_y"))
            r.expect(difference < 1e-8, f"{ranks} ranks agree with 1 rank ({difference:.1e} < 1e-8)")

    # The case's first 4 load steps (0.6 Pa each).
    steps = ["--set", "steps=4", "--set", "pressures[0].pressure=2.4", "--set", "pressures[1].pressure=2.4",
             "--set", "output.vtk=false"]
    results = {}
    for method in ("finite_difference", "frozen"):
        summary, rows = run_with_series(r, case, f"leaflets-{method}", *steps,
                                        "--set", f"contact.linearisation={method}")
        if summary is not None:
            results[method] = rows
    if len(results) == 2:
        fd, frozen = results["finite_difference"], results["frozen"]
        its = {m: [int(row["newton_iterations"]) for row in rows] for m, rows in results.items()}
        print(f"Newton iterations: finite_difference {its['finite_difference']}, frozen {its['frozen']}")
        difference = abs(frozen[-1]["lower_tip_displacement_y"] / fd[-1]["lower_tip_displacement_y"] - 1)
        r.expect(difference < 1e-7, f"frozen and finite_difference reach the same solution ({difference:.1e})")
        r.expect(sum(its["frozen"][1:]) > sum(its["finite_difference"][1:]),
                 "the frozen geometry needs more Newton iterations after the first step")

    result = r.run("run", case, "--output", r.work / "bad", "--set", "contact.linearisation=exact")
    r.expect(result.returncode == 2 and "linearisation" in result.stderr,
             "an unknown linearisation is an input error naming the key", result.stderr)
    r.finish()


if __name__ == "__main__":
    main()
