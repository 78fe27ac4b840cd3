#!/usr/bin/python3
"""Metric functions against closed forms (no processes)."""
import math

import numpy as np

import common  # noqa: F401 (sys.path)
import fsi_study as fs
from common import check

# A pure sine: amplitude, frequency, mean, phase lag.
t = np.linspace(0.0, 10.0, 4001)
A, f, lag, off = 2.0, 1.5, 0.05, 0.3
ref = A * np.sin(2 * np.pi * f * t)
y = A * np.sin(2 * np.pi * f * (t - lag)) + off
s = fs.signal_metrics(t, y)
check(abs(s["amplitude"] - A) < 1e-3, f"amplitude of a sine {s['amplitude']:.6f} = {A}")
check(abs(s["frequency"] - f) < 1e-6, f"frequency from mean crossings {s['frequency']:.8f} = {f}")
check(abs(s["mean"] - off) < 1e-3, f"time mean {s['mean']:.6f} = {off}")
check(abs(fs.fft_frequency(t, y) - f) < 2e-3, f"FFT peak frequency {fs.fft_frequency(t, y):.5f} = {f}")
m = fs.compare(t, y, t, ref)
check(abs(m["phase_lag"] - lag) < 1e-3, f"phase lag {m['phase_lag']:.5f} s = {lag} s (y lags: positive)")
check(abs(m["phase_lag_deg"] - 360 * f * lag) < 0.5, f"phase lag {m['phase_lag_deg']:.3f} deg = {360 * f * lag}")
m2 = fs.compare(t, ref, t, y)
check(abs(m2["phase_lag"] + lag) < 1e-3, f"reference ahead: lag {m2['phase_lag']:.5f} = {-lag}")
check(abs(m["amplitude_rel"]) < 1e-3 and abs(m["frequency_rel"]) < 1e-6, "amplitude/frequency errors vanish")
check(m["mean_rel"] is None, "relative error against a zero mean is empty, not inf")

# L2 over time of a known difference: e = 0.1 sin(2 pi t) on [0, 10]: RMS 0.1/sqrt(2).
y3 = ref + 0.1 * np.sin(2 * np.pi * t)
m3 = fs.compare(t, y3, t, ref)
check(abs(m3["l2"] - 0.1 / math.sqrt(2)) < 1e-4, f"L2 over time {m3['l2']:.6f} = 0.1/sqrt(2)")
check(abs(m3["l2_rel"] - 0.1 / A) < 1e-4, f"relative L2 {m3['l2_rel']:.6f} = 0.1/A")
check(abs(m3["max_abs"] - 0.1) < 1e-4, f"max abs error {m3['max_abs']:.6f} = 0.1")
# Different time grids: the coarse run is compared on the union of both grids.
tc = t[::8]
m4 = fs.compare(tc, np.interp(tc, t, y3), t, ref)
check(abs(m4["l2"] - 0.1 / math.sqrt(2)) < 5e-3, f"L2 with a coarse run {m4['l2']:.5f} ~ 0.1/sqrt(2)")
# A constant offset: steady error and L2 both equal the offset.
m5 = fs.compare(t, 1.0 + 0 * t + 0.01, t, 1.0 + 0 * t)
check(abs(m5["steady_err"] - 0.01) < 1e-12 and abs(m5["l2"] - 0.01) < 1e-12, "steady error and L2 of an offset")
check(m5["phase_lag"] is None, "a constant reference has no phase lag")
# Published values.
v = fs.compare_values(t, y, {"amplitude": 2.0, "frequency": 1.5, "mean": 0.3})
check(v["amplitude_rel"] < 1e-3 and v["frequency_rel"] < 1e-6 and abs(v["mean_err"]) < 1e-3, "published values")
# Nothing non-finite comes out.
bad = fs.compare(t, np.where(t > 5, np.inf, y), t, ref)
check(all(x is None or math.isfinite(x) for x in bad.values()), "non-finite samples give finite or empty metrics")

# Closed forms: the README's added-mass limits and the exact SDOF solution.
p = {"solid.mass": 1.0, "solid.damping": 0.5, "solid.stiffness": 4.0, "fluid.added_mass": 10.0, "time.dt": 0.01,
     "coupling.algorithm": 1, "coupling.gamma_n1": 0}
check(abs(fs.added_mass_beta_c(p) - 0.1827) < 1e-4, f"Alg 1 beta_c {fs.added_mass_beta_c(p):.4f} = 0.1827")
# m_eff = 1.0054: 2 (1.0054 + 0.01 g) / 11.0054 (the README rounds 100 and 300 to 0.3646 / 0.7281).
for g, bc in ((10, 0.20088), (100, 0.36444), (300, 0.72790)):
    q = dict(p, **{"coupling.algorithm": 2, "coupling.gamma_n1": g})
    check(abs(fs.added_mass_beta_c(q) - bc) < 1e-5, f"Alg 2 gamma {g}: beta_c {fs.added_mass_beta_c(q):.5f} = {bc}")
sd = {"solid.mass": 1.0, "solid.damping": 2.5, "solid.stiffness": 10.0, "fluid.force": 1.282}
x = fs.sdof_exact(sd, t)
# Residual of m x'' + c x' + k x = F by finite differences.
h = t[1] - t[0]
res = (x[2:] - 2 * x[1:-1] + x[:-2]) / h**2 + 2.5 * (x[2:] - x[:-2]) / (2 * h) + 10 * x[1:-1] - 1.282
check(np.max(np.abs(res)) < 1e-3 and abs(x[-1] - 0.1282) < 1e-6, "sdof_exact solves m x'' + c x' + k x = F")

# Classification of summaries.
c = fs.classify({"status": "diverged", "reason": "coupling residual grew from 1e-1 to 1e4 at step 3 iteration 7"}, 2,
                "finished")
check(c["outcome"] == "diverged" and c["stop_step"] == 3 and c["stop_iteration"] == 7 and
      c["reason_kind"] == "residual growth", "diverged: step, iteration and reason kind")
c = fs.classify({"status": "diverged", "reason": "solver failed at step 4: element 7 near (1, 2) is inverted; "
                 "the mesh motion tangled the mesh"}, 2, "finished")
check(c["outcome"] == "mesh tangled", "a tangled mesh is its own outcome")
check(fs.classify(None, -11, "finished")["outcome"] == "crashed", "a signal exit is a crash")
check(fs.classify(None, 0, "finished")["outcome"] == "crashed", "a missing summary.json is a crash")
check(fs.classify({"status": "completed"}, 0, "timeout")["outcome"] == "timeout", "past the time limit: timeout")
# `extends`: a second reference for the same sweep without copying it.
a, b = fs.Study(common.SRC / "studies" / "fsi3.yaml"), fs.Study(common.SRC / "studies" / "fsi3_published.yaml")
na, nb = [a.spec(x)["name"] for x in a.combos()], [b.spec(x)["name"] for x in b.combos()]
check(len(na) == 10 and na == nb, f"extends: the same {len(na)} runs (names) as the parent study")
check("run" in a.reference and "values" in b.reference and b.window == a.window and b.scene == a.scene,
      "extends: own reference, inherited window and scene (resolved relative to the parent)")
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402


def expect_study_error(path, needle, what):
    try:
        fs.Study(path)
        check(False, what)
    except fs.StudyError as e:
        check(needle in str(e), f"{what}, named: {e}")


with tempfile.TemporaryDirectory() as tmp:
    (Path(tmp) / "x.yaml").write_text("extends: y.yaml\n")
    (Path(tmp) / "y.yaml").write_text("extends: x.yaml\n")
    expect_study_error(Path(tmp) / "x.yaml", "cycle", "an extends cycle is an error")
    (Path(tmp) / "z.yaml").write_text("extends: missing.yaml\n")
    expect_study_error(Path(tmp) / "z.yaml", "missing.yaml", "a missing parent is an error")
print("all metric tests passed")
