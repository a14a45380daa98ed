#!/usr/bin/python3
"""Last-period statistics of the immersed `forces` benchmark (benchmark.statistics_from,
coupling/fsci_problem.cpp forces_statistics), on a short transient run of the Turek-Hron FSI3
set-up (cases/turek_hron/fsi3.yaml, level 0, IQN-ILS as in the case) made cheap: a pulsating
inflow (peak 0.3 m/s times 1 + 0.5 sin(2πt/0.04 s), ramped up over 0.02 s) and the bar 1000
times stiffer (E = 5.6e9 Pa), so that drag, lift and the displacement of A oscillate at 25 Hz
from the first steps on; 80 steps of 2 ms, statistics from t = 0.03 s.
 - the run completes and summary.json -> benchmark holds drag, lift, displacement_x,
   displacement_y as {mean, amplitude, frequency, periods, final};
 - each of them equals, to 1e-9 relative, the statistics recomputed here from series.csv
   (the rows from statistics_from on) by the documented rule: periods between successive
   upward crossings of the record's mid-level with hysteresis a quarter of its range (the
   range without its ⌊(n − 1)/100⌋ largest and smallest samples: none on these 66 rows), the
   last full period's largest and smallest samples refined by a parabola through their
   neighbours; mean = (max + min)/2, amplitude = (max − min)/2, frequency = 1/period;
 - drag and displacement_x complete at least two full periods, at 25 Hz to 1 % (the
   statistics are not empty, and they are of the forcing; lift and displacement_y, with a
   slow drift of the mean, need not: displacement_y has no full period by the rule);
 - the relative errors against references given with --set are |value/reference − 1|;
 - a run of 40 steps writing a checkpoint, restarted to 80 steps, gives the same statistics
   to 1e-6 relative (the history of the statistics comes back from the checkpoint; not bit
   for bit: the restarted run's time is the checkpoint's, 0.082 s at step 41 against the
   straight run's summed 0.082000000000000059 s, and the coupling, stopping at a relative
   change of 1e-4, carries that round-off of the inflow to about 1e-8 in the lift);
 - statistics_from in a steady run is refused with one error line naming the key."""

import math

from cli_common import (DETERMINISTIC_FLUID, DETERMINISTIC_SOLID, Runner, parse_arguments,
                        run_with_series)

DIRECT = ["--", *DETERMINISTIC_FLUID, *DETERMINISTIC_SOLID]
START = 0.03  # s: statistics_from
CHEAP = ["--set", "output.vtk=false", "--set", "fluid.boundary[2].value=[0.3, 0]",
         "--set", "fluid.boundary[2].ramp_time=0.02",
         "--set", "fluid.boundary[2].waveform={type: sinusoid, amplitude: 0.5, period: 0.04}",
         "--set", "solids[0].bodies[0].material.young_modulus=5.6e9",
         "--set", "solids[0].newton.absolute_tolerance=1e-5",  # the stiff bar's round-off floor
         "--set", "time.step=0.002", "--set", f"benchmark.statistics_from={START}"]
COLUMNS = {"drag": "drag", "lift": "lift", "displacement_x": "bar_A_ux",
           "displacement_y": "bar_A_uy"}


def parabola_vertex(t, y, i):
    """The vertex value of the parabola through samples i−1, i, i+1 (kept within them)."""
    h0, h2 = t[i - 1] - t[i], t[i + 1] - t[i]
    s0, s2 = (y[i - 1] - y[i]) / h0, (y[i + 1] - y[i]) / h2
    c = (s2 - s0) / (h2 - h0)
    b = s0 - c * h0
    if c == 0 or not math.isfinite(c):
        return y[i]
    shift = min(max(-b / (2 * c), h0), h2)
    return y[i] + b * shift + c * shift * shift


def last_period(t, y):
    """(mean, amplitude, frequency, periods) of the last full period, None's if there is none."""
    if len(t) < 5:
        return None, None, None, 0
    ordered = sorted(value for value in y if math.isfinite(value))
    if len(ordered) < 5:
        return None, None, None, 0
    set_aside = (len(ordered) - 1) // 100  # a one- or two-step spike must not set the level
    top, bottom = ordered[-1 - set_aside], ordered[set_aside]
    level, band = 0.5 * (top + bottom), 0.25 * (top - bottom)
    if not band > 0:
        return None, None, None, 0
    crossings, index, armed = [], [], False
    for i in range(len(t)):
        if y[i] < level - band:
            armed = True
        if armed and i > 0 and y[i - 1] < level <= y[i]:
            crossings.append(t[i - 1] + (level - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]))
            index.append(i)
            armed = False
    if len(crossings) < 2:
        return None, None, None, 0
    window = range(index[-2] - 1, index[-1] + 1)
    highest = max(window, key=lambda i: y[i])
    lowest = min(window, key=lambda i: y[i])
    refined = [parabola_vertex(t, y, i) if 0 < i < len(t) - 1 else y[i] for i in (highest, lowest)]
    return (0.5 * (refined[0] + refined[1]), 0.5 * (refined[0] - refined[1]),
            1 / (crossings[-1] - crossings[-2]), len(crossings) - 1)


def close(a, b, tolerance=1e-9):
    if a is None or b is None:
        return a is None and b is None
    return abs(a - b) <= tolerance * max(abs(a), abs(b), 1e-300)


def main():
    arguments = parse_arguments()
    runner = Runner(arguments)
    case = runner.source / "cases" / "turek_hron" / "fsi3.yaml"
    reference = {"drag": 400.0, "lift_amplitude": 10.0, "displacement_x_frequency": 20.0}
    given = [a for key, value in reference.items() for a in ("--set", f"benchmark.reference.{key}={value}")]
    summary, rows = run_with_series(runner, case, "straight", *CHEAP, "--set", "time.end_time=0.16",
                                    *given, *DIRECT)
    if summary is None:
        runner.finish()
    benchmark = summary["benchmark"]
    recorded = [row for row in rows if row["time"] >= START]
    times = [row["time"] for row in recorded]
    for key, column in COLUMNS.items():
        entry = benchmark.get(key, {})
        values = [row[column] for row in recorded]
        mean, amplitude, frequency, periods = last_period(times, values)
        print(f"{key}: mean {entry.get('mean')}, amplitude {entry.get('amplitude')}, frequency "
              f"{entry.get('frequency')} Hz, {entry.get('periods')} period(s); recomputed {mean}, "
              f"{amplitude}, {frequency}, {periods}")
        runner.expect(isinstance(entry, dict) and close(entry.get("mean"), mean)
                      and close(entry.get("amplitude"), amplitude)
                      and close(entry.get("frequency"), frequency) and entry.get("periods") == periods
                      and entry.get("final") == values[-1],
                      f"{key}: the benchmark's last-period statistics are those of series.csv")
    for key in ("drag", "displacement_x"):
        entry = benchmark.get(key, {})
        runner.expect(entry.get("periods", 0) >= 2 and abs(entry["frequency"] / 25 - 1) < 0.01,
                      f"{key}: at least 2 full periods after statistics_from, at 25 Hz to 1 %")
    for key, value in reference.items():
        quantity, _, statistic = key.rpartition("_") if key != "drag" else ("drag", "", "mean")
        entry = benchmark.get(quantity, {})
        expected = abs(entry[statistic] / value - 1) if entry.get(statistic) is not None else None
        runner.expect(close(entry.get(f"{statistic}_error"), expected),
                      f"{quantity}: {statistic}_error = |{statistic}/reference - 1| "
                      f"({entry.get(f'{statistic}_error')})")

    first, _ = run_with_series(runner, case, "first", *CHEAP, "--set", "time.end_time=0.08", *given,
                               "--set", "output.checkpoint_interval=40", *DIRECT)
    if first is not None:
        again, _ = run_with_series(runner, case, "again", *CHEAP, "--set", "time.end_time=0.16",
                                   *given, "--restart", runner.work / "first", *DIRECT)
        if again is not None:
            a = {key: benchmark[key] for key in COLUMNS}
            b = {key: again["benchmark"].get(key, {}) for key in COLUMNS}
            same = all(close(a[key].get(k), b[key].get(k), 1e-6) for key in COLUMNS
                       for k in ("mean", "amplitude", "frequency", "final"))
            same = same and all(a[key]["periods"] == b[key].get("periods") for key in COLUMNS)
            runner.expect(same, "restarted at step 40: the same statistics as the straight run",
                          f"{a}\n{b}")

    steady = runner.run("run", runner.source / "cases" / "turek_hron" / "fsi1.yaml", "--output",
                        runner.work / "steady", "--set", "benchmark.statistics_from=1")
    errors = [line for line in steady.stderr.splitlines() if "error:" in line]
    runner.expect(steady.returncode == 2 and len(errors) == 1 and "statistics_from" in errors[0],
                  "statistics_from in a steady run is refused naming the key",
                  steady.stdout + steady.stderr)
    runner.finish()


if __name__ == "__main__":
    main()
