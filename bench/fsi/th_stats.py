#!/usr/bin/python3
"""Turek-Hron FSI1-3 statistics of a coupled run (or of a reference history), against FEATFLOW's
published values.

Usage:
  /usr/bin/python3 bench/fsi/th_stats.py CASE RUN [--periods N] [--smooth S] [--t-end T]
                                         [--plot PNG] [--json OUT]
      CASE: fsi1 | fsi2 | fsi3
      RUN:  a run folder (its probes.csv) or a CSV with columns time, ux, uy (m), drag, lift
            (FEATFLOW's reference history, bench/fsi/reference/)

fsi1 (steady): the last row of RUN/probes.csv against the 2006 values.
fsi2 / fsi3 (periodic), as FEATFLOW defines them: over the last N whole periods of u_y
(default 4; crossings of its midrange with a 10 % hysteresis, so ripple is not counted), every
quantity's mean = (max + min) / 2 and amplitude = (max - min) / 2 over the same window (a u_y
period holds two periods of u_x and of the drag), its frequency from its own crossings; the
amplitudes also after a centred moving average of S seconds (default 0.005: step-to-step
noise adds directly to max - min). Errors against FEATFLOW's level 4 (the reference), level 3
beside it (about our mesh size) and the 2006 summary. Fewer than 3 whole u_y periods: refused
(exit 3). Displacements in 1e-3 m, forces in N/m; the means of u_y and lift (near 0) are
compared relative to their amplitude. Also prints iterations per step and the wall-time split
from summary.json.
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

REF = {  # (mean, amplitude, frequency); displacement in 1e-3 m; ../shared/REFERENCES.md
    "fsi1": {"ux": 0.0227, "uy": 0.8209, "drag": 14.295, "lift": 0.7638},
    "fsi2": {"ux": (-14.58, 12.44, 3.8), "uy": (1.23, 80.6, 2.0), "drag": (208.83, 73.75, 3.8),
             "lift": (0.88, 234.2, 2.0)},
    "fsi3": {"ux": (-2.69, 2.53, 10.9), "uy": (1.48, 34.38, 5.3), "drag": (457.3, 22.66, 10.9),
             "lift": (2.22, 149.78, 5.3)},
}
# FEATFLOW's refined tables by mesh level (monolithic Q2/P1disc; FSI2 dt 0.0005, FSI3 0.00025).
# The drag and lift frequencies are those of u_x and u_y (the tables give one per pair).
LEVELS = {
    "fsi2": {
        2: {"ux": (-14.01, 12.04, 3.86), "uy": (1.28, 79.2, 1.93), "drag": (210.14, 72.86, 3.86),
            "lift": (0.49, 228.7, 1.93)},
        3: {"ux": (-14.48, 12.45, 3.86), "uy": (1.24, 80.7, 1.93), "drag": (213.05, 75.74, 3.86),
            "lift": (0.84, 234.8, 1.93)},
        4: {"ux": (-14.85, 12.70, 3.86), "uy": (1.30, 81.6, 1.93), "drag": (215.06, 77.65, 3.86),
            "lift": (0.61, 237.8, 1.93)},
    },
    "fsi3": {
        2: {"ux": (-3.02, 2.85, 10.74), "uy": (1.32, 35.73, 5.36), "drag": (458.7, 28.80, 10.74),
            "lift": (2.23, 146.0, 5.33)},
        3: {"ux": (-2.77, 2.61, 10.93), "uy": (1.43, 34.43, 5.46), "drag": (459.1, 26.50, 10.93),
            "lift": (2.36, 149.91, 5.46)},
        4: {"ux": (-2.88, 2.72, 10.93), "uy": (1.47, 34.99, 5.46), "drag": (460.5, 27.74, 10.93),
            "lift": (2.50, 153.91, 5.46)},
    },
}
# FEATFLOW's velocity + pressure unknowns per level
LEVEL_UNKNOWNS = {2: 11232, 3: 44288, 4: 175872}
NEAR_ZERO_MEAN = ("uy", "lift")  # their means are compared relative to the amplitude
COLUMNS = {"ux": ("solid.A_x", 1e3), "uy": ("solid.A_y", 1e3), "drag": ("fluid.drag", 1.0),
           "lift": ("fluid.lift", 1.0)}


def read(run):
    """(t, data) of a run folder's probes.csv, or of a reference-history CSV (time, drag, lift,
    ux, uy in m; '#' comment lines)."""
    if os.path.isdir(run):
        rows = list(csv.DictReader(open(os.path.join(run, "probes.csv"))))
        t = [float(r["time"]) for r in rows]
        data = {k: [float(r[c]) * s for r in rows] for k, (c, s) in COLUMNS.items()}
        data["iterations"] = [float(r["coupling.iterations"]) for r in rows]
        return t, data
    rows = list(csv.DictReader(line for line in open(run) if not line.startswith("#")))
    t = [float(r["time"]) for r in rows]
    data = {k: [float(r[k]) * (1e3 if k in ("ux", "uy") else 1.0) for r in rows]
            for k in ("ux", "uy", "drag", "lift")}
    return t, data


def level_errors(stats, refs):
    """Per quantity: errors (%) of mean (u_y, lift: relative to the reference amplitude),
    amplitude, smoothed amplitude and frequency against refs {q: (mean, amp, f)}."""
    out = {}
    for k, (m, amp, f) in refs.items():
        s = stats[k]
        em = err(s["mean"] - m + amp, amp) if k in NEAR_ZERO_MEAN else err(s["mean"], m)
        out[k] = {"mean": em, "amplitude": err(s["amplitude"], amp),
                  "amplitude_smoothed": err(s.get("amplitude_smoothed", s["amplitude"]), amp),
                  "frequency": err(s["frequency"], f)}
    return out


err = fstats.relative_error_percent


def featflow_limits(case):
    """FEATFLOW's own levels 2, 3, 4 (h halved per level) Richardson-extrapolated, per quantity
    and part: {q: {"mean"|"amplitude": {"limit", "order", "vs_level4" (%)} or None}}. None where
    the sequence is not monotonically convergent (FSI3's) and for the near-zero means of u_y and
    lift: there is no extrapolated value. (The frequencies, equal on FSI2's three levels, are
    not extrapolated.)"""
    out = {}
    for q in COLUMNS:
        out[q] = {}
        for i, part in enumerate(("mean", "amplitude")):
            v = [LEVELS[case][lv][q][i] for lv in (2, 3, 4)]
            if part == "mean" and q in NEAR_ZERO_MEAN:
                out[q][part] = None
                continue
            try:
                r = fstats.richardson(v)
            except fstats.StatsError:
                out[q][part] = None
                continue
            out[q][part] = {"limit": r["limit"], "order": r["order"], "vs_level4": err(r["limit"], v[2])}
    return out


def plot(a, t, d, ref):
    """PNG of A's displacement and the forces over time, FEATFLOW's band (mean +/- amplitude) shaded."""
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
        r = LEVELS[a.case][4][k] if a.case in LEVELS else ref[k]
        if isinstance(r, tuple):
            axis.axhspan(r[0] - r[1], r[0] + r[1], color="tab:green", alpha=0.12, lw=0)
            for v in (r[0] - r[1], r[0] + r[1]):
                axis.axhline(v, color="k", ls=":", lw=0.7)
        else:
            axis.axhline(r, color="k", ls=":", lw=0.7)
    for k, color in (("lift", "tab:blue"), ("drag", "tab:orange")):
        r = LEVELS[a.case][4][k] if a.case in LEVELS else ref[k]
        if isinstance(r, tuple):
            ax[2].axhspan(r[0] - r[1], r[0] + r[1], color=color, alpha=0.08, lw=0)
        else:
            ax[2].axhline(r, color=color, ls=":", lw=0.7)
    ax[0].set_title(f"{a.case}: {os.path.basename(os.path.normpath(a.run))} (shaded between dotted lines: the "
                    "reference's min to max, FEATFLOW level 4 for FSI2/FSI3; FSI1: its steady value)", fontsize=9)
    fig.tight_layout()
    fig.savefig(a.plot, dpi=110)
    print(f"plot: {a.plot}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", choices=sorted(REF))
    ap.add_argument("run")
    ap.add_argument("--periods", type=int, default=4, help="whole u_y periods at the end (default 4, at least 3)")
    ap.add_argument("--smooth", type=float, default=0.005, help="moving-average width in s (default 0.005)")
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
        cols = {k: d[k] for k in ("ux", "uy", "drag", "lift")}
        try:
            table = fstats.turek_hron_table(t, cols, "uy", min_periods=3, periods=a.periods, smooth=a.smooth)
        except fstats.StatsError as e:
            print(f"th_stats: refused: the run is too short for the periodic statistics: {e}", file=sys.stderr)
            if a.plot:  # the histories against the reference are still worth a look
                plot(a, t, d, ref)
            return 3
        stats = table["columns"]
        result.update({"window": [table["t0"], table["t1"]], "periods": table["periods"], "smooth": a.smooth})
        print(f"window [{table['t0']:.4g}, {table['t1']:.4g}] s = {table['periods']} whole u_y periods; "
              f"mean = (max+min)/2, amplitude = (max-min)/2 over it; 'smoothed': after a {1e3 * a.smooth:g} ms "
              "moving average; the means of u_y and lift are compared relative to the amplitude")
        levels = LEVELS[a.case]
        errors = {f"level{lv}": level_errors(stats, r) for lv, r in levels.items() if lv >= 3}
        errors["2006"] = level_errors(stats, ref)
        print("| quantity | ours: mean +/- amplitude [Hz] | smoothed amplitude | FEATFLOW level 4 | "
              "error mean / amplitude / smoothed / frequency | error vs level 3 | error vs 2006 |")
        print("|---|---|---|---|---|---|---|")
        for k in ("ux", "uy", "drag", "lift"):
            s = stats[k]
            m, amp, f = levels[4][k]
            e4, e3, e6 = errors["level4"][k], errors["level3"][k], errors["2006"][k]
            unit = " (1e-3 m)" if k in ("ux", "uy") else " (N/m)"
            fmt = lambda e: f"{e['mean']:+.2f} / {e['amplitude']:+.2f} / {e['amplitude_smoothed']:+.2f} / {e['frequency']:+.2f} %"
            print(f"| {k}{unit} | {s['mean']:.4g} +/- {s['amplitude']:.4g} [{s['frequency']:.4g}] | "
                  f"{s['amplitude_smoothed']:.4g} | {m} +/- {amp} [{f}] | {fmt(e4)} | {fmt(e3)} | {fmt(e6)} |")
            result[k] = dict(s, reference_level4=levels[4][k], errors_percent={n: e[k] for n, e in errors.items()})
    if "iterations" in d:  # a run folder (a reference history has neither)
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
                    counts = ("remeshes", "remesh_retries")  # counts, not seconds
                    print(f"  {k}: " + ", ".join(f"{n} {x:.0f}" if n in counts else
                                                 f"{n} {x:.1f} s ({100 * x / tot:.2f}% of the total)"
                                                 for n, x in v.items()))
    if a.json:
        json.dump(result, open(a.json, "w"), indent=2)
    if a.plot:
        plot(a, t, d, ref)


if __name__ == "__main__":
    sys.exit(main())
