"""The fluid's pressure carried by an immersed compressible solid (coupling.pressure_in_solid),
on Turek-Hron FSI1 level 0 (cases/turek_hron/fsi1.yaml, which sets it), on 1, 2 and 3 ranks.

An immersed solid is loaded by the multiplier, which carries the pressure's gradient but not its
level; with pressure_in_solid it also carries -int p div w over its region. Raising the outlet
pressure by 1000 Pa raises the pressure everywhere by 1000 Pa, so:
 - without pressure_in_solid the bar does not notice: u(A), drag and lift change by less than
   1e-9 relative (a uniform pressure has no gradient);
 - with it, u_x(A) moves as that of the bar alone (problem: solid, the same 70 x 4 mesh,
   clamped on the left, a follower pressure of 1000 Pa on its other three sides), within 1 %
   (measured 0.1-0.2 %): -0.0706 mm, three times the benchmark's u_x(A);
 - drag and lift keep their values within 1 % (measured -0.008 % and -0.38 %): the load has no
   resultant, so they change only with the bar's shape (u_y(A) of the bar alone moves by 0.7 %
   of the case's under the 1000 Pa); a load with a resultant would add up to 1000 Pa x 0.02 m
   = 20 N/m, fifteen times the lift;
 - 2 and 3 ranks give the same u(A) as 1 rank to 1e-6 relative (the coupling stops at a
   relative change of 1e-6).
A transient run carries the pressure in its checkpoint: FSI3 (cases/turek_hron/fsi3.yaml, level
0) with pressure_in_solid, 10 steps straight and 5 + 5 restarted from the checkpoint after 5,
gives the same series.csv rows bit for bit.
The drag, lift and u_y(A) of the case at level 0 are checked by test_fsci_fsi1.py."""

from cli_common import DETERMINISTIC_FLUID, DETERMINISTIC_SOLID, Runner, parse_arguments, read_json, read_rows

DIRECT = ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu", "-fluid_pc_factor_mat_solver_type", "mumps"]
RAISED = "fluid.outlets=[{group: outlet, type: traction, pressure: 1000}]"
SIDES = "pressures=[{boundary: right, pressure: 1000}, {boundary: top, pressure: 1000}, " \
        "{boundary: bottom, pressure: 1000}]"


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    case = r.source / "cases" / "turek_hron" / "fsi1.yaml"

    def run(name, *settings, ranks=1):
        out = r.work / name
        arguments = []
        for setting in settings:
            arguments += ["--set", setting]
        result = r.run("run", case, "--output", out, "--set", "output.vtk=false", *arguments, "--", *DIRECT,
                       ranks=ranks)
        summary = read_json(out / "summary.json") if (out / "summary.json").is_file() else {}
        r.expect(result.returncode == 0 and summary.get("status") == "completed", f"{name}: converges",
                 result.stdout[-3000:] + result.stderr)
        return summary.get("benchmark")

    alone_out = r.work / "bar-alone"
    result = r.run("run", r.source / "cases" / "turek_hron" / "csm1.yaml", "--output", alone_out,
                   "--set", "gravity=[0, 0]", "--set", "mesh.cells=[70, 4]", "--set", "steps=1",
                   "--set", SIDES, "--set", "output.vtk=false")
    r.expect(result.returncode == 0, "the bar alone under 1000 Pa", result.stdout[-3000:] + result.stderr)
    alone = read_json(alone_out / "summary.json")["benchmark"]["A_displacement_x"] if result.returncode == 0 else None

    off, off_raised = run("off", "coupling.pressure_in_solid=false"), \
        run("off-raised", "coupling.pressure_in_solid=false", RAISED)
    if off and off_raised:
        change = max(abs(off_raised[k] / off[k] - 1) for k in ("drag", "lift", "displacement_x", "displacement_y"))
        print(f"without pressure_in_solid: u_x(A) {1e3 * off['displacement_x']:.6f} mm, 1000 Pa more: "
              f"{1e3 * off_raised['displacement_x']:.6f} mm")
        r.expect(change < 1e-9, f"without pressure_in_solid the level changes nothing ({change:.1e} < 1e-9)")

    results = {}
    for ranks in (1, 2, 3):
        base, raised = run(f"np{ranks}", ranks=ranks), run(f"np{ranks}-raised", RAISED, ranks=ranks)
        if not (base and raised):
            continue
        results[ranks] = (base, raised)
        shift = raised["displacement_x"] - base["displacement_x"]
        print(f"{ranks} rank(s): u_x(A) {1e3 * base['displacement_x']:.6f} mm, 1000 Pa more: "
              f"{1e3 * raised['displacement_x']:.6f} mm (shift {1e3 * shift:.6f} mm; the bar alone "
              f"{1e3 * alone:.6f} mm)" if alone else "")
        if alone:
            r.expect(abs(shift / alone - 1) < 0.01,
                     f"{ranks} rank(s): the shift is the bar alone's ({100 * (shift / alone - 1):+.2f} %)")
        for k in ("drag", "lift"):
            r.expect(abs(raised[k] / base[k] - 1) < 1e-2,
                     f"{ranks} rank(s): {k} keeps its value ({100 * (raised[k] / base[k] - 1):+.4f} %)")
    for ranks in (2, 3):
        if 1 in results and ranks in results:
            difference = max(abs(results[ranks][i][k] / results[1][i][k] - 1)
                             for i in (0, 1) for k in ("displacement_x", "displacement_y"))
            r.expect(difference < 1e-6, f"{ranks} ranks agree with 1 ({difference:.1e} < 1e-6)")

    fsi3 = r.source / "cases" / "turek_hron" / "fsi3.yaml"

    def transient(name, end_time, *extra):
        out = r.work / name
        result = r.run("run", fsi3, "--output", out, "--set", f"time.end_time={end_time}", "--set",
                       "output.vtk=false", "--set", "output.checkpoint_interval=5", "--set",
                       "coupling.pressure_in_solid=true", *extra, "--", *DETERMINISTIC_FLUID,
                       *DETERMINISTIC_SOLID)
        r.expect(result.returncode == 0, f"{name}: runs", result.stdout[-3000:] + result.stderr)
        return read_rows(out / "series.csv") if result.returncode == 0 else None

    straight = transient("fsi3-straight", 0.01)
    transient("fsi3-first", 0.005)
    again = transient("fsi3-again", 0.01, "--restart", r.work / "fsi3-first")
    if straight and again:
        r.expect(again == straight[5:], f"fsi3 restarted after 5 steps continues bit for bit "
                 f"({len(again)} rows against {len(straight[5:])})")
    r.finish()


if __name__ == "__main__":
    main()
