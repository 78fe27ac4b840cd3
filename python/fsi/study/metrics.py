"""Metrics of probe histories (pure functions; tested against closed forms in tests/study)."""
import math

import numpy as np

from .util import StudyError, finite


def _window(t, y, window):
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    ok = np.isfinite(t) & np.isfinite(y)
    t, y = t[ok], y[ok]
    if window is not None:
        a, b = window
        sel = np.ones_like(t, bool)
        if a is not None:
            sel &= t >= a - 1e-12
        if b is not None:
            sel &= t <= b + 1e-12
        t, y = t[sel], y[sel]
    return t, y


def time_mean(t, y):
    if len(t) < 2 or t[-1] <= t[0]:
        return float(np.mean(y)) if len(y) else None
    return float(np.trapz(y, t) / (t[-1] - t[0]))


def zero_crossing_frequency(t, y):
    """Frequency from the upward crossings of the time-mean: (crossings - 1) / (last - first),
    crossing times interpolated linearly."""
    if len(t) < 4:
        return None
    z = y - time_mean(t, y)
    scale = np.max(np.abs(z)) if len(z) else 0.0
    if not scale > 0:
        return None
    s = np.sign(z)
    s[s == 0] = 1
    idx = np.nonzero((s[:-1] < 0) & (s[1:] > 0))[0]
    if len(idx) < 2:
        return None
    tc = t[idx] - z[idx] * (t[idx + 1] - t[idx]) / (z[idx + 1] - z[idx])
    return float((len(tc) - 1) / (tc[-1] - tc[0]))


def fft_frequency(t, y):
    """Frequency of the largest FFT peak of the detrended signal resampled uniformly."""
    if len(t) < 8 or t[-1] <= t[0]:
        return None
    n = len(t)
    tu = np.linspace(t[0], t[-1], n)
    yu = np.interp(tu, t, y)
    yu = yu - np.polyval(np.polyfit(tu - tu[0], yu, 1), tu - tu[0])
    spec = np.abs(np.fft.rfft(yu * np.hanning(n)))
    if len(spec) < 3 or not np.max(spec[1:]) > 0:
        return None
    k = int(np.argmax(spec[1:]) + 1)
    # Parabolic refinement of the peak.
    if 1 <= k < len(spec) - 1:
        a, b, c = np.log(spec[k - 1] + 1e-300), np.log(spec[k] + 1e-300), np.log(spec[k + 1] + 1e-300)
        den = a - 2 * b + c
        k = k + (0.5 * (a - c) / den if den != 0 else 0.0)
    return float(k / (tu[1] - tu[0]) / n)


def signal_metrics(t, y, window=None, steady_fraction=0.1):
    """mean, amplitude ((max-min)/2), frequency, steady value (time-mean of the last fraction)."""
    t, y = _window(t, y, window)
    out = {"mean": None, "amplitude": None, "frequency": None, "steady": None, "final": None}
    if len(t) == 0:
        return out
    out["mean"] = time_mean(t, y)
    out["amplitude"] = float((np.max(y) - np.min(y)) / 2)
    f = zero_crossing_frequency(t, y)
    out["frequency"] = f if f is not None else None
    t_s = t[-1] - steady_fraction * (t[-1] - t[0])
    sel = t >= t_s - 1e-12
    out["steady"] = time_mean(t[sel], y[sel]) if np.count_nonzero(sel) >= 1 else None
    out["final"] = float(y[-1])
    return {k: finite(v) for k, v in out.items()}


def phase_lag(t, y, tr, yr, max_lag=None):
    """Time lag of y behind the reference yr: the shift s minimising the mean square of
    y(t) - yr(t - s) over the overlap (for zero-mean periodic signals: the cross-correlation
    peak), on a uniform grid of at most 4000 samples, refined parabolically. Positive: y lags.
    max_lag: the search range (default: a quarter of the overlap)."""
    a, b = max(t[0], tr[0]), min(t[-1], tr[-1])
    if not b > a:
        return None
    dt = min(np.min(np.diff(t)) if len(t) > 1 else b - a, np.min(np.diff(tr)) if len(tr) > 1 else b - a)
    n = int(min(max((b - a) / max(dt, 1e-300), 16), 4000)) + 1
    tu = np.linspace(a, b, n)
    h = tu[1] - tu[0]
    u = np.interp(tu, t, y)
    v = np.interp(tu, tr, yr)
    if not np.any(v != v[0]):
        return None  # a constant reference has no phase
    if max_lag is None:
        max_lag = 0.25 * (b - a)
    ms = max(1, min(n // 2, int(math.ceil(max_lag / h))))
    shifts = np.arange(-ms, ms + 1)
    cost = np.empty(len(shifts))
    with np.errstate(over="ignore", invalid="ignore"):
        for i, sft in enumerate(shifts):
            d = u[sft:] - v[:n - sft] if sft >= 0 else u[:n + sft] - v[-sft:]
            cost[i] = np.mean(d * d)
    if not np.all(np.isfinite(cost)):
        return None
    k = int(np.argmin(cost))
    shift = float(shifts[k])
    if 0 < k < len(cost) - 1:
        den = cost[k - 1] - 2 * cost[k] + cost[k + 1]
        if den > 0:
            shift += 0.5 * (cost[k - 1] - cost[k + 1]) / den
    return finite(shift * h)


def compare(t, y, tr, yr, window=None, steady_fraction=0.1):
    """Error metrics of the history (t, y) against the reference history (tr, yr)."""
    t, y = _window(t, y, window)
    tr, yr = _window(tr, yr, window)
    m = {}
    if len(t) == 0 or len(tr) == 0:
        return m
    a, b = max(t[0], tr[0]), min(t[-1], tr[-1])
    if b > a:
        tc = np.union1d(t[(t >= a) & (t <= b)], tr[(tr >= a) & (tr <= b)])
        e = np.interp(tc, t, y) - np.interp(tc, tr, yr)
        r = np.interp(tc, tr, yr)
        with np.errstate(over="ignore", invalid="ignore"):
            l2 = math.sqrt(max(float(np.trapz(e * e, tc)), 0.0) / (b - a)) if len(tc) > 1 else abs(float(e[0]))
            rms = math.sqrt(max(float(np.trapz(r * r, tc)), 0.0) / (b - a)) if len(tc) > 1 else abs(float(r[0]))
            m["l2"] = l2
            m["l2_rel"] = l2 / rms if rms > 0 else None
            m["max_abs"] = float(np.max(np.abs(e)))
            m["max_rel"] = m["max_abs"] / float(np.max(np.abs(r))) if np.max(np.abs(r)) > 0 else None
    s = signal_metrics(t, y, None, steady_fraction)
    sr = signal_metrics(tr, yr, None, steady_fraction)
    scale = float(np.max(np.abs(yr)))
    for q in ("steady", "mean", "amplitude", "frequency"):
        m[q] = s[q]
        m[q + "_ref"] = sr[q]
        if s[q] is not None and sr[q] is not None:
            m[q + "_err"] = s[q] - sr[q]
            # Relative only against a reference value that is not zero at the signal's scale.
            small = 1e-9 * scale if q in ("steady", "mean", "amplitude") else 0.0
            m[q + "_rel"] = abs(s[q] - sr[q]) / abs(sr[q]) if abs(sr[q]) > small else None
    max_lag = 0.5 / sr["frequency"] if sr["frequency"] else None
    m["phase_lag"] = phase_lag(t, y, tr, yr, max_lag) if b > a else None
    if m["phase_lag"] is not None and sr["frequency"]:
        m["phase_lag_deg"] = 360.0 * m["phase_lag"] * sr["frequency"]
    return {k: finite(v) for k, v in m.items()}


def compare_values(t, y, values, window=None, steady_fraction=0.1):
    """Errors against published values {steady, mean, amplitude, frequency, final}."""
    s = signal_metrics(t, y, window, steady_fraction)
    m = {}
    for q, ref in values.items():
        if q not in s:
            raise StudyError(f"reference value '{q}' unknown (steady, mean, amplitude, frequency, final)")
        m[q] = s[q]
        m[q + "_ref"] = finite(ref)
        if s[q] is not None and finite(ref) is not None:
            m[q + "_err"] = s[q] - float(ref)
            m[q + "_rel"] = abs(s[q] - float(ref)) / abs(float(ref)) if float(ref) != 0 else None
    return {k: finite(v) for k, v in m.items()}

