#!/usr/bin/env python3
"""Runs of a scene against a reference run: outcome, steps, wall time, solver passes per step,
A_x errors (relative L2 and max over the window, phase lag), the mean kinematic gap of the
explicit Robin-Neumann scheme (iterations.csv), and a plot of the A_x histories.

Usage: python3 bench/fsi/robin_neumann_table.py --window T0,T1 [--plot FILE --title TEXT]
           REF_LABEL=REF_DIR LABEL=RUN_DIR ...
"""
import argparse
import csv
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
from fsi import stats  # noqa: E402


def history(run, probe="solid.A_x"):
    rows = list(csv.DictReader(open(f"{run}/probes.csv")))
    return [float(r["time"]) for r in rows], [float(r[probe]) for r in rows]


def kinematic_gap(run):
    rows = list(csv.DictReader(open(f"{run}/iterations.csv")))
    gaps = [float(r["kinematic_gap"]) for r in rows if r.get("kinematic_gap") not in (None, "")]
    return sum(gaps) / len(gaps) if gaps else None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--window", required=True)
    ap.add_argument("--plot")
    ap.add_argument("--title", default="")
    ap.add_argument("runs", nargs="+")
    a = ap.parse_args()
    window = tuple(float(x) for x in a.window.split(","))
    runs = [r.split("=", 1) for r in a.runs]
    tr, yr = history(runs[0][1])
    print(f"| run | outcome | steps | wall (s) | passes / step | rel. L2 A_x | max abs A_x error | lag (s) "
          f"| mean kinematic gap |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, run in runs:
        s = json.load(open(f"{run}/summary.json"))
        t, y = history(run)
        c = stats.compare(t, y, tr, yr, window=window)
        complete = s["status"] == "completed"
        outcome = "completed" if complete else f"{s['status']} at t = {t[-1] if t else 0:.3f}"
        # (an incomplete run: the errors over the part it ran)
        passes = s["coupling_iterations"] / s["steps"] if s.get("steps") else None
        gap = kinematic_gap(run)
        lag = c.get("phase_lag") if complete else None
        l2 = f"{100 * c['l2_rel']:.2f} %" if c.get("l2_rel") is not None else ""
        mx = f"{c['max_abs']:.4f}" if c.get("max_abs") is not None else ""
        print(f"| {label} | {outcome} | {s['steps']} | {s['wall_time']['total']:.1f} | "
              f"{'' if passes is None else f'{passes:.2f}'} | {l2}{'' if complete else ' (until then)'} | {mx} | "
              f"{'' if lag is None else f'{lag:+.3f}'} | {'' if gap is None else f'{gap:.3g}'} |")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(8, 4.2))
        for i, (label, run) in enumerate(runs):
            t, y = history(run)
            ax.plot(t, y, lw=2.2 if i == 0 else 1.2, color="k" if i == 0 else None, label=label)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("A_x (cm)")
        ax.set_xlim(0, window[1])
        lo, hi = min(yr), max(yr)
        ax.set_ylim(lo - 0.5 * (hi - lo) - 1e-3, hi + 0.5 * (hi - lo) + 1e-3)
        ax.set_title(a.title, fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print(f"wrote {a.plot}")


if __name__ == "__main__":
    main()
