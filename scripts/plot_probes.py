#!/usr/bin/env python3
"""Overlays one probe from several runs' probes.csv into a PNG.

    scripts/plot_probes.py --probe solid.d_x --out docs/img/x.png runs/a:label_a runs/b:label_b
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", nargs="+", help="run folder, optionally :label")
    p.add_argument("--probe", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--title", default="")
    p.add_argument("--ylabel", default=None)
    p.add_argument("--hline", type=float, default=None, help="reference value to draw")
    a = p.parse_args()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for item in a.runs:
        folder, _, label = item.partition(":")
        with open(os.path.join(folder, "probes.csv")) as f:
            rows = list(csv.DictReader(f))
        ax.plot([float(r["time"]) for r in rows], [float(r[a.probe]) for r in rows], label=label or folder)
    if a.hline is not None:
        ax.axhline(a.hline, color="k", lw=0.8, ls="--", label=f"{a.hline:g}")
    ax.set_xlabel("time")
    ax.set_ylabel(a.ylabel or a.probe)
    ax.set_title(a.title)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
