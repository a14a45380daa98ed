#!/usr/bin/python3
"""The solid against closed-form solutions, and fibre fields given per element:

- cases/solid/fibre_uniaxial.yaml: a fibre-reinforced block stretched by 1.2 along and across
  its fibres; P1 reproduces the homogeneous state, so the axial Cauchy stress, the lateral
  stretch and the reaction force agree with the closed form to solver tolerance; 1 and 2
  ranks agree;
- the same block with its fibres read from a CSV file (one row per element) gives the constant
  rule's answer, and bad files are reported by file and line or element;
- cases/solid/lame_cylinder.yaml: an inflated thick-walled cylinder (follower pressure) against
  Lame's solution on levels 0-2: the error in the radial displacement at the inner and outer
  radius decreases and is below a bound at level 2; 1 and 2 ranks agree."""

from cli_common import Runner, parse_arguments, read_json

DIRECT = ["--", "-solid_ksp_type", "preonly", "-solid_pc_type", "lu",
          "-solid_pc_factor_mat_solver_type", "mumps"]


def run_case(runner, case, output, ranks=1, extra=()):
    result = runner.run("run", case, "--output", output, "--set", "output.vtk=false", *extra,
                        ranks=ranks)
    summary_path = output / "summary.json"
    summary = read_json(summary_path) if summary_path.exists() else {}
    ok = result.returncode == 0 and summary.get("status") == "completed"
    return result, summary, ok


def fibre_uniaxial(runner):
    case = runner.source / "cases" / "solid" / "fibre_uniaxial.yaml"
    results = {}
    for name, direction, rank_counts in [("along", "[1,0,0]", (1, 2)), ("across", "[0,1,0]", (1,))]:
        for ranks in rank_counts:
            result, summary, ok = run_case(
                runner, case, runner.work / f"uniaxial_{name}_{ranks}", ranks=ranks,
                extra=["--set", f"bodies[0].fibres.direction={direction}"])
            runner.expect(ok, f"fibre_uniaxial {name} on {ranks} rank(s) runs",
                          result.stdout[-3000:] + result.stderr)
            if not ok:
                continue
            b = summary["benchmark"]
            results[(name, ranks)] = b
            print(f"fibre_uniaxial {name}, {ranks} rank(s): sigma = {b['cauchy_stress_axial']:.10e} "
                  f"(closed form {b['cauchy_stress_axial_analytic']:.10e}), lateral stretch "
                  f"{b['lateral_stretch']:.10f} ({b['lateral_stretch_analytic']:.10f}), reaction "
                  f"{b['reaction_force']:.10e} N ({b['reaction_force_analytic']:.10e})")
            runner.expect(abs(b["stretch"] - 1.2) < 1e-12, f"{name}: the stretch is 1.2")
            runner.expect(b["cauchy_stress_axial_error"] < 1e-9,
                          f"{name}, {ranks} rank(s): axial stress error "
                          f"{b['cauchy_stress_axial_error']:.2e} < 1e-9")
            runner.expect(abs(b["lateral_stretch"] - b["lateral_stretch_analytic"]) < 1e-9,
                          f"{name}: lateral stretch matches the closed form")
            runner.expect(b["reaction_force_error"] < 1e-9,
                          f"{name}: reaction force error {b['reaction_force_error']:.2e} < 1e-9")
            runner.expect(b["cauchy_stress_lateral_max"] < 1e-8 * b["cauchy_stress_axial"],
                          f"{name}: the lateral stresses vanish")
        if (name, 1) in results and (name, 2) in results:
            one, two = results[(name, 1)], results[(name, 2)]
            worst = abs(one["cauchy_stress_axial"] - two["cauchy_stress_axial"]) / \
                abs(one["cauchy_stress_axial"])
            runner.expect(worst < 1e-9, f"{name}: 1 and 2 ranks agree (relative {worst:.1e})")
    if ("along", 1) in results and ("across", 1) in results:
        ratio = results[("along", 1)]["cauchy_stress_axial"] / \
            results[("across", 1)]["cauchy_stress_axial"]
        runner.expect(ratio > 5, f"the fibres stiffen the block along them ({ratio:.1f} x)")


def fibre_file(runner):
    """Fibres from a CSV file against the constant rule (a probe at the far corner)."""
    source = (runner.source / "cases" / "solid" / "fibre_uniaxial.yaml").read_text()
    base = source.split("uniaxial_reference:")[0]
    base += "probes:\n  - {name: corner, point: [0.001, 0.001, 0.001]}\n"
    folder = runner.work / "fibre_file"
    folder.mkdir(parents=True, exist_ok=True)
    constant_case = folder / "constant.yaml"
    constant_case.write_text(base.replace("direction: [1, 0, 0]", "direction: [1, 1, 0]"))
    file_case = folder / "file.yaml"
    file_case.write_text(base.replace("rule: constant", "rule: file\n      file: fibres.csv")
                         .replace("      direction: [1, 0, 0]\n", ""))
    n_cells = 2 * 2 * 2 * 6
    rows = [f"{e}, 2.5, 2.5, 0" for e in range(1, n_cells + 1)]
    (folder / "fibres.csv").write_text("element, a1x, a1y, a1z\n" + "\n".join(rows) + "\n")

    values = {}
    for name, case, ranks in [("constant", constant_case, 1), ("file", file_case, 1),
                              ("file", file_case, 2)]:
        result, summary, ok = run_case(runner, case, folder / f"{name}_{ranks}", ranks=ranks)
        runner.expect(ok, f"fibres {name} on {ranks} rank(s) runs",
                      result.stdout[-3000:] + result.stderr)
        if ok:
            values[(name, ranks)] = [summary["benchmark"][f"corner_displacement_{c}"]
                                     for c in "yz"]
    if len(values) == 3:
        reference = values[("constant", 1)]
        for key in [("file", 1), ("file", 2)]:
            worst = max(abs(a - b) for a, b in zip(values[key], reference)) / \
                max(abs(v) for v in reference)
            runner.expect(worst < 1e-9, f"fibres from the file ({key[1]} rank(s)) give the "
                          f"constant rule's answer (relative {worst:.1e})", str(values))

    bad = [("2, 0, 0, 0", "fibres.csv:3: element 2: fibre direction 1 is zero"),
           ("2, 1, 0", "fibres.csv:3: 3 columns, expected 4"),
           (None, "element 2 of the body has no row")]
    for k, (row, message) in enumerate(bad):
        lines = list(rows)
        if row is None:
            del lines[1]
        else:
            lines[1] = row
        (folder / "fibres.csv").write_text("element, a1x, a1y, a1z\n" + "\n".join(lines) + "\n")
        # The missing row on 2 ranks: the rank that lacks it reports for all.
        result, _, ok = run_case(runner, file_case, folder / f"bad_{k}",
                                 ranks=2 if row is None else 1)
        text = result.stdout + result.stderr
        runner.expect(not ok and message in text, f"bad fibre file: '{message}'", text[-2000:])


def lame(runner):
    case = runner.source / "cases" / "solid" / "lame_cylinder.yaml"
    errors = {"inner": [], "outer": []}
    # Bounds: about 1.5 x the level-2 errors measured when the test was written (docs table).
    bounds = {"inner": 4e-3, "outer": 2.5e-3}
    for level in (0, 1, 2):
        result, summary, ok = run_case(runner, case, runner.work / f"lame_{level}",
                                       extra=["--set", f"mesh.level={level}"])
        runner.expect(ok, f"lame_cylinder level {level} runs", result.stdout[-3000:] + result.stderr)
        if not ok:
            return
        b = summary["benchmark"]
        for which in errors:
            errors[which].append(b[f"radial_displacement_{which}_error"])
            print(f"lame level {level}: u_r({which}) = {b[f'radial_displacement_{which}']:.8e} "
                  f"(Lame {b[f'radial_displacement_{which}_analytic']:.8e}), relative error "
                  f"{errors[which][-1]:.3e}")
    for which, values in errors.items():
        runner.expect(all(b < a for a, b in zip(values, values[1:])),
                      f"lame: the {which} error decreases with the level", str(values))
        runner.expect(values[-1] < bounds[which],
                      f"lame: {which} error {values[-1]:.2e} at level 2 < {bounds[which]}")
    values = {}
    for ranks in (1, 2):
        result, summary, ok = run_case(runner, case, runner.work / f"lame_ranks_{ranks}",
                                       ranks=ranks, extra=["--set", "mesh.level=1", *DIRECT])
        runner.expect(ok, f"lame on {ranks} rank(s) with MUMPS", result.stdout[-3000:] + result.stderr)
        if ok:
            values[ranks] = summary["benchmark"]["radial_displacement_inner"]
    if len(values) == 2:
        worst = abs(values[2] - values[1]) / abs(values[1])
        runner.expect(worst < 1e-9, f"lame: 1 and 2 ranks agree (relative {worst:.1e})")


def main():
    runner = Runner(parse_arguments())
    fibre_uniaxial(runner)
    fibre_file(runner)
    lame(runner)
    runner.finish()


if __name__ == "__main__":
    main()
