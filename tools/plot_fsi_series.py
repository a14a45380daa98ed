#!/usr/bin/python3
"""Time histories of a transient Turek-Hron FSI run (docs/verification/fsci.md): u_y(A), u_x(A),
lift and drag over time from the series.csv of one run, or of a run and its restarts (folders
in order; where two overlap in time the later folder's rows are kept). With --compare each
folder is a run of its own, drawn as its own curve (labelled by --labels), e.g. one case at
several time steps.

    /usr/bin/python3 tools/plot_fsi_series.py out/fsi2 out/fsi2-more \\
        --title "FSI2, level 0" --output docs/img/fsci_fsi2.png
    /usr/bin/python3 tools/plot_fsi_series.py out/fsi3-2ms out/fsi3-1ms --compare \\
        --labels "dt = 2 ms" "dt = 1 ms" --from 5.0 --output fsi3-dt.png

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
    parser.add_argument("--compare", action="store_true",
                        help="each folder a separate run, drawn as its own curve")
    parser.add_argument("--labels", nargs="+", default=None,
                        help="with --compare: one legend label per folder (default: the folder)")
    parser.add_argument("--from", dest="start", type=float, default=None,
                        help="draw from this time on [s]")
    arguments = parser.parse_args()
    if arguments.labels is not None and (not arguments.compare or
                                         len(arguments.labels) != len(arguments.folders)):
        parser.error("--labels needs --compare and one label per folder")

    def read(folder, rows):
        path = folder / "series.csv"
        if not path.is_file():
            parser.error(f"{path}: no such file")
        with open(path) as f:
            for row in csv.DictReader(f):
                time = float(row["time"])
                if arguments.start is None or time >= arguments.start:
                    rows[time] = row
        return rows

    if arguments.compare:
        labels = arguments.labels or [str(folder) for folder in arguments.folders]
        curves = [(label, read(folder, {})) for label, folder in zip(labels, arguments.folders)]
    else:
        rows = {}
        for folder in arguments.folders:
            read(folder, rows)
        curves = [(None, rows)]
    for label, rows in curves:
        if not rows:
            parser.error(f"{label or 'the run'}: no rows from t = {arguments.start} s on")
    prefix = f"{arguments.solid}_{arguments.probe}"
    panels = [(f"{prefix}_uy", "u_y(A) [mm]", 1e3), (f"{prefix}_ux", "u_x(A) [mm]", 1e3),
              ("lift", "lift [N/m]", 1.0), ("drag", "drag [N/m]", 1.0)]
    for label, rows in curves:
        first = rows[min(rows)]
        missing = [key for key, _, _ in panels if key not in first]
        if missing:
            parser.error(f"{label or 'series.csv'} has no column {', '.join(missing)}")
    figure, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(9, 9))
    for axis, (key, label, scale) in zip(axes, panels):
        for name, rows in curves:
            times = sorted(rows)
            axis.plot(times, [scale * float(rows[t][key]) for t in times], linewidth=0.6,
                      label=name)
        axis.set_ylabel(label)
        axis.grid(True, linewidth=0.3)
    if arguments.compare:
        axes[0].legend(loc="upper left", fontsize="small")
    axes[-1].set_xlabel("t [s]")
    if arguments.title:
        axes[0].set_title(arguments.title)
    figure.tight_layout()
    figure.savefig(arguments.output, dpi=110)
    for name, rows in curves:
        print(f"wrote {arguments.output}: {name + ': ' if name else ''}{len(rows)} steps, "
              f"t = {min(rows):g} to {max(rows):g} s")


if __name__ == "__main__":
    main()
