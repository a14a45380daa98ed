"""Turek-Hron FSI1 by the immersed method (cases/turek_hron/fsi1.yaml: the bar a deformable
solid immersed in the fluid mesh, steady block Gauss-Seidel coupling, partial coverage), level 0:
 - the coupling iteration converges (|df| below the case's tolerances) within the case's
   40 iterations, on 1 and 2 ranks, and the run completes;
 - the force on the bar B^T lambda balances the constraint reactions to round-off;
 - 2 ranks agree with 1 rank to 1e-6 relative in drag, lift and the displacement of A (the
   coupling stops at a relative change of 1e-6);
 - the drag (cylinder + bar) is within 2 % of the reference 14.295 N/m (measured −0.23 %; when
   the cylinder's no-slip vertices under the bar's end were constrained by the bar too, their
   reaction was counted twice and the drag was 4.9 % low), and point A moves up
   as in the reference (its size, 3.7 mm against the reference's 0.82 mm, is not asserted: on
   this coarse level the bar's lift is far too large, see docs/verification/fsci.md);
 - the bar's volume changes by less than 1e-3 (it is loaded by the fluid only).
Level 1 (one rank; a bound suited to the level, from the converged run of docs/verification/
fsci.md, whose level 2 is within 0.7 % of the reference in u_y(A), lift and drag):
 - the coupling converges without freezing the constrained set (partial coverage makes the
   iteration map continuous; with the covered-node rule alone it ends in a limit cycle);
 - drag within 1 % (measured +0.01 %), u_y(A) within 6 % (measured -4.5 %) and lift within
   10 % (measured +6.9 %) of the reference, each closer to it than on level 0;
 - u_x(A) within 1 % (measured +0.18 %; 11 % high without coupling.pressure_in_solid, which
   the case sets: tests/cli/test_fsci_pressure_in_solid.py)."""

import csv

from cli_common import Runner, parse_arguments, read_json

DIRECT = ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu", "-fluid_pc_factor_mat_solver_type", "mumps"]
KEYS = ("drag", "lift", "displacement_x", "displacement_y")


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    case = r.source / "cases" / "turek_hron" / "fsi1.yaml"
    results = {}
    for ranks in (1, 2):
        out = r.work / f"fsi1-np{ranks}"
        result = r.run("run", case, "--output", out, "--set", "output.vtk=false", "--", *DIRECT, ranks=ranks)
        summary = read_json(out / "summary.json") if (out / "summary.json").is_file() else {}
        r.expect(result.returncode == 0 and summary.get("status") == "completed",
                 f"fsi1 level 0 on {ranks} rank(s): the coupling converges", result.stdout[-3000:] + result.stderr)
        if result.returncode != 0:
            continue
        b = summary["benchmark"]
        results[ranks] = b
        with open(out / "series.csv") as f:
            row = list(csv.DictReader(f))[-1]
        iterations = int(float(row["coupling_iterations"]))
        print(f"{ranks} rank(s): drag {b['drag']:.5f} N/m, lift {b['lift']:.5f} N/m, u(A) = "
              f"({1e3 * b['displacement_x']:.5f}, {1e3 * b['displacement_y']:.5f}) mm, {iterations} coupling iterations")
        r.expect(b["force_balance_error"] < 1e-12, f"{ranks} rank(s): force balance ({b['force_balance_error']:.1e} < 1e-12)")
        r.expect(b["drag_error"] < 0.02, f"{ranks} rank(s): drag within 2 % ({100 * b['drag_error']:.2f} %)")
        r.expect(b["displacement_y"] > 0, f"{ranks} rank(s): A moves up")
        volume_change = abs(float(row["volume_bar"]) / (0.35101020514433644 * 0.02) - 1)
        r.expect(volume_change < 1e-3, f"{ranks} rank(s): bar volume change {volume_change:.1e} < 1e-3")
    if 1 in results and 2 in results:
        difference = max(abs(results[2][k] - results[1][k]) / abs(results[1][k]) for k in KEYS)
        r.expect(difference < 1e-6, f"2 ranks agree with 1 rank ({difference:.1e} < 1e-6)")

    out = r.work / "fsi1-level1"
    result = r.run("run", case, "--output", out, "--set", "output.vtk=false", "--set", "mesh.level=1",
                   "--set", "coupling.iteration.freeze_constrained_after=0", "--", *DIRECT)
    summary = read_json(out / "summary.json") if (out / "summary.json").is_file() else {}
    r.expect(result.returncode == 0 and summary.get("status") == "completed",
             "fsi1 level 1: the coupling converges without freezing the constrained set",
             result.stdout[-3000:] + result.stderr)
    if result.returncode == 0 and 1 in results:
        b, coarse = summary["benchmark"], results[1]
        errors = {k: b[f"{k}_error"] for k in ("drag", "lift", "displacement_y", "displacement_x")}
        print("level 1: " + ", ".join(f"{k} {100 * v:.2f} %" for k, v in errors.items()))
        r.expect(errors["drag"] < 0.01, f"level 1: drag within 1 % ({100 * errors['drag']:.2f} %)")
        r.expect(errors["displacement_y"] < 0.06,
                 f"level 1: u_y(A) within 6 % ({100 * errors['displacement_y']:.2f} %)")
        r.expect(errors["lift"] < 0.10, f"level 1: lift within 10 % ({100 * errors['lift']:.2f} %)")
        r.expect(errors["displacement_x"] < 0.01,
                 f"level 1: u_x(A) within 1 % ({100 * errors['displacement_x']:.2f} %)")
        for k in ("lift", "displacement_y"):
            r.expect(errors[k] < coarse[f"{k}_error"],
                     f"level 1: {k} closer to the reference than level 0 "
                     f"({100 * errors[k]:.2f} % < {100 * coarse[f'{k}_error']:.2f} %)")
    r.finish()


if __name__ == "__main__":
    main()
