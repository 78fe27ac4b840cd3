#!/usr/bin/env python3
"""A_x(t) of the thin beam (configs/thin_beam.yaml) with remeshing: Algorithm 1 and Algorithm 2
at several gamma_N1, the remeshes marked (from each run's fluid_server.log) and the steps in
contact with the channel wall drawn thick (from its solid_server.log).

Usage: python3 bench/fsi/thin_beam_remesh_plot.py OUT.png LABEL=RUN_DIR [LABEL=RUN_DIR ...]
"""
import csv
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def contact_intervals(run, t_end):
    """[(t_begin, t_end)] of the steps in contact with an obstacle (solid_server.log)."""
    try:
        log = open(f"{run}/solid_server.log").read()
    except OSError:
        return []
    out, begin = [], None
    for t, what in re.findall(r"\(t = ([0-9.e+-]+)\): contact (begins|ends)", log):
        if what == "begins":
            begin = float(t)
        elif begin is not None:
            out.append((begin, float(t)))
            begin = None
    if begin is not None:
        out.append((begin, t_end))
    return out


def main():
    out, runs = sys.argv[1], [a.split("=", 1) for a in sys.argv[2:]]
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for label, run in runs:
        rows = list(csv.DictReader(open(f"{run}/probes.csv")))
        t = [float(r["time"]) for r in rows]
        a = [float(r["solid.A_x"]) for r in rows]
        try:
            log = open(f"{run}/fluid_server.log").read()
        except OSError:
            log = ""
        steps = [int(s) for s in re.findall(r"fluid: remesh \d+ at step (\d+)", log)]
        line, = ax.plot(t, a, lw=1.2, label=f"{label} ({len(steps)} remeshes)" if steps else label)
        for begin, end in contact_intervals(run, t[-1]):
            inside = [(ti, ai) for ti, ai in zip(t, a) if begin - 1e-9 <= ti <= end + 1e-9]
            ax.plot([p[0] for p in inside], [p[1] for p in inside], lw=4, alpha=0.35, color=line.get_color())
        by_step = {round(ti / (t[0] or 1)): ai for ti, ai in zip(t, a)}
        xs = [s * t[0] for s in steps if s in by_step]
        ax.plot(xs, [by_step[s] for s in steps if s in by_step], "|", ms=8, color=line.get_color())
        if t[-1] < 2.99:
            ax.plot(t[-1], a[-1], "x", ms=8, color=line.get_color())
    ax.set_xlabel("t (s)")
    ax.set_ylabel("A_x (cm)")
    ax.set_title("Thin beam, k_max 2: tip x-displacement (| remesh, x run stopped, thick: in contact)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
