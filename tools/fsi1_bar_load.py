#!/usr/bin/python3
"""The load on the Turek-Hron bar and the tip deflection it stands for (docs/verification/fsci.md,
"Where u_y(A)'s scatter comes from").

For each run folder given: a body-fitted flow (`problem: navier_stokes` with the bar a no-slip
group, its fluid VTK's `reaction` field on the bar's vertices) or an FSI1 run (`problem: fsci`,
the bar's `coupling_force` B^T lambda in its solid VTK). Prints the bar's total force, the
lateral load per 0.05 m from the clamp, and delta = sum_j f_j . w_j with w the displacement of
the clamped bar under a unit tip load (Euler-Bernoulli, plane strain: w_y = xi^2 (3L - xi) /
(6 EI), w_x = -(y - 0.2) xi (2L - xi) / (2 EI), xi = x - x0, EI = E t^3 / (12 (1 - nu^2))): the
tip deflection that load gives a beam (Betti's theorem), split into the lateral part (f_y) and
the part of the faces' shear (f_x). An FSI1 run also gets u_y(A) and u_y(A) / delta.

    /usr/bin/python3 tools/fsi1_bar_load.py out/cfd1-bar-L2 out/fsi1-L2 [--young 1.4e6]
"""

import argparse
import glob
import sys

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader

X0 = 0.24898979485566356  # the clamp: where the bar meets the cylinder
TIP, THICKNESS, AXIS = 0.6, 0.02, 0.2
LENGTH = TIP - X0
BINS = [0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, LENGTH]


def read_last(folder, series):
    files = sorted(glob.glob(f"{folder}/{series}_*.pvtu"))
    if not files:
        return None
    reader = vtkXMLPUnstructuredGridReader()
    reader.SetFileName(files[-1])
    reader.Update()
    grid = reader.GetOutput()
    data = grid.GetPointData()
    fields = {data.GetArrayName(i): vtk_to_numpy(data.GetArray(i)) for i in range(data.GetNumberOfArrays())}
    points = vtk_to_numpy(grid.GetPoints().GetData())[:, :2]
    # a parallel file repeats the vertices its pieces share: keep each once
    _, first = np.unique(fields["global_id"], return_index=True)
    return points[first], {name: values[first] for name, values in fields.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--young", type=float, default=1.4e6, help="E of the beam [Pa]")
    parser.add_argument("--poisson", type=float, default=0.4)
    arguments = parser.parse_args()
    bending = arguments.young * THICKNESS**3 / (12 * (1 - arguments.poisson**2))
    print("run | F_x, F_y [N/m] | delta: lateral + shear = total [mm] | F_y per 0.05 m from the clamp "
          "[N/m] | u_y(A) [mm] | u_y / delta")
    for run in arguments.runs:
        immersed = read_last(run, "solid")
        if immersed is not None:
            points, fields = immersed
            force = fields["coupling_force"][:, :2]
            tip = np.argmin(np.hypot(points[:, 0] - TIP, points[:, 1] - AXIS))
            u_y = fields["displacement"][tip, 1]
        else:
            flow = read_last(run, "solution")
            if flow is None:
                sys.exit(f"{run}: no solid_*.pvtu or solution_*.pvtu")
            points, fields = flow
            force = fields["reaction"][:, :2]
            on_bar = ((points[:, 0] > X0 - 1e-9) & (points[:, 0] < TIP + 1e-9)
                      & (np.abs(points[:, 1] - AXIS) < THICKNESS / 2 + 1e-9))
            points, force, u_y = points[on_bar], force[on_bar], None
        xi = np.clip(points[:, 0] - X0, 0.0, None)
        w_y = xi**2 * (3 * LENGTH - xi) / (6 * bending)
        w_x = -(points[:, 1] - AXIS) * xi * (2 * LENGTH - xi) / (2 * bending)
        lateral, shear = np.sum(force[:, 1] * w_y), np.sum(force[:, 0] * w_x)
        bins = [force[(xi >= BINS[i] - 1e-9) & ((xi < BINS[i + 1] - 1e-9) | (i == len(BINS) - 2)), 1].sum()
                for i in range(len(BINS) - 1)]
        total = lateral + shear
        tail = f"{u_y * 1e3:.4f} | {u_y / total:.3f}" if u_y is not None else "– | –"
        print(f"{run} | {force[:, 0].sum():.4f}, {force[:, 1].sum():.4f} | {lateral * 1e3:.4f} + "
              f"{shear * 1e3:.4f} = {total * 1e3:.4f} | {' '.join(f'{b:.4f}' for b in bins)} | {tail}")


if __name__ == "__main__":
    main()
