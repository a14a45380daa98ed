"""Schäfer-Turek 3D-1Z (cases/dfg/3d1z.yaml, steady, Re = 20) on level 0 (17 655 tetrahedra) on
2 ranks and on 1, with the direct solver (MUMPS LU; the default GMRES + Schur fieldsplit takes
about 200 Krylov iterations per Newton step here, docs/verification/fluid.md, and is tested on
the box channel by test_fluid_3d.py):
 - Newton converges on both, and 2 ranks agree with 1 on c_D and c_L to 1e-7 relative;
 - the inflow through the inlet, the P1 interpolant of 16 U_m y z (H - y)(H - z)/H^4 (the
   `rectangle` profile), is within 5 % of the exact U_bar H^2 (the interpolant of the concave
   profile lies below it: 3.7 % at level 0, shrinking as h^2);
 - c_D = 2F/(rho U_bar^2 D H) within 15 % of the fine reference 6.18533 (Braack & Richter 2006)
   and c_L positive and within a factor 2 of 0.009401: level 0 is coarse (the table over the
   levels is in docs/verification/fluid.md, "Schäfer-Turek 3D-1Z"), so the bounds are the
   level's, not the benchmark's intervals;
 - drag_error and lift_error are the relative errors of the written coefficients."""

from cli_common import Runner, parse_arguments, run_with_series

DIRECT = ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu", "-fluid_pc_factor_mat_solver_type", "mumps"]

REFERENCE_DRAG, REFERENCE_LIFT = 6.18533, 0.009401
MEAN_VELOCITY, HEIGHT = 0.2, 0.41


def main():
    r = Runner(parse_arguments())
    case = r.source / "cases" / "dfg" / "3d1z.yaml"
    arguments = ("--set", "mesh.level=0", "--set", "output.vtk=false", "--", *DIRECT)
    summary, rows = run_with_series(r, case, "dfg3d1z-L0-np2", *arguments, ranks=2)
    serial, _ = run_with_series(r, case, "dfg3d1z-L0-np1", *arguments, ranks=1)
    if summary is None:
        r.finish()
    b = summary["benchmark"]
    newton, linear = summary["iterations"]["newton"], summary["iterations"]["linear"]
    drag, lift = b["drag_coefficient"], b["lift_coefficient"]
    print(f"3D-1Z level 0: {b['cells']} cells, c_D {drag:.5f} ({100 * b['drag_error']:.2f} %), "
          f"c_L {lift:.6f} ({100 * b['lift_error']:.1f} %), {newton} Newton steps")
    if serial is not None:
        difference = max(abs(b[k] / serial["benchmark"][k] - 1) for k in ("drag_coefficient", "lift_coefficient"))
        r.expect(difference < 1e-7, f"2 ranks agree with 1 on c_D and c_L ({difference:.1e} < 1e-7)")
    flow = -rows[-1]["flow_inlet"]
    exact = MEAN_VELOCITY * HEIGHT * HEIGHT
    r.expect(abs(flow / exact - 1) < 0.05, f"inflow {flow:.6f} m^3/s within 5 % of U_bar H^2 = {exact:.6f}")
    r.expect(abs(drag / REFERENCE_DRAG - 1) < 0.15, f"c_D {drag:.5f} within 15 % of {REFERENCE_DRAG}")
    r.expect(0.5 * REFERENCE_LIFT < lift < 2 * REFERENCE_LIFT,
             f"c_L {lift:.6f} positive and within a factor 2 of {REFERENCE_LIFT}")
    r.expect(abs(b["drag_error"] - abs(drag / REFERENCE_DRAG - 1)) < 1e-12
             and abs(b["lift_error"] - abs(lift / REFERENCE_LIFT - 1)) < 1e-12,
             "drag_error and lift_error are the coefficients' relative errors")
    r.finish()


if __name__ == "__main__":
    main()
