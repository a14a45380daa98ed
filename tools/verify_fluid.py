#!/usr/bin/python3
"""Verification runs of the fluid benchmark cases documented in docs/verification/fluid.md:
Turek-Hron CFD1-3 (body-fitted rigid cylinder and bar), DFG 2D-2 and the Re = 1000 cavity.
Runs `coapt run` on the listed levels (a direct solver, output.vtk off), prints one table row
per run with the wall time, and draws

  docs/img/fluid_periodic.png   c_D(t), c_L(t) of 2D-2 and drag(t), lift(t) of CFD3 (last runs)
  docs/img/fluid_cavity1000.png the Re = 1000 centreline profiles, one line per level

    /usr/bin/python3 tools/verify_fluid.py --coapt build/coapt              # all (about 1 h here)
    /usr/bin/python3 tools/verify_fluid.py --coapt build/coapt --quick      # coarse levels only
    /usr/bin/python3 tools/verify_fluid.py --coapt build/coapt --only cfd1 cfd2

Existing output folders are reused (--rerun to run again), so the plots can be redrawn from
earlier runs. The published values are those of ../shared/refs/benchmarks.md (CFD1, CFD2);
2D-2, CFD3 and the Re = 1000 table are held back there, so only the computed values are shown.
"""

import argparse
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# name -> (case file, levels, quick levels, ranks)
# (one rank: on the shared 2-core machine these 2D meshes gain little from a second one)
RUNS = {
    "cfd1": ("cases/turek_hron/cfd1.yaml", [0, 1, 2, 3], [0, 1], 1),
    "cfd2": ("cases/turek_hron/cfd2.yaml", [0, 1, 2, 3], [0, 1], 1),
    "cavity1000": ("cases/cavity/re1000.yaml", [0, 1, 2, 3], [0, 1], 1),
    "dfg2d2": ("cases/dfg/2d2.yaml", [0, 1], [0], 1),
    "cfd3": ("cases/turek_hron/cfd3.yaml", [0], [0], 1),
}


def run(coapt, name, level, ranks, work, rerun):
    case = RUNS[name][0]
    out = work / f"{name}-L{level}"
    if rerun or not (out / "summary.json").is_file():
        command = ["mpirun", "--oversubscribe", "--bind-to", "none", "-np", str(ranks), coapt, "run",
                   str(ROOT / case), "--output", str(out), "--set", f"mesh.level={level}",
                   "--set", "output.vtk=false", "--", "-fluid_ksp_type", "preonly", "-fluid_pc_type", "lu",
                   "-fluid_pc_factor_mat_solver_type", "mumps"]
        env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1")
        start = time.monotonic()
        subprocess.run(command, check=True, capture_output=True, env=env)
        (out / "elapsed.txt").write_text(f"{time.monotonic() - start:.1f}\n")
    summary = json.loads((out / "summary.json").read_text())
    elapsed = (out / "elapsed.txt").read_text().strip() if (out / "elapsed.txt").is_file() else "?"
    return summary["benchmark"], summary, elapsed, out


def fmt(x, digits=6):
    return "–" if x is None else f"{x:.{digits}g}"


def row(name, level, b, summary, elapsed):
    cells = b["cells"]
    wall = f"{elapsed} s / {summary.get('wall_time_seconds', 0):.1f} s"
    if name in ("cfd1", "cfd2"):
        return (f"| {name} | {level} | {cells} | {fmt(b['drag'], 7)} | {100 * b['drag_error']:.3f} % | "
                f"{fmt(b['lift'], 6)} | {100 * b['lift_error']:.2f} % | {wall} |")
    if name == "cavity1000":
        return (f"| {level} | {cells} | {b['u_min']:.5f} | {b['u_min_y']:.4f} | {b['v_max']:.5f} | "
                f"{b['v_max_x']:.4f} | {b['v_min']:.5f} | {b['v_min_x']:.4f} | {wall} |")
    if name == "dfg2d2":
        lift = b["lift_coefficient"]
        return (f"| {level} | {cells} | {fmt(b['drag_coefficient_max'])} | {fmt(b['lift_coefficient_max'])} | "
                f"{fmt(b['strouhal'])} | {lift['periods']} | {wall} |")
    drag, lift = b["drag"], b["lift"]
    return (f"| {level} | {cells} | {fmt(drag['mean'])} ± {fmt(drag['amplitude'], 4)} [{fmt(drag['frequency'], 4)}] | "
            f"{fmt(lift['mean'], 4)} ± {fmt(lift['amplitude'], 5)} [{fmt(lift['frequency'], 4)}] | {wall} |")


def read_columns(path, names):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [[float(r[n]) for r in rows] for n in names]


def plot(outputs, img):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    periodic = [(n, o) for n, o in outputs if n in ("dfg2d2", "cfd3")]
    if periodic:
        figure, axes = plt.subplots(len(periodic), 2, figsize=(11, 3.2 * len(periodic)), squeeze=False)
        for k, (name, out) in enumerate(periodic):
            columns = ("drag_coefficient", "lift_coefficient") if name == "dfg2d2" else ("drag", "lift")
            t, drag, lift = read_columns(out / "series.csv", ("time",) + columns)
            start = max(0.0, t[-1] - 1.0)
            keep = [i for i, x in enumerate(t) if x >= start]
            for j, (values, label) in enumerate(((drag, columns[0]), (lift, columns[1]))):
                axes[k][j].plot([t[i] for i in keep], [values[i] for i in keep])
                axes[k][j].set_xlabel("t [s]")
                unit = "" if name == "dfg2d2" else " [N/m]"
                axes[k][j].set_title(f"{'DFG 2D-2' if name == 'dfg2d2' else 'Turek-Hron CFD3'}, {out.name}: "
                                     f"{label}{unit}")
                axes[k][j].grid(True, alpha=0.3)
        figure.tight_layout()
        figure.savefig(img / "fluid_periodic.png", dpi=110)
        print(f"wrote {img / 'fluid_periodic.png'}")

    cavity = [o for n, o in outputs if n == "cavity1000"]
    if cavity:
        figure, axes = plt.subplots(1, 2, figsize=(11, 4.5))
        for out in cavity:
            y, u = read_columns(out / "centreline_u.csv", ("y", "u"))
            x, v = read_columns(out / "centreline_v.csv", ("x", "v"))
            axes[0].plot(u, y, label=out.name)
            axes[1].plot(x, v, label=out.name)
        axes[0].set_xlabel("u(0.5, y)")
        axes[0].set_ylabel("y")
        axes[1].set_xlabel("x")
        axes[1].set_ylabel("v(x, 0.5)")
        for a in axes:
            a.grid(True, alpha=0.3)
            a.legend()
        figure.suptitle("Lid-driven cavity, Re = 1000: centreline profiles per level")
        figure.tight_layout()
        figure.savefig(img / "fluid_cavity1000.png", dpi=110)
        print(f"wrote {img / 'fluid_cavity1000.png'}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--coapt", default=str(ROOT / "build" / "coapt"))
    parser.add_argument("--work", default=str(ROOT / "out" / "verify-fluid"))
    parser.add_argument("--img", default=str(ROOT / "docs" / "img"))
    parser.add_argument("--only", nargs="*", choices=sorted(RUNS), help="these cases only")
    parser.add_argument("--quick", action="store_true", help="the coarse levels only")
    parser.add_argument("--rerun", action="store_true", help="run again even where a summary exists")
    args = parser.parse_args()
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    outputs = []
    for name, (case, levels, quick, ranks) in RUNS.items():
        if args.only and name not in args.only:
            continue
        for level in quick if args.quick else levels:
            b, summary, elapsed, out = run(args.coapt, name, level, ranks, work, args.rerun)
            print(row(name, level, b, summary, elapsed), flush=True)
            outputs.append((name, out))
    # The finest run of each case goes into the plots (all levels for the cavity).
    finest = {}
    for name, out in outputs:
        finest[name] = out
    plot([(n, o) for n, o in outputs if n == "cavity1000"] +
         [(n, o) for n, o in finest.items() if n != "cavity1000"], Path(args.img))
    return 0


if __name__ == "__main__":
    sys.exit(main())
