#!/usr/bin/python3
"""Two deformable blocks colliding (cases/contact/impact2d.yaml, docs/verification/contact.md):
the contact-stabilized predictor between two deformable bodies, on 1 and 2 ranks.
 - the run completes (10 steps of 5 ms): the blocks are in contact from the start, rebound and
   separate (no active node at the last step);
 - the total y momentum (momentum_y_lower + momentum_y_upper, 0 at the start: +500 and -500
   kg m/s per m) stays 0 to 1e-9 of one block's momentum at every step. The predictor's
   projection in the mass norm moves slave and master nodes so that it conserves momentum; a
   clip of the slave nodes alone would take momentum out of the slave only;
 - no penetration beyond the gap tolerance at any step, pressure >= 0 on the active set;
 - 2 ranks agree with 1 (momenta, energy) to 1e-8 relative at the last step."""

from cli_common import Runner, parse_arguments, run_with_series

CASE = ("cases", "contact", "impact2d.yaml")


def main():
    r = Runner(parse_arguments())
    last = {}
    for ranks in (1, 2):
        summary, rows = run_with_series(r, r.source.joinpath(*CASE), f"impact-np{ranks}", ranks=ranks)
        if summary is None:
            continue
        scale = abs(rows[0]["momentum_y_lower"])
        drift = max(abs(row["momentum_y_lower"] + row["momentum_y_upper"]) for row in rows) / scale
        print(f"{ranks} rank(s): y momentum of the lower block {rows[0]['momentum_y_lower']:.6g} -> "
              f"{rows[-1]['momentum_y_lower']:.6g}, largest total {drift:.1e} of it, energy "
              f"{rows[0]['total_energy']:.6g} -> {rows[-1]['total_energy']:.6g}")
        r.expect(drift < 1e-9, f"{ranks} rank(s): total y momentum conserved ({drift:.1e} < 1e-9)")
        r.expect(rows[0]["contact_active_nodes"] > 0 and rows[-1]["contact_active_nodes"] == 0,
                 f"{ranks} rank(s): in contact at the start, separated at the end")
        r.expect(rows[-1]["momentum_y_lower"] < 0, f"{ranks} rank(s): the lower block rebounds")
        tolerance = summary["benchmark"]["contact_gap_tolerance"]
        penetration = max(row["contact_max_penetration"] for row in rows)
        r.expect(penetration <= tolerance, f"{ranks} rank(s): penetration {penetration:.1e} m "
                 f"<= gap tolerance {tolerance:.1e} m")
        r.expect(all(row["contact_min_active_pressure"] >= 0 for row in rows),
                 f"{ranks} rank(s): pressure >= 0 on the active set")
        last[ranks] = rows[-1]
    if len(last) == 2:
        difference = max(abs(last[2][k] / last[1][k] - 1)
                         for k in ("momentum_y_lower", "momentum_y_upper", "total_energy"))
        r.expect(difference < 1e-8, f"2 ranks agree with 1 ({difference:.1e} < 1e-8)")
    r.finish()


if __name__ == "__main__":
    main()
