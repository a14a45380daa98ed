#!/usr/bin/python3
"""The valve's case format with everything the 3D aortic valve needs, on the 2D valve's
geometry (cases/valve2d/): several solids with their own materials and fibres (the leaflets,
one deformable solid whose two bodies are fibre-reinforced with their own fibre direction, in
mortar contact; a rigid 'stent' block clamping the upper leaflet's base, so that the two solids
share fluid nodes), a pressure inlet whose waveform is a CSV file and a 3-element Windkessel
outlet. 3 steps of 2 ms (the pressure reversed, the leaflets closing), on 1 and 2 ranks:
 - the run completes, every step at its first try, with the force balance below 1e-12 for
   each solid (Sum B_k^T lambda against Sum r_i D_k,i / D_i);
 - the stent and the leaflets share fluid nodes (their constrained counts add up to more than
   the distinct constrained fluid vertices of benchmark.constrained_fluid_vertices), which
   they could not before the summed projections (coupling::ConstraintGroup);
 - the Windkessel's state is in the summary and its outlet pressure follows the RCR relation
   (P = R_p Q + P_c: outlet_pressure against outlet_flow and the state, to 1e-6 relative);
 - 2 ranks agree with 1 in the opening and the flows to 1e-5 relative (the coupling stops at a
   relative change of 1e-3)."""

import json

from cli_common import Runner, parse_arguments, read_json, read_rows

PROXIMAL, COMPLIANCE, DISTAL = 2.0e4, 1.0e-6, 2.0e5  # Pa s/m^2, m^2/Pa, Pa s/m^2 (2D: per depth)


def case_text(source, work):
    valve = source / "cases" / "valve2d"
    return f"""problem: fsci
mesh: {{level: 0}}
fluid:
  mesh: {{type: geo, file: {valve / 'channel.geo'}, size: 0.001}}
  density: 1000
  viscosity: 0.02
  boundary:
    - {{group: walls, type: no_slip}}
  outlets:
    - group: inlet
      type: traction
      pressure: 20.0
      backflow: 0
      waveform: {{type: csv, file: {work / 'inlet.csv'}}}
    - group: outlet
      type: windkessel
      windkessel: {{proximal_resistance: {PROXIMAL}, compliance: {COMPLIANCE},
                    distal_resistance: {DISTAL}, distal_pressure: 0.0}}
      backflow: 0.2
solids:
  - name: leaflets
    rigid: false
    mesh: {{type: geo, file: {valve / 'leaflets.geo'}, size: 0.0002, level: 0}}
    bodies:
      - name: lower
        cell_groups: [lower]
        density: 1100
        material: {{model: fibre_reinforced, shear_modulus: 1.0e4, bulk_modulus: 5.0e4,
                    fibre_k1: 2.0e4, fibre_k2: 5.0}}
        fibres: {{rule: constant, direction: [0.5, 0.866]}}
      - name: upper
        cell_groups: [upper]
        density: 1100
        material: {{model: fibre_reinforced, shear_modulus: 1.0e4, bulk_modulus: 5.0e4,
                    fibre_k1: 2.0e4, fibre_k2: 5.0}}
        fibres: {{rule: constant, direction: [0.5, -0.866]}}
    dirichlet:
      - boundary: lower_base
      - boundary: upper_base
    contact:
      pairs:
        - {{slave: lower_inner, master: upper_inner}}
      search_distance: 0.0003
      linearisation: finite_difference
      coverage_threshold: 0.5
    newton: {{relative_tolerance: 1.0e-8, absolute_tolerance: 1.0e-12, max_iterations: 60,
              line_search: 4}}
  - name: stent
    rigid: true
    mesh: {{type: rectangle, lower: [0.0105, 0.0088], upper: [0.0135, 0.01], cells: [15, 6]}}
coupling:
  coverage_threshold: 0.5
  search_margin: 0.0
  iteration: {{absolute_tolerance: 1.0e-8, relative_tolerance: 1.0e-3, max_iterations: 60,
               relaxation: 0.5, method: iqn_ils, reuse_steps: 4, max_columns: 30}}
time: {{steady: false, step: 0.002, end_time: 0.006}}
benchmark: {{type: valve, solid: leaflets, flow_boundary: inlet}}
output: {{vtk: false}}
"""


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    source = r.source.resolve()
    (r.work / "inlet.csv").write_text("# time [s], factor\n0, 0\n0.03, -1.5\n1, -1.5\n")
    case = r.work / "valve_format.yaml"
    case.write_text(case_text(source, r.work.resolve()))
    rows = {}
    for ranks in (1, 2):
        out = r.work / f"np{ranks}"
        result = r.run("run", case, "--output", out, ranks=ranks)
        summary = read_json(out / "summary.json") if (out / "summary.json").is_file() else {}
        ok = result.returncode == 0 and summary.get("status") == "completed"
        r.expect(ok, f"{ranks} rank(s): the run completes", result.stdout[-3000:] + result.stderr)
        if not ok:
            continue
        series = read_rows(out / "series.csv")
        rows[ranks] = series
        tries = [int(float(row["coupling_tries"])) for row in series]
        r.expect(len(series) == 3 and max(tries) == 1, f"{ranks} rank(s): 3 steps, each at its first try", str(tries))
        b = summary["benchmark"]
        r.expect(b["force_balance_error"] < 1e-12, f"{ranks} rank(s): force balance {b['force_balance_error']:.1e} < 1e-12")
        counts = {name: b["solids"][name]["constrained_fluid_vertices"] for name in ("leaflets", "stent")}
        distinct = b["constrained_fluid_vertices"]
        print(f"{ranks} rank(s): constrained fluid vertices {counts}, {distinct} distinct")
        r.expect(min(counts.values()) > 0 and sum(counts.values()) > distinct,
                 f"{ranks} rank(s): the stent and the leaflets share fluid nodes", json.dumps(b)[:1500])
        state = summary.get("windkessel_state", {}).get("outlet")
        r.expect(state is not None, f"{ranks} rank(s): the Windkessel state is in the summary", json.dumps(summary)[:1500])
        if state is not None:
            last = series[-1]
            pressure, flow = float(last["outlet_pressure_outlet"]), float(last["outlet_flow_outlet"])
            # state: version, step count, time, last step, P_c^n, P_c^(n-1) (lumped/windkessel.hpp)
            expected = PROXIMAL * flow + float(state[4])
            r.expect(len(state) == 6 and abs(pressure - expected) <= 1e-6 * max(abs(pressure), 1e-300),
                     f"{ranks} rank(s): outlet pressure = R_p Q + P_c",
                     f"P {pressure:.6e}, Q {flow:.6e}, state {state}")
    if 1 in rows and 2 in rows:
        worst = max(abs(float(b[key]) / float(a[key]) - 1)
                    for a, b in zip(rows[1], rows[2]) for key in ("opening_leaflets", "outlet_flow_inlet",
                                                                 "outlet_flow_outlet"))
        r.expect(worst < 1e-5, f"2 ranks agree with 1 ({worst:.1e} < 1e-5)")
    r.finish()


if __name__ == "__main__":
    main()
