#!/usr/bin/python3
"""The contact cases on coarse levels (docs/verification/contact.md): the 2D and 3D patch tests
with non-matching interfaces transmit a uniform pressure to 1e-8, the Hertz cylinder (2D) and
sphere (3D) come within the stated bounds of Johnson's values, the complementarity conditions
hold at convergence (pressure >= 0 on the active set, no penetration beyond the gap tolerance,
no pressure off it), 1 and 2 ranks agree, and a bad contact group is reported by key."""

from cli_common import Runner, parse_arguments, read_json


def run_case(runner, case, output, ranks=1, extra=()):
    result = runner.run("run", runner.source / "cases" / case, "--output", output,
                        "--set", "output.vtk=false", *extra, ranks=ranks)
    summary_path = output / "summary.json"
    summary = read_json(summary_path) if summary_path.exists() else {}
    ok = result.returncode == 0 and summary.get("status") == "completed"
    runner.expect(ok, f"{case} {' '.join(extra)} on {ranks} rank(s) runs",
                  result.stdout[-3000:] + result.stderr)
    return summary.get("benchmark", {}) if ok else None


def check_complementarity(runner, name, b):
    """λ_n ≥ 0 on the active set, gap ≥ −tolerance, λ_n g = 0, λ = 0 off the active set."""
    scale = b["max_pressure"] if "max_pressure" in b else b["contact_total_force"]
    runner.expect(b["contact_active_nodes"] > 0, f"{name}: some nodes in contact")
    runner.expect(b["contact_min_active_pressure"] >= -1e-8 * scale,
                  f"{name}: pressure >= 0 on the active set ({b['contact_min_active_pressure']:.3e})")
    runner.expect(b["contact_max_penetration"] <= b["contact_gap_tolerance"],
                  f"{name}: penetration {b['contact_max_penetration']:.3e} m within the gap "
                  f"tolerance {b['contact_gap_tolerance']:.3e} m")
    runner.expect(b["contact_max_open_pressure"] <= 1e-6 * scale,
                  f"{name}: no pressure off the active set ({b['contact_max_open_pressure']:.3e})")
    runner.expect(b["contact_max_complementarity"] <= scale * b["contact_gap_tolerance"],
                  f"{name}: max |p g| = {b['contact_max_complementarity']:.3e} Pa m")


def main():
    arguments = parse_arguments()
    runner = Runner(arguments)

    # Patch tests: uniform pressure, the whole load, on 1 and 2 ranks.
    for case in ["contact/patch2d.yaml", "contact/patch3d.yaml"]:
        results = {}
        for ranks in [1, 2]:
            name = case.replace("/", "_").replace(".yaml", "")
            b = run_case(runner, case, runner.work / f"{name}_np{ranks}", ranks=ranks)
            if b is None:
                continue
            results[ranks] = b
            print(f"{case} np {ranks}: spread {b['contact_pressure_relative_spread']:.3e}, "
                  f"pressure error {b['contact_pressure_error']:.3e}, force error "
                  f"{b['contact_force_error']:.3e}, {b['contact_active_nodes']} active nodes")
            runner.expect(b["contact_pressure_relative_spread"] < 1e-8,
                          f"{case} np {ranks}: uniform contact pressure")
            runner.expect(b["contact_pressure_error"] < 1e-8,
                          f"{case} np {ranks}: pressure = load / contact area")
            runner.expect(b["contact_force_error"] < 1e-8, f"{case} np {ranks}: whole load carried")
            check_complementarity(runner, f"{case} np {ranks}", b)
        if len(results) == 2:
            runner.expect(results[1]["contact_active_nodes"] == results[2]["contact_active_nodes"],
                          f"{case}: same active set on 1 and 2 ranks")

    # Hertz on the coarse level: the errors against Johnson's values below bounds about 1.5x
    # those measured at level 0 when written (max pressure per current area / nominal max
    # pressure / contact size: cylinder 1.25 % / 0.01 % / 0.05 %, sphere 6.4 % / 2.8 % /
    # 0.9 %; finer levels in the docs; the cylinder's nominal bound is 0.5 %, what its finer
    # levels reach), 1 and 2 ranks agree.
    hertz = [("hertz/cylinder.yaml", "contact_half_width", 0.02, 0.005, 0.01),
             ("hertz/sphere.yaml", "contact_radius", 0.095, 0.045, 0.014)]
    for case, size, pressure_bound, nominal_bound, size_bound in hertz:
        results = {}
        for ranks in [1, 2]:
            name = case.replace("/", "_").replace(".yaml", "")
            b = run_case(runner, case, runner.work / f"{name}_np{ranks}", ranks=ranks)
            if b is None:
                continue
            results[ranks] = b
            print(f"{case} np {ranks}: max_pressure {b['max_pressure']:.6e} (analytic "
                  f"{b['max_pressure_analytic']:.6e}, error {b['max_pressure_error']:.3e}), "
                  f"max_nominal_pressure {b['max_nominal_pressure']:.6e} (error "
                  f"{b['max_nominal_pressure_error']:.3e}), {size} {b[size]:.6e} (analytic "
                  f"{b[size + '_analytic']:.6e}, error {b[size + '_error']:.3e})")
            runner.expect(b["max_pressure_error"] < pressure_bound,
                          f"{case}: max pressure within {pressure_bound:.1%}")
            runner.expect(b["max_nominal_pressure_error"] < nominal_bound,
                          f"{case}: max nominal pressure within {nominal_bound:.1%}")
            runner.expect(b[size + "_error"] < size_bound, f"{case}: {size} within {size_bound:.1%}")
            check_complementarity(runner, f"{case} np {ranks}", b)
        if len(results) == 2:
            for key in ["max_pressure", "max_nominal_pressure"]:
                difference = abs(results[1][key] - results[2][key])
                runner.expect(difference <= 1e-6 * results[1][key],
                              f"{case}: 1 and 2 ranks agree ({key} differs by {difference:.3e})")

    # Bad input: an unknown contact group is named with its key.
    result = runner.run("run", runner.source / "cases" / "contact" / "patch2d.yaml", "--output",
                        runner.work / "bad", "--set", "contact.pairs=[{slave: nowhere, master: lower_top}]")
    runner.expect(result.returncode == 2 and "nowhere" in result.stderr + result.stdout,
                  "an unknown contact group is an input error naming it",
                  result.stdout[-2000:] + result.stderr)
    runner.finish()


if __name__ == "__main__":
    main()
