#!/usr/bin/env python3
"""A_x(t) of the thin beam (configs/thin_beam.yaml) with remeshing: Algorithm 1 and Algorithm 2
at several gamma_N1, the remeshes marked (from each run's fluid_server.log).

Usage: python3 bench/fsi/thin_beam_remesh_plot.py OUT.png LABEL=RUN_DIR [LABEL=RUN_DIR ...]
"""
import csv
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


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
        by_step = {round(ti / (t[0] or 1)): ai for ti, ai in zip(t, a)}
        xs = [s * t[0] for s in steps if s in by_step]
        ax.plot(xs, [by_step[s] for s in steps if s in by_step], "|", ms=8, color=line.get_color())
        if t[-1] < 2.99:
            ax.plot(t[-1], a[-1], "x", ms=8, color=line.get_color())
    ax.set_xlabel("t (s)")
    ax.set_ylabel("A_x (cm)")
    ax.set_title("Thin beam, dt 0.005, k_max 2: tip x-displacement (| remesh, x run stopped)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
