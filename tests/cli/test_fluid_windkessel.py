"""The tube with a 3-element Windkessel outlet (cases/tube_windkessel.yaml), level 0, two periods
of pulsatile inflow (T = 1 s, 25 BDF2 steps per period), on 1 and 2 ranks:
 - the outlet pressure is exactly what the Windkessel gives for the computed outlet flow: the
   BDF1-then-BDF2 recursion of the RCR model, recomputed here from series.csv, matches the
   written pressure to 1e-9 relative (the coupling is implicit: P and Q are of the same step);
 - the RCR relation holds in continuous time: P_RCR from the RCR ODE integrated independently
   here (RK4, 64 substeps per step, Q linear between steps) differs from the outlet pressure by
   at most 2e-3 of max |P| over the last period (the time error of the 0D model's BDF2 at
   Δt = 0.04 s; 5.5e-4 was obtained), and the driver's rcr_relative_error agrees with it;
 - mass: Q_out = Q_in to 1e-10 relative (incompressible fluid, rigid walls: the discrete
   continuity equation tested with q = 1 makes the net boundary flux vanish);
 - every step converged in at most 6 Newton iterations;
 - summary.json holds the Windkessel's state (6 entries, version 1, 50 steps, t = 2 s);
 - 2 ranks agree with 1 rank to 1e-8 relative (direct solver);
 - a misspelt outlet group is an input error naming the file and the group."""

import csv
import math
import time

from cli_common import Runner, parse_arguments, read_json

DIRECT = ["-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu", "-fluid_pc_factor_mat_solver_type", "mumps"]
# The case's RCR parameters (cases/tube_windkessel.yaml).
RP, C, RD, PD, PC0 = 4.0e7, 5.0e-9, 3.6e8, 0.0, 11309.7
PERIOD = 1.0


def read_series(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {key: [float(row[key]) for row in rows] for key in rows[0]}


def bdf_windkessel(times, flows):
    """P of the Windkessel's own scheme (BDF1 on the first step, BDF2 after) for the flows."""
    tau = RD * C
    pc, pc_old, last_dt, previous_time = PC0, PC0, 0.0, 0.0
    pressures = []
    for t, q in zip(times, flows):
        dt = t - previous_time
        if last_dt == 0.0:
            a0, a1, a2 = 1.0, 1.0, 0.0
        else:
            w = dt / last_dt
            a0, a1, a2 = (1 + 2 * w) / (1 + w), 1 + w, w * w / (1 + w)
        h = a1 * pc - a2 * pc_old
        pc_new = (RD * dt * q + tau * h + dt * PD) / (a0 * tau + dt)
        pc_old, pc, last_dt, previous_time = pc, pc_new, dt, t
        pressures.append(RP * q + pc)
    return pressures


def ode_windkessel(times, flows, substeps=64):
    """P_RCR = R_p Q + P_c with C dP_c/dt = Q − (P_c − P_d)/R_d integrated by RK4, Q linear
    between steps (constant Q_1 on the first step: the initial state is not a solution)."""
    def rate(q, pc):
        return (q - (pc - PD) / RD) / C
    pc, previous_time = PC0, 0.0
    pressures = []
    for k, (t, q1) in enumerate(zip(times, flows)):
        q0 = flows[k - 1] if k > 0 else q1
        h = (t - previous_time) / substeps
        for j in range(substeps):
            s0, s1 = j / substeps, (j + 1) / substeps
            qa, qm, qb = q0 + (q1 - q0) * s0, q0 + (q1 - q0) * 0.5 * (s0 + s1), q0 + (q1 - q0) * s1
            k1 = rate(qa, pc)
            k2 = rate(qm, pc + 0.5 * h * k1)
            k3 = rate(qm, pc + 0.5 * h * k2)
            k4 = rate(qb, pc + h * k3)
            pc += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        pressures.append(RP * q1 + pc)
        previous_time = t
    return pressures


def relative(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    case = r.source / "cases" / "tube_windkessel.yaml"
    results = {}
    for ranks in (1, 2):
        out = r.work / f"tube-np{ranks}"
        start = time.monotonic()
        result = r.run("run", case, "--output", out, "--", *DIRECT, ranks=ranks)
        elapsed = time.monotonic() - start
        print(f"tube_windkessel on {ranks} rank(s): {elapsed:.1f} s")
        if result.returncode != 0:
            r.expect(False, f"tube_windkessel runs on {ranks} rank(s)", result.stdout + result.stderr)
            continue
        results[ranks] = (read_json(out / "summary.json"), read_series(out / "series.csv"))

    if 1 in results:
        summary, series = results[1]
        b = summary["benchmark"]
        t, q, p = series["time"], series["outlet_flow_outlet"], series["outlet_pressure_outlet"]
        q_in = [-x for x in series["flow_inlet"]]
        print(f"rcr_relative_error = {b['rcr_relative_error']:.3e}, P mean = {b['outlet_pressure_mean']:.2f} Pa, "
              f"amplitude = {b['outlet_pressure_amplitude']:.2f} Pa, Q mean = {b['outlet_flow_mean']:.6e} m^3/s")

        discrete = bdf_windkessel(t, q)
        scheme_error = max(abs(a - c) for a, c in zip(p, discrete)) / max(abs(x) for x in p)
        print(f"outlet pressure vs the Windkessel's BDF recursion: {scheme_error:.2e}")
        r.expect(scheme_error < 1e-9, f"the outlet pressure is the Windkessel's for the computed flow "
                                      f"({scheme_error:.1e} < 1e-9)")

        model = ode_windkessel(t, q)
        last = [k for k, x in enumerate(t) if x >= t[-1] - PERIOD * (1 + 1e-9)]
        ode_error = max(abs(p[k] - model[k]) for k in last) / max(abs(p[k]) for k in last)
        print(f"max |P - P_RCR| / max |P| over the last period (independent RK4): {ode_error:.3e}")
        r.expect(ode_error < 2e-3, f"the RCR relation holds over the last period ({ode_error:.2e} < 2e-3)")
        r.expect(abs(ode_error - b["rcr_relative_error"]) < 1e-6 * max(ode_error, 1e-12) + 1e-9,
                 f"the driver's rcr_relative_error agrees ({b['rcr_relative_error']:.6e} vs {ode_error:.6e})")

        mass = max(abs(a - c) for a, c in zip(q, q_in)) / max(abs(x) for x in q_in)
        print(f"max |Q_out - Q_in| / max |Q_in| = {mass:.2e}")
        r.expect(mass < 1e-10, f"Q_out = Q_in ({mass:.1e} < 1e-10)")
        swing = (max(q_in[k] for k in last) - min(q_in[k] for k in last)) / b["outlet_flow_mean"]
        r.expect(0.9 < swing < 1.1, f"the inflow swings by ~100 % of its mean (1 ± 0.5 sin): {swing:.3f}")

        newton = max(series["newton_iterations"])
        r.expect(newton <= 6, f"every step converged in <= 6 Newton iterations (max {newton:.0f})")

        state = summary.get("windkessel_state", {}).get("outlet")
        r.expect(state is not None and len(state) == 6 and state[0] == 1 and state[1] == 50
                 and abs(state[2] - 2.0) < 1e-12,
                 f"summary.json holds the Windkessel state (version, steps, time, dt, P_c, P_c old): {state}")

    if 1 in results and 2 in results:
        b1, b2 = results[1][0]["benchmark"], results[2][0]["benchmark"]
        keys = ("rcr_relative_error", "outlet_pressure_mean", "outlet_pressure_amplitude", "outlet_flow_mean")
        difference = max(relative(b2[k], b1[k]) for k in keys)
        p1, p2 = results[1][1]["outlet_pressure_outlet"], results[2][1]["outlet_pressure_outlet"]
        difference = max(difference, max(relative(a, c) for a, c in zip(p2, p1)))
        r.expect(difference < 1e-8, f"2 ranks agree with 1 rank ({difference:.1e} < 1e-8)")

    bad_case = r.work / "bad_outlet.yaml"
    bad_case.write_text(case.read_text().replace("  - group: outlet\n", "  - group: outlett\n")
                        .replace("file: tube_windkessel.geo", f"file: {r.source / 'cases' / 'tube_windkessel.geo'}"))
    result = r.run("run", bad_case, "--output", r.work / "bad-outlet")
    text = result.stdout + result.stderr
    r.expect(result.returncode != 0 and "no boundary group 'outlett'" in text and "bad_outlet.yaml" in text,
             "a misspelt outlet group is an input error naming the file and the group", text)
    r.finish()


if __name__ == "__main__":
    main()
