#!/usr/bin/python3
"""Convergence study of the finite-element core (manufactured solutions, Poisson and linear
elasticity, 2D and 3D): runs `coapt run` on successive levels with a direct solver, prints
the errors and rates, draws docs/img/fem_convergence.png and rewrites the FEM section of
docs/verification.md.

    /usr/bin/python3 tools/verify_fem.py --coapt build/coapt --levels 5 --report docs/verification.md
"""

import argparse
import json
import math
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CASES = [("poisson", "mms2d"), ("poisson", "mms3d"), ("elasticity", "mms2d"), ("elasticity", "mms3d")]
BEGIN, END = "<!-- fem:begin -->", "<!-- fem:end -->"


def run_level(coapt, problem, name, level, ranks, work):
    out = work / f"{problem}-{name}-L{level}"
    prefix = f"-{problem}_"
    command = ["mpirun", "--oversubscribe", "--bind-to", "none", "-np", str(ranks), coapt, "run",
               str(ROOT / "cases" / problem / f"{name}.yaml"), "--output", str(out),
               "--set", f"mesh.level={level}", "--set", "output.vtk=false", "--", prefix + "ksp_rtol", "1e-12"]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1")
    subprocess.run(command, check=True, capture_output=True, env=env)
    return json.loads((out / "summary.json").read_text())["benchmark"]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--coapt", default=str(ROOT / "build" / "coapt"))
    parser.add_argument("--levels", type=int, default=5, help="levels in 2D")
    parser.add_argument("--levels-3d", type=int, default=4, help="levels in 3D")
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--work", default=str(ROOT / "out" / "verify-fem"))
    parser.add_argument("--report", default=str(ROOT / "docs" / "verification.md"))
    args = parser.parse_args()
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)

    results = {}
    for problem, name in CASES:
        rows = []
        for level in range(args.levels if name.endswith("2d") else args.levels_3d):
            b = run_level(args.coapt, problem, name, level, args.ranks, work)
            rows.append((level, b["cells"], b["h"], b["l2_error"], b["h1_error"]))
            print(f"{problem} {name} level {level}: cells {b['cells']}  h {b['h']:.4e}  "
                  f"L2 {b['l2_error']:.6e}  H1 {b['h1_error']:.6e}", flush=True)
        results[(problem, name)] = rows

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for (problem, name), rows in results.items():
        h = [r[2] for r in rows]
        axes[0].loglog(h, [r[3] for r in rows], "o-", label=f"{problem} {name[-2:]}")
        axes[1].loglog(h, [r[4] for r in rows], "o-", label=f"{problem} {name[-2:]}")
    for axis, title, order in ((axes[0], "L2 error", 2), (axes[1], "H1 seminorm error", 1)):
        h = [r[2] for r in next(iter(results.values()))]
        axis.loglog(h, [0.5 * (x / h[0]) ** order for x in h], "k--", label=f"slope {order}")
        axis.set_xlabel("h (longest edge) [m]")
        axis.set_title(title)
        axis.grid(True, which="both", alpha=0.3)
        axis.legend(fontsize=8)
    figure.tight_layout()
    image = ROOT / "docs" / "img" / "fem_convergence.png"
    image.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(image, dpi=110)

    lines = [BEGIN, "", "### Manufactured solutions (Poisson, linear elasticity)", "",
             f"Command: `/usr/bin/python3 tools/verify_fem.py --levels {args.levels} --levels-3d {args.levels_3d} --ranks {args.ranks}` "
             "(CG + GAMG to a relative residual of 1e-12; each level halves h).", "",
             "| case | level | cells | h [m] | L2 error | L2 rate | H1 error | H1 rate |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for (problem, name), rows in results.items():
        for i, (level, cells, h, l2, h1) in enumerate(rows):
            if i == 0:
                rates = ("", "")
            else:
                _, _, h0, l20, h10 = rows[i - 1]
                rates = (f"{math.log(l20 / l2) / math.log(h0 / h):.3f}", f"{math.log(h10 / h1) / math.log(h0 / h):.3f}")
            lines.append(f"| {problem} {name} | {level} | {cells} | {h:.4e} | {l2:.4e} | {rates[0]} | {h1:.4e} | {rates[1]} |")
    lines += ["", "![convergence](img/fem_convergence.png)", "", END]
    report = Path(args.report)
    text = report.read_text() if report.exists() else "# Verification\n\n" + BEGIN + "\n" + END + "\n"
    if BEGIN in text and END in text:
        text = text[: text.index(BEGIN)] + "\n".join(lines) + text[text.index(END) + len(END):]
    else:
        text += "\n" + "\n".join(lines) + "\n"
    report.write_text(text)
    print(f"wrote {report} and {image}")


if __name__ == "__main__":
    sys.exit(main())
