#!/usr/bin/python3
"""Turek-Hron FSI1-3 statistics of a coupled run, against the published reference.

Usage:
  /usr/bin/python3 bench/fsi/th_stats.py CASE RUN_DIR [--window W] [--plot PNG] [--json OUT]
      CASE: fsi1 | fsi2 | fsi3 (| fsi3r: the refined 2010 FSI3 values)

fsi1 (steady): the last row of RUN_DIR/probes.csv.
fsi2 / fsi3 (periodic): the last W seconds (default: 4 periods of the lift). Turek & Hron's
definitions: mean = (max + min) / 2 and amplitude = (max - min) / 2 over the last whole
periods (crossings of the level (max + min) / 2 with a hysteresis of 10% of the amplitude,
so the high-frequency ripple of the non-dissipative solid does not count); frequency = number
of periods / their duration. Displacements are reported in 1e-3 m, forces in N/m.
Also prints iterations per step and the wall-time split from summary.json.
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

REF = {  # (mean, amplitude, frequency); displacement in 1e-3 m
    "fsi1": {"ux": 0.0227, "uy": 0.8209, "drag": 14.295, "lift": 0.7638},
    "fsi2": {"ux": (-14.58, 12.44, 3.8), "uy": (1.23, 80.6, 2.0), "drag": (208.83, 73.75, 3.8),
             "lift": (0.88, 234.2, 2.0)},
    "fsi3": {"ux": (-2.69, 2.53, 10.9), "uy": (1.48, 34.38, 5.3), "drag": (457.3, 22.66, 10.9),
             "lift": (2.22, 149.78, 5.3)},
    "fsi3r": {"ux": (-2.88, 2.72, 10.93), "uy": (1.47, 34.99, 5.46), "drag": (460.5, 27.74, 10.93),
              "lift": (2.50, 153.91, 5.46)},
}
COLUMNS = {"ux": ("solid.A_x", 1e3), "uy": ("solid.A_y", 1e3), "drag": ("fluid.drag", 1.0),
           "lift": ("fluid.lift", 1.0)}


def read(run):
    rows = list(csv.DictReader(open(os.path.join(run, "probes.csv"))))
    t = [float(r["time"]) for r in rows]
    data = {k: [float(r[c]) * s for r in rows] for k, (c, s) in COLUMNS.items()}
    data["iterations"] = [float(r["coupling.iterations"]) for r in rows]
    return t, data


def up_crossings(t, y, level, hyst):
    """Upward crossings of level, re-armed only after y fell below level - hyst."""
    return fstats.crossings(t, y, level, hyst)


def periodic(t, y):
    """Turek & Hron's mean = (max + min) / 2, amplitude, frequency over the whole periods."""
    return fstats.turek_hron(t, y, hysteresis=0.1)


err = fstats.relative_error_percent


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", choices=sorted(REF))
    ap.add_argument("run")
    ap.add_argument("--window", type=float, default=0.0, help="seconds at the end (default: 4 lift periods)")
    ap.add_argument("--t-end", type=float, default=0.0, help="analyse up to this time (default: the last row)")
    ap.add_argument("--plot", help="PNG of A's displacement and the lift over time")
    ap.add_argument("--json")
    a = ap.parse_args()
    t, d = read(a.run)
    if a.t_end > 0:
        n = sum(1 for ti in t if ti <= a.t_end + 1e-12)
        t = t[:n]
        d = {k: v[:n] for k, v in d.items()}
    ref = REF[a.case]
    result = {"case": a.case, "run": a.run, "t_end": t[-1], "steps": len(t)}
    print(f"{a.case}: {a.run}, t_end = {t[-1]:.4g}, {len(t)} steps")
    if a.case == "fsi1":
        print(f"| quantity | ours | reference | error |\n|---|---|---|---|")
        for k in ("ux", "uy", "drag", "lift"):
            v = d[k][-1]
            result[k] = {"value": v, "reference": ref[k], "error_percent": err(v, ref[k])}
            unit = " (1e-3 m)" if k in ("ux", "uy") else " (N/m)"
            print(f"| {k}{unit} | {v:.5g} | {ref[k]} | {err(v, ref[k]):+.2f}% |")
    else:
        f_lift = ref["lift"][2]
        window = a.window if a.window > 0 else 4.0 / f_lift
        i0 = next(i for i, ti in enumerate(t) if ti >= t[-1] - window)
        result["window"] = window
        print(f"window [{t[i0]:.4g}, {t[-1]:.4g}] s; mean = (max+min)/2, amplitude = (max-min)/2; "
              "'mean/amp' = mean error relative to the reference amplitude (u_y and lift have means near 0)")
        stats = {k: periodic(t[i0:], d[k][i0:]) for k in ("ux", "uy", "drag", "lift")}
        # FSI3 also against the refined values of Turek et al. 2010 (finer level, dt = 0.00025).
        for name in [a.case] + (["fsi3r"] if a.case == "fsi3" else []):
            refs = REF[name]
            print(f"\nreference {name}:")
            print("| quantity | ours: mean +/- amplitude [Hz] | reference | error mean | mean/amp | error amplitude | "
                  "error frequency |")
            print("|---|---|---|---|---|---|---|")
            for k in ("ux", "uy", "drag", "lift"):
                s = dict(stats[k])
                m, amp, f = refs[k]
                s.update({"reference": refs[k], "error_mean_percent": err(s["mean"], m),
                          "error_mean_over_amplitude_percent": err(s["mean"] - m + amp, amp),
                          "error_amplitude_percent": err(s["amplitude"], amp),
                          "error_frequency_percent": err(s["frequency"], f)})
                result[k if name == a.case else f"{k}_{name}"] = s
                unit = " (1e-3 m)" if k in ("ux", "uy") else " (N/m)"
                print(f"| {k}{unit} | {s['mean']:.4g} +/- {s['amplitude']:.4g} [{s['frequency']:.4g}] | "
                      f"{m} +/- {amp} [{f}] | {s['error_mean_percent']:+.1f}% | "
                      f"{s['error_mean_over_amplitude_percent']:+.1f}% | {s['error_amplitude_percent']:+.1f}% | "
                      f"{s['error_frequency_percent']:+.1f}% |")
    its = d["iterations"]
    result["iterations_per_step"] = sum(its) / len(its)
    print(f"coupling iterations per step: mean {sum(its) / len(its):.2f}, max {max(its):.0f}")
    sp = os.path.join(a.run, "summary.json")
    if os.path.exists(sp):
        s = json.load(open(sp))
        w = s.get("wall_time", {})
        result["wall_time"] = w
        tot = w.get("total", float("nan"))
        parts = ", ".join(f"{k} {v:.1f} s ({100 * v / tot:.2f}%)" for k, v in w.items() if k != "total" and not isinstance(v, dict))
        print(f"status {s.get('status')}; wall time {tot:.1f} s: {parts}")
        for k, v in w.items():
            if isinstance(v, dict):
                print(f"  {k}: " + ", ".join(f"{n} {x:.1f} s ({100 * x / tot:.2f}% of the total)" for n, x in v.items()))
    if a.json:
        json.dump(result, open(a.json, "w"), indent=2)
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)
        ax[0].plot(t, d["ux"], lw=0.8)
        ax[0].set_ylabel("u_x(A) [1e-3 m]")
        ax[1].plot(t, d["uy"], lw=0.8)
        ax[1].set_ylabel("u_y(A) [1e-3 m]")
        ax[2].plot(t, d["lift"], lw=0.8, label="lift")
        ax[2].plot(t, d["drag"], lw=0.8, label="drag")
        ax[2].set_ylabel("force [N/m]")
        ax[2].legend(loc="upper left")
        ax[2].set_xlabel("t [s]")
        for k, axis in (("ux", ax[0]), ("uy", ax[1])):
            r = ref[k]
            if isinstance(r, tuple):
                for v in (r[0] - r[1], r[0] + r[1]):
                    axis.axhline(v, color="k", ls=":", lw=0.7)
            else:
                axis.axhline(r, color="k", ls=":", lw=0.7)
        ax[0].set_title(f"{a.case}: {os.path.basename(os.path.normpath(a.run))} (dotted: reference)")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print(f"plot: {a.plot}")


if __name__ == "__main__":
    sys.exit(main())
