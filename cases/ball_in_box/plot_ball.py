#!/usr/bin/python3
"""Plots ball-in-a-box runs side by side: the barycentre trajectory of the ball inside the box
[0, 200]^2 (left) and the total energy over time relative to its initial value (right), one
line per run, from each run's series.csv and summary.json.

    /usr/bin/python3 cases/ball_in_box/plot_ball.py OUT.png RUN_DIR[=LABEL] [RUN_DIR[=LABEL] ...]
"""

import csv
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    figure, (path, energy) = plt.subplots(1, 2, figsize=(11, 4.8))
    path.add_patch(plt.Rectangle((0, 0), 200, 200, fill=False, color="k", lw=1.5))
    diamond = [(100, 10), (190, 100), (100, 190), (10, 100), (100, 10)]
    path.plot(*zip(*diamond), ":", color="grey", lw=1, label="diamond (45°, ball radius 10)")
    for argument in sys.argv[2:]:
        directory, _, label = argument.partition("=")
        directory = Path(directory)
        summary = json.loads((directory / "summary.json").read_text())
        with open(directory / "series.csv") as f:
            rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
        label = label or summary.get("case", str(directory))
        angles = summary.get("benchmark", {}).get("rebound_angles", [])
        if angles:
            label += " (rebound " + ", ".join(f"{a:.1f}" for a in angles) + "°)"
        x = [row["barycentre_x_ball"] for row in rows]
        y = [row["barycentre_y_ball"] for row in rows]
        path.plot(x, y, lw=1.2, label=label)
        e0 = rows[0]["total_energy"]
        energy.plot([row["time"] for row in rows], [row["total_energy"] / e0 for row in rows], lw=1.2,
                    label=label.split(" (")[0])
    path.set_xlim(-15, 215)
    path.set_ylim(-15, 215)
    path.set_aspect("equal")
    path.set_title("barycentre of the ball")
    path.legend(fontsize=7, loc="center")
    energy.set_xlabel("time")
    energy.set_ylabel("total energy / initial")
    energy.set_title("total energy")
    energy.grid(alpha=0.3)
    energy.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(sys.argv[1], dpi=110)


if __name__ == "__main__":
    main()
