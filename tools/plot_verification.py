#!/usr/bin/python3
"""Convergence plots of the solid and fluid verification cases (docs/verification/solid.md and
fluid.md): relative error against the published value vs number of cells, log-log, one line
per benchmark quantity. The numbers come from the `summary.json` of `coapt run` output folders,
so the plots can be redrawn from any set of runs without re-running anything.

1. Run the levels, one output folder per case and level (any folder names; the case is read
   from summary.json -> case, the level from benchmark.level or the `--set mesh.level=N` of
   summary.json -> command), e.g.

       for l in 0 1 2 3; do
         OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \\
         mpirun --oversubscribe --bind-to none -np 2 build/coapt run cases/cook/linear.yaml \\
           --output /tmp/verif/cooklin-L$l --set mesh.level=$l --set output.vtk=false
       done

   likewise cases/cook/neohookean.yaml, cases/turek_hron/csm1.yaml, csm2.yaml (solid) and
   cases/dfg/2d1.yaml, cases/cavity/re100.yaml (fluid); the levels used in the documents are
   listed there with their commands.

2. Draw the plots (and print the tables) from the folders under one or more roots:

       /usr/bin/python3 tools/plot_verification.py /tmp/verif

   writes docs/img/solid_convergence.png and docs/img/fluid_convergence.png (`--img DIR` to
   write elsewhere). If several folders hold the same case and level, the newest one is used.
   The printed tables also give summary.json -> wall_time_seconds, which leaves out building
   the mesh (Gmsh meshing of .geo files runs before the clock starts).

Relative error = |value - reference| / |reference|, with the references of the documents
(Cook linear 23.96 at (48, 52); Cook Neo-Hookean 14.33 mm; Turek-Hron CSM1/CSM2 u(A); DFG 2D-1
c_D, c_L, dp from Nabh 1998). For the cavity the plotted quantity is the max centreline error
against Ghia et al. (1982), which is already relative to the lid speed 1.
"""

import argparse
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# case file -> list of (label, benchmark key, reference); reference None: the key is the error.
SOLID = {
    "cases/cook/linear.yaml": [("Cook linear, u_y(48, 52)", "mid_edge_displacement_y", 23.96)],
    "cases/cook/neohookean.yaml": [("Cook Neo-Hookean slab, u_y(48, 60)", "tip_displacement_y", 14.33e-3)],
    "cases/cook/neohookean_plane_strain.yaml": [
        ("Cook Neo-Hookean plane strain, u_y(48, 60)", "tip_displacement_y", 14.33e-3)],
    "cases/turek_hron/csm1.yaml": [("CSM1, u_x(A)", "A_displacement_x", -7.187e-3),
                                   ("CSM1, u_y(A)", "A_displacement_y", -66.10e-3)],
    "cases/turek_hron/csm2.yaml": [("CSM2, u_x(A)", "A_displacement_x", -0.4690e-3),
                                   ("CSM2, u_y(A)", "A_displacement_y", -16.97e-3)],
}
FLUID = {
    "cases/dfg/2d1.yaml": [("DFG 2D-1, c_D", "drag_coefficient", 5.57953523384),
                           ("DFG 2D-1, c_L", "lift_coefficient", 0.010618948146),
                           ("DFG 2D-1, Δp", "pressure_difference", 0.11752016697)],
    "cases/cavity/re100.yaml": [("cavity Re 100, max |u - u_Ghia|", "max_error_u", None),
                                ("cavity Re 100, max |v - v_Ghia|", "max_error_v", None)],
}


def case_key(case):
    """Normalise summary.json -> case to 'cases/...yaml' (it may be absolute or relative)."""
    text = str(case).replace("\\", "/")
    index = text.rfind("cases/")
    return text[index:] if index >= 0 else text


def level_of(summary):
    benchmark = summary.get("benchmark", {})
    if "level" in benchmark:
        return int(benchmark["level"])
    match = re.search(r"mesh\.level=(\d+)", summary.get("command", ""))
    return int(match.group(1)) if match else 0


def collect(roots):
    """{case: {level: (summary, folder)}}, the newest folder per case and level."""
    found = {}
    for root in roots:
        for path in sorted(Path(root).glob("**/summary.json")):
            try:
                summary = json.loads(path.read_text())
            except (OSError, ValueError):
                continue
            if summary.get("status", "completed") != "completed" or "benchmark" not in summary:
                continue
            key, level = case_key(summary.get("case", "")), level_of(summary)
            previous = found.setdefault(key, {}).get(level)
            if previous is None or path.stat().st_mtime >= previous[1].stat().st_mtime:
                found[key][level] = (summary, path)
    return found


def series(found, cases):
    """[(case, label, [(level, cells, value, error, wall, folder, ranks, beyond)])]."""
    out = []
    for case, quantities in cases.items():
        levels = found.get(case, {})
        if not levels:
            print(f"warning: no completed run of {case}", file=sys.stderr)
            continue
        for label, key, reference in quantities:
            rows = []
            for level in sorted(levels):
                summary, path = levels[level]
                benchmark = summary["benchmark"]
                if key not in benchmark:
                    continue
                value = benchmark[key]
                error = abs(value) if reference is None else abs(value - reference) / abs(reference)
                rows.append((level, int(benchmark.get("cells", 0)), value, error,
                             summary.get("wall_time_seconds"), path.parent, summary.get("ranks")))
            # levels whose value lies beyond the reference (the error changed sign since the
            # coarsest level): marked with "*" in the plot
            if reference is not None and rows:
                first = rows[0][2] - reference
                rows = [row + ((row[2] - reference) * first < 0,) for row in rows]
            else:
                rows = [row + (False,) for row in rows]
            out.append((case, label, rows))
    return out


def plot(data, title, image):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(7.5, 5.2))
    markers = "osD^v<>ph*"
    for index, (_, label, rows) in enumerate(data):
        if not rows:
            continue
        axis.loglog([r[1] for r in rows], [r[3] for r in rows], marker=markers[index % len(markers)],
                    label=label)
        for row in rows:
            axis.annotate(str(row[0]) + ("*" if row[7] else ""), (row[1], row[3]), textcoords="offset points", xytext=(3, 3),
                          fontsize=7, alpha=0.7)
    axis.set_xlabel("number of cells")
    axis.set_ylabel("relative error |value − reference| / |reference|")
    axis.set_title(title + " (labels: mesh level; *: beyond the reference)", fontsize=10)
    axis.grid(True, which="both", alpha=0.3)
    axis.legend(fontsize=8)
    figure.tight_layout()
    image.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(image, dpi=110)
    plt.close(figure)
    print(f"wrote {image}")


def print_table(data):
    for case, label, rows in data:
        print(f"\n{label}  ({case})")
        print("| level | cells | value | error | wall_time_seconds (no meshing) | ranks | folder |")
        print("|---|---|---|---|---|---|---|")
        for level, cells, value, error, wall, folder, ranks, beyond in rows:
            wall_text = f"{wall:.3g}" if wall is not None else "?"
            print(f"| {level} | {cells} | {value:.8g} | {error:.3e}{' (beyond)' if beyond else ''} "
                  f"| {wall_text} | {ranks} | {folder} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("roots", nargs="*", default=["/tmp/verif"],
                        help="folders searched (recursively) for summary.json files")
    parser.add_argument("--img", default=str(ROOT / "docs" / "img"), help="where the PNG files go")
    args = parser.parse_args()
    found = collect(args.roots)
    if not found:
        print(f"no summary.json under {args.roots}", file=sys.stderr)
        return 1
    image_dir = Path(args.img)
    for cases, name, title in ((SOLID, "solid_convergence.png", "Solid verification"),
                               (FLUID, "fluid_convergence.png", "Fluid verification")):
        data = series(found, cases)
        print_table(data)
        if any(rows for _, _, rows in data):
            plot(data, title, image_dir / name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
