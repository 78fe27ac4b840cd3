#!/usr/bin/env python3
"""Mean, amplitude, extrema and frequency of periodic probe signals (DFG 2D-2, CFD3).

Usage:
  python3 bench/fluid/periodic_stats.py OUT/probes.csv --columns cd cl --window 1.0 \
      [--strouhal-scale 0.1] [--json OUT/stats.json]

Uses the last `window` seconds; the frequency comes from the upward mean crossings
(linearly interpolated) of each column; amplitude = (max - min) / 2 over whole periods.
"""
import argparse
import csv
import json
import sys


def crossings(t, y, level):
    out = []
    for i in range(1, len(y)):
        if y[i - 1] < level <= y[i]:
            s = (level - y[i - 1]) / (y[i] - y[i - 1])
            out.append(t[i - 1] + s * (t[i] - t[i - 1]))
    return out


def stats(t, y):
    mean = sum(y) / len(y)
    up = crossings(t, y, mean)
    if len(up) < 3:
        return {"mean": mean, "max": max(y), "min": min(y), "amplitude": (max(y) - min(y)) / 2,
                "frequency": float("nan"), "periods": max(0, len(up) - 1)}
    # restrict to whole periods
    sel = [(ti, yi) for ti, yi in zip(t, y) if up[0] <= ti <= up[-1]]
    ys = [p[1] for p in sel]
    mean = sum(ys) / len(ys)
    freq = (len(up) - 1) / (up[-1] - up[0])
    return {"mean": mean, "max": max(ys), "min": min(ys), "amplitude": (max(ys) - min(ys)) / 2,
            "frequency": freq, "periods": len(up) - 1}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--columns", nargs="+", default=["cd", "cl"])
    ap.add_argument("--window", type=float, default=1.0)
    ap.add_argument("--strouhal-scale", type=float, default=0.0, help="D / U_bar: St = f * scale")
    ap.add_argument("--json")
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.csv)))
    t = [float(r["time"]) for r in rows]
    t_end = t[-1]
    result = {"t_end": t_end, "window": a.window}
    for c in a.columns:
        pts = [(ti, float(r[c])) for ti, r in zip(t, rows) if ti >= t_end - a.window]
        s = stats([p[0] for p in pts], [p[1] for p in pts])
        if a.strouhal_scale:
            s["strouhal"] = s["frequency"] * a.strouhal_scale
        result[c] = s
        print(f"{c:>6}: mean {s['mean']:.6g}  amplitude {s['amplitude']:.6g}  max {s['max']:.6g}  "
              f"min {s['min']:.6g}  frequency {s['frequency']:.5g} Hz ({s['periods']} periods)"
              + (f"  St {s['strouhal']:.5f}" if a.strouhal_scale else ""))
    if "cl" in a.columns and "dp" in a.columns and result["cl"]["frequency"] == result["cl"]["frequency"]:
        # DFG 2D-2: dp at t0 + 1/(2f), t0 = time of the last complete C_L maximum.
        pts = [(ti, float(r["cl"]), float(r["dp"])) for ti, r in zip(t, rows)]
        half = 0.5 / result["cl"]["frequency"]
        peaks = [i for i in range(1, len(pts) - 1)
                 if pts[i][1] >= pts[i - 1][1] and pts[i][1] > pts[i + 1][1] and pts[i][0] + half <= t_end]
        if peaks:
            t0 = pts[peaks[-1]][0]
            target = t0 + half
            for i in range(1, len(pts)):
                if pts[i][0] >= target:
                    s_ = (target - pts[i - 1][0]) / (pts[i][0] - pts[i - 1][0])
                    dp_half = pts[i - 1][2] + s_ * (pts[i][2] - pts[i - 1][2])
                    result["dp_half_period"] = {"t0": t0, "value": dp_half}
                    print(f"    dp(t0 + 1/(2f)) = {dp_half:.5f} (t0 = {t0:.4f}, time of the last C_L maximum)")
                    break
    if a.json:
        json.dump(result, open(a.json, "w"), indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
