#!/usr/bin/python3
"""fsi.plots: legends in numeric order (g=0, g=1, g=10, g=100), titles wrapped to fit the
axes (measured with the renderer), medians of repeated times, the work-precision plot's points.
"""
import os
import sys
from pathlib import Path

os.environ["MPLBACKEND"] = "Agg"
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
import matplotlib.pyplot as plt  # noqa: E402

from fsi import plots as P  # noqa: E402

from checks import check, failures  # noqa: E402


got = P.natural_sorted(["g=100", "g=10", "g=0", "g=1", "g=1e-3", "g=-1", "dt=0.01", "dt=2e-3"])
want = ["dt=2e-3", "dt=0.01", "g=-1", "g=0", "g=1e-3", "g=1", "g=10", "g=100"]
check(got == want, f"natural order {got}")
check(sorted(["g=100", "g=2"]) == ["g=100", "g=2"] and P.natural_sorted(["g=100", "g=2"]) == ["g=2", "g=100"],
      "text order puts g=100 before g=2, natural order after")

fig, ax = plt.subplots(figsize=(5, 3))
for g in (100, 10, 0, 1):
    ax.plot([0, 1], [0, g], label=f"g={g}")
leg = P.sort_legend(ax)
labels = [t.get_text() for t in leg.get_texts()]
check(labels == ["g=0", "g=1", "g=10", "g=100"], f"legend order {labels}")
lines = {ln.get_label(): ln for ln in ax.get_lines()}
check(all(h.get_color() == lines[lab].get_color() for h, lab in zip(leg.legend_handles if hasattr(leg, "legend_handles")
                                                                     else leg.legendHandles, labels)),
      "every legend entry keeps its line's colour")

title = ("Work precision of Algorithm 2 on the thick beam: error of A_x against CPU time for "
         "gamma_N1 in {1, 10, 100, 1000}, beta in {0.5, 1}, k_max in {1, 2, 4}, median of 3 repeats")
t = P.wrap_title(ax, title)
fig.canvas.draw()
r = fig.canvas.get_renderer()
w_ax = ax.get_window_extent(r).width
w_t = t.get_window_extent(r).width
nlines = t.get_text().count("\n") + 1
check(w_t <= w_ax and nlines >= 2 and t.get_text().replace("\n", " ") == title,
      f"wrapped title: {nlines} lines, {w_t:.0f} px <= axes {w_ax:.0f} px, same words")
ax.set_title(title)
fig.canvas.draw()
check(ax.title.get_window_extent(r).width > w_ax, "(unwrapped it would not fit)")
ts = P.wrap_title(ax, title, fig=True)
fig.canvas.draw()
check(ts.get_window_extent(r).width <= fig.bbox.width, "suptitle wrapped to the figure width")
plt.close(fig)

m = P.median_by(["a", "b", "a", "a", "b", "c"], [3.0, 10.0, 1.0, 2.0, 12.0, float("nan")])
check(m == {"a": {"median": 2.0, "min": 1.0, "max": 3.0, "n": 3}, "b": {"median": 11.0, "min": 10.0, "max": 12.0, "n": 2}},
      f"median_by {m}")

fig, ax = plt.subplots()
cost = [1.0, 1.2, 0.9, 2.0, 2.2, 4.0, 10.0]
err = [1e-2, 1e-2, 1e-2, 5e-3, 5e-3, 2e-3, 1e-3]
lab = ["k=1", "k=1", "k=1", "k=2", "k=2", "k=4", "k=10"]
ser = ["g=10", "g=10", "g=10", "g=10", "g=10", "g=10", "g=2"]
out = P.work_precision(ax, cost, err, lab, series=ser)
check(list(out) == ["g=2", "g=10"], f"series in numeric order {list(out)}")
check(out["g=10"] == [("k=1", 1.0, 1e-2), ("k=2", 2.1, 5e-3), ("k=4", 4.0, 2e-3)],
      f"medians of repeats, labels in numeric order: {out['g=10']}")
check([tx.get_text() for tx in ax.get_legend().get_texts()] == ["g=2", "g=10"], "work-precision legend g=2, g=10")
check(ax.get_xscale() == "log" and ax.get_yscale() == "log", "log-log")
plt.close(fig)
sys.exit(1 if failures else 0)
