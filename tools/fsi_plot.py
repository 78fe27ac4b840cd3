#!/usr/bin/python3
"""fsi plot: the pictures of a run folder or a study folder, as PNG files in that folder.

  fsi_plot.py FOLDER [--quiet]        (`fsi plot FOLDER`, `fsi run ... --plot`)

A run folder (probes.csv):
  histories.png    every physical probe over time (not the iteration counts and coupling
                   bookkeeping); the statistics `fsi run` wrote into summary.json drawn in:
                   a periodic probe's window of whole periods shaded with its mean dotted,
                   a steady probe's value dotted
  turek_hron.png   the Turek-Hron scenes (fsi1, fsi2, fsi3 and their variants such as
                   fsi3_p2p1): bench/fsi/th_stats.py's comparison with FEATFLOW, its reference
                   band shaded (also turek_hron.json); a run shorter than 3 whole periods of
                   u_y is said to be too short, the histories are still drawn
A study folder (results.csv): fsi_study.py plot (work-precision, stability maps, outcomes,
histories).
Prints the PNG files it wrote. Exit 0, or 1 when the folder holds neither.
"""
import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
PYTHON_DIR = HERE.parent / "python"  # source tree: tools/../python; installed: share/fsi/python
sys.path.insert(0, str(PYTHON_DIR))

TUREK_HRON = ("fsi1", "fsi2", "fsi3")


def diagnostic(name):
    """Columns a user does not look at first (as fsi run's final values)."""
    return (name.startswith("coupling.") or name.endswith(("iterations", "nonlinear_change", "factorisations"))
            or ".mesh_" in name)


def constant_to(y, limit=1e-6):
    """The relative spread (max - min) / |median| of a probe whose values are constant to
    within limit (a steady probe); None for a probe that changes, or one that is zero."""
    import numpy as np
    y = y[np.isfinite(y)]
    if y.size < 2:
        return None
    scale = abs(float(np.median(y)))
    if scale == 0:
        return None
    spread = float(y.max() - y.min()) / scale
    return max(spread, 1e-16) if spread <= limit else None


def th_stats_script():
    for p in (HERE / "th_stats.py", HERE.parent / "bench" / "fsi" / "th_stats.py"):
        if p.is_file():
            return p
    return None


def plot_run(folder, quiet):
    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from fsi.plots import wrap_title
    from fsi.units import label as unit_label

    import csv
    with open(folder / "probes.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    if len(rows) < 2:
        print(f"fsi plot: {folder}/probes.csv has no rows yet", file=sys.stderr)
        return []
    header = rows[0]
    data = np.array([[float(x) if x else float("nan") for x in r] for r in rows[1:] if len(r) == len(header)])
    summary = {}
    if (folder / "summary.json").is_file():
        try:
            summary = json.loads((folder / "summary.json").read_text())
        except ValueError:
            summary = {}
    stats = summary.get("statistics") or {}
    t = data[:, header.index("time")]
    shown = [c for c in header if c != "time" and not diagnostic(c)] or [c for c in header if c != "time"]
    # Probes that are exactly zero throughout (a clamped point, a component the problem does not
    # move) get no panel of their own: the title names them.
    zero = [c for c in shown if np.all(data[:, header.index(c)] == 0)]
    if len(zero) < len(shown):
        shown = [c for c in shown if c not in zero]
    else:
        zero = []
    more = len(shown) - 8
    shown = shown[:8]
    fig, axes = plt.subplots(len(shown), 1, figsize=(9, 1.9 * len(shown) + 0.8), sharex=True, squeeze=False)
    for ax, c in zip(axes[:, 0], shown):
        y = data[:, header.index(c)]
        ax.plot(t, y, lw=0.9)
        ax.ticklabel_format(axis="y", useOffset=False)
        flat = constant_to(y)
        if flat is not None:  # a steady probe: a flat line with its value, not round-off magnified
            mid, scale = float(np.nanmedian(y)), max(abs(float(np.nanmedian(y))), 1e-300)
            ax.set_ylim(mid - 0.05 * scale, mid + 0.05 * scale)
        ax.set_ylabel(unit_label(c, summary.get("parameters")), fontsize=8)
        ax.grid(alpha=0.3)
        s = stats.get(c) or {}
        note = ""
        if s.get("kind") == "periodic":
            t0, t1 = s["window"]
            ax.axvspan(t0, t1, color="tab:orange", alpha=0.12)
            ax.axhline(s["mean"], color="k", ls=":", lw=0.8)
            note = (f"mean {s['mean']:.5g}, amplitude {s['amplitude']:.4g}, {s['frequency']:.4g} Hz "
                    f"over the last {s['periods']} periods (shaded)")
        elif s.get("kind") == "steady":
            ax.axhline(s["final"], color="k", ls=":", lw=0.8)
            note = f"steady {s['final']:.6g}"
        elif s.get("kind") == "changing":
            note = f"final {s['final']:.6g}, still changing"
            if s.get("periods"):
                note += f" ({s['periods']} whole period{'s' if s['periods'] > 1 else ''}: fewer than 3)"
        if flat is not None:
            note = (note + "; " if note else "") + f"constant to {flat:.0e} (relative)"
        if note:
            ax.text(0.01, 0.95, note, transform=ax.transAxes, va="top", fontsize=8,
                    bbox={"facecolor": "white", "alpha": 0.7, "lw": 0})
    axes[-1, 0].set_xlabel("t [s]")
    title = f"{summary.get('scene', folder.name)}: {folder}"
    if summary.get("status"):
        title += f" ({summary['status']}, {summary.get('steps', len(t))} steps)"
    if more > 0:
        title += f"; {more} more probes in probes.csv"
    if zero:
        title += f"; zero throughout (not drawn): {', '.join(zero[:6])}" + (", ..." if len(zero) > 6 else "")
    wrap_title(axes[0, 0], title, fontsize=9)
    fig.tight_layout()
    path = folder / "histories.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    made = [path]
    case = str(summary.get("scene", "")).split("_")[0]
    if case in TUREK_HRON and all(c in header for c in ("solid.A_x", "solid.A_y", "fluid.drag", "fluid.lift")):
        script = th_stats_script()
        if script is None:
            print("fsi plot: bench/fsi/th_stats.py not found: no Turek-Hron comparison", file=sys.stderr)
            return made
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(PYTHON_DIR), os.environ.get("PYTHONPATH", "")]))
        png = folder / "turek_hron.png"
        p = subprocess.run([sys.executable, str(script), case, str(folder), "--plot", str(png), "--json",
                            str(folder / "turek_hron.json")], capture_output=True, text=True, env=env, timeout=300)
        if not quiet:
            sys.stdout.write("".join(line + "\n" for line in p.stdout.splitlines() if not line.startswith("plot: ")))
        if p.returncode == 3:
            print("Turek-Hron comparison: " + p.stderr.strip().replace("th_stats: refused: ", ""))
        elif p.returncode != 0:
            print(f"fsi plot: th_stats.py exited with {p.returncode}: {p.stderr.strip()[-500:]}", file=sys.stderr)
        if png.is_file():
            made.append(png)
    return made


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder")
    ap.add_argument("--quiet", action="store_true", help="print only the files written")
    a = ap.parse_args(argv)
    folder = Path(a.folder)
    if (folder / "results.csv").is_file():
        from fsi.study.plots import cmd_plot
        return cmd_plot(argparse.Namespace(dir=str(folder)))
    if (folder / "probes.csv").is_file():
        for p in plot_run(folder, a.quiet):
            print(p)
        return 0
    print(f"fsi plot: {folder} holds neither a run (probes.csv) nor a study (results.csv)", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
