"""Fluid verification cases on coarse levels (longer runs are documented in
docs/verification/fluid.md):
 - lid-driven cavity Re = 100 (cases/cavity/re100.yaml), levels 0 and 1: the max centreline
   error against Ghia, Ghia & Shin (1982) is below a bound per level and falls by >= 1.6x per level;
   the centreline CSV files exist; BDF1-then-BDF2 time stepping to t = 30 reaches the steady
   solution;
 - Schäfer-Turek 2D-1 (cases/dfg/2d1.yaml), levels 0 and 1: c_D within 1 % and Δp within 2 % of
   the reference, the c_D error not growing from level 0 to 1;
 - the benchmark quantities agree on 1, 2 and 3 ranks (direct solver) to 1e-7 relative;
 - a misspelt boundary group is an input error naming the group."""

from cli_common import Runner, parse_arguments, read_json

DIRECT = ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu", "-fluid_pc_factor_mat_solver_type", "mumps"]


def run_case(r, case, name, level, ranks=1, extra=()):
    out = r.work / f"{name}-L{level}-np{ranks}"
    result = r.run("run", case, "--output", out, "--set", f"mesh.level={level}", "--set", "output.vtk=false",
                   *extra, "--", *DIRECT, ranks=ranks)
    if result.returncode != 0:
        r.expect(False, f"{name} level {level} on {ranks} rank(s) runs", result.stdout + result.stderr)
        return None, out
    return read_json(out / "summary.json")["benchmark"], out


def relative(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


def main():
    arguments = parse_arguments()
    r = Runner(arguments)

    # Lid-driven cavity, Re = 100.
    cavity = r.source / "cases" / "cavity" / "re100.yaml"
    bounds = {0: 0.08, 1: 0.04}  # max |u_h - u_Ghia| and |v_h - v_Ghia| per level
    errors = {}
    for level in (0, 1):
        b, out = run_case(r, cavity, "cavity", level)
        if b is None:
            continue
        errors[level] = (b["max_error_u"], b["max_error_v"])
        print(f"cavity level {level}: max_error_u = {b['max_error_u']:.4e}, max_error_v = {b['max_error_v']:.4e}")
        r.expect(max(errors[level]) < bounds[level], f"cavity level {level}: centreline errors < {bounds[level]}")
        r.expect(all((out / f).is_file() for f in ("centreline_u.csv", "centreline_v.csv", "reference_u.csv")),
                 f"cavity level {level}: centreline CSV files written")
    if len(errors) == 2:
        for k, name in enumerate("uv"):
            ratio = errors[0][k] / errors[1][k]
            r.expect(ratio > 1.6, f"cavity: {name} error falls from level 0 to 1 (ratio {ratio:.2f} > 1.6)")
        b, _ = run_case(r, cavity, "cavity-transient", 0,
                        extra=("--set", "time.steady=false", "--set", "time.end_time=30", "--set", "time.step=0.5"))
        if b is not None:
            difference = abs(b["max_error_u"] - errors[0][0]) + abs(b["max_error_v"] - errors[0][1])
            r.expect(difference < 1e-4, f"cavity: BDF2 steps reach the steady solution by t = 30 "
                                        f"(centreline errors differ by {difference:.1e} < 1e-4)")
    for ranks in (2, 3):
        b, _ = run_case(r, cavity, "cavity", 0, ranks=ranks)
        if b is not None and 0 in errors:
            difference = max(relative(b["max_error_u"], errors[0][0]), relative(b["max_error_v"], errors[0][1]))
            r.expect(difference < 1e-7, f"cavity level 0: {ranks} ranks agree with 1 rank ({difference:.1e} < 1e-7)")

    # Schäfer-Turek 2D-1.
    dfg = r.source / "cases" / "dfg" / "2d1.yaml"
    results = {}
    for level in (0, 1):
        b, _ = run_case(r, dfg, "dfg", level)
        if b is None:
            continue
        results[level] = b
        print(f"dfg 2D-1 level {level}: c_D = {b['drag_coefficient']:.6f} ({100 * b['drag_error']:.3f} %), "
              f"c_L = {b['lift_coefficient']:.6f} ({100 * b['lift_error']:.1f} %), "
              f"dp = {b['pressure_difference']:.6f} ({100 * b['pressure_difference_error']:.3f} %)")
        r.expect(b["drag_error"] < 0.01, f"dfg level {level}: c_D within 1 %")
        r.expect(b["pressure_difference_error"] < 0.02, f"dfg level {level}: dp within 2 %")
    if len(results) == 2:
        r.expect(results[1]["drag_error"] <= results[0]["drag_error"], "dfg: the c_D error does not grow with the level")
    for ranks in (2, 3):
        b, _ = run_case(r, dfg, "dfg", 0, ranks=ranks)
        if b is not None and 0 in results:
            keys = ("drag_coefficient", "lift_coefficient", "pressure_difference")
            difference = max(relative(b[k], results[0][k]) for k in keys)
            r.expect(difference < 1e-7, f"dfg level 0: {ranks} ranks agree with 1 rank ({difference:.1e} < 1e-7)")

    # Bad input: an unknown boundary group (a copy of the cavity case with a typo).
    bad_case = r.work / "bad_group.yaml"
    bad_case.write_text(cavity.read_text().replace("{group: left,", "{group: lefft,"))
    result = r.run("run", bad_case, "--output", r.work / "bad-group")
    text = result.stdout + result.stderr
    r.expect(result.returncode != 0 and "no boundary group 'lefft'" in text and "bad_group.yaml" in text,
             "a misspelt boundary group is an input error naming the file and the group", text)
    r.finish()


if __name__ == "__main__":
    main()
