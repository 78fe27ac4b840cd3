"""Small matplotlib helpers for run and study plots.

- ``natural_key`` / ``natural_sorted``: "g=0, g=1, g=10, g=100" in numeric, not text, order
  (numbers inside labels compare as numbers, 1e-3 and -1 included).
- ``sort_legend(ax)``: the legend in that order.
- ``wrap_title(ax, text)``: a title wrapped to the width of the axes (or ``fig``), so it fits.
- ``median_by(labels, values)``: the median (and min, max, count) of repeated measurements per
  label: CPU or wall times of repeated runs, where a single wall time is noisy.
- ``work_precision(ax, cost, error, labels)``: error against cost, log-log, one marker per
  point, series in numeric label order, medians of repeats.
- ``histories(ax, runs, probe)``: one probe of several run folders over time.

matplotlib is imported only by the functions that draw.
"""
import re
import textwrap

import numpy as np

__all__ = ["natural_key", "natural_sorted", "sort_legend", "wrap_title", "median_by", "work_precision", "histories"]

_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def natural_key(label):
    """Sort key: the label split into text and numbers, numbers compared by value
    ("g=2" < "g=10", "dt=1e-3" < "dt=0.01", "x=-1" < "x=0"); text parts case-insensitively."""
    s = str(label)
    key, pos = [], 0
    for m in _NUMBER.finditer(s):
        text = s[pos:m.start()]
        # a '-' or '+' glued to a preceding word is a separator, not a sign ("run-2")
        tok = m.group()
        if tok[0] in "+-" and m.start() > 0 and (s[m.start() - 1].isalnum() or s[m.start() - 1] == "_"):
            text += tok[0]
            tok = tok[1:]
        key.append((0, text.lower(), 0.0))
        key.append((1, "", float(tok)))
        pos = m.end()
    key.append((0, s[pos:].lower(), 0.0))
    return tuple(key)


def natural_sorted(labels):
    """The labels in natural_key order."""
    return sorted(labels, key=natural_key)


def sort_legend(ax, key=natural_key, **legend_kw):
    """Redraw the legend of ax with its entries in numeric order of their labels; returns the
    legend (None when nothing is labelled)."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    order = sorted(range(len(labels)), key=lambda i: key(labels[i]))
    return ax.legend([handles[i] for i in order], [labels[i] for i in order], **legend_kw)


def wrap_title(ax, text, fontsize=None, fig=False, **kw):
    """Set a title wrapped so that every line fits the width of the axes (fig=True: a figure
    suptitle fitting the figure). Returns the Text. The width is measured with the renderer,
    shortening the wrap width until every line fits."""
    import matplotlib.pyplot as plt  # noqa: F401 (a backend)
    figure = ax.figure
    setter = figure.suptitle if fig else ax.set_title
    t = setter(text, fontsize=fontsize, **kw)
    renderer = figure.canvas.get_renderer()
    box = figure.bbox if fig else ax.get_window_extent(renderer)
    width = box.width
    size = t.get_fontsize()
    chars = max(10, int(width / (0.5 * size * figure.dpi / 72)))  # a first guess: 0.5 em per character
    while True:
        t.set_text("\n".join(textwrap.wrap(text, chars)) if len(text) > chars else text)
        if t.get_window_extent(renderer).width <= width or chars <= 10:
            break
        chars -= max(1, chars // 10)
    return t


def median_by(labels, values):
    """{label: {"median", "min", "max", "n"}} of the values grouped by label (e.g. CPU or wall
    seconds of repeated runs with the same parameters), in natural label order. NaN and None
    values are ignored."""
    groups = {}
    for k, v in zip(labels, values):
        if v is None:
            continue
        v = float(v)
        if v == v:
            groups.setdefault(k, []).append(v)
    return {k: {"median": float(np.median(groups[k])), "min": min(groups[k]), "max": max(groups[k]),
                "n": len(groups[k])} for k in natural_sorted(groups)}


def work_precision(ax, cost, error, labels, series=None, xlabel="CPU time [s]", ylabel="error", annotate=True,
                   spread=True):
    """Error against cost, log-log. cost, error, labels: one entry per run; runs with the same
    (series, label) are repeats: plotted at the median cost (and median error) with the min-max
    cost as a horizontal bar (spread=True). series: one line per series value (default: one
    line); series and labels in numeric order; annotate: each point with its label.
    Returns {series: [(label, median cost, median error), ...]}."""
    series = list(series) if series is not None else [""] * len(labels)
    keyed = [(s, lab) for s, lab in zip(series, labels)]
    out = {}
    for s in natural_sorted(set(series)):
        idx = [i for i, k in enumerate(keyed) if k[0] == s]
        c = median_by([labels[i] for i in idx], [cost[i] for i in idx])
        e = median_by([labels[i] for i in idx], [error[i] for i in idx])
        pts = [(lab, c[lab]["median"], e[lab]["median"], c[lab]["min"], c[lab]["max"]) for lab in c if lab in e]
        pts = [p for p in pts if p[1] > 0 and p[2] > 0]
        if not pts:
            continue
        (line,) = ax.loglog([p[1] for p in pts], [p[2] for p in pts], "o-", label=str(s) if s != "" else None)
        if spread:
            for p in pts:
                if p[4] > p[3]:
                    ax.plot([p[3], p[4]], [p[2], p[2]], "-", color=line.get_color(), lw=0.8, alpha=0.6)
        if annotate:
            for p in pts:
                ax.annotate(str(p[0]), (p[1], p[2]), textcoords="offset points", xytext=(4, 3), fontsize=7)
        out[s] = [(p[0], p[1], p[2]) for p in pts]
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3, which="both")
    if any(s != "" for s in out):
        sort_legend(ax)
    return out


def histories(ax, runs, probe, labels=None):
    """Plot probe over time for several run folders (paths, fsi.run / fsi.load results), or a
    {label: run} dict; labels in the given order; the legend in numeric order. Returns the lines."""
    from fsi.results import load, Results
    if isinstance(runs, dict):
        labels, runs = list(runs), list(runs.values())
    from fsi.units import label as unit_label
    lines = []
    parameters = None
    for i, r in enumerate(runs):
        if hasattr(r, "out") and not isinstance(r, Results):  # an fsi.run() result: its folder
            r = r.out
        res = r if isinstance(r, Results) else load(r)
        label = labels[i] if labels else str(res.out)
        lines += ax.plot(res["time"], res[probe], label=label)
        if parameters is None:
            parameters = res.summary.get("parameters") or {}
    ax.set_xlabel("time [s]")
    ax.set_ylabel(unit_label(probe, parameters))
    ax.grid(alpha=0.3)
    sort_legend(ax)
    return lines
