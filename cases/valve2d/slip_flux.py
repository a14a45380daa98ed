#!/usr/bin/python3
"""Where the closed valve's leak goes (a diagnostic of docs/verification/fsci.md, "The case as
committed since 2026-12-07"): from a valve2d run with the fluid's and the solid's fields
written at every step (output.vtk_interval 1), per closed phase, the leak on the inlet's side
split into the fluid's slip through the leaflets' upstream sides and the rest.

The fluid on the inlet's side of the closed valve is bounded by the inlet, the walls, the
leaflets' upstream sides Γ up to the contact point, and the contact point itself. The leak is
Q − S (Q the flow out through the inlet, S the rate at which Γ sweeps that side). With F the
flux of the fluid's velocity through Γ, F = ∫_Γ v_f · n (n out of the solid),

    Q − S = (F − S) + (Q − F):

 - F − S, the **slip**: the fluid's velocity on Γ is not the leaflets' (the immersed constraint
   holds at the fluid nodes the solid covers; across the cells Γ cuts, the P1 velocity mixes
   constrained and free nodes), so fluid crosses Γ. It is a discretisation error of the
   immersed boundary's position;
 - Q − F: what leaves the region otherwise, across the contact point and by the discrete
   divergence of the fluid's velocity in the region (PSPG).

The slip is split between the facets of Γ next to the nodes the contact moved (those whose
displacement over the step is not Δt (vₙ + vₙ₊₁)/2: the contact-stabilized Newmark scheme
moves them by a projected predictor that their velocity does not follow; a node held in
contact keeps the normal velocity it came in with) and the rest of Γ. On the facets next to
them it also gives V − S, with V the flux of the solid's own velocity: how much the scheme's
velocity there says that the displacement does not do (the fluid need not follow it).

Γ is the inner sides of wedge_sweep.py without their part downstream of the contact node (its
rule), less the facets that lie, in part, outside the fluid mesh (the leaflets' ends in the
walls: no fluid there; their sweep is reported apart). F and V are evaluated at the steps'
ends (the velocities interpolated at two Gauss points of each facet of Γ in its place at the
step's end) and, like Q (the series' flow), integrated over each step by the trapezoidal rule,
as the benchmark integrates Q (the flux at the step's start taken over the same facets in
their place then); S is the sweep over the step of those facets (wedge_sweep.swept).

    /usr/bin/python3 cases/valve2d/slip_flux.py RUN_DIR
"""

import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np
from plot_valve import read_run  # this folder's
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkPolyData
from vtkmodules.vtkFiltersCore import vtkProbeFilter
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader
from wedge_sweep import past_contact, read, sides, swept  # this folder's

GAUSS = np.array([0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0)])


def read_fluid(path):
    """The grid of one .pvtu of the fluid."""
    reader = vtkXMLPUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def fluid_velocity(grid, points):
    """The fluid's velocity (x, y) at `points` (n x 2) from a grid of read_fluid, and whether
    each point lies in the fluid mesh."""
    probes = vtkPoints()
    for x, y in points:
        probes.InsertNextPoint(x, y, 0.0)
    data = vtkPolyData()
    data.SetPoints(probes)
    probe = vtkProbeFilter()
    probe.SetInputData(data)
    probe.SetSourceData(grid)
    probe.Update()
    values = probe.GetOutput().GetPointData()
    return (vtk_to_numpy(values.GetArray("velocity"))[:, :2],
            vtk_to_numpy(values.GetArray(probe.GetValidPointMaskArrayName())) > 0)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run = Path(sys.argv[1])
    steps, rows = read_run(run)
    fluid = [(float(d.get("timestep")), run / d.get("file"))
             for d in ElementTree.parse(run / "solution.pvd").getroot().iter("DataSet")]
    if not (len(steps) == len(rows) == len(fluid)
            and all(abs(a[0] - b[0]) < 1e-12 for a, b in zip(steps, fluid))):
        sys.exit(f"{run}: {len(steps)} solid and {len(fluid)} fluid fields for {len(rows)} steps: "
                 f"write them at every step (--set output.vtk_interval=1)")
    first = read(steps[0][1], ("velocity",))
    points, cells = first[0], first[3]
    facets, inner, lower_face, upper_face = sides(points, cells)

    def fluxes(state, chosen):
        """Per facet of `chosen`, in its place in `state` (its positions, the solid's velocity and
        the fluid's grid; None: at rest before the first step): the fluxes of the fluid's and of
        the solid's velocity, and whether it lies in the fluid."""
        if state is None:
            return np.zeros(len(chosen)), np.zeros(len(chosen)), np.ones(len(chosen), dtype=bool)
        current, solid_velocity, grid = state
        a, b = current[facets[chosen, 0]], current[facets[chosen, 1]]
        edge = b - a
        area_normal = np.stack([edge[:, 1], -edge[:, 0]], axis=1)  # |F| n, n out of the solid
        velocity, inside = fluid_velocity(grid, np.concatenate([a + g * edge for g in GAUSS]))
        n = len(chosen)
        fluid_flux = sum(np.einsum("ij,ij->i", velocity[q * n:(q + 1) * n], area_normal)
                         for q in range(len(GAUSS))) / len(GAUSS)
        # the solid's own velocity, linear on the facet: its mean times |F| n
        mean_velocity = 0.5 * (solid_velocity[facets[chosen, 0]] + solid_velocity[facets[chosen, 1]])
        return (fluid_flux, np.einsum("ij,ij->i", mean_velocity, area_normal),
                inside.reshape(len(GAUSS), -1).all(axis=0))

    previous = None  # (positions, solid velocity, fluid grid) at the last step's end
    phases = []
    for k, ((time, path), row) in enumerate(zip(steps, rows)):
        fields = first if k == 0 else read(path, ("velocity",))
        _, displacement, active, _, solid_velocity = fields
        # the fluid's grid is read only where it is probed: the closed steps and the step before
        state = [points + displacement, solid_velocity, None]
        current = state[0]
        step = time - (rows[k - 1]["time"] if k else 0.0)
        downstream, node = past_contact(points, current, active, facets, lower_face, upper_face)
        if node is not None:
            state[2] = read_fluid(fluid[k][1])
            if previous is not None and previous[2] is None:
                previous[2] = read_fluid(fluid[k - 1][1])
            upstream = np.flatnonzero(inner & ~downstream)
            fluid_end, solid_end, inside = fluxes(state, upstream)
            fluid_start, solid_start, inside_start = fluxes(previous, upstream)
            inside &= inside_start
            start_positions, start_velocity = ((points, np.zeros_like(points)) if previous is None
                                               else (previous[0], previous[1]))
            sweep = swept(facets, start_positions, current)[upstream]
            # the nodes whose displacement is not the trapezoidal rule of their velocity
            mismatch = np.linalg.norm(current - start_positions
                                      - 0.5 * step * (start_velocity + solid_velocity), axis=1)
            moved = (mismatch[facets[upstream, 0]] > 1e-12) | (mismatch[facets[upstream, 1]] > 1e-12)
            if not phases or phases[-1]["end"] != rows[k - 1]["time"]:
                phases.append({"start": time, "Q": 0.0, "slip": 0.0, "slip moved": 0.0,
                               "scheme": 0.0, "S": 0.0, "walls": 0.0, "leak": 0.0})
            phase = phases[-1]
            phase["end"] = time
            flow_start = rows[k - 1]["outlet_flow_inlet"] if k else 0.0
            phase["Q"] += 0.5 * (flow_start + row["outlet_flow_inlet"]) * step
            slip = 0.5 * (fluid_start + fluid_end) * step - sweep
            phase["slip"] += slip[inside & ~moved].sum()
            phase["slip moved"] += slip[inside & moved].sum()
            phase["scheme"] += (0.5 * (solid_start + solid_end) * step - sweep)[inside & moved].sum()
            phase["S"] += sweep[inside].sum()
            phase["walls"] += sweep[~inside].sum()
            phase["leak"] += row["leak_flow"] * step
        previous = state
    print(f"{run}: {len(steps)} steps, {len(phases)} closed phase(s); per phase [m^2]: the flow out "
          f"through the inlet Q and the sweep S of the upstream sides to the contact node")
    for p in phases:
        slip = p["slip"] + p["slip moved"]
        rest = p["Q"] - p["S"] - slip
        print(f"closed {p['start']:.4f}-{p['end']:.4f} s: Q {p['Q']:+.3e}, S {p['S']:+.3e}; leak "
              f"Q - S {p['Q'] - p['S']:+.3e} = slip F - S {slip:+.3e} + rest Q - F {rest:+.3e}; "
              f"slip away from the nodes the contact moved {p['slip']:+.3e}, next to them "
              f"{p['slip moved']:+.3e} (where the scheme's velocity V says V - S "
              f"{p['scheme']:+.3e}); the benchmark's leak {p['leak']:+.3e}; the sweep of the "
              f"sides' parts in the walls {p['walls']:+.1e}")


if __name__ == "__main__":
    main()
