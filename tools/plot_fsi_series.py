#!/usr/bin/python3
"""Time histories of a transient Turek-Hron FSI run (docs/verification/fsci.md): u_y(A), u_x(A),
lift and drag over time from the series.csv of one run, or of a run and its restarts (folders
in order; where two overlap in time the later folder's rows are kept).

    /usr/bin/python3 tools/plot_fsi_series.py out/fsi2 out/fsi2-more \\
        --title "FSI2, level 0" --output docs/img/fsci_fsi2.png

The solid and probe names are those of cases/turek_hron/fsi*.yaml (`bar`, `A`); --solid and
--probe change them."""

import argparse
import csv
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", type=Path, help="run output folders, in time order")
    parser.add_argument("--output", type=Path, required=True, help="the PNG to write")
    parser.add_argument("--title", default="")
    parser.add_argument("--solid", default="bar")
    parser.add_argument("--probe", default="A")
    arguments = parser.parse_args()

    rows = {}
    for folder in arguments.folders:
        path = folder / "series.csv"
        if not path.is_file():
            parser.error(f"{path}: no such file")
        with open(path) as f:
            for row in csv.DictReader(f):
                rows[float(row["time"])] = row
    times = sorted(rows)
    prefix = f"{arguments.solid}_{arguments.probe}"
    panels = [(f"{prefix}_uy", "u_y(A) [mm]", 1e3), (f"{prefix}_ux", "u_x(A) [mm]", 1e3),
              ("lift", "lift [N/m]", 1.0), ("drag", "drag [N/m]", 1.0)]
    missing = [key for key, _, _ in panels if key not in rows[times[0]]]
    if missing:
        parser.error(f"series.csv has no column {', '.join(missing)}")
    figure, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(9, 9))
    for axis, (key, label, scale) in zip(axes, panels):
        axis.plot(times, [scale * float(rows[t][key]) for t in times], linewidth=0.6)
        axis.set_ylabel(label)
        axis.grid(True, linewidth=0.3)
    axes[-1].set_xlabel("t [s]")
    if arguments.title:
        axes[0].set_title(arguments.title)
    figure.tight_layout()
    figure.savefig(arguments.output, dpi=110)
    print(f"wrote {arguments.output} ({len(times)} steps, t = {times[0]:g} to {times[-1]:g} s)")


if __name__ == "__main__":
    main()
