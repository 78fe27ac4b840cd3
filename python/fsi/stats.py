"""Statistics of probe histories: one implementation for the study tool, the benchmark scripts
and notebooks.

Every function takes the samples ``t`` (increasing) and ``y`` as sequences or numpy arrays.

Windows
    ``select_window(t, y, (a, b))``   finite samples with a <= t <= b (either end None: open)
    ``last_seconds(t, y, seconds)``   the samples with t >= t_end - seconds
    ``last_periods(t, y, n)``         the last n whole periods (Turek-Hron crossings)
Levels and sizes
    ``time_mean`` (trapezoidal time average), ``midrange`` ((max + min) / 2),
    ``amplitude`` ((max - min) / 2)
Frequency
    ``crossings(t, y, level, hysteresis)``  upward crossing times, linearly interpolated
    ``zero_crossing_frequency``  from the upward crossings of the time mean
    ``fft_frequency``            the largest FFT peak, parabolically refined
    ``harmonic_amplitudes``      least-squares amplitudes at f, 2f, ..., nf
Periodic signals
    ``periodic_stats``  mean / midrange / amplitude / frequency over whole periods (DFG, CFD3)
    ``turek_hron``      Turek & Hron's mean = (max + min) / 2 and amplitude = (max - min) / 2
                        over the last whole periods (crossings of the midrange with a 10 %
                        hysteresis), frequency = periods / their duration
    ``by_period``       midrange and amplitude of every column, period by period
    ``moving_average``  centred moving average over a time width (the ripple filter)
    ``turek_hron_table`` Turek & Hron's statistics of several histories over the same whole
                        periods of one of them (u_y for FSI2/FSI3), raw and after a moving
                        average; refuses (StatsError) fewer than ``min_periods`` periods
Transients
    ``settling_time``   the time after which y stays within a band around its final value
    ``peak``            the largest value and its time
Comparison with a reference
    ``phase_lag``, ``signal_metrics``, ``compare`` (against a reference history),
    ``compare_values`` (against published numbers)

Functions that cannot compute a value (too few samples, no crossing) return None (or NaN
where the benchmark scripts always reported NaN), never raise, except ``compare_values`` on an
unknown quantity (``StatsError``, a ``ValueError``).
"""
import math

import numpy as np

__all__ = [
    "StatsError", "finite", "select_window", "last_seconds", "last_periods", "time_mean", "midrange",
    "amplitude", "crossings", "zero_crossing_frequency", "fft_frequency", "harmonic_amplitudes",
    "periodic_stats", "turek_hron", "by_period", "moving_average", "turek_hron_table", "settling_time", "peak",
    "phase_lag", "signal_metrics", "compare", "compare_values", "relative_error_percent",
]

_trapz = getattr(np, "trapezoid", None) or np.trapz


class StatsError(ValueError):
    """A request the statistics cannot answer (e.g. an unknown reference quantity)."""


def finite(x):
    """float(x) if it is a finite number, else None (None stays None)."""
    if x is None:
        return None
    try:
        x = float(x)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def _mean(y):
    """Arithmetic mean summed left to right (as the benchmark scripts always did, so their
    results stay identical to the last bit)."""
    return float(sum(np.asarray(y, float).tolist()) / len(y))


def _arrays(t, y):
    return np.asarray(t, float), np.asarray(y, float)


# ----------------------------------------------------------------------------------------------
# Windows
# ----------------------------------------------------------------------------------------------

def select_window(t, y, window=None):
    """The finite samples of (t, y) with a <= t <= b for window = (a, b) (1e-12 slack; None for
    an open end; window None: all finite samples). Returns numpy arrays (t, y)."""
    t, y = _arrays(t, y)
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


def last_seconds(t, y, seconds):
    """The samples with t >= t[-1] - seconds (no slack: the benchmark scripts' convention)."""
    t, y = _arrays(t, y)
    if len(t) == 0:
        return t, y
    sel = t >= t[-1] - seconds
    return t[sel], y[sel]


def last_periods(t, y, n, hysteresis=0.1):
    """The last n whole periods of y: from the (n+1)-th last to the last upward crossing of its
    midrange (hysteresis as in ``turek_hron``). Returns (t, y) of the samples between those
    crossings, or all samples when there are fewer than n + 1 crossings."""
    t, y = _arrays(t, y)
    if len(y) == 0:
        return t, y
    hi, lo = float(np.max(y)), float(np.min(y))
    up = crossings(t, y, 0.5 * (hi + lo), hysteresis * (hi - lo))
    if len(up) < n + 1:
        return t, y
    sel = (t >= up[-n - 1]) & (t <= up[-1])
    return t[sel], y[sel]


# ----------------------------------------------------------------------------------------------
# Levels, sizes, frequencies
# ----------------------------------------------------------------------------------------------

def time_mean(t, y):
    """Trapezoidal time average over [t0, t_end]; the plain mean of fewer than 2 distinct times;
    None for no samples."""
    t, y = _arrays(t, y)
    if len(t) < 2 or t[-1] <= t[0]:
        return float(np.mean(y)) if len(y) else None
    return float(_trapz(y, t) / (t[-1] - t[0]))


def midrange(y):
    """(max + min) / 2."""
    y = np.asarray(y, float)
    return float((np.max(y) + np.min(y)) / 2)


def amplitude(y):
    """(max - min) / 2."""
    y = np.asarray(y, float)
    return float((np.max(y) - np.min(y)) / 2)


def crossings(t, y, level, hysteresis=0.0):
    """Times where y crosses level upwards (y[i-1] < level <= y[i]), linearly interpolated.
    With hysteresis h > 0 a crossing counts only when y fell below level - h since the previous
    one (so ripple around the level is not counted twice)."""
    t, y = _arrays(t, y)
    if len(y) < 2:
        return []
    cand = np.nonzero((y[:-1] < level) & (level <= y[1:]))[0] + 1
    if hysteresis > 0:
        low = np.nonzero(y[:-1] < level - hysteresis)[0] + 1  # indices i at which the test re-arms
        keep, last = [], 0
        for i in cand:
            # armed iff some re-arming index j with last < j <= i
            k = np.searchsorted(low, last, side="right")
            if k < len(low) and low[k] <= i:
                keep.append(i)
                last = i
        cand = np.asarray(keep, int)
    out = []
    for i in cand:
        s = (level - y[i - 1]) / (y[i] - y[i - 1])
        out.append(float(t[i - 1] + s * (t[i] - t[i - 1])))
    return out


def zero_crossing_frequency(t, y):
    """Frequency from the upward crossings of the time mean: (crossings - 1) / (last - first),
    crossing times interpolated linearly. None with fewer than 4 samples or 2 crossings."""
    t, y = _arrays(t, y)
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
    """Frequency of the largest FFT peak of the linearly detrended, Hann-windowed signal
    resampled uniformly, refined by a parabola through the log magnitudes. None with fewer
    than 8 samples."""
    t, y = _arrays(t, y)
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
    if 1 <= k < len(spec) - 1:
        a, b, c = np.log(spec[k - 1] + 1e-300), np.log(spec[k] + 1e-300), np.log(spec[k + 1] + 1e-300)
        den = a - 2 * b + c
        k = k + (0.5 * (a - c) / den if den != 0 else 0.0)
    return float(k / (tu[1] - tu[0]) / n)


def harmonic_amplitudes(t, y, f, n):
    """Amplitudes of y at f, 2f, ..., nf: least squares of a0 + sum (a_k cos + b_k sin)(2 pi k f t)."""
    t, y = _arrays(t, y)
    cols = [np.ones_like(t)]
    for k in range(1, n + 1):
        cols += [np.cos(2 * math.pi * k * f * t), np.sin(2 * math.pi * k * f * t)]
    c, *_ = np.linalg.lstsq(np.column_stack(cols), y, rcond=None)
    return [float(math.hypot(c[2 * k - 1], c[2 * k])) for k in range(1, n + 1)]


# ----------------------------------------------------------------------------------------------
# Periodic signals
# ----------------------------------------------------------------------------------------------

def periodic_stats(t, y, level=None, hysteresis=0.0, min_crossings=3):
    """Statistics over the whole periods of y (between its first and last upward crossing of
    level, default: the arithmetic mean of y): mean (arithmetic, of those samples), max, min,
    midrange, amplitude ((max - min) / 2), frequency (periods / their duration), periods.
    With fewer than min_crossings crossings: the same over all samples, frequency NaN."""
    t, y = _arrays(t, y)
    mean = _mean(y)
    up = crossings(t, y, mean if level is None else level, hysteresis)
    if len(up) < min_crossings:
        hi, lo = float(np.max(y)), float(np.min(y))
        return {"mean": mean, "max": hi, "min": lo, "midrange": (hi + lo) / 2, "amplitude": (hi - lo) / 2,
                "frequency": float("nan"), "periods": max(0, len(up) - 1)}
    ys = y[(t >= up[0]) & (t <= up[-1])]
    hi, lo = float(np.max(ys)), float(np.min(ys))
    return {"mean": _mean(ys), "max": hi, "min": lo, "midrange": (hi + lo) / 2,
            "amplitude": (hi - lo) / 2, "frequency": (len(up) - 1) / (up[-1] - up[0]), "periods": len(up) - 1}


def turek_hron(t, y, hysteresis=0.1):
    """Turek & Hron's (2006) statistics of a periodic history: mean = (max + min) / 2 and
    amplitude = (max - min) / 2 over the whole periods between the first and last upward
    crossings of the level (max + min) / 2 (re-armed only after y fell hysteresis * (max - min)
    below it), frequency = periods / their duration. Fewer than 2 crossings: over all samples,
    frequency NaN, periods 0."""
    t, y = _arrays(t, y)
    hi, lo = float(np.max(y)), float(np.min(y))
    level, hyst = 0.5 * (hi + lo), hysteresis * (hi - lo)
    up = crossings(t, y, level, hyst)
    if len(up) < 2:
        return {"mean": level, "amplitude": 0.5 * (hi - lo), "frequency": float("nan"), "periods": 0}
    ys = y[(t >= up[0]) & (t <= up[-1])]
    hi, lo = float(np.max(ys)), float(np.min(ys))
    return {"mean": 0.5 * (hi + lo), "amplitude": 0.5 * (hi - lo),
            "frequency": (len(up) - 1) / (up[-1] - up[0]), "periods": len(up) - 1}


def by_period(t, cols, key):
    """Per period of cols[key] (between successive upward crossings of its arithmetic mean):
    t0, t1, frequency = 1 / (t1 - t0), and for every column {midrange, amplitude}."""
    t = np.asarray(t, float)
    cols = {c: np.asarray(v, float) for c, v in cols.items()}
    up = crossings(t, cols[key], _mean(cols[key]))
    out = []
    for a, b in zip(up[:-1], up[1:]):
        sel = (t >= a) & (t <= b)
        row = {"t0": a, "t1": b, "frequency": 1.0 / (b - a)}
        for c, v in cols.items():
            vs = v[sel]
            row[c] = {"midrange": float((np.max(vs) + np.min(vs)) / 2), "amplitude": float((np.max(vs) - np.min(vs)) / 2)}
        out.append(row)
    return out


def moving_average(t, y, width):
    """Centred moving average: at every t_i the mean of the samples with |t_j - t_i| <= width / 2
    (fewer near the ends). Works on non-uniform samples; width <= 0 returns y unchanged."""
    t, y = _arrays(t, y)
    if not width > 0 or len(y) == 0:
        return y.copy()
    cs = np.concatenate(([0.0], np.cumsum(y)))
    lo = np.searchsorted(t, t - 0.5 * width - 1e-12, side="left")
    hi = np.searchsorted(t, t + 0.5 * width + 1e-12, side="right")
    return (cs[hi] - cs[lo]) / (hi - lo)


def turek_hron_table(t, cols, key, min_periods=3, periods=None, hysteresis=0.1, smooth=0.0):
    """Turek & Hron's statistics of several histories over the **same whole periods** of
    cols[key] (FSI2/FSI3: u_y, whose period contains two of u_x and of the drag).

    The window runs from an upward crossing of key's midrange (hysteresis as in ``turek_hron``)
    to the last one: the last ``periods`` whole periods (None: all). Per column c:
    mean = (max + min) / 2 and amplitude = (max - min) / 2 over that window, and the frequency
    from c's own upward crossings inside it; with smooth > 0 (seconds) also
    ``mean_smoothed`` / ``amplitude_smoothed`` of the ``moving_average`` (the extrema of a noisy
    force history otherwise measure its noise). Fewer than min_periods whole periods of key:
    StatsError (a table over less than that is not a periodic state)."""
    t = np.asarray(t, float)
    cols = {c: np.asarray(v, float) for c, v in cols.items()}
    y = cols[key]
    hi, lo = float(np.max(y)), float(np.min(y))
    up = crossings(t, y, 0.5 * (hi + lo), hysteresis * (hi - lo))
    n = len(up) - 1
    if n < min_periods:
        raise StatsError(f"{max(n, 0)} whole period(s) of {key} in t = [{t[0]:.4g}, {t[-1]:.4g}]; "
                         f"at least {min_periods} are needed (run longer)")
    if periods is not None:
        if periods < min_periods:
            raise StatsError(f"periods = {periods} is fewer than min_periods = {min_periods}")
        up = up[-min(periods, n) - 1:]
    t0, t1 = up[0], up[-1]
    sel = (t >= t0) & (t <= t1)
    out = {"t0": t0, "t1": t1, "periods": len(up) - 1, "frequency": (len(up) - 1) / (t1 - t0),
           "smooth": smooth, "columns": {}}
    for c, v in cols.items():
        vs, ts = v[sel], t[sel]
        chi, clo = float(np.max(vs)), float(np.min(vs))
        cu = crossings(ts, vs, 0.5 * (chi + clo), hysteresis * (chi - clo))
        row = {"mean": 0.5 * (chi + clo), "amplitude": 0.5 * (chi - clo),
               "frequency": (len(cu) - 1) / (cu[-1] - cu[0]) if len(cu) >= 2 else float("nan")}
        if smooth > 0:
            vm = moving_average(t, v, smooth)[sel]
            row["mean_smoothed"] = 0.5 * float(np.max(vm) + np.min(vm))
            row["amplitude_smoothed"] = 0.5 * float(np.max(vm) - np.min(vm))
        out["columns"][c] = row
    return out


# ----------------------------------------------------------------------------------------------
# Transients
# ----------------------------------------------------------------------------------------------

def settling_time(t, y, final=None, band=0.02, relative=True, how="interpolate"):
    """The time after which y stays within the band around final: |y - final| <= band * |final|
    (relative, the "2 % settling time") or <= band (relative=False). final defaults to the last
    sample. Returns t[0] when y never leaves the band, None when the last sample is outside it.
    how: "interpolate" (default): where the straight line between the last sample outside the
    band and the next one enters the band; "last_outside": the time of the last sample outside
    (the convention of the README's and docs/paper_examples.md's settling times);
    "first_inside": the time of the first sample inside for good."""
    if how not in ("interpolate", "last_outside", "first_inside"):
        raise StatsError(f"settling_time: how must be interpolate, last_outside or first_inside, not {how!r}")
    t, y = _arrays(t, y)
    if len(t) == 0:
        return None
    final = float(y[-1]) if final is None else float(final)
    tol = band * abs(final) if relative else band
    e = np.abs(y - final)
    out = np.nonzero(e > tol)[0]
    if len(out) == 0:
        return float(t[0])
    i = int(out[-1])
    if i == len(t) - 1:
        return None
    if how == "last_outside":
        return float(t[i])
    if how == "first_inside":
        return float(t[i + 1])
    # the line y(t) between samples i and i+1 meets final +- tol
    edge = final + tol if y[i] > final else final - tol
    s = (edge - y[i]) / (y[i + 1] - y[i])
    return float(t[i] + s * (t[i + 1] - t[i]))


def peak(t, y):
    """(t, y) of the largest sample (the first one if several)."""
    t, y = _arrays(t, y)
    i = int(np.argmax(y))
    return float(t[i]), float(y[i])


# ----------------------------------------------------------------------------------------------
# Against a reference
# ----------------------------------------------------------------------------------------------

def signal_metrics(t, y, window=None, steady_fraction=0.1):
    """mean (time mean), amplitude ((max - min) / 2), frequency (zero crossings), steady (time
    mean of the last steady_fraction of the window), final (last value); None where undefined."""
    t, y = select_window(t, y, window)
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
    max_lag: the search range (default: a quarter of the overlap). None without an overlap or
    for a constant reference."""
    t, y = _arrays(t, y)
    tr, yr = _arrays(tr, yr)
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
        return None
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
    """Errors of the history (t, y) against the reference history (tr, yr): l2 (RMS of the
    difference over the overlap), l2_rel, max_abs, max_rel; for steady, mean, amplitude and
    frequency the value, *_ref, *_err (difference) and *_rel; phase_lag (s) and phase_lag_deg."""
    t, y = select_window(t, y, window)
    tr, yr = select_window(tr, yr, window)
    m = {}
    if len(t) == 0 or len(tr) == 0:
        return m
    a, b = max(t[0], tr[0]), min(t[-1], tr[-1])
    if b > a:
        tc = np.union1d(t[(t >= a) & (t <= b)], tr[(tr >= a) & (tr <= b)])
        e = np.interp(tc, t, y) - np.interp(tc, tr, yr)
        r = np.interp(tc, tr, yr)
        with np.errstate(over="ignore", invalid="ignore"):
            l2 = math.sqrt(max(float(_trapz(e * e, tc)), 0.0) / (b - a)) if len(tc) > 1 else abs(float(e[0]))
            rms = math.sqrt(max(float(_trapz(r * r, tc)), 0.0) / (b - a)) if len(tc) > 1 else abs(float(r[0]))
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
    """Errors against published values {steady, mean, amplitude, frequency, final}: the value,
    *_ref, *_err, *_rel. An unknown quantity raises StatsError."""
    s = signal_metrics(t, y, window, steady_fraction)
    m = {}
    for q, ref in values.items():
        if q not in s:
            raise StatsError(f"reference value '{q}' unknown (steady, mean, amplitude, frequency, final)")
        m[q] = s[q]
        m[q + "_ref"] = finite(ref)
        if s[q] is not None and finite(ref) is not None:
            m[q + "_err"] = s[q] - float(ref)
            m[q + "_rel"] = abs(s[q] - float(ref)) / abs(float(ref)) if float(ref) != 0 else None
    return {k: finite(v) for k, v in m.items()}


def relative_error_percent(ours, ref):
    """100 (ours - ref) / |ref|; NaN for ref = 0."""
    return 100.0 * (ours - ref) / abs(ref) if ref else float("nan")


def richardson(values, ratio=2.0):
    """Richardson extrapolation of a quantity computed on three meshes, coarse to fine, each
    refined by `ratio` in h (Roache's grid-convergence analysis): the observed order
    p = log(|f1 - f2| / |f2 - f3|) / log(ratio) and the extrapolated limit
    f3 + (f3 - f2) / (ratio^p - 1). Only for monotone convergence (the two differences of the
    same sign, the finer one smaller); otherwise (oscillating or diverging sequences, where the
    extrapolation means nothing) StatsError. Returns {"limit", "order", "ratio"}: "ratio" is
    d_fine / d_coarse."""
    if len(values) != 3:
        raise StatsError(f"richardson needs three levels (got {len(values)})")
    f1, f2, f3 = (float(v) for v in values)
    d1, d2 = f2 - f1, f3 - f2
    if d1 == 0.0 or d2 == 0.0 or (d1 > 0) != (d2 > 0) or abs(d2) >= abs(d1):
        raise StatsError(f"not monotonically convergent ({f1:g}, {f2:g}, {f3:g}): no extrapolation")
    r = d2 / d1
    p = math.log(1.0 / r) / math.log(ratio)
    return {"limit": f3 + d2 * r / (1.0 - r), "order": p, "ratio": r}
