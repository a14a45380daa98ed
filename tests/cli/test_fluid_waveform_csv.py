#!/usr/bin/python3
"""A velocity inlet whose time factor is read from a CSV file (`waveform: {type: csv, file}`,
src/coapt/fluid/fluid_model.cpp) on a small transient 2D channel (unit square, 8 x 8 squares,
plug inflow on the left, no-slip top and bottom, outflow on the right, 6 steps):
 - the CSV file holding the same points as an inline `table` gives the same run bit for bit
   (series.csv identical), on 1 rank and on 2 (with LU on one rank's copy of the matrix,
   `redundant`: MUMPS on 2 ranks is not bitwise reproducible from run to run);
 - the inflow follows the factor: flow_left = -factor(t) x 1 m/s x 7/8 m at every step (the
   plug speed on the inlet's free nodes: the two corner nodes are no-slip), to 1e-12;
 - a CSV row that is not two numbers and a missing file are input errors (exit 2) naming the
   file and line, or the key."""

import csv
import io

from cli_common import DETERMINISTIC_FLUID, Runner, parse_arguments

CASE = """problem: navier_stokes
mesh:
  type: rectangle
  cells: [8, 8]
  level: 0
fluid:
  density: 1.0
  viscosity: 0.05
boundary:
  - {group: left, type: velocity, value: [1.0, 0.0], waveform: WAVEFORM}
  - {group: bottom, type: no_slip}
  - {group: top, type: no_slip}
  - {group: right, type: outflow}
time:
  steady: false
  step: 0.05
  end_time: 0.3
output:
  vtk: false
"""

DETERMINISTIC = ["--", *DETERMINISTIC_FLUID]
TIMES = [0.0, 0.1, 0.2, 0.4]
VALUES = [0.0, 1.0, 0.25, 0.5]


def factor(t):
    for (t0, v0), (t1, v1) in zip(zip(TIMES, VALUES), zip(TIMES[1:], VALUES[1:])):
        if t0 <= t <= t1:
            return v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    return VALUES[-1]


def main():
    r = Runner(parse_arguments())
    table = "{type: table, times: %s, values: %s}" % (TIMES, VALUES)
    (r.work / "pulse.csv").write_text("time,factor   # a small pulse\n" + "".join(
        f"{t}, {v}\n" for t, v in zip(TIMES, VALUES)))
    (r.work / "broken.csv").write_text("time,factor\n0, 0\n0.1; 1\n")
    for name, waveform in [("table", table), ("csv", "{type: csv, file: pulse.csv}"),
                           ("broken", "{type: csv, file: broken.csv}"),
                           ("missing", "{type: csv, file: nowhere.csv}")]:
        (r.work / f"{name}.yaml").write_text(CASE.replace("WAVEFORM", waveform))

    series = {}
    for ranks in (1, 2):
        for name in ("table", "csv"):
            out = r.work / f"{name}-np{ranks}"
            result = r.run("run", r.work / f"{name}.yaml", "--output", out, *DETERMINISTIC,
                           ranks=ranks)
            ok = result.returncode == 0 and (out / "series.csv").is_file()
            r.expect(ok, f"{name} on {ranks} rank(s) runs", result.stdout[-2000:] + result.stderr)
            if ok:
                series[(name, ranks)] = (out / "series.csv").read_text()
        if ("table", ranks) in series and ("csv", ranks) in series:
            r.expect(series[("table", ranks)] == series[("csv", ranks)],
                     f"{ranks} rank(s): the CSV waveform gives the table's run bit for bit")

    if ("csv", 1) in series:
        rows = list(csv.DictReader(io.StringIO(series[("csv", 1)])))
        worst = max(abs(float(row["flow_left"]) + factor(float(row["time"])) * 0.875) for row in rows)
        r.expect(len(rows) == 6 and worst < 1e-12,
                 f"the inflow follows the CSV factor at each of the {len(rows)} steps ({worst:.1e})")

    result = r.run("run", r.work / "broken.yaml", "--output", r.work / "broken-out")
    r.expect(result.returncode == 2 and "broken.csv:3" in result.stderr,
             "a bad CSV row is an input error naming the file and line", result.stderr)
    result = r.run("run", r.work / "missing.yaml", "--output", r.work / "missing-out")
    r.expect(result.returncode == 2 and "waveform.file" in result.stderr and
             "nowhere.csv" in result.stderr, "a missing CSV file is an input error naming the key",
             result.stderr)
    r.finish()


if __name__ == "__main__":
    main()
