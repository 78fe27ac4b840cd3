#!/usr/bin/env python3
"""Mean, amplitude, extrema and frequency of periodic probe signals (DFG 2D-2, CFD3).

Usage:
  python3 bench/fluid/periodic_stats.py OUT/probes.csv --columns cd cl --window 1.0 \
      [--strouhal-scale 0.1] [--json OUT/stats.json]

Uses the last `window` seconds; the frequency comes from the upward mean crossings
(linearly interpolated) of each column; amplitude = (max - min) / 2 over whole periods;
"mean" is the time average, "midrange" = (max + min) / 2 (Turek & Hron's definition of the
mean in their CFD/FSI tables).

  --by-period lift   splits the window into the periods of that column (upward crossings of
                     its mean) and prints every column's midrange / amplitude per period: the
                     way to see whether a run has reached its periodic state.
  --reference cfd3   prints the errors against a published reference (Turek & Hron 2006);
                     refused (exit 3) when the window holds fewer than 3 whole periods of the
                     lift (a column with fewer is flagged in any case).
  --harmonics 3      least-squares amplitudes of every column at 1, 2, 3 x the lift frequency
                     (CFD3: the drag oscillates at f and 2f; its f part follows the lift mean).
"""
import argparse
import csv
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
import fsi.interpreter  # noqa: E402

fsi.interpreter.require("numpy")  # under another python3: re-run with FSI_PYTHON
from fsi import stats as fstats  # noqa: E402

MIN_PERIODS = 3  # fewer whole periods in the window: flagged; with --reference: refused (exit 3)

# (midrange mean, amplitude, frequency of the lift) per column
REFERENCES = {
    "cfd3": {"drag": (439.45, 5.6183, 4.3956), "lift": (-11.893, 437.81, 4.3956)},
}

# The statistics live in fsi.stats (python/fsi/stats.py); these names stay importable from here.
crossings = fstats.crossings
stats = fstats.periodic_stats
harmonic_amplitudes = fstats.harmonic_amplitudes
by_period = fstats.by_period


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("--columns", nargs="+", default=["cd", "cl"])
    ap.add_argument("--window", type=float, default=1.0)
    ap.add_argument("--strouhal-scale", type=float, default=0.0, help="D / U_bar: St = f * scale")
    ap.add_argument("--by-period", metavar="COLUMN", help="print statistics per period of COLUMN")
    ap.add_argument("--reference", choices=sorted(REFERENCES), help="print errors against a published reference")
    ap.add_argument("--harmonics", type=int, default=0, metavar="N",
                    help="amplitudes at 1..N times the frequency of the lift (or the first column)")
    ap.add_argument("--json")
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.csv)))
    if not rows:
        sys.exit(f"periodic_stats: {a.csv}: no data rows")
    # fsi run writes the fluid's probes as fluid.cd, fluid.lift, ...: accept the bare names too.
    a.columns = [c if c in rows[0] or "fluid." + c not in rows[0] else "fluid." + c for c in a.columns]
    if a.by_period and a.by_period not in rows[0] and "fluid." + a.by_period in rows[0]:
        a.by_period = "fluid." + a.by_period
    missing = [c for c in a.columns + ([a.by_period] if a.by_period else []) if c not in rows[0]]
    if missing:
        sys.exit(f"periodic_stats: {a.csv}: no column {', '.join(missing)} (columns: {', '.join(rows[0])})")
    t = [float(r["time"]) for r in rows]
    t_end = t[-1]
    result = {"t_end": t_end, "window": a.window}
    for c in a.columns:
        pts = [(ti, float(r[c])) for ti, r in zip(t, rows) if ti >= t_end - a.window]
        s = stats([p[0] for p in pts], [p[1] for p in pts])
        if a.strouhal_scale:
            s["strouhal"] = s["frequency"] * a.strouhal_scale
        result[c] = s
        s["too_short"] = s["periods"] < MIN_PERIODS
        print(f"{c:>6}: mean {s['mean']:.6g}  midrange {s['midrange']:.6g}  "
              f"amplitude {s['amplitude']:.6g}  max {s['max']:.6g}  "
              f"min {s['min']:.6g}  frequency {s['frequency']:.5g} Hz ({s['periods']} periods)"
              + (f"  St {s['strouhal']:.5f}" if a.strouhal_scale else "")
              + (f"  FLAGGED: fewer than {MIN_PERIODS} whole periods in the window, not a periodic state "
                 "(run longer or widen --window)" if s["too_short"] else ""))
    # The published frequency is the lift's (the drag oscillates at twice it, plus a part at it).
    bare = {c: c[len("fluid."):] if c.startswith("fluid.") else c for c in a.columns}
    fcol = next((c for c in a.columns if bare[c] == "lift"), a.columns[0])
    f0 = result[fcol]["frequency"]
    pts = [i for i, ti in enumerate(t) if ti >= t_end - a.window]  # rows of the window
    if a.reference and result[fcol]["too_short"]:
        print(f"periodic_stats: refused: {result[fcol]['periods']} whole period(s) of {fcol} in the last "
              f"{a.window:g} s; at least {MIN_PERIODS} are needed for errors against {a.reference} (run longer "
              "or widen --window)", file=sys.stderr)
        if a.json:
            json.dump(result, open(a.json, "w"), indent=2)
        return 3
    if a.reference:
        ref = REFERENCES[a.reference]
        print(f"against {a.reference}: midrange +/- amplitude [frequency of {fcol}]")
        for c in a.columns:
            if bare[c] not in ref:
                continue
            m, amp, f = ref[bare[c]]
            s = result[c]
            e = {"midrange_over_amplitude_percent": 100 * (s["midrange"] - m) / amp,
                 "midrange_percent": 100 * (s["midrange"] - m) / abs(m),
                 "amplitude_percent": 100 * (s["amplitude"] - amp) / amp,
                 "frequency_percent": 100 * (f0 - f) / f}
            s["errors"] = e
            print(f"{c:>6}: {s['midrange']:.5g} +/- {s['amplitude']:.5g} [{f0:.5g}] vs "
                  f"{m} +/- {amp} [{f}]: midrange {e['midrange_percent']:+.2f}% "
                  f"({e['midrange_over_amplitude_percent']:+.2f}% of the amplitude), "
                  f"amplitude {e['amplitude_percent']:+.2f}%, frequency {e['frequency_percent']:+.2f}%")
    if a.harmonics > 0:
        tw = [t[i] for i in pts]
        print(f"harmonics of f = {f0:.5g} Hz (frequency of {fcol}), least squares over the window:")
        for c in a.columns:
            ys = [float(rows[i][c]) for i in pts]
            amps = harmonic_amplitudes(tw, ys, f0, a.harmonics)
            result[c]["harmonics"] = amps
            print(f"{c:>6}: " + "  ".join(f"{k + 1}f {v:.5g}" for k, v in enumerate(amps)))
    if a.by_period:
        cols = {c: [float(rows[i][c]) for i in pts] for c in dict.fromkeys([a.by_period] + a.columns)}
        periods = by_period([t[i] for i in pts], cols, a.by_period)
        result["by_period"] = periods
        print(f"per period of {a.by_period}: " + "  ".join(f"{c} midrange +/- amplitude" for c in cols))
        for p in periods:
            print(f"  [{p['t0']:8.4f}, {p['t1']:8.4f}] {p['frequency']:.4f} Hz  " +
                  "  ".join(f"{p[c]['midrange']:10.4f} +/- {p[c]['amplitude']:9.4f}" for c in cols))
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
