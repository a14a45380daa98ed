"""The immersed rigid cylinder (cases/dfg/2d1_immersed.yaml: the DFG 2D-1 channel meshed
without a hole, the cylinder a separate solid mesh held at rest by the velocity constraint):
 - the force on the solid B^T lambda equals the total constraint reaction on the fluid to
   round-off (force_balance_error < 1e-12) on 1, 2 and 3 ranks;
 - the benchmark quantities agree on 1, 2 and 3 ranks to 1e-8 relative (direct solver);
 - with the whole-support covered-node rule the constrained region is smaller than the disc,
   so c_D lies below the reference, and its error falls by more than 1.5x from level 0 to
   level 1 (first order in h: the constrained region grows by about one element layer);
 - the looser rule (coverage_threshold 0.5) constrains more fluid nodes and gives a c_D
   closer to the reference on level 0;
 - a transient run with the body translating moves the solid (the constrained set changes)
   and keeps the force balance;
 - a benchmark body that names no solid is an input error naming the key."""

from cli_common import Runner, parse_arguments, read_json

DIRECT = ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu", "-fluid_pc_factor_mat_solver_type", "mumps"]


def run_case(r, name, level=0, ranks=1, extra=()):
    case = r.source / "cases" / "dfg" / "2d1_immersed.yaml"
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
    keys = ("drag_coefficient", "lift_coefficient", "pressure_difference")

    results = {}
    for ranks in (1, 2, 3):
        b, _ = run_case(r, "immersed", 0, ranks)
        if b is None:
            continue
        results[ranks] = b
        print(f"level 0, {ranks} rank(s): c_D = {b['drag_coefficient']:.6f} ({100 * b['drag_error']:.2f} %), "
              f"c_L = {b['lift_coefficient']:.6f}, dp = {b['pressure_difference']:.6f}, "
              f"{b['solids']['cylinder']['constrained_fluid_vertices']} constrained, "
              f"balance {b['force_balance_error']:.1e}")
        r.expect(b["force_balance_error"] < 1e-12,
                 f"{ranks} rank(s): sum of B^T lambda = sum of the reactions ({b['force_balance_error']:.1e} < 1e-12)")
    if 1 in results:
        for ranks in (2, 3):
            if ranks in results:
                difference = max(relative(results[ranks][k], results[1][k]) for k in keys)
                r.expect(difference < 1e-8, f"{ranks} ranks agree with 1 rank ({difference:.1e} < 1e-8)")
                r.expect(results[ranks]["solids"]["cylinder"]["constrained_fluid_vertices"]
                         == results[1]["solids"]["cylinder"]["constrained_fluid_vertices"],
                         f"{ranks} ranks: the same constrained set")

        level0 = results[1]
        r.expect(level0["drag_coefficient"] < 5.57953523384,
                 "whole-support rule: c_D below the reference (the constrained region lies inside the disc)")
        level1, _ = run_case(r, "immersed", 1)
        if level1 is not None:
            ratio = level0["drag_error"] / level1["drag_error"]
            print(f"level 1: c_D = {level1['drag_coefficient']:.6f} ({100 * level1['drag_error']:.2f} %), "
                  f"error ratio {ratio:.2f}")
            r.expect(ratio > 1.5, f"c_D error falls from level 0 to 1 by more than 1.5x ({ratio:.2f})")
        loose, _ = run_case(r, "immersed-loose", 0, extra=("--set", "coupling.coverage_threshold=0.5"))
        if loose is not None:
            print(f"threshold 0.5, level 0: c_D = {loose['drag_coefficient']:.6f} ({100 * loose['drag_error']:.2f} %)")
            r.expect(loose["solids"]["cylinder"]["constrained_fluid_vertices"]
                     > level0["solids"]["cylinder"]["constrained_fluid_vertices"],
                     "threshold 0.5 constrains more fluid nodes")
            r.expect(loose["drag_error"] < level0["drag_error"], "threshold 0.5: c_D closer to the reference on level 0")

    # A translating body: the solid mesh moves, the constrained set follows it.
    moving, out = run_case(r, "moving", 0, ranks=2,
                           extra=("--set", "time.steady=false", "--set", "time.end_time=0.2", "--set", "time.step=0.05",
                                  "--set", "solids[0].velocity=[0.1, 0]"))
    if moving is not None:
        with open(out / "series.csv") as f:
            rows = f.read().splitlines()
        header = rows[0].split(",")
        balance = [float(row.split(",")[header.index("force_balance")]) for row in rows[1:]]
        r.expect(len(rows) == 5, "moving body: 4 steps in series.csv")
        r.expect(max(balance) < 1e-12, f"moving body: force balance every step ({max(balance):.1e} < 1e-12)")

    bad = r.run("run", r.source / "cases" / "dfg" / "2d1_immersed.yaml", "--output", r.work / "bad",
                "--set", "benchmark.body=cylindre")
    r.expect(bad.returncode == 2 and "benchmark.body" in bad.stdout + bad.stderr and "cylindre" in bad.stdout + bad.stderr,
             "a benchmark body naming no solid is an input error naming the key", bad.stdout + bad.stderr)
    r.finish()


if __name__ == "__main__":
    main()
