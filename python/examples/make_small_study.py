#!/usr/bin/python3
"""Writes small_study.ipynb (next to this file) with nbformat: the notebook's source of truth.

    /usr/bin/python3 python/examples/make_small_study.py
"""
from pathlib import Path

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

cells = [
    new_markdown_cell("""# A small study: gamma_N1 on the appendix model problem

Runs `configs/sdof_model.yaml` (m = 1, c = 2.5, k = 10, F = 1.282; Algorithm 2, beta = 1,
k_max = 1) for gamma_N1 in {0, 1, 10, 100} and dt in {0.04, 0.02, 0.01}, twice each, with
`fsi.run`; reads the runs with `fsi.load`; plots the displacement histories against the exact
solution of `m a + c v + k d = F` and the error against the run time (median of the repeats:
one wall time alone is noisy).

Needs the build (`build/bin/fsi`, or `FSI_BIN`) and a Python with numpy and matplotlib.
Open it from anywhere inside the repository (or set `FSI_SOURCE`); the runs go to
`runs/small_study` (or `FSI_EXAMPLE_OUT`). About 20 s on one core."""),
    new_code_cell("""import os
import sys
from pathlib import Path

import numpy as np
import matplotlib.pyplot as plt


def find_source():
    if os.environ.get("FSI_SOURCE"):
        return Path(os.environ["FSI_SOURCE"]).resolve()
    for d in [Path.cwd(), *Path.cwd().parents]:
        if (d / "configs" / "sdof_model.yaml").exists() and (d / "python" / "fsi").is_dir():
            return d
    raise RuntimeError("open the notebook inside the repository, or set FSI_SOURCE")


SRC = find_source()
sys.path.insert(0, str(SRC / "python"))  # the fsi package, without installing it
import fsi
from fsi import plots, stats

SCENE = SRC / "configs" / "sdof_model.yaml"
OUT = Path(os.environ.get("FSI_EXAMPLE_OUT", SRC / "runs" / "small_study"))
OUT.mkdir(parents=True, exist_ok=True)
print("fsi:", fsi.results.find_fsi(), " runs in:", OUT)"""),
    new_markdown_cell("## The runs\n\n`fsi.run` raises `fsi.RunError` (status, reason, exit code) if a run does not complete."),
    new_code_cell("""gammas = [0, 1, 10, 100]
dts = [0.04, 0.02, 0.01]
repeats = 2
runs = []
for g in gammas:
    for dt in dts:
        for rep in range(repeats):
            out = OUT / f"g{g}_dt{dt}_r{rep}"
            r = fsi.run(SCENE, out, set={"coupling.gamma_n1": g, "time.dt": dt, "time.end": 10.0}, force=True)
            runs.append({"gamma": g, "dt": dt, "repeat": rep, "out": out, "seconds": r.summary["wall_time"]["total"]})
print(len(runs), "runs completed")"""),
    new_markdown_cell("""## Error against the exact solution

The scene's parameters come from the run's summary. The exact displacement of
`m a + c v + k d = F`, `d(0) = v(0) = 0` (under-damped): `d = F/k (1 - e^(-zeta w t) (cos w_d t + zeta w / w_d sin w_d t))`."""),
    new_code_cell("""p = fsi.load(runs[0]["out"]).summary["parameters"]
m, c, k = p["solid"]["mass"], p["solid"]["damping"], p["solid"]["stiffness"]
F = p["fluid"]["force"]


def exact(t):
    w = np.sqrt(k / m)
    zeta = c / (2 * np.sqrt(k * m))
    wd = w * np.sqrt(1 - zeta ** 2)
    return F / k * (1 - np.exp(-zeta * w * t) * (np.cos(wd * t) + zeta * w / wd * np.sin(wd * t)))


for r in runs:
    d = fsi.load(r["out"])
    r["error"] = float(np.max(np.abs(d["solid.d_x"] - exact(d["time"]))))
print(f"m = {m}, c = {c}, k = {k}, F = {F}: settles to F/k = {F / k}")"""),
    new_markdown_cell("## Displacement histories (dt = 0.02) and 2 % settling times"),
    new_code_cell("""fig, ax = plt.subplots(figsize=(7, 4))
settling = {}
for g in reversed(gammas):  # any order: the legend is sorted numerically
    d = fsi.load(OUT / f"g{g}_dt0.02_r0")
    ax.plot(d["time"], d["solid.d_x"], label=f"gamma_N1={g}")
    # the README's convention: the last time |d - F/k| exceeded 2 % of F/k
    settling[g] = stats.settling_time(d["time"], d["solid.d_x"], final=F / k, band=0.02, how="last_outside")
t = np.linspace(0, 10, 1001)
ax.plot(t, exact(t), "k--", lw=0.8, label="exact (no coupling lag)")
ax.set_xlabel("time [s]")
ax.set_ylabel("solid.d_x [m]")
plots.sort_legend(ax)
plots.wrap_title(ax, "Appendix model problem, Algorithm 2, beta = 1, k_max = 1, dt = 0.02: "
                     "the lagged gamma_N1 v_n acts like an extra mass gamma_N1 dt")
fig.tight_layout()
fig.savefig(OUT / "histories.png", dpi=100)
print({g: round(s, 2) for g, s in sorted(settling.items())})"""),
    new_markdown_cell("## Error against run time\n\nMedian wall time of the repeats; the bars span their min and max."),
    new_code_cell("""fig, ax = plt.subplots(figsize=(7, 4))
wp = plots.work_precision(ax, [r["seconds"] for r in runs], [r["error"] for r in runs],
                          [f"dt={r['dt']}" for r in runs], series=[f"gamma_N1={r['gamma']}" for r in runs],
                          xlabel="wall time of the run [s] (median of repeats)", ylabel="max |d - d_exact| [m]")
plots.wrap_title(ax, "Error against run time: BDF1 halves the error with dt; gamma_N1 adds error at every dt")
fig.tight_layout()
fig.savefig(OUT / "error_vs_time.png", dpi=100)
for s, pts in wp.items():
    print(s, "  ".join(f"{lab}: {e:.2e} in {tm:.2f} s" for lab, tm, e in pts))"""),
    new_markdown_cell("## As a table (pandas, when installed)"),
    new_code_cell("""try:
    import pandas as pd
    table = pd.DataFrame([{k_: v for k_, v in r.items() if k_ != "out"} for r in runs])
    table = table.groupby(["gamma", "dt"]).agg(error=("error", "median"), seconds=("seconds", "median"))
    print(table)
except ImportError:
    table = None
    print("pandas not installed")"""),
]
nb = new_notebook(cells=cells, metadata={"kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"},
                                         "language_info": {"name": "python"}})
path = Path(__file__).resolve().parent / "small_study.ipynb"
nbformat.validate(nb)
nbformat.write(nb, str(path))
print(f"wrote {path}")
