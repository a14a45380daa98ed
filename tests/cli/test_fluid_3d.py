"""Steady Navier-Stokes in a 3D box channel [0, 4] x [0, 1] x [0, 1] (12 x 3 x 3 cubes of 6
tetrahedra at level 0, 8 times as many at level 1; radial inflow profile with peak 1 m/s,
no-slip side walls, do-nothing outlet, rho = 1, mu = 0.05) with the default linear solver
(GMRES + Schur-complement fieldsplit with BoomerAMG, src/coapt/fluid/navier_stokes.cpp) on
2 ranks:
 - both levels converge, and the Krylov iterations per Newton step grow by at most 1.5x from
   level 0 to level 1 (the scalability requirement of the fluid solver; the growth over four
   levels is in docs/verification/fluid.md, "Linear solver");
 - the default solver and the direct one (-fluid_pc_type lu) take the same number of Newton
   steps, and the force of the fluid on the bottom wall (benchmark drag_force, lift_force)
   agrees to 1e-6 relative (the Krylov tolerance of a Newton step is 1e-6, the Newton
   tolerance 1e-8)."""

from cli_common import Runner, parse_arguments, read_json

CASE = """problem: navier_stokes
mesh:
  type: box
  lower: [0.0, 0.0, 0.0]
  upper: [4.0, 1.0, 1.0]
  cells: [12, 3, 3]
  level: 0
fluid:
  density: 1.0
  viscosity: 0.05
boundary:
  - {group: left, type: velocity, value: [1.0, 0.0, 0.0], profile: radial, centre: [0.0, 0.5, 0.5], radius: 0.5}
  - {group: front, type: no_slip}
  - {group: back, type: no_slip}
  - {group: bottom, type: no_slip}
  - {group: top, type: no_slip}
  - {group: right, type: outflow}
time:
  steady: true
benchmark: {type: cylinder, body: bottom, mean_velocity: 1.0, diameter: 1.0}
output:
  vtk: false
"""

DIRECT = ["-fluid_pc_type", "lu"]


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    case = r.work / "channel3d.yaml"
    case.write_text(CASE)

    def run(name, level, extra=()):
        out = r.work / name
        result = r.run("run", case, "--output", out, "--set", f"mesh.level={level}",
                       "--", *extra, ranks=2)
        r.expect(result.returncode == 0, f"{name}: level {level} runs", result.stdout + result.stderr)
        if result.returncode != 0:
            return None
        return read_json(out / "summary.json")

    per_step = {}
    runs = {}
    for level in (0, 1):
        runs[level] = run(f"iterative-L{level}", level)
        if runs[level] is None:
            continue
        summary = runs[level]
        newton, linear = summary["iterations"]["newton"], summary["iterations"]["linear"]
        per_step[level] = linear / newton
        print(f"level {level}: {summary['benchmark']['cells']} cells, {newton} Newton steps, "
              f"{linear} Krylov iterations ({per_step[level]:.1f} per step)")
    if len(per_step) == 2:
        growth = per_step[1] / per_step[0]
        r.expect(growth <= 1.5, f"Krylov iterations per Newton step grow {growth:.2f}x <= 1.5x "
                                f"({per_step[0]:.1f} -> {per_step[1]:.1f})")

    direct = run("direct-L0", 0, DIRECT)
    if direct is not None and runs.get(0) is not None:
        summary, direct_summary = runs[0], direct
        r.expect(summary["iterations"]["newton"] == direct_summary["iterations"]["newton"],
                 f"same Newton steps as the direct solver ({summary['iterations']['newton']})")
        for key in ("drag_force", "lift_force"):
            a, b = summary["benchmark"][key], direct_summary["benchmark"][key]
            difference = abs(a - b) / max(abs(b), 1e-12)
            r.expect(difference < 1e-6, f"{key}: iterative {a:.9e} vs direct {b:.9e} ({difference:.1e} < 1e-6)")
    r.finish()


if __name__ == "__main__":
    main()
