#!/usr/bin/python3
"""Plots the nodal contact pressure of Hertz runs against Johnson's profile
p(r) = p0 sqrt(1 - r^2/b^2), from each run's contact_nodes.csv and summary.json: the nominal
pressure (force per reference area, filled markers) and, for the last run, the pressure per
current area (open markers; docs/verification/contact.md).

    /usr/bin/python3 cases/hertz/plot_hertz.py OUT.png RUN_DIR [RUN_DIR ...]

r is |x| for a cylinder (2D) and sqrt(x^2 + y^2) for a sphere (3D), from the reference
coordinates of the slave nodes."""

import csv
import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    p0 = size = None
    runs = sys.argv[2:]
    for index, run in enumerate(runs):
        run = Path(run)
        summary = json.loads((run / "summary.json").read_text())
        benchmark = summary["benchmark"]
        sphere = "contact_radius" in benchmark
        p0 = benchmark["max_pressure_analytic"]
        size = benchmark["contact_radius_analytic" if sphere else "contact_half_width_analytic"]
        points = []
        with open(run / "contact_nodes.csv") as f:
            for row in csv.DictReader(f):
                if row["constrained"] != "1":
                    continue
                r = math.hypot(float(row["x"]), float(row["y"])) if sphere else abs(float(row["x"]))
                active = row["active"] == "1"
                points.append((r, float(row["nominal_pressure"]) if active else 0.0,
                               float(row["pressure"]) if active else 0.0))
        points.sort()
        label = f"level {benchmark['level']} ({benchmark['cells']} cells)"
        line, = axes.plot([p[0] / size for p in points], [p[1] / p0 for p in points], "o", ms=3,
                          label=label + ", nominal")
        if index == len(runs) - 1:
            axes.plot([p[0] / size for p in points], [p[2] / p0 for p in points], "o", ms=4,
                      mfc="none", color=line.get_color(), alpha=0.6,
                      label=label + ", per current area")
    r = [1.3 * k / 400 for k in range(401)]
    axes.plot(r, [math.sqrt(max(0.0, 1 - x * x)) for x in r], "k-", lw=1, label="Johnson (Hertz)")
    axes.set_xlim(0, 1.3)
    axes.set_xlabel("r / a" if sphere else "x / b")
    axes.set_ylabel("p / p0")
    axes.legend()
    axes.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(sys.argv[1], dpi=120)
    print(f"wrote {sys.argv[1]}")


if __name__ == "__main__":
    main()
