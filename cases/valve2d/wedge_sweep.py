#!/usr/bin/python3
"""The sweep of the coaptation faces downstream of where they touch, found from the geometry
alone, against the solver's (a check of docs/verification/fsci.md, "The case as committed
since 2026-12-07"): from a valve2d run with the solid's fields written at every step
(output.vtk_interval 1), per closed phase, the volume W swept by the parts of the two
coaptation faces downstream of the contact point.

Once the faces touch, the fluid between their parts downstream of the contact point (the wedge
they open, and the upper face's overhang) is the outlet's, not the inlet's: the benchmark's
swept flow S (swept_flow) counts the inner sides (benchmark.upstream_surfaces: lower_inner,
upper_inner) from the clamped base to the contact zone only, and their sweep beyond it is
series.csv's swept_flow_past_contact (src/coapt/coupling/valve_surface.hpp). This tool finds
that part by another rule and sets its W against the solver's.

Per step, from the deformed coordinates at the step's start and end, each inner facet sweeps
the area (d0 + d1)/2 . n|F| (n out of the solid at the mid-path: exact for the straight path
the benchmark takes); the sum over all inner facets is checked against swept_flow +
swept_flow_past_contact + swept_flow_outside_fluid of series.csv (the last: the sweep of the
inner sides' parts in the walls, where there is no fluid, not counted in S either). W sums the
facets of the lower face (outward normal +y) whose reference nodes lie downstream of the most
upstream active contact node at the step's end, and of the upper face (normal -y) whose
deformed midpoint lies downstream of that node's deformed position. The solver cuts the upper
face where the active nodes' multipliers cover half a node's support instead, so the two W may
differ by about a facet's sweep.

    /usr/bin/python3 cases/valve2d/wedge_sweep.py RUN_DIR
"""

import sys
from pathlib import Path

import numpy as np
from plot_valve import read_run  # this folder's
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader

FACE_NORMAL = 0.999  # |n_y| of a facet on a coaptation face (flat, along x)


def read(path, extra=()):
    """Reference coordinates, displacement and contact_active of one .pvtu of the solid, one
    vertex per global id in the ids' order (so that every step lists them alike), and its
    triangles; then the (x, y) of each vector field named in `extra`."""
    reader = vtkXMLPUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    data = grid.GetPointData()
    ids = vtk_to_numpy(data.GetArray("global_id")).astype(np.int64)
    # one copy of the vertices that several ranks write
    _, keep, inverse = np.unique(ids, return_index=True, return_inverse=True)
    cells = inverse[vtk_to_numpy(grid.GetCells().GetConnectivityArray()).reshape(-1, 3)]
    return (vtk_to_numpy(grid.GetPoints().GetData())[keep, :2],
            vtk_to_numpy(data.GetArray("displacement"))[keep, :2],
            vtk_to_numpy(data.GetArray("contact_active"))[keep], cells,
            *(vtk_to_numpy(data.GetArray(name))[keep, :2] for name in extra))


def boundary_facets(points, cells):
    """Boundary edges (a, b) ordered so that (b - a) turned clockwise points out of the solid,
    with their outward unit normals in the reference configuration."""
    cells_of_edge = {}  # (a, b, the cell's third vertex) per cell of each edge
    for cell in cells:
        for i in range(3):
            a, b, c = cell[i], cell[(i + 1) % 3], cell[(i + 2) % 3]
            cells_of_edge.setdefault((min(a, b), max(a, b)), []).append((a, b, c))
    facets, normals = [], []
    for edges in cells_of_edge.values():
        if len(edges) != 1:
            continue
        a, b, c = edges[0]
        edge = points[b] - points[a]
        normal = np.array([edge[1], -edge[0]])
        if np.dot(normal, points[c] - points[a]) > 0:  # the third vertex must be behind
            a, b, normal = b, a, -normal
        facets.append((a, b))
        normals.append(normal / np.linalg.norm(normal))
    return np.array(facets), np.array(normals)


def swept(facets, start, end):
    """The area each facet sweeps from start to end (positive out of the solid)."""
    d = end - start
    mid = 0.5 * (start + end)
    edge = mid[facets[:, 1]] - mid[facets[:, 0]]
    area_normal = np.stack([edge[:, 1], -edge[:, 0]], axis=1)
    return np.einsum("ij,ij->i", 0.5 * (d[facets[:, 0]] + d[facets[:, 1]]), area_normal)


def sides(points, cells):
    """The solid's boundary facets (boundary_facets), and which of them are on the inner sides
    (facing the other leaflet: upwards on the lower one, downwards on the upper), on the lower
    coaptation face and on the upper one."""
    facets, normals = boundary_facets(points, cells)
    centre = 0.5 * (points[:, 1].min() + points[:, 1].max())
    lower = points[facets[:, 0], 1] < centre
    inner = np.where(lower, normals[:, 1] > 1e-6, normals[:, 1] < -1e-6)
    lower_face = lower & (normals[:, 1] > FACE_NORMAL)
    upper_face = ~lower & (normals[:, 1] < -FACE_NORMAL)
    return facets, inner, lower_face, upper_face


def past_contact(points, current, active, facets, lower_face, upper_face):
    """The facets of the coaptation faces downstream of the most upstream active node (the
    module comment's rule), and that node (None, and no facets, without contact)."""
    contact = np.flatnonzero(active > 0.5)
    if not len(contact):
        return np.zeros(len(facets), dtype=bool), None
    node = contact[np.argmin(points[contact, 0])]
    x = points[node, 0] - 1e-12
    middle = 0.5 * (current[facets[:, 0], 0] + current[facets[:, 1], 0])
    return ((lower_face & (points[facets[:, 0], 0] >= x) & (points[facets[:, 1], 0] >= x))
            | (upper_face & (middle >= current[node, 0]))), node


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run = Path(sys.argv[1])
    steps, rows = read_run(run)
    if len(steps) != len(rows):
        sys.exit(f"{run}: {len(steps)} solid fields for {len(rows)} steps: write them at every "
                 f"step (--set output.vtk_interval=1)")
    first = read(steps[0][1])
    points, cells = first[0], first[3]
    facets, inner, lower_face, upper_face = sides(points, cells)
    previous = points.copy()  # the run starts at rest
    phases, worst = [], 0.0
    for k, ((time, path), row) in enumerate(zip(steps, rows)):
        _, displacement, active, _ = first if k == 0 else read(path)
        current = points + displacement
        step = time - (rows[k - 1]["time"] if k else 0.0)
        sweep = swept(facets, previous, current)
        total = sweep[inner].sum()
        whole = (row["swept_flow"] + row.get("swept_flow_past_contact", 0.0)
                 + row.get("swept_flow_outside_fluid", 0.0))
        worst = max(worst, abs(total - whole * step) / max(abs(total), 1e-30))
        downstream, node = past_contact(points, current, active, facets, lower_face, upper_face)
        if node is not None:
            if not phases or phases[-1]["end"] != rows[k - 1]["time"]:
                phases.append({"start": time, "wedge": 0.0, "solver": 0.0, "leak": 0.0,
                               "downstream": 0.0, "at": []})
            phase = phases[-1]
            phase["end"] = time
            phase["wedge"] += sweep[downstream].sum()
            phase["solver"] += row.get("swept_flow_past_contact", 0.0) * step
            phase["leak"] += row["leak_flow"] * step
            phase["downstream"] += row.get("leak_flow_downstream", float("nan")) * step
            phase["at"].append(points[node, 0])
        previous = current
    print(f"{run}: {len(steps)} steps; the inner sides' sweep against series.csv's swept_flow + "
          f"swept_flow_past_contact + swept_flow_outside_fluid: largest relative difference "
          f"{worst:.1e}")
    if not worst < 1e-9:
        sys.exit(f"{run}: the inner sides found here are not benchmark.upstream_surfaces (their "
                 f"sweep differs from the series' by {worst:.1e} relative)")
    for phase in phases:
        print(f"closed {phase['start']:.4f}-{phase['end']:.4f} s: contact at reference x = "
              f"{1e3 * min(phase['at']):.3f}-{1e3 * max(phase['at']):.3f} mm; the faces' sweep "
              f"downstream of it W = {phase['wedge']:+.3e} m^2, the solver's "
              f"{phase['solver']:+.3e} m^2; leak (inlet side) {phase['leak']:+.3e}, "
              f"(outlet side) {phase['downstream']:+.3e} m^2")


if __name__ == "__main__":
    main()
