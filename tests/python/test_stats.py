#!/usr/bin/python3
"""fsi.stats against closed forms: a sine of known mean, amplitude, frequency and phase, a
ripple that only the hysteresis keeps from being counted twice, harmonics, whole periods,
an exponential approach's 2 % settling time tau ln 50, errors against a reference history.
"""
import math
import sys
from pathlib import Path

import numpy as np

SRC = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(SRC / "python"))
from fsi import stats as S  # noqa: E402

from checks import check, failures  # noqa: E402


def close(x, ref, tol, what):
    ok = x is not None and abs(x - ref) <= tol
    check(ok, f"{what}: {x!r} = {ref!r} (tolerance {tol:g})")


# --- a sine: y = m + A sin(2 pi f t + phi), 10 whole periods, dt = 1e-3
m, A, f, phi = 0.7, 2.5, 3.0, 0.4
T = 10 / f
t = np.linspace(0.0, T, 10001)
y = m + A * np.sin(2 * np.pi * f * t + phi)
close(S.time_mean(t, y), m, 1e-7, "time mean over whole periods")
close(S.amplitude(y), A, A * (1 - math.cos(math.pi * f * (t[1] - t[0]))) + 1e-12, "amplitude (max - min) / 2")
close(S.midrange(y), m, 1e-4, "midrange")
close(S.zero_crossing_frequency(t, y), f, 1e-6 * f, "zero-crossing frequency")
close(S.fft_frequency(t, y), f, 1e-3 * f, "FFT peak frequency (parabolic refinement)")
ps = S.periodic_stats(t, y)
close(ps["frequency"], f, 1e-6 * f, "periodic_stats frequency")
check(ps["periods"] == 9, f"periodic_stats: {ps['periods']} whole periods between the first and last crossing = 9")
close(ps["midrange"], m, 1e-4, "periodic_stats midrange")
close(ps["amplitude"], A, 1e-3, "periodic_stats amplitude")
th = S.turek_hron(t, y)
close(th["mean"], m, 1e-4, "turek_hron mean = midrange")
close(th["amplitude"], A, 1e-3, "turek_hron amplitude")
close(th["frequency"], f, 1e-6 * f, "turek_hron frequency")
# upward crossings of m: 2 pi f t + phi = 2 pi k  ->  t_k = (k - phi / (2 pi)) / f
up = S.crossings(t, y, m)
exact = [(k - phi / (2 * np.pi)) / f for k in range(1, 11)]
check(len(up) == 10 and max(abs(a - b) for a, b in zip(up, exact)) < 1e-6,
      f"crossing times = (k - phi/2pi)/f, max error {max(abs(a - b) for a, b in zip(up, exact)) if len(up) == 10 else 'n/a'}")

# phase: y2 lags y by tau (a quarter of a period would be ambiguous; take 0.07 s < 1/(2f))
tau = 0.07
y2 = m + A * np.sin(2 * np.pi * f * (t - tau) + phi)
close(S.phase_lag(t, y2, t, y, max_lag=0.5 / f), tau, 1e-5, "phase_lag of a shifted sine")
close(S.phase_lag(t, y, t, y2, max_lag=0.5 / f), -tau, 1e-5, "phase_lag, the other way round (negative: leads)")
c = S.compare(t, y2, t, y)
close(c["phase_lag"], tau, 1e-5, "compare: phase_lag")
close(c["phase_lag_deg"], 360 * tau * f, 1e-3, "compare: phase_lag_deg = 360 tau f")
# ||y2 - y||_rms = A * |2 sin(pi f tau)| / sqrt(2) over whole periods
close(c["l2"], A * 2 * abs(math.sin(np.pi * f * tau)) / math.sqrt(2), 1e-4, "compare: l2 of the difference (closed form)")
close(c["frequency_err"], 0.0, 1e-6, "compare: same frequency")
c0 = S.compare(t, y + 0.01, t, y)
close(c0["l2"], 0.01, 1e-12, "compare: l2 of a constant offset 0.01")
close(c0["mean_err"], 0.01, 1e-12, "compare: mean error of a constant offset")
cv = S.compare_values(t, y, {"mean": m, "frequency": f})
close(cv["mean_rel"], 0.0, 1e-6, "compare_values: mean")
try:
    S.compare_values(t, y, {"avg": 1.0})
    check(False, "compare_values on an unknown quantity raises")
except S.StatsError as e:
    check("'avg'" in str(e), f"compare_values on an unknown quantity raises StatsError ({e})")
sm = S.signal_metrics(t, y, window=(T / 2, None))
close(sm["final"], y[-1], 0.0, "signal_metrics final")
check(S.signal_metrics([], [])["mean"] is None, "signal_metrics of nothing: None")
check(S.zero_crossing_frequency(t[:3], y[:3]) is None and S.fft_frequency(t[:5], y[:5]) is None,
      "too few samples: frequency None")

# --- harmonics: a0 + 3 cos(2 pi f t) + 0.5 sin(4 pi f t)
yh = 1.0 + 3.0 * np.cos(2 * np.pi * f * t) + 0.5 * np.sin(4 * np.pi * f * t)
h = S.harmonic_amplitudes(t, yh, f, 3)
check(abs(h[0] - 3) < 1e-10 and abs(h[1] - 0.5) < 1e-10 and abs(h[2]) < 1e-10, f"harmonics {h} = [3, 0.5, 0]")

# --- ripple: a slow sine plus a fast one steep enough to cross the level several times per
# crossing; without hysteresis the frequency is wrong, Turek-Hron's 10 % hysteresis gets it.
yr = np.sin(2 * np.pi * f * t) + 0.05 * np.sin(2 * np.pi * 40 * f * t + 0.3)
n0 = len(S.crossings(t, yr, 0.0))
n1 = len(S.crossings(t, yr, 0.0, hysteresis=0.2))
check(n0 > 10 and n1 == 10, f"ripple: {n0} upward crossings without hysteresis (> 10), {n1} with it (= 10)")
thr = S.turek_hron(t, yr)
close(thr["frequency"], f, 2e-3 * f, "turek_hron frequency with ripple")
check(thr["periods"] == 9, f"turek_hron periods with ripple {thr['periods']} = 9")
tl, yl = S.last_periods(t, y, 4)
close(tl[-1] - tl[0], 4 / f, 2 * (t[1] - t[0]), "last_periods(4) spans 4 periods")
tw, yw = S.last_seconds(t, y, 1.0)
check(abs(tw[0] - (T - 1.0)) <= t[1] - t[0] and tw[-1] == t[-1], "last_seconds(1.0) starts 1 s before the end")
tw, yw = S.select_window(np.r_[t, T + 1], np.r_[y, np.nan], (1.0, 2.0))
check(tw[0] >= 1.0 - 1e-12 and tw[-1] <= 2.0 + 1e-12 and np.all(np.isfinite(yw)), "select_window drops NaN, keeps [a, b]")

# per period: amplitude 1 then 2 from t = 5 / f on
ya = np.where(t < 5 / f, 1.0, 2.0) * np.sin(2 * np.pi * f * t)
bp = S.by_period(t, {"y": ya, "z": 3 * ya}, "y")
amps = [round(p["y"]["amplitude"], 4) for p in bp]
check(len(bp) == 9 and all(abs(p["frequency"] - f) < 1e-3 for p in bp), f"by_period: 9 periods of 1/f ({len(bp)})")
check(amps[:4] == [1.0] * 4 and amps[5:] == [2.0] * 4, f"by_period amplitudes {amps}")
check(all(abs(p["z"]["amplitude"] - 3 * p["y"]["amplitude"]) < 1e-12 for p in bp), "by_period: every column")

# --- settling: y = F/k (1 - exp(-t / tau)): |y - F/k| <= 2 % F/k from t = tau ln 50 on
Fk, tau = 0.1282, 0.6
ts = np.linspace(0.0, 10.0, 5001)
ys = Fk * (1 - np.exp(-ts / tau))
st = S.settling_time(ts, ys, final=Fk, band=0.02)
# linear interpolation of a convex curve over dt = 2e-3: error < dt^2 / (8 tau) relative... bound by dt
close(st, tau * math.log(50), 1e-5, "settling time (2 %) of an exponential = tau ln 50")
ts50 = tau * math.log(50)
fi = S.settling_time(ts, ys, final=Fk, band=0.02, how="first_inside")
lo = S.settling_time(ts, ys, final=Fk, band=0.02, how="last_outside")
check(lo < ts50 <= fi and abs(fi - lo - 2e-3) < 1e-12 and abs(fi - ts50) < 2e-3,
      f"settling time, last sample outside {lo} < tau ln 50 = {ts50:.6f} <= first sample inside {fi}, one step apart")
close(S.settling_time(ts, ys, final=Fk, band=0.001 * Fk, relative=False), tau * math.log(1000), 1e-5,
      "settling time, absolute band = tau ln 1000")
# damped oscillation: last exit of the band
wd, zeta_w = 2 * np.pi, 0.8
yo = 1 - np.exp(-zeta_w * ts) * np.cos(wd * ts)
st2 = S.settling_time(ts, yo, final=1.0, band=0.02)
check(st2 is not None and np.all(np.abs(yo[ts > st2 + 1e-9] - 1) <= 0.02) and abs(yo[np.searchsorted(ts, st2) - 1] - 1) > 0.02 - 1e-9,
      f"damped oscillation: settled from {st2} on, outside just before")
check(S.settling_time([0, 1, 2], [0, 1, 0.5], final=1.0) is None, "not settled at the end: None")
check(S.settling_time([0, 1, 2], [1, 1, 1]) == 0.0, "never outside: t0")
check(S.peak([0, 1, 2], [0, 3, 1]) == (1.0, 3.0), "peak")

# --- Turek-Hron tables: u_y at f, u_x and drag at 2 f, over the same whole u_y periods; a
# moving average removes a step-to-step noise that max - min would count; fewer than 3
# periods are refused.
fy = 2.0
tt = np.arange(0.0, 3.0 + 1e-9, 5e-4)
uy = 1.0 + 80.0 * np.sin(2 * np.pi * fy * tt)
ux = -14.0 + 12.0 * np.cos(4 * np.pi * fy * tt)
noise = 10.0 * (-1.0) ** np.arange(len(tt))          # +-10, alternating every sample
lift = 0.5 + 230.0 * np.sin(2 * np.pi * fy * tt + 0.3) + noise
tab = S.turek_hron_table(tt, {"uy": uy, "ux": ux, "lift": lift}, "uy", periods=4, smooth=0.005)
c = tab["columns"]
check(tab["periods"] == 4, f"turek_hron_table: 4 whole u_y periods ({tab['periods']})")
close(tab["t1"] - tab["t0"], 4 / fy, 1e-6, "turek_hron_table window = 4 u_y periods")
close(c["uy"]["amplitude"], 80.0, 80.0 * (1 - math.cos(math.pi * fy * 5e-4)) + 1e-9, "u_y amplitude")
close(c["ux"]["mean"], -14.0, 1e-3, "u_x midrange over the u_y window")
close(c["ux"]["amplitude"], 12.0, 1e-3, "u_x amplitude over the u_y window")
close(c["ux"]["frequency"], 2 * fy, 1e-6, "u_x frequency = 2 f_y from its own crossings")
close(c["lift"]["amplitude"], 240.0, 0.1, "raw lift amplitude counts the +-10 noise")
# an 11-sample centred average damps the sine by sin(11 x) / (11 sin x), x = pi f dt, and leaves
# 1/11 of the alternating noise
x = math.pi * fy * 5e-4
damp = math.sin(11 * x) / (11 * math.sin(x))
close(c["lift"]["amplitude_smoothed"], 230.0 * damp + 10.0 / 11, 0.05, "moving average: the noise down 11 times, the signal kept")
try:
    S.turek_hron_table(tt[tt < 1.2], {"uy": uy[tt < 1.2]}, "uy")
    check(False, "2 whole periods refused")
except S.StatsError as e:
    check("at least 3" in str(e), f"2 whole periods refused: {e}")
ma = S.moving_average([0, 1, 2, 3, 4], [0, 0, 3, 0, 0], 2.0)
check(np.allclose(ma, [0, 1, 1, 1, 0]), f"moving_average of a spike over 3 samples: {ma}")

# --- Richardson extrapolation: f(h) = 10 + 3 h^1.5 on h = 1, 1/2, 1/4 gives the limit 10 and
# the order 1.5 exactly; a sequence converging from above likewise; oscillating, diverging or
# stagnating sequences are refused
rx = S.richardson([10 + 3 * h ** 1.5 for h in (1.0, 0.5, 0.25)])
close(rx["limit"], 10.0, 1e-12, "richardson limit of 10 + 3 h^1.5")
close(rx["order"], 1.5, 1e-12, "richardson observed order 1.5")
rx = S.richardson([5 - 2 * h ** 0.6 for h in (0.4, 0.2, 0.1)])
close(rx["limit"], 5.0, 1e-12, "richardson limit from below, order 0.6")
close(rx["order"], 0.6, 1e-12, "richardson observed order 0.6")
for bad in ([1.0, 2.0, 1.5], [1.0, 2.0, 3.5], [1.0, 1.0, 1.0], [1.0, 2.0]):
    try:
        S.richardson(bad)
        check(False, f"richardson refuses {bad}")
    except S.StatsError as e:
        check(True, f"richardson refuses {bad}: {e}")

sys.exit(1 if failures else 0)
