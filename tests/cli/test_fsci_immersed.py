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
 - two solids that share fluid nodes (coupling::ConstraintGroup): the disc cut along y = 0.2
   into two half-disc solids (tests/data/meshes/half_disk_*.geo, with the disc's own arcs)
   constrains the fluid as the whole disc: the sum of the halves' forces equals the disc's
   force to 1e-8 relative, the nodes along the cut count in both halves (more constrained
   nodes in the two than in the disc), the balance holds, and 2 ranks agree with 1;
 - a benchmark body that names no solid is an input error naming the key."""

from cli_common import Runner, parse_arguments, read_json, read_rows

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


def two_halves(r, disc):
    """The disc as two half-disc solids against the disc's run (`disc`: its benchmark, 1 rank)."""
    source = r.source.resolve()
    text = (source / "cases" / "dfg" / "2d1_immersed.yaml").read_text()
    text = text.replace("file: channel_filled.geo", f"file: {source / 'cases' / 'dfg' / 'channel_filled.geo'}")
    solids = text[text.index("solids:"):text.index("coupling:")]
    halves = "solids:\n" + "".join(
        f"  - name: {half}\n    rigid: true\n    mesh:\n      type: geo\n"
        f"      file: {source / 'tests' / 'data' / 'meshes' / f'half_disk_{half}.geo'}\n      size: 0.005\n"
        for half in ("upper", "lower"))
    text = text.replace(solids, halves).replace("body: cylinder", "body: upper")
    case = r.work / "two_halves.yaml"
    case.write_text(text)
    rows = {}
    for ranks in (1, 2):
        out = r.work / f"halves-np{ranks}"
        result = r.run("run", case, "--output", out, "--set", "output.vtk=false", "--", *DIRECT, ranks=ranks)
        r.expect(result.returncode == 0, f"two half discs on {ranks} rank(s) run", result.stdout[-2000:] + result.stderr)
        if result.returncode != 0:
            return
        rows[ranks] = read_rows(out / "series.csv")[-1]
        balance = read_json(out / "summary.json")["benchmark"]["force_balance_error"]
        r.expect(balance < 1e-12, f"two half discs on {ranks} rank(s): force balance {balance:.1e} < 1e-12")
    one, two = rows[1], rows[2]
    total = [float(one[f"force_{c}_upper"]) + float(one[f"force_{c}_lower"]) for c in "xy"]
    shared = int(float(one["constrained_upper"])) + int(float(one["constrained_lower"]))
    if disc is not None:
        whole = disc["solids"]["cylinder"]
        print(f"two half discs: force ({total[0]:.10e}, {total[1]:.10e}), the disc ({whole['force'][0]:.10e}, "
              f"{whole['force'][1]:.10e}); constrained {shared} in the halves, {whole['constrained_fluid_vertices']} "
              f"in the disc")
        r.expect(relative(total[0], whole["force"][0]) < 1e-8 and abs(total[1] - whole["force"][1]) < 1e-8 * abs(whole["force"][0]),
                 "two half discs: their forces sum to the disc's force (1e-8)")
        r.expect(shared > whole["constrained_fluid_vertices"],
                 "two half discs: the nodes along the cut are constrained by both")
    worst = max(relative(float(two[k]), float(one[k])) for k in ("force_x_upper", "force_x_lower"))
    r.expect(worst < 1e-8, f"two half discs: 2 ranks agree with 1 ({worst:.1e} < 1e-8)")


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

    two_halves(r, results.get(1))

    bad = r.run("run", r.source / "cases" / "dfg" / "2d1_immersed.yaml", "--output", r.work / "bad",
                "--set", "benchmark.body=cylindre")
    r.expect(bad.returncode == 2 and "benchmark.body" in bad.stdout + bad.stderr and "cylindre" in bad.stdout + bad.stderr,
             "a benchmark body naming no solid is an input error naming the key", bad.stdout + bad.stderr)
    r.finish()


if __name__ == "__main__":
    main()
