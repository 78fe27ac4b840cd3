#!/usr/bin/env python3
"""DFG 2D-3 (John 2004): C_D,max, C_L,max, their times and dp(8) from a probes.csv, with errors.

Usage:
  python3 bench/fluid/dfg_2d3_stats.py OUT/probes.csv [--json OUT/stats.json] [--t-final 8]

The inflow is U_m(t) = 1.5 sin(pi t / 8) on t in [0, 8]. Each maximum is the largest sample,
refined by the parabola through it and its two neighbours (the vertex of that parabola; the
sample itself when the maximum is the first or last row). dp is p_front - p_back at
t = --t-final (8), linearly interpolated between the rows around it. Errors: percent
(v - ref) / |ref| for the values, absolute (t - t_ref) in seconds for the times.
Reference (John 2004, Int. J. Numer. Meth. Fluids 44): C_D,max 2.950921575 at t 3.93625,
C_L,max 0.47795 at t 5.693125, dp(8) -0.1116.

A run that stops before t-final (a smoke run) gets the maxima of what it has, dp at its last
row and no dp error (null in the JSON), with a note on stderr.
"""
import argparse
import csv
import json
import math
import sys

REF = {"cd_max": 2.950921575, "t_cd_max": 3.93625,
       "cl_max": 0.47795, "t_cl_max": 5.693125,
       "dp_final": -0.1116}
COLUMNS = ("time", "fluid.cd", "fluid.cl", "fluid.dp")  # as `fsi run` writes them
T_FINAL = 8.0


class StatsError(Exception):
    """Unreadable input: the message names the file and, where it applies, the column."""


def refined_max(t, y):
    """(t*, y*) of the maximum of the samples y(t): the vertex of the parabola through the
    largest sample and its two neighbours (any spacing); the sample itself at either end or
    when the three points do not bend downwards."""
    if len(t) != len(y) or not y:
        raise ValueError("refined_max: t and y must be non-empty and of equal length")
    i = max(range(len(y)), key=lambda k: y[k])
    if i == 0 or i == len(y) - 1:
        return float(t[i]), float(y[i])
    t0, t1, t2 = t[i - 1], t[i], t[i + 1]
    y0, y1, y2 = y[i - 1], y[i], y[i + 1]
    # Newton form: p(s) = y0 + d1 (s - t0) + d2 (s - t0)(s - t1).
    d1 = (y1 - y0) / (t1 - t0)
    d2 = ((y2 - y1) / (t2 - t1) - d1) / (t2 - t0)
    if not d2 < 0:
        return float(t1), float(y1)
    ts = 0.5 * (t0 + t1) - d1 / (2 * d2)
    ys = y0 + d1 * (ts - t0) + d2 * (ts - t0) * (ts - t1)
    return float(ts), float(ys)


def value_at(t, y, target):
    """y at `target` by linear interpolation; None when target is outside [t[0], t[-1]]."""
    if not t or target < t[0] - 1e-12 or target > t[-1] + 1e-9:
        return None
    for i in range(1, len(t)):
        if t[i] >= target:
            if t[i] == t[i - 1]:
                return float(y[i])
            s = (target - t[i - 1]) / (t[i] - t[i - 1])
            return float(y[i - 1] + s * (y[i] - y[i - 1]))
    return float(y[-1])  # target within rounding of the last time


def read_columns(path, columns=COLUMNS):
    """{column: [floats]} of a probes.csv; StatsError naming the file / column on bad input."""
    try:
        fh = open(path, newline="")
    except OSError as e:
        raise StatsError(f"{path}: cannot open ({e.strerror})")
    with fh:
        reader = csv.DictReader(fh)
        header = reader.fieldnames or []
        missing = [c for c in columns if c not in header]
        if missing:
            raise StatsError(f"{path}: no column {', '.join(missing)} (columns: {', '.join(header) or 'none'})")
        out = {c: [] for c in columns}
        for line, row in enumerate(reader, start=2):
            for c in columns:
                try:
                    out[c].append(float(row[c]))
                except (TypeError, ValueError):
                    raise StatsError(f"{path}: line {line}, column {c}: not a number ({row[c]!r})")
    if not out["time"]:
        raise StatsError(f"{path}: no data rows")
    return out


def percent_error(value, ref):
    """100 (value - ref) / |ref|, None when value is None or not finite."""
    if value is None or not math.isfinite(value):
        return None
    return 100.0 * (value - ref) / abs(ref)


def compute(t, cd, cl, dp, t_final=T_FINAL):
    """Statistics and errors of DFG 2D-3 signals (lists of equal length)."""
    t_cd, cd_max = refined_max(t, cd)
    t_cl, cl_max = refined_max(t, cl)
    complete = t[-1] >= t_final - 1e-9
    dp_time = t_final if complete else t[-1]
    dp_final = value_at(t, dp, dp_time)
    r = {"t_end": t[-1], "t_final": t_final, "complete": complete,
         "cd_max": cd_max, "t_cd_max": t_cd, "cl_max": cl_max, "t_cl_max": t_cl,
         "dp_final": dp_final, "dp_time": dp_time, "reference": dict(REF)}
    r["errors"] = {
        "cd_max_percent": percent_error(cd_max, REF["cd_max"]),
        "t_cd_max": t_cd - REF["t_cd_max"],
        "cl_max_percent": percent_error(cl_max, REF["cl_max"]),
        "t_cl_max": t_cl - REF["t_cl_max"],
        "dp_final_percent": percent_error(dp_final, REF["dp_final"]) if complete else None,
    }
    return r


def stats(path, t_final=T_FINAL):
    """compute() on the columns time, fluid.cd, fluid.cl, fluid.dp of the probes.csv at `path`."""
    c = read_columns(path)
    return compute(c["time"], c["fluid.cd"], c["fluid.cl"], c["fluid.dp"], t_final)


def _fmt(v, spec, suffix=""):
    return "n/a" if v is None else f"{v:{spec}}{suffix}"


def report(r):
    e = r["errors"]
    return "\n".join([
        f"C_D,max {r['cd_max']:.6f} at t {r['t_cd_max']:.5f}   (ref {REF['cd_max']} at {REF['t_cd_max']}: "
        f"{_fmt(e['cd_max_percent'], '+.3f', '%')}, time {e['t_cd_max']:+.5f} s)",
        f"C_L,max {r['cl_max']:.6f} at t {r['t_cl_max']:.5f}   (ref {REF['cl_max']} at {REF['t_cl_max']}: "
        f"{_fmt(e['cl_max_percent'], '+.3f', '%')}, time {e['t_cl_max']:+.5f} s)",
        f"dp({r['dp_time']:g}) {_fmt(r['dp_final'], '.5f')}   (ref dp({r['t_final']:g}) {REF['dp_final']}: "
        f"{_fmt(e['dp_final_percent'], '+.3f', '%')})",
    ])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", help="probes.csv of `fsi run` with columns time, fluid.cd, fluid.cl, fluid.dp")
    ap.add_argument("--json", metavar="OUT", help="write the values and errors here")
    ap.add_argument("--t-final", type=float, default=T_FINAL, help="time of the dp value (default 8)")
    a = ap.parse_args(argv)
    try:
        r = stats(a.csv, a.t_final)
    except StatsError as e:
        print(f"dfg_2d3_stats: {e}", file=sys.stderr)
        return 1
    if not r["complete"]:
        print(f"dfg_2d3_stats: {a.csv}: ends at t = {r['t_end']:g} < {a.t_final:g}: maxima of the rows present, "
              f"dp at the last row, no dp error", file=sys.stderr)
    print(report(r))
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(r, fh, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
