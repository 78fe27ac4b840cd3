"""PNGs from a study folder: work precision, stability map, outcomes, histories."""
import csv
import json
import math
from pathlib import Path

import numpy as np
import yaml

from .analysis import read_probes
from .forms import SCALAR_FORMS, evaluate
from .util import ABBREV, read_json
from ..units import label as unit_label


def run_parameters(runs_dir, runs):
    """The scene parameters (summary.json) of the first of these runs that has them, for units."""
    for r in runs:
        try:
            return json.loads((Path(runs_dir) / r["name"] / "summary.json").read_text()).get("parameters") or {}
        except (OSError, ValueError):
            continue
    return {}

def load_results(d):
    with open(Path(d) / "results.csv") as f:
        rows = list(csv.DictReader(f))
    meta = read_json(Path(d) / "results.json") or {}
    return rows, meta


def is_reference_row(r, meta):
    """The reference run: its own run ('reference-<hash>') or the sweep's run it coincides with."""
    return r["name"].startswith("reference-") or (bool(meta.get("reference_run")) and r["name"] == meta["reference_run"])


def num(s):
    try:
        v = float(s)
        return v if math.isfinite(v) else None
    except (TypeError, ValueError):
        return None


X_LABELS = {"wall_time": "wall time of the run (s)", "cpu_time": "CPU time of the run (s)",
            "coupling_iterations": "coupling iterations of the run (each one fluid and one solid solve)"}


def metric_label(metric):
    """'solid.r2_x.l2_rel' -> 'relative L2 error of solid.r2_x' (the study metrics' names)."""
    forms = {"l2_rel": "relative L2 error", "l2": "L2 error", "max_rel": "largest relative error",
             "max_abs": "largest error", "steady_rel": "relative error of the steady value",
             "mean_rel": "relative error of the mean", "amplitude_rel": "relative error of the amplitude"}
    probe, _, form = metric.rpartition(".")
    return f"{forms[form]} of {probe}" if probe and form in forms else metric


def plot_work_precision(plt, d, rows, meta, cfg):
    """Error against cost (wall time by default; `x: cpu_time` or `coupling_iterations` where
    process start-up or a shared machine would dominate wall time), one line per group of
    `lines`; each point names the varied values its line does not (e.g. g=100). `metric` is one
    column or a list of columns (one panel each). Runs that did not complete are counted in a
    note on the figure (outcomes.png shows them)."""
    import textwrap
    from matplotlib.ticker import NullFormatter, ScalarFormatter
    probes = meta.get("probes") or []
    if not probes:
        return None
    metrics = cfg.get("metric", f"{probes[0]}.l2_rel")
    metrics = [metrics] if isinstance(metrics, str) else list(metrics)
    xkey = cfg.get("x", "wall_time")
    color_key = cfg.get("color", "coupling.algorithm")
    varied = [k for k in meta.get("varied", [])]
    line_keys = cfg.get("lines", [k for k in varied if k not in ("time.dt", "fluid.mesh.size")])
    point_keys = [k for k in varied if k not in line_keys and k != color_key]
    sweep = [r for r in rows if r["name"] and not is_reference_row(r, meta)]
    runs = [r for r in sweep if num(r.get(xkey))]
    if not any(num(r.get(m)) for r in runs for m in metrics):
        return None
    fig, axes = plt.subplots(1, len(metrics), figsize=(7.5 if len(metrics) == 1 else 5.5 * len(metrics), 5.2),
                             squeeze=False)
    cyc = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    markers = "osD^v<>px*h"
    colors, mk = {}, {}
    for ax, metric in zip(axes[0], metrics):
        groups = {}
        for r in runs:
            if num(r.get(metric)) is not None:
                groups.setdefault(tuple(r.get(k, "") for k in line_keys), []).append(r)
        xs_all = []
        for g, rs in sorted(groups.items()):
            rs.sort(key=lambda r: num(r[xkey]))
            ckey = rs[0].get(color_key, "")
            colors.setdefault(ckey, cyc[len(colors) % len(cyc)])
            other = tuple(v for k, v in zip(line_keys, g) if k != color_key)
            mk.setdefault(other, markers[len(mk) % len(markers)])
            label = ", ".join(f"{ABBREV.get(k, k)}={v}" for k, v in zip(line_keys, g))
            xs = [num(r[xkey]) for r in rs]
            xs_all += xs
            ax.plot(xs, [max(num(r[metric]), 1e-300) for r in rs], "-", marker=mk[other], color=colors[ckey],
                    label=label)
            within = [k for k in point_keys if len({r.get(k, "") for r in rs}) > 1]  # what moves along the line
            spots = {}  # coincident points (the same run under another name) share one label
            for r in rs:
                spots.setdefault((num(r[xkey]), num(r[metric])), []).append(r)
            for (x, y), same in spots.items():
                tag = ", ".join(f"{ABBREV.get(k, k)}=" + " / ".join(dict.fromkeys(r[k] for r in same)) for k in within)
                if tag:
                    ax.annotate(tag, (x, y), fontsize=7, alpha=0.75, textcoords="offset points", xytext=(4, 4))
        ax.set_yscale("log")
        if xs_all and max(xs_all) > 10 * min(xs_all):
            ax.set_xscale("log")
        else:  # within a decade: a linear axis with plain numbers (no overlapping 1.3x10^2 labels)
            ax.xaxis.set_major_formatter(ScalarFormatter(useOffset=False))
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(X_LABELS.get(xkey, xkey))
        ax.set_ylabel(metric_label(metric))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=1 if len(metrics) > 1 else 2)
    title = cfg.get("title", f"{meta.get('study', '')}: error against {X_LABELS.get(xkey, xkey).split(' (')[0]}")
    missing = [r for r in sweep if r.get("outcome") != "completed"]
    if missing:
        title += f" (not shown: {len(missing)} of {len(sweep)} runs did not complete, see outcomes.png)"
    wrapped = textwrap.fill(title, 70 if len(metrics) == 1 else 110)
    if len(metrics) == 1:
        axes[0][0].set_title(wrapped, fontsize=10)
    else:
        fig.suptitle(wrapped, fontsize=10)
    fig.tight_layout()
    path = Path(d) / cfg.get("file", "work_precision.png")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_stability(plt, d, meta, cfg):
    st = meta.get("stability") or {}
    table = meta.get("stability_table") or []
    if not st or not table:
        return None
    key, x = st["parameter"], st["x"]
    series = list(st.get("series", []))
    fig, ax = plt.subplots(figsize=(7, 5))
    groups = {}
    for r in table:
        groups.setdefault(tuple(r.get(k) for k in series), []).append(r)
    cyc = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    xs_all = sorted({float(r[x]) for r in table if r.get(x) is not None})
    pos = [v for v in xs_all if v > 0]
    linthresh = min(pos) if pos else 1.0
    for i, (g, rs) in enumerate(sorted(groups.items(), key=lambda kv: str(kv[0]))):
        rs.sort(key=lambda r: float(r[x]))
        label = ", ".join(f"{ABBREV.get(k, k)}={v}" for k, v in zip(series, g))
        c = cyc[i % len(cyc)]
        xs = [float(r[x]) for r in rs if r.get("stable_max") is not None]
        ys = [r["stable_max"] for r in rs if r.get("stable_max") is not None]
        ax.plot(xs, ys, "o", color=c, label=f"largest stable (measured), {label}")
        hx = [float(r[x]) for r in rs if r.get("unstable_min") is not None]
        hy = [r["unstable_min"] for r in rs if r.get("unstable_min") is not None]
        ax.plot(hx, hy, "x", color=c, alpha=0.6, label=f"smallest unstable, {label}")
        form = st.get("closed_form")
        if form:
            base = dict(meta.get("base_params") or {})
            base.update({k: v for k, v in zip(series, g)})
            grid = np.unique(np.concatenate([np.linspace(0.0, linthresh, 50), np.geomspace(linthresh, max(xs_all + [1.0]) * 1.5, 300)]))
            vals = []
            for gx in grid:
                p = dict(base)
                p[x] = gx
                v = SCALAR_FORMS[form](p) if form in SCALAR_FORMS else evaluate(form, p)
                vals.append(min(v, float(st.get("cap", 1.0))))
            ax.plot(grid, vals, "--", color=c, label=f"closed form {form}, {label}")
    ax.set_xscale("symlog", linthresh=linthresh)
    ax.set_xlabel(x)
    ax.set_ylabel(f"largest stable {key}")
    ax.set_title(cfg.get("title", f"{meta.get('study', '')}: stability map"))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path = Path(d) / cfg.get("file", "stability_map.png")
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_histories(plt, d, rows, meta, cfg):
    probes = cfg.get("probes") or meta.get("probes") or []
    if not probes:
        return []
    done = [r for r in rows if r.get("outcome") == "completed"]
    ref = [r for r in done if is_reference_row(r, meta)]
    others = [r for r in done if not is_reference_row(r, meta)]
    sel = cfg.get("select")
    if sel:
        keep = []
        for r in others:
            p = {k: (num(v) if num(v) is not None else v) for k, v in r.items()}
            if evaluate(sel, p, what="plots.histories.select"):
                keep.append(r)
        others = keep
    nmax = int(cfg.get("max_runs", 8))
    if len(others) > nmax:
        idx = np.linspace(0, len(others) - 1, nmax).round().astype(int)
        others = [others[i] for i in sorted(set(idx))]
    paths = []
    varied = meta.get("varied", [])
    for p in probes:
        fig, ax = plt.subplots(figsize=(8, 4.5))
        for r in ref + others:
            data = read_probes(Path(d) / "runs" / r["name"] / "probes.csv")
            if not data or p not in data:
                continue
            is_ref = r in ref
            label = "reference" if is_ref else ", ".join(f"{ABBREV.get(k, k)}={r.get(k)}" for k in varied)
            ax.plot(data["time"], data[p], "k-" if is_ref else "-", lw=2.2 if is_ref else 1.0, label=label,
                    zorder=3 if is_ref else 2)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(unit_label(p, run_parameters(Path(d) / "runs", ref + others)))
        ax.set_title(cfg.get("title", f"{meta.get('study', '')}: {p}"))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        path = Path(d) / f"{cfg.get('file_prefix', 'histories')}_{p.replace('.', '_')}.png"
        fig.savefig(path, dpi=120)
        plt.close(fig)
        paths.append(path)
    return paths


def plot_outcomes(plt, d, meta):
    c = meta.get("outcomes") or {}
    if not c.get("cases"):
        return None
    labels, vals = ["completed"], [c["completed"]]
    for k, v in sorted(c.get("diverged_by_reason", {}).items()):
        labels.append(f"diverged: {k}")
        vals.append(v)
    for k in ("mesh_tangled", "solver_failed", "failed", "timeouts", "crashes"):
        labels.append(k.replace("_", " "))
        vals.append(c.get(k, 0))
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.barh(labels, vals)
    for i, v in enumerate(vals):
        ax.text(v, i, f" {v}", va="center", fontsize=8)
    ax.set_xlabel("cases")
    ax.set_title(f"{meta.get('study', '')}: {c['cases']} cases by outcome")
    fig.tight_layout()
    path = Path(d) / "outcomes.png"
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def cmd_plot(args):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    d = Path(args.dir)
    rows, meta = load_results(d)
    cfg = {}
    study_file = d / "study.yaml"
    if study_file.is_file():
        cfg = (yaml.safe_load(study_file.read_text()) or {}).get("plots") or {}
    made = [plot_work_precision(plt, d, rows, meta, cfg.get("work_precision") or {}),
            plot_stability(plt, d, meta, cfg.get("stability") or {}), plot_outcomes(plt, d, meta)]
    made += plot_histories(plt, d, rows, meta, cfg.get("histories") or {})
    for p in made:
        if p:
            print(p)
    return 0

