#!/usr/bin/env python3
"""Overlays one probe from several runs' probes.csv into a PNG.

    scripts/plot_probes.py --probe solid.d_x --out docs/img/x.png runs/a:label_a runs/b:label_b
"""
import argparse
import csv
import difflib
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
import fsi.interpreter  # noqa: E402

fsi.interpreter.require("numpy", "matplotlib")  # under another python3: re-run with FSI_PYTHON

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from fsi.plots import sort_legend, wrap_title  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", nargs="+", help="run folder, optionally :label")
    p.add_argument("--probe", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--title", default="")
    p.add_argument("--ylabel", default=None)
    p.add_argument("--hline", type=float, default=None, help="reference value to draw")
    a = p.parse_args()
    series = []
    for item in a.runs:
        folder, _, label = item.partition(":")
        path = os.path.join(folder, "probes.csv")
        try:
            with open(path) as f:
                reader = csv.DictReader(f)
                rows = list(reader)
                columns = reader.fieldnames or []
        except OSError as e:
            print(f"plot_probes.py: {path}: {e.strerror}", file=sys.stderr)
            return 1
        if a.probe not in columns:
            near = difflib.get_close_matches(a.probe, columns, n=1)
            print(f"plot_probes.py: {path} has no probe '{a.probe}'"
                  + (f" (did you mean '{near[0]}'?)" if near else "")
                  + f"; columns: {', '.join(c for c in columns if c != 'time')}", file=sys.stderr)
            return 1
        series.append(([float(r["time"]) for r in rows], [float(r[a.probe]) for r in rows], label or folder))
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for t, y, label in series:
        ax.plot(t, y, label=label)
    if a.hline is not None:
        ax.axhline(a.hline, color="k", lw=0.8, ls="--", label=f"{a.hline:g}")
    ax.set_xlabel("time")
    ax.set_ylabel(a.ylabel or a.probe)
    wrap_title(ax, a.title)
    ax.grid(alpha=0.3)
    sort_legend(ax)  # runs/g0 runs/g1 runs/g10 runs/g100 in numeric order, however given
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
