#!/usr/bin/python3
"""Dynamic contact: the ball in a box (cases/ball_in_box.yaml, docs/verification/contact.md)
on level 0 up to the first impact (t = 40), with the contact-stabilized Newmark scheme and
with plain Newmark:
 - contact-stabilized, 1 and 2 ranks: one impact, incidence 45 degrees within 0.5, rebound
   within 5 degrees of 45 (41.7 here: the soft ball keeps part of its energy as vibration),
   energy lost at the impact between 0 and 2 %, no penetration beyond the gap tolerance at
   any step, the linear momentum constant to 1e-9 in free flight before the impact and its
   component along the wall changed by less than 2 % through it; 2 ranks agree with 1 to 1e-8;
 - the contact force over the impact is one smooth hump with the stabilized scheme (its total
   variation at most 1.1 times twice its peak) and oscillates with plain Newmark (more than
   twice that);
 - plain Newmark: the same impact gains energy (more than 10 %: the blow-up the stabilized
   scheme removes);
 - an `impacts.body` that is no body is an input error naming the key."""

from cli_common import Runner, parse_arguments, run_with_series


def run(r, name, ranks=1, extra=()):
    summary, rows = run_with_series(r, r.source / "cases" / "ball_in_box.yaml", name, "--set", "output.vtk=false",
                                    "--set", "time.end_time=40", *extra, ranks=ranks)
    return (summary["benchmark"], rows) if summary else (None, None)


def force_oscillation(rows, start, end):
    """Total variation of the contact force over [start, end] divided by twice its peak: 1 for
    a single hump, larger when the force oscillates."""
    force = [row["contact_total_force"] for row in rows if start <= row["time"] <= end]
    variation = sum(abs(b - a) for a, b in zip(force, force[1:]))
    return variation / (2 * max(force))


def main():
    r = Runner(parse_arguments())
    results = {}
    for ranks in (1, 2):
        b, rows = run(r, f"csnm-np{ranks}", ranks)
        if b is None:
            continue
        results[ranks] = b
        r.expect(b["impacts"] == 1, f"{ranks} rank(s): one impact ({b['impacts']})")
        if b["impacts"] != 1:
            continue
        incidence, rebound = b["incidence_angles"][0], b["rebound_angles"][0]
        loss = b["energy_loss_per_impact"][0]
        print(f"{ranks} rank(s): incidence {incidence:.4f} deg, rebound {rebound:.4f} deg, energy loss {100 * loss:.3f} %")
        r.expect(abs(incidence - 45) < 0.5, f"{ranks} rank(s): incidence {incidence:.3f} deg within 0.5 of 45")
        r.expect(abs(rebound - 45) < 5, f"{ranks} rank(s): rebound {rebound:.3f} deg within 5 of 45")
        r.expect(0 <= loss < 0.02, f"{ranks} rank(s): energy loss at the impact {100 * loss:.3f} % in [0, 2) %")
        penetration = max(row["contact_max_penetration"] for row in rows)
        r.expect(penetration <= b["contact_gap_tolerance"],
                 f"{ranks} rank(s): max penetration {penetration:.2e} within the gap tolerance {b['contact_gap_tolerance']:.2e}")
        start = b["impact_times"][0]
        flight = [row for row in rows if row["time"] < start - 1e-9]
        drift = max(abs(row["momentum_x_ball"] - flight[0]["momentum_x_ball"]) +
                    abs(row["momentum_y_ball"] - flight[0]["momentum_y_ball"]) for row in flight)
        scale = abs(flight[0]["momentum_x_ball"]) + abs(flight[0]["momentum_y_ball"])
        r.expect(drift < 1e-9 * scale, f"{ranks} rank(s): momentum constant in free flight ({drift / scale:.1e})")
        # the first wall is x = 200: the momentum along it (y) is what a frictionless wall keeps
        tangential = abs(rows[-1]["momentum_y_ball"] / flight[-1]["momentum_y_ball"] - 1)
        r.expect(tangential < 0.02, f"{ranks} rank(s): momentum along the wall changed by {100 * tangential:.2f} % < 2 %")
        oscillation = force_oscillation(rows, start - 1, start + 7)
        r.expect(oscillation < 1.1, f"{ranks} rank(s): contact force one hump (variation / 2 peak = {oscillation:.3f} < 1.1)")
    if 1 in results and 2 in results:
        keys = ("energy_initial", "max_energy_loss_per_impact")
        difference = max(abs(results[2][k] - results[1][k]) / max(abs(results[1][k]), 1e-300) for k in keys)
        difference = max(difference, abs(results[2]["rebound_angles"][0] - results[1]["rebound_angles"][0]) / 45)
        r.expect(difference < 1e-8, f"2 ranks agree with 1 rank ({difference:.1e} < 1e-8)")

    b, rows = run(r, "newmark", 1, ("--set", "time.scheme=newmark"))
    if b is not None and b["impacts"] >= 1:
        start = b["impact_times"][0]
        oscillation = force_oscillation(rows, start - 1, start + 7)
        r.expect(oscillation > 2, f"plain Newmark: the contact force oscillates (variation / 2 peak = {oscillation:.2f} > 2)")
        loss = b["energy_loss_per_impact"][0]
        print(f"plain Newmark: first impact energy change {-100 * loss:+.2f} %, rebound {b['rebound_angles'][0]:.3f} deg")
        r.expect(loss < -0.10, f"plain Newmark gains energy at the impact ({-100 * loss:+.1f} %)")
    elif b is not None:
        r.expect(False, "plain Newmark: an impact is seen")

    result = r.run("run", r.source / "cases" / "ball_in_box.yaml", "--output", r.work / "bad",
                   "--set", "impacts.body=sphere")
    r.expect(result.returncode == 2 and "impacts.body" in result.stderr and "sphere" in result.stderr,
             "an unknown impacts.body is an input error naming the key", result.stderr)
    r.finish()


if __name__ == "__main__":
    main()
