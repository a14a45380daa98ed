"""Two flaps pressed together by the flow in a 3D channel (cases/flap3d/contact.yaml: one
deformable solid with two bodies, the front flap [0.3, 0.34] x [0.1, 0.3] x [0, 0.2] m and the
back flap touching it behind, both clamped on the floor, frictionless mortar contact between the
front flap's downstream face and the back flap's upstream face, immersed in the fluid mesh;
transient block Gauss-Seidel coupling with IQN-ILS), level 0, the first 4 steps of the inflow's
ramp (t <= 0.2 s) on 1 and 2 ranks and the first 2 on 3 ranks (oversubscribed on a 2-core
machine), the fluid by MUMPS LU: 3D mortar contact inside the immersed coupling, as the 3D
valve's leaflets need it.
 - the run completes and every step's coupling converges at the first try;
 - the force on the flaps B^T lambda balances the constraint reactions to round-off (1e-12);
 - the faces are in contact at every step (active slave nodes), with penetration and opening
   below 1e-9 m (5e-8 of the cell size; measured 8e-16 and 6e-17 m);
 - the contact carries load from the front flap to the back one: the contact force's x
   component is positive and grows with the inflow at every step (1.7e-3 to 5.9e-2 N);
 - the flaps bend together: the back flap's tip u_x is within 5 % of the front flap's at every
   step (measured 0.2 %), and both grow;
 - the flaps' volume changes by less than 1e-3;
 - the force on each flap (series.csv's force_x_flaps_front and _back: the part of B^T lambda on
   its vertices) sums to the force on the solid (1e-12 relative), both are positive (the flow
   pushes both downstream) and grow;
 - the contact acts: the same case without its contact pair (1 rank) lets the front flap's
   downstream face pass into the back flap (at the middle of the top edge its u_x exceeds the
   back flap's upstream face's by 15 um at t = 0.2 s); with the pair the front flap's tip moves
   less and the back flap's more than without it (measured -0.6 % and +0.3 %: on this fluid
   mesh the fluid nodes around the interface, covered by both flaps, carry most of the load
   from one to the other, docs/verification/fsci.md);
 - 2 and 3 ranks agree with 1 rank at every step to 1e-3 relative in both tips' u_x, the drag,
   the front flap's force and the contact force (the coupling stops within about 1e-4 of the
   fixed point; measured 1e-10)."""

import re

from cli_common import Runner, parse_arguments, run_with_series

STEPS = {1: 4, 2: 4, 3: 2}  # per rank count
DIRECT = ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu", "-fluid_pc_factor_mat_solver_type", "mumps"]
VOLUME = 2 * 0.04 * 0.2 * 0.2  # two flaps of 0.04 x 0.2 x 0.2 m, m^3
COMPARED = ("flaps_front_tip_ux", "flaps_back_tip_ux", "force_x_flaps", "force_x_flaps_front",
            "contact_force_x_flaps")


def increasing(values):
    return values[0] > 0 and all(a < b for a, b in zip(values, values[1:]))


def main():
    r = Runner(parse_arguments())
    case = r.source / "cases" / "flap3d" / "contact.yaml"
    rows_of = {}
    for ranks, steps in STEPS.items():
        summary, rows = run_with_series(r, case, f"contact3d-np{ranks}", "--set", "output.vtk=false",
                                        "--set", f"time.end_time={0.05 * steps}", "--", *DIRECT, ranks=ranks)
        if summary is None:
            continue
        rows_of[ranks] = rows
        b = summary["benchmark"]
        front = [row["flaps_front_tip_ux"] for row in rows]
        back = [row["flaps_back_tip_ux"] for row in rows]
        push = [row["contact_force_x_flaps"] for row in rows]
        active = [int(row["contact_active_nodes_flaps"]) for row in rows]
        penetration = max(row["contact_max_penetration_flaps"] for row in rows)
        opening = max(abs(row["opening_flaps"]) for row in rows)
        apart = max(abs(u / v - 1) for u, v in zip(back, front))
        volume_change = max(abs(row["volume_flaps"] / VOLUME - 1) for row in rows)
        print(f"{ranks} rank(s): front tip u_x {', '.join(f'{1e3 * u:.5f}' for u in front)} mm, back "
              f"{', '.join(f'{1e3 * u:.5f}' for u in back)} mm, contact force x "
              f"{', '.join(f'{f:.3e}' for f in push)} N, active nodes {active}, penetration "
              f"{penetration:.1e} m, opening {opening:.1e} m, coupling iterations "
              f"{[int(row['coupling_iterations']) for row in rows]}, volume change {volume_change:.1e}")
        r.expect(len(rows) == steps, f"{ranks} rank(s): {steps} steps ({len(rows)})")
        r.expect(all(row["coupling_tries"] == 1 for row in rows),
                 f"{ranks} rank(s): every step's coupling converges at the first try")
        r.expect(b["force_balance_error"] < 1e-12,
                 f"{ranks} rank(s): force balance {b['force_balance_error']:.1e} < 1e-12")
        r.expect(min(active) > 0, f"{ranks} rank(s): the faces are in contact at every step ({active})")
        r.expect(penetration < 1e-9 and opening < 1e-9,
                 f"{ranks} rank(s): penetration {penetration:.1e} m and opening {opening:.1e} m < 1e-9 m")
        r.expect(increasing(push), f"{ranks} rank(s): the contact pushes the back flap downstream, "
                                   f"harder at every step")
        r.expect(increasing(front) and increasing(back) and apart < 0.05,
                 f"{ranks} rank(s): the flaps bend downstream together (tips within {apart:.1e} < 5 %)")
        r.expect(volume_change < 1e-3, f"{ranks} rank(s): flaps' volume change {volume_change:.1e} < 1e-3")
        parts = max(abs(row[f"force_{a}_flaps_front"] + row[f"force_{a}_flaps_back"] - row[f"force_{a}_flaps"])
                    / abs(row["force_x_flaps"]) for row in rows for a in "xyz")
        r.expect(parts < 1e-12, f"{ranks} rank(s): the flaps' forces sum to the solid's ({parts:.1e} < 1e-12)")
        r.expect(increasing([row["force_x_flaps_front"] for row in rows])
                 and increasing([row["force_x_flaps_back"] for row in rows]),
                 f"{ranks} rank(s): the flow pushes both flaps downstream, harder at every step")
        r.expect(set(b["solids"]["flaps"]["body_forces"]) == {"front", "back"},
                 f"{ranks} rank(s): summary.json has the force on each body")
    for ranks in (2, 3):
        if 1 in rows_of and ranks in rows_of:
            difference = max(abs(other[k] / one[k] - 1) for one, other in zip(rows_of[1], rows_of[ranks])
                             for k in COMPARED)
            r.expect(difference < 1e-3, f"{ranks} ranks agree with 1 rank in the tips, drag and contact "
                                        f"force ({difference:.1e} < 1e-3)")

    # the case without its contact pair, probed on both sides of the interface's top edge
    text = case.read_text()
    text = re.sub(r"\n    contact:\n(      .*\n)+", "\n", text)
    for name in ("channel.geo", "two_flaps.geo"):
        text = text.replace(f"file: {name}", f"file: {case.parent / name}")
    text = text.replace("      - {name: back_tip, point: [0.36, 0.2, 0.2]}\n",
                        "      - {name: back_tip, point: [0.36, 0.2, 0.2]}\n"
                        "      - {name: front_face, point: [0.3399, 0.2, 0.2]}\n"
                        "      - {name: back_face, point: [0.3401, 0.2, 0.2]}\n")
    free = r.work / "no-contact.yaml"
    free.write_text(text)
    summary, rows = run_with_series(r, free, "no-contact", "--set", "output.vtk=false",
                                    "--set", f"time.end_time={0.05 * STEPS[1]}", "--", *DIRECT)
    if summary is not None and 1 in rows_of:
        last, pressed = rows[-1], rows_of[1][-1]
        r.expect("contact_active_nodes_flaps" not in last, "the case without contact has no contact")
        overlap = last["flaps_front_face_ux"] - last["flaps_back_face_ux"]
        print(f"without contact at t = {last['time']:g} s: front tip u_x {1e3 * last['flaps_front_tip_ux']:.5f} mm, "
              f"back {1e3 * last['flaps_back_tip_ux']:.5f} mm, the faces overlap by {1e6 * overlap:.2f} um")
        r.expect(overlap > 1e-6, f"without contact the front flap's face passes into the back flap "
                                 f"({1e6 * overlap:.2f} um > 1 um)")
        r.expect(pressed["flaps_front_tip_ux"] < last["flaps_front_tip_ux"]
                 and pressed["flaps_back_tip_ux"] > last["flaps_back_tip_ux"],
                 "with contact the front flap moves less and the back flap more than without it")
    r.finish()


if __name__ == "__main__":
    main()
