#!/usr/bin/python3
"""Plots a valve2d run: the leaflets (deformed solid mesh) at up to eight times of the solid's
VTK series inside the channel near the valve (left), and over time the opening, the flow through
the inlet, the leak (that flow less the flow the leaflets sweep out, where the case gives
benchmark.upstream_surfaces) and the inlet pressure (right), from RUN_DIR/solid.pvd and
RUN_DIR/series.csv.

    /usr/bin/python3 cases/valve2d/plot_valve.py OUT.png RUN_DIR
"""

import csv
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader  # noqa: E402


def read_solid(path):
    """Deformed coordinates (x + u) and triangles of one .pvtu of the solid."""
    reader = vtkXMLPUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    points = vtk_to_numpy(grid.GetPoints().GetData())
    displacement = vtk_to_numpy(grid.GetPointData().GetArray("displacement"))
    connectivity = vtk_to_numpy(grid.GetCells().GetConnectivityArray()).reshape(-1, 3)
    x = points[:, 0] + displacement[:, 0]
    y = points[:, 1] + displacement[:, 1]
    return x, y, connectivity


def read_run(run):
    """The solid's fields of a run, [(time, .pvtu path)] from solid.pvd, and series.csv's rows
    as floats."""
    steps = [(float(d.get("timestep")), run / d.get("file"))
             for d in ElementTree.parse(run / "solid.pvd").getroot().iter("DataSet")]
    with open(run / "series.csv") as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    return steps, rows


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    steps, rows = read_run(Path(sys.argv[2]))
    figure, (shape, history) = plt.subplots(1, 2, figsize=(12, 4.5))
    if len(steps) > 8:  # at most 8 shapes, evenly spread, the last one included
        steps = [steps[round(k * (len(steps) - 1) / 7)] for k in range(8)]
    colours = plt.cm.viridis([i / max(len(steps) - 1, 1) for i in range(len(steps))])
    for (time, path), colour in zip(steps, colours):
        x, y, triangles = read_solid(path)
        shape.triplot(Triangulation(1e3 * x, 1e3 * y, triangles), color=colour, lw=0.3)
        shape.plot([], [], color=colour, label=f"t = {time:.3f} s")
    shape.axhline(0, color="k", lw=1)
    shape.axhline(10, color="k", lw=1)
    shape.set_xlim(9, 22)
    shape.set_ylim(-1, 11)
    shape.set_aspect("equal")
    shape.set_xlabel("x [mm]")
    shape.set_ylabel("y [mm]")
    shape.legend(fontsize=6, loc="center right")
    shape.set_title("leaflets")
    t = [row["time"] for row in rows]
    history.plot(t, [1e3 * row["opening_leaflets"] for row in rows], label="opening [mm]")
    history.plot(t, [-1e4 * row["outlet_flow_inlet"] for row in rows], label="flow in [cm²/s]")
    if rows and "leak_flow" in rows[0]:
        history.plot(t, [1e4 * row["leak_flow"] for row in rows], "--",
                     label="leak: flow out − swept [cm²/s]")
    history.plot(t, [row["outlet_pressure_inlet"] / 10 for row in rows], label="inlet pressure [10 Pa]")
    closed = [row["contact_active_nodes_leaflets"] > 0 for row in rows]
    for i, c in enumerate(closed):
        if c:
            history.axvspan(t[i - 1] if i else t[i], t[i], color="red", alpha=0.15, lw=0)
    history.axhline(0, color="k", lw=0.5)
    history.set_xlabel("time [s]")
    history.legend(fontsize=8)
    history.grid(alpha=0.3)
    history.set_title("opening, flow, pressure (red: in contact)")
    figure.tight_layout()
    figure.savefig(sys.argv[1], dpi=110)


if __name__ == "__main__":
    main()
