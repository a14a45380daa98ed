#!/usr/bin/python3
"""Nearly incompressible Cook's membrane (cases/cook/incompressible.yaml, nu = 0.4999): the
mixed P1-P1 displacement-pressure formulation does not lock (the tip deflection changes by
less than 1 % from level 0 to level 2), while the displacement formulation on the same meshes
does (its deflection is more than 15 % smaller and still grows level by level); Newton
converges in a few iterations per load step; 1 and 2 ranks agree; a law without a bulk modulus
is rejected for the mixed formulation by key."""

from cli_common import Runner, parse_arguments, read_json

DIRECT = ["--", "-solid_ksp_type", "preonly", "-solid_pc_type", "lu",
          "-solid_pc_factor_mat_solver_type", "mumps"]


def run_case(runner, output, ranks=1, extra=()):
    result = runner.run("run", runner.source / "cases" / "cook" / "incompressible.yaml",
                        "--output", output, "--set", "output.vtk=false", *extra, ranks=ranks)
    summary_path = output / "summary.json"
    summary = read_json(summary_path) if summary_path.exists() else {}
    return result, summary, result.returncode == 0 and summary.get("status") == "completed"


def main():
    runner = Runner(parse_arguments())
    tips = {"mixed": [], "displacement": []}
    for formulation in tips:
        for level in (0, 1, 2):
            result, summary, ok = run_case(
                runner, runner.work / f"{formulation}_{level}",
                extra=["--set", f"mesh.level={level}", "--set", f"formulation={formulation}",
                       *DIRECT])
            runner.expect(ok, f"{formulation} level {level} runs",
                          result.stdout[-3000:] + result.stderr)
            if not ok:
                break
            tips[formulation].append(summary["benchmark"]["tip_displacement_y"])
            newton = summary["iterations"]["newton"]
            print(f"{formulation} level {level}: tip_displacement_y = "
                  f"{tips[formulation][-1]:.6e} m, {newton} Newton iterations in 10 load steps")
            if formulation == "mixed":
                runner.expect(newton <= 10 * 6, f"mixed level {level}: {newton} Newton "
                              "iterations for 10 load steps")
    mixed, plain = tips["mixed"], tips["displacement"]
    if len(mixed) == 3 and len(plain) == 3:
        spread = (max(mixed) - min(mixed)) / mixed[-1]
        runner.expect(spread < 0.01, f"mixed: tip deflection varies by {spread:.2%} < 1 % over "
                      "levels 0-2 (no locking)", str(mixed))
        runner.expect(all(b > a for a, b in zip(plain, plain[1:])),
                      "displacement formulation: the deflection still grows with the level",
                      str(plain))
        runner.expect(plain[-1] < 0.85 * mixed[-1],
                      f"displacement formulation locks: {plain[-1]:.4e} < 0.85 x {mixed[-1]:.4e}")

    values = {}
    for ranks in (1, 2):
        result, summary, ok = run_case(runner, runner.work / f"ranks_{ranks}", ranks=ranks,
                                       extra=["--set", "mesh.level=1"])
        runner.expect(ok, f"mixed on {ranks} rank(s)", result.stdout[-3000:] + result.stderr)
        if ok:
            values[ranks] = summary["benchmark"]["tip_displacement_y"]
    if len(values) == 2:
        worst = abs(values[2] - values[1]) / abs(values[1])
        runner.expect(worst < 1e-8, f"mixed: 1 and 2 ranks agree (relative {worst:.1e})")

    result, _, ok = run_case(runner, runner.work / "bad_law",
                             extra=["--set", "bodies[0].material.model=neo_hookean"])
    text = result.stdout + result.stderr
    runner.expect(not ok and "formulation" in text and "bulk modulus" in text,
                  "mixed with a law without a bulk modulus is an error naming formulation",
                  text[-2000:])
    runner.finish()


if __name__ == "__main__":
    main()
