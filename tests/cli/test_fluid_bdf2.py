"""Temporal convergence of the fluid's BDF2 (BDF1 on the first step): a 2D channel [0, 2] x [0, 1]
(16 x 8 squares, two triangles each), rho = 1, mu = 0.01, a parabolic inflow of peak 1 m/s
ramped in by (1 - cos(pi t / 0.25)) / 2 and modulated by 1 + 0.5 sin(2 pi t / 0.5), no-slip walls,
do-nothing outlet, run to t = 1 s with dt = 0.025, 0.0125, ..., 0.0015625 (40 to 640 steps) on one mesh:
 - with `fluid.tau_time_term: false` (tau_M independent of dt, so every dt solves the same
   semi-discrete problem) the pressure force on the bottom wall at t = 1 (lift_coefficient)
   and the shear force on it (drag_coefficient) converge at second order: the observed order
   log2(|q(dt) - q(dt/2)| / |q(dt/2) - q(dt/4)|) is >= 1.8 for every triple (lift 1.93, 1.98,
   1.99; drag 1.94, 1.98, 1.99 when written). The forces are read after each step is
   committed; they are the residual of that step with its own BDF history (before
   2026-12-03 they took the history that already held the new state, and the shear force
   kept a tail of a few 1e-5 that did not converge);
 - with the default tau_M (its (2/dt)^2 term) the stabilisation fades as dt -> 0: the run on
   the finest dt is printed against the dt-independent one (docs/verification/fluid.md,
   "Temporal convergence of BDF2"); it is not asserted.
The orders are those of the time discretisation alone: the mesh does not change."""

import math

from cli_common import Runner, parse_arguments, read_json

CASE = """problem: navier_stokes
mesh:
  type: rectangle
  lower: [0.0, 0.0]
  upper: [2.0, 1.0]
  cells: [16, 8]
fluid:
  density: 1.0
  viscosity: 0.01
boundary:
  - {group: left, type: velocity, value: [1.0, 0.0], profile: parabolic, from: [0.0, 0.0], to: [0.0, 1.0],
     ramp_time: 0.25, waveform: {type: sinusoid, amplitude: 0.5, period: 0.5}}
  - {group: bottom, type: no_slip}
  - {group: top, type: no_slip}
  - {group: right, type: outflow}
time:
  steady: false
  step: 0.05
  end_time: 1.0
benchmark: {type: cylinder, body: bottom, mean_velocity: 1.0, diameter: 1.0}
output:
  vtk: false
"""

STEPS = [0.025, 0.0125, 0.00625, 0.003125, 0.0015625]
DIRECT = ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu"]


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    case = r.work / "channel2d.yaml"
    case.write_text(CASE)

    def final_forces(name, step, *settings):
        out = r.work / name
        result = r.run("run", case, "--output", out, "--set", f"time.step={step}", *settings,
                       "--", *DIRECT)
        r.expect(result.returncode == 0, f"{name} runs", result.stdout[-3000:] + result.stderr)
        if result.returncode != 0:
            return None
        b = read_json(out / "summary.json")["benchmark"]
        return b["drag_coefficient"]["final"], b["lift_coefficient"]["final"]

    values = [final_forces(f"fixed-tau-dt{k}", step, "--set", "fluid.tau_time_term=false")
              for k, step in enumerate(STEPS)]
    if any(v is None for v in values):
        r.finish()
        return
    for component, name in enumerate(("drag_coefficient", "lift_coefficient")):
        q = [v[component] for v in values]
        differences = [abs(q[k] - q[k + 1]) for k in range(len(q) - 1)]
        orders = [math.log2(differences[k] / differences[k + 1]) for k in range(len(differences) - 1)]
        print(f"{name} at t = 1: " + ", ".join(f"{x:.9e}" for x in q))
        print("  differences per halving of dt: " + ", ".join(f"{d:.3e}" for d in differences))
        print("  observed orders: " + ", ".join(f"{p:.2f}" for p in orders))
        r.expect(min(orders) >= 1.8, f"{name}: second order in dt (observed orders "
                                     f"{', '.join(f'{p:.2f}' for p in orders)} >= 1.8)")

    default = final_forces("default-tau-finest", STEPS[-1])
    if default is not None:
        for component, name in enumerate(("drag_coefficient", "lift_coefficient")):
            a, b = default[component], values[-1][component]
            print(f"default tau_M at dt = {STEPS[-1]}: {name} {a:.9e} "
                  f"({abs(a - b) / abs(b):.2e} from the dt-independent tau_M)")
    r.finish()


if __name__ == "__main__":
    main()
