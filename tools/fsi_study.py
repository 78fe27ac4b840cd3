#!/usr/bin/python3
"""fsi_study: parameter studies over `fsi run` (issue 6).

  fsi_study.py run STUDY.yaml --out DIR [--jobs N] [--fsi PATH]   run (or resume) a sweep
  fsi_study.py plot DIR                                           PNGs from DIR/results.csv
  fsi_study.py analyse DIR                                        recompute tables without running

A study file names a scene, fixed overrides, the parameters to vary (cartesian product of
lists, `zip` groups, derived expressions, a `where` filter), a per-run time limit, the probes
and a reference (a designated fine run, a closed form, or published values). Each run is one
`fsi run` process tree in DIR/runs/<name>; finished runs are not run again; a run past its
time limit is killed (its whole process tree) and classified "timeout". Results:
DIR/results.csv (one row per run), DIR/results.json, DIR/outcomes.json, DIR/stability.csv
when the study has a `stability` section. Every number written is finite or empty.
See docs/studies.md for every key.

Only the standard library, numpy, yaml and (for `plot`) matplotlib.
"""
import argparse
import csv
import hashlib
import itertools
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import yaml

TOOL_DIR = Path(__file__).resolve().parent
REPO = TOOL_DIR.parent

STUDY_KEYS = {"extends", "study", "description", "scene", "fixed", "vary", "zip", "derived", "where", "time_limit",
              "probes", "reference", "metrics", "stability", "plots"}
FINISHED = ("completed", "diverged", "failed")
ABBREV = {"coupling.algorithm": "alg", "coupling.gamma_n1": "g", "coupling.relaxation": "beta",
          "coupling.iterations.max": "kmax", "coupling.iterations.tolerance": "tol", "time.dt": "dt",
          "fluid.mesh.size": "h", "solid.mass": "m", "solid.stiffness": "k", "solid.damping": "c",
          "fluid.added_mass": "ma", "coupling.predictor": "pred",
          "coupling.acceleration": "acc"}


class StudyError(Exception):
    pass


# ----------------------------------------------------------------------------------------------
# Numbers
# ----------------------------------------------------------------------------------------------

def finite(x):
    """x as a float if finite, else None."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def fmt_num(x):
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    v = finite(x)
    if v is None:
        return ""
    return "%.10g" % v


def clean_value(v):
    """Stable representation of a parameter value (floats rounded to 12 significant digits)."""
    if isinstance(v, str) and re.fullmatch(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?", v.strip()):
        v = float(v)  # YAML 1.1 reads 1.0e9 (no exponent sign) as a string
    if isinstance(v, bool) or isinstance(v, int) or isinstance(v, str):
        return v
    if isinstance(v, (float, np.floating)):
        return float("%.12g" % float(v))
    if isinstance(v, np.integer):
        return int(v)
    return v


def set_value(v):
    """A value as text for `--set key=value`."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    return str(v)


# ----------------------------------------------------------------------------------------------
# Metrics (pure functions; tested against closed forms in tests/study)
# ----------------------------------------------------------------------------------------------

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


# ----------------------------------------------------------------------------------------------
# Closed forms
# ----------------------------------------------------------------------------------------------

def _p(params, key, default=None):
    v = params.get(key, default)
    if v is None:
        raise StudyError(f"closed form needs '{key}'")
    return float(v)


def added_mass_beta_c(params):
    """Largest stable relaxation of the pure added-mass model (README): m_eff = m + c dt + k dt^2,
    Algorithm 1: 2 m_eff / (m_eff + m_a); Algorithm 2: 2 (m_eff + gamma mu dt) / (m_eff + m_a)."""
    m, c, k = _p(params, "solid.mass"), _p(params, "solid.damping", 0.0), _p(params, "solid.stiffness", 0.0)
    dt, ma = _p(params, "time.dt"), _p(params, "fluid.added_mass", 0.0)
    mu = _p(params, "solid.interface_measure", 1.0)
    m_eff = m + c * dt + k * dt * dt
    if int(_p(params, "coupling.algorithm")) == 1:
        return 2 * m_eff / (m_eff + ma)
    return 2 * (m_eff + _p(params, "coupling.gamma_n1") * mu * dt) / (m_eff + ma)


def sdof_exact(params, t):
    """Exact displacement of m x'' + c x' + k x = F (F = fluid.force + solid.force) from rest."""
    m, c, k = _p(params, "solid.mass"), _p(params, "solid.damping", 0.0), _p(params, "solid.stiffness", 0.0)
    F = _p(params, "fluid.force", 0.0) + _p(params, "solid.force", 0.0)
    t = np.asarray(t, float)
    if k == 0:
        if c == 0:
            return F * t * t / (2 * m)
        return F / c * (t - m / c * (1 - np.exp(-c * t / m)))
    xs = F / k
    disc = c * c - 4 * m * k
    if abs(disc) < 1e-12 * c * c + 1e-300:
        s = -c / (2 * m)
        return xs * (1 - (1 - s * t) * np.exp(s * t))
    if disc < 0:
        a, w = -c / (2 * m), math.sqrt(-disc) / (2 * m)
        return xs * (1 - np.exp(a * t) * (np.cos(w * t) - a / w * np.sin(w * t)))
    s1, s2 = (-c + math.sqrt(disc)) / (2 * m), (-c - math.sqrt(disc)) / (2 * m)
    return xs * (1 - (s2 * np.exp(s1 * t) - s1 * np.exp(s2 * t)) / (s2 - s1))


SCALAR_FORMS = {"added_mass_beta_c": added_mass_beta_c}
SERIES_FORMS = {"sdof_exact": sdof_exact}


def namespace(params, t=None):
    ns = {"pi": math.pi, "e": math.e, "exp": np.exp, "sqrt": np.sqrt, "log": np.log, "log10": np.log10,
          "sin": np.sin, "cos": np.cos, "tan": np.tan, "abs": np.abs, "min": min, "max": max, "floor": math.floor,
          "round": round, "int": int, "float": float, "p": params}
    for k, v in params.items():
        ns[k.replace(".", "_")] = v
    for name, fn in SCALAR_FORMS.items():
        try:
            ns[name] = fn(params)
        except (StudyError, ValueError, TypeError, ZeroDivisionError):
            pass
    if "time.dt" in params and "solid.mass" in params:
        dt = float(params["time.dt"])
        ns["m_eff"] = float(params["solid.mass"]) + float(params.get("solid.damping", 0) or 0) * dt + \
            float(params.get("solid.stiffness", 0) or 0) * dt * dt
    if t is not None:
        ns["t"] = np.asarray(t, float)
    return ns


def evaluate(expr, params, t=None, what="expression"):
    if not isinstance(expr, str):
        return expr
    try:
        return eval(compile(expr, what, "eval"), {"__builtins__": {}}, namespace(params, t))  # noqa: S307
    except Exception as e:  # noqa: BLE001 - report the expression
        raise StudyError(f"{what} '{expr}': {e}") from None


# ----------------------------------------------------------------------------------------------
# Study file
# ----------------------------------------------------------------------------------------------

def flatten(d, prefix=""):
    out = {}
    for k, v in (d or {}).items():
        key = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(flatten(v, key + "."))
        else:
            out[key] = v
    return out


def expand(key, values):
    if isinstance(values, list):
        return [clean_value(v) for v in values]
    if isinstance(values, dict) and len(values) == 1:
        (kind, args), = values.items()
        if kind == "linspace":
            return [clean_value(v) for v in np.linspace(float(args[0]), float(args[1]), int(args[2]))]
        if kind == "geomspace":
            return [clean_value(v) for v in np.geomspace(float(args[0]), float(args[1]), int(args[2]))]
        if kind == "range":
            a, b, s = (float(x) for x in args)
            n = int(math.floor((b - a) / s + 1e-9)) + 1
            return [clean_value(a + i * s) for i in range(n)]
    if isinstance(values, (int, float, str, bool)):
        return [clean_value(values)]
    raise StudyError(f"vary '{key}': a list, or one of {{linspace|geomspace|range: [a, b, n|step]}}")


def load_study_file(path, seen=()):
    """The study file as a mapping; `extends: OTHER.yaml` (relative to this file) takes every
    top-level key of OTHER that this file does not set (a second reference or other plots for
    the same sweep without copying it). The inherited scene is resolved relative to OTHER."""
    path = Path(path).resolve()
    if path in seen:
        raise StudyError(f"{path}: 'extends' cycle ({' -> '.join(str(p) for p in seen + (path,))})")
    try:
        d = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as e:
        raise StudyError(f"{path}: {e}") from None
    if not isinstance(d, dict):
        raise StudyError(f"{path}: not a mapping")
    parent_name = d.pop("extends", None)
    if parent_name is None:
        return d
    parent_path = (path.parent / str(parent_name)).resolve()
    if not parent_path.is_file():
        raise StudyError(f"{path}: extends '{parent_name}': no such file ({parent_path})")
    parent = load_study_file(parent_path, seen + (path,))
    if "scene" in parent and not Path(str(parent["scene"])).is_absolute():
        c = parent_path.parent / str(parent["scene"])
        if c.is_file():
            parent["scene"] = str(c.resolve())
    merged = dict(parent)
    merged.update(d)
    return merged


class Study:
    def __init__(self, path):
        self.path = Path(path).resolve()
        d = load_study_file(self.path)
        unknown = sorted(set(d) - STUDY_KEYS)
        if unknown:
            raise StudyError(f"{path}: unknown key(s) {unknown}; known: {sorted(STUDY_KEYS)}")
        self.raw = d
        self.name = str(d.get("study", self.path.stem))
        self.description = str(d.get("description", ""))
        if "scene" not in d:
            raise StudyError(f"{path}: 'scene' is required")
        self.scene = self._find(d["scene"])
        self.fixed = {k: clean_value(v) for k, v in flatten(d.get("fixed")).items()}
        self.vary = {k: expand(k, v) for k, v in (d.get("vary") or {}).items()}
        self.zip = []
        for i, group in enumerate(d.get("zip") or []):
            g = {k: expand(k, v) for k, v in group.items()}
            lens = {len(v) for v in g.values()}
            if len(lens) != 1:
                raise StudyError(f"{path}: zip group {i}: lists of different lengths {sorted(lens)}")
            self.zip.append(g)
        self.derived = dict(d.get("derived") or {})
        self.where = d.get("where")
        self.time_limit = float(d.get("time_limit", 600))
        self.probes = list(d.get("probes") or [])
        self.reference = d.get("reference") or {}
        rkinds = set(self.reference) & {"run", "closed_form", "values"}
        if self.reference and len(rkinds) != 1:
            raise StudyError(f"{path}: reference needs exactly one of run / closed_form / values")
        metrics = d.get("metrics") or {}
        self.window = metrics.get("window")
        self.steady_fraction = float(metrics.get("steady_fraction", 0.1))
        self.stability = d.get("stability")
        if self.stability:
            for k in ("parameter", "x"):
                if k not in self.stability:
                    raise StudyError(f"{path}: stability.{k} is required")
            bis = self.stability.get("bisection")
            if bis and self.stability["parameter"] in self.vary:
                raise StudyError(f"{path}: stability.parameter is bisected: do not also vary it")
        self.plots = d.get("plots") or {}
        self.scene_values = flatten(yaml.safe_load(self.scene.read_text()))
        self.scene_sha = hashlib.sha256(self.scene.read_bytes()).hexdigest()

    def _find(self, scene):
        p = Path(scene)
        for c in ([p] if p.is_absolute() else [self.path.parent / p, Path.cwd() / p, REPO / p]):
            if c.is_file():
                return c.resolve()
        raise StudyError(f"{self.path}: scene '{scene}' not found (relative to the study, the cwd or {REPO})")

    def base_params(self):
        b = dict(self.scene_values)
        b.update(self.fixed)
        return b

    def combos(self):
        axes = [[{k: v} for v in vals] for k, vals in self.vary.items()]
        for g in self.zip:
            keys = list(g)
            axes.append([dict(zip(keys, vals)) for vals in zip(*(g[k] for k in keys))])
        out = []
        for prod in itertools.product(*axes):
            combo = {}
            for part in prod:
                combo.update(part)
            full = self.base_params()
            full.update(combo)
            for key, expr in self.derived.items():
                v = clean_value(evaluate(expr, full, what=f"derived '{key}'"))
                if isinstance(v, (np.ndarray,)):
                    v = clean_value(float(v))
                combo[key] = v
                full[key] = v
            if self.where is not None and not evaluate(self.where, full, what="where"):
                continue
            out.append(combo)
        return out

    def spec(self, combo, name=None):
        """A run: its varied values, every override it gets, its name."""
        overrides = dict(self.fixed)
        overrides.update({k: v for k, v in combo.items() if "." in k})  # no dot: a study variable
        sets = [f"{k}={set_value(v)}" for k, v in sorted(overrides.items())]
        key = json.dumps({"scene": self.scene.name, "sets": sets}, sort_keys=True)
        h = hashlib.sha1(key.encode()).hexdigest()[:8]
        if name is None:
            parts = []
            for k, v in combo.items():
                parts.append(f"{ABBREV.get(k, k)}{set_value(v) if not isinstance(v, float) else '%.6g' % v}")
            name = re.sub(r"[^A-Za-z0-9._+-]", "-", "_".join(parts))[:150]
            name = f"{name}-{h}" if name else h
        else:
            name = f"{name}-{h}"
        full = self.base_params()
        full.update(combo)
        return {"name": name, "combo": dict(combo), "sets": sets, "params": full}


# ----------------------------------------------------------------------------------------------
# Running
# ----------------------------------------------------------------------------------------------

def descendants(pid):
    children = {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as f:
                s = f.read()
            ppid = int(s[s.rindex(")") + 2:].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        children.setdefault(ppid, []).append(int(d))
    out, pending = [], [pid]
    while pending:
        for c in children.get(pending.pop(), []):
            out.append(c)
            pending.append(c)
    return out


def kill_tree(proc, grace=3.0):
    """Stops a run's whole process tree: SIGTERM to the launcher's group (it stops its children),
    then SIGKILL to every process and process group of the tree that is left."""
    tree = set(descendants(proc.pid))
    try:
        os.killpg(proc.pid, signal.SIGTERM)
    except OSError:
        pass
    end = time.monotonic() + grace
    while proc.poll() is None and time.monotonic() < end:
        tree |= set(descendants(proc.pid))
        time.sleep(0.02)
    tree |= set(descendants(proc.pid)) if proc.poll() is None else set()
    for pid in [proc.pid] + sorted(tree):
        for kill in (lambda p: os.killpg(os.getpgid(p), signal.SIGKILL), lambda p: os.kill(p, signal.SIGKILL)):
            try:
                if pid == proc.pid or Path(f"/proc/{pid}").exists():
                    kill(pid)
            except OSError:
                pass
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        pass


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def write_json(path, data):
    tmp = Path(str(path) + ".tmp")
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1, sort_keys=True, allow_nan=False)
        f.write("\n")
    os.replace(tmp, path)


REASON_KINDS = [
    ("tangled", "mesh tangled"), ("inverted", "mesh tangled"), ("solver failed", "solver failed"),
    ("exceeds force_limit", "force limit"), ("residual grew", "residual growth"),
    ("tolerance", "tolerance not reached"), ("not finite", "non-finite"), ("non-finite", "non-finite"),
    ("configuration", "configuration"), ("interrupted", "interrupted"), ("dead", "dead peer"),
    ("did not reply", "no reply"), ("timed out", "no reply"),
]


def classify(summary, exit_code, marker_state, log_tail=""):
    """outcome (completed / diverged / mesh tangled / solver failed / failed / timeout / crashed),
    reason kind, reason, step and iteration of a stop."""
    r = {"status": "", "outcome": "", "reason_kind": "", "reason": "", "stop_step": None, "stop_iteration": None}
    if marker_state == "interrupted":
        r.update(status=(summary or {}).get("status", ""), outcome="interrupted", reason_kind="study interrupted",
                 reason="stopped by Ctrl-C / SIGTERM of the study; run again to resume")
        return r
    if marker_state == "timeout":
        r.update(status=(summary or {}).get("status", ""), outcome="timeout", reason_kind="time limit")
        r["reason"] = "killed after the study's time limit"
        return r
    signalled = exit_code is None or exit_code < 0 or (exit_code >= 128)
    if summary is None or signalled:
        if summary is None and exit_code == 1 and not signalled and log_tail:
            # The launcher refused the scene before any process ran (bad key or value): no summary.
            r.update(outcome="failed", reason_kind="configuration", reason=log_tail)
            return r
        r.update(outcome="crashed", reason_kind="signal" if signalled else "no summary.json",
                 reason=f"exit code {exit_code}" + ("" if summary else ", no summary.json"))
        return r
    status, reason = summary.get("status", ""), summary.get("reason", "") or ""
    r.update(status=status, reason=reason)
    for needle, kind in REASON_KINDS:
        if needle in reason:
            r["reason_kind"] = kind
            break
    m = re.search(r"at step (\d+)", reason)
    r["stop_step"] = int(m.group(1)) if m else None
    m = re.search(r"iteration (\d+)", reason)
    r["stop_iteration"] = int(m.group(1)) if m else None
    if status == "completed":
        r["outcome"] = "completed"
    elif status == "diverged":
        r["outcome"] = r["reason_kind"] if r["reason_kind"] in ("mesh tangled", "solver failed") else "diverged"
    elif status == "failed":
        r["outcome"] = "failed"
    else:
        r["outcome"] = "crashed"
        r["reason_kind"] = "bad summary"
    return r


def log_tail(path):
    try:
        lines = [l.strip() for l in Path(path).read_text(errors="replace").splitlines() if l.strip()]
    except OSError:
        return ""
    errors = [l for l in lines if "[error]" in l]
    return re.sub(r"^\[[^]]*\] \[[^]]*\] \[error\] ", "", (errors or lines or [""])[-1])[:300]


class Runner:
    def __init__(self, study, out, fsi, jobs, quiet=False):
        self.study, self.out, self.fsi, self.jobs, self.quiet = study, Path(out), fsi, jobs, quiet
        self.runs_dir = self.out / "runs"
        self.runs_dir.mkdir(parents=True, exist_ok=True)
        self.results = {}  # name -> record
        self.running = {}  # name -> (proc, spec, start, logfile)
        self.started = 0
        self.resumed = 0
        self.total_hint = 0

    def marker(self, spec):
        return {"name": spec["name"], "scene": str(self.study.scene), "scene_sha256": self.study.scene_sha,
                "sets": spec["sets"], "combo": spec["combo"]}

    def resumable(self, spec):
        d = self.runs_dir / spec["name"]
        m = read_json(d / "study_run.json")
        s = read_json(d / "summary.json")
        if not m or not s or m.get("state") != "finished":
            return None
        if m.get("sets") != spec["sets"] or m.get("scene_sha256") != self.study.scene_sha:
            return None
        if s.get("status") not in FINISHED or sorted(s.get("overrides", [])) != sorted(spec["sets"]):
            return None
        return m

    def record(self, spec, marker):
        d = self.runs_dir / spec["name"]
        summary = read_json(d / "summary.json")
        c = classify(summary, marker.get("exit_code"), marker.get("state"), log_tail(d / "fsi.log"))
        wall = finite(((summary or {}).get("wall_time") or {}).get("total"))
        rec = {"name": spec["name"], "combo": spec["combo"], "params": spec["params"], **c,
               "exit_code": marker.get("exit_code"), "elapsed": finite(marker.get("elapsed")),
               "wall_time": wall if wall is not None else finite(marker.get("elapsed")),
               "steps": (summary or {}).get("steps"), "coupling_iterations": (summary or {}).get("coupling_iterations")}
        if rec["steps"] and rec["coupling_iterations"] is not None:
            rec["iterations_per_step"] = rec["coupling_iterations"] / rec["steps"]
        self.results[spec["name"]] = rec
        return rec

    def start(self, spec):
        d = self.runs_dir / spec["name"]
        d.mkdir(parents=True, exist_ok=True)
        for f in ("summary.json", "probes.csv", "iterations.csv"):
            (d / f).unlink(missing_ok=True)
        m = self.marker(spec)
        m["state"] = "running"
        write_json(d / "study_run.json", m)
        cmd = [self.fsi, "run", str(self.study.scene), "--out", str(d), "--force"]
        for s in spec["sets"]:
            cmd += ["--set", s]
        log = open(d / "fsi.log", "w")
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                start_new_session=True)
        self.running[spec["name"]] = (proc, spec, time.monotonic(), log)
        self.started += 1

    def finish(self, name, state):
        proc, spec, t0, log = self.running.pop(name)
        log.close()
        m = self.marker(spec)
        m.update(state=state, exit_code=proc.returncode, elapsed=time.monotonic() - t0)
        write_json(self.runs_dir / name / "study_run.json", m)
        rec = self.record(spec, m)
        self.progress(rec)
        return rec

    def progress(self, rec, resumed=False):
        if self.quiet:
            return
        n = len(self.results)
        extra = f" ({rec['reason_kind']})" if rec["reason_kind"] and rec["outcome"] != "completed" else ""
        wt = "%.2f s" % rec["wall_time"] if rec["wall_time"] is not None else "-"
        print(f"[{n}{'/' + str(self.total_hint) if self.total_hint else ''}] {rec['name']}: "
              f"{rec['outcome']}{extra}, {wt}{' (done before)' if resumed else ''}", file=sys.stderr, flush=True)

    def kill_all(self, state):
        for name in list(self.running):
            kill_tree(self.running[name][0])
            self.finish(name, state)

    def execute(self, sources):
        """Runs every spec the sources hand out, at most `jobs` at a time."""
        limit = self.study.time_limit
        while True:
            progressed = False
            while len(self.running) < self.jobs:
                spec = None
                for src in sources:
                    spec = src.next()
                    if spec is not None:
                        break
                if spec is None:
                    break
                progressed = True
                if spec["name"] in self.results:
                    src.done(spec, self.results[spec["name"]])
                    continue
                m = self.resumable(spec)
                if m is not None:
                    rec = self.record(spec, m)
                    self.resumed += 1
                    self.progress(rec, resumed=True)
                    src.done(spec, rec)
                    continue
                self.start(spec)
                spec["_source"] = src
            for name in list(self.running):
                proc, spec, t0, _ = self.running[name]
                if proc.poll() is not None:
                    spec["_source"].done(spec, self.finish(name, "finished"))
                    progressed = True
                elif time.monotonic() - t0 > limit:
                    kill_tree(proc)
                    spec["_source"].done(spec, self.finish(name, "timeout"))
                    progressed = True
            if not self.running and all(s.finished() for s in sources):
                return
            if not progressed:
                time.sleep(0.01)


class GridSource:
    def __init__(self, specs):
        self.specs = list(specs)
        self.i = 0
        self.outstanding = 0

    def next(self):
        if self.i >= len(self.specs):
            return None
        self.i += 1
        self.outstanding += 1
        return self.specs[self.i - 1]

    def done(self, spec, rec):
        self.outstanding -= 1

    def finished(self):
        return self.i >= len(self.specs) and self.outstanding == 0


class BisectionSource:
    """Largest stable value of one parameter (stable = the run completed) by bisection, for one
    combination of the other parameters. Runs `hi` first (stable: done), then `lo` if lo > 0
    (unstable: nothing stable), then midpoints until hi - lo <= tol."""

    def __init__(self, study, combo, key, lo, hi, tol):
        self.study, self.combo, self.key, self.tol = study, combo, key, tol
        self.lo, self.hi = lo, hi
        self.phase = "hi"
        self.waiting = False
        self.done_flag = False
        self.stable = None

    def _spec(self, value):
        c = dict(self.combo)
        c[self.key] = clean_value(value)
        return self.study.spec(c)

    def next(self):
        if self.waiting or self.done_flag:
            return None
        if self.phase == "hi":
            v = self.hi
        elif self.phase == "lo":
            v = self.lo
        else:
            v = 0.5 * (self.lo + self.hi)
        self.waiting = True
        return self._spec(v)

    def done(self, spec, rec):
        self.waiting = False
        v = spec["combo"][self.key]
        ok = rec["outcome"] == "completed"
        if rec["outcome"] in ("failed", "crashed"):
            self.done_flag = True  # not a stability question (bad input, a crash): stop, the table shows it
            return
        if self.phase == "hi":
            if ok:
                self.done_flag = True
                return
            self.phase = "lo" if self.lo > 0 else "mid"
        elif self.phase == "lo":
            if not ok:
                self.done_flag = True
                return
            self.phase = "mid"
        else:
            if ok:
                self.lo = v
            else:
                self.hi = v
        if self.hi - self.lo <= self.tol:
            self.done_flag = True

    def finished(self):
        return self.done_flag and not self.waiting


# ----------------------------------------------------------------------------------------------
# Analysis
# ----------------------------------------------------------------------------------------------

def read_probes(path):
    try:
        with open(path) as f:
            rows = list(csv.reader(f))
    except OSError:
        return None
    if len(rows) < 2:
        return None
    head = rows[0]
    data = {}
    for j, h in enumerate(head):
        col = []
        for r in rows[1:]:
            try:
                col.append(float(r[j]))
            except (ValueError, IndexError):
                col.append(float("nan"))
        data[h] = np.array(col)
    return data


def reference_series(study, out, ref_spec):
    """probe -> (t, y) of a reference run, or None."""
    if ref_spec is None:
        return None
    data = read_probes(Path(out) / "runs" / ref_spec["name"] / "probes.csv")
    if data is None or "time" not in data:
        return None
    return {p: (data["time"], data[p]) for p in study.probes if p in data}


def run_metrics(study, out, rec, ref_series):
    m = {}
    if rec["outcome"] != "completed" or not study.probes:
        return m
    data = read_probes(Path(out) / "runs" / rec["name"] / "probes.csv")
    if data is None or "time" not in data:
        return m
    ref = study.reference
    for p in study.probes:
        if p not in data:
            continue
        t, y = data["time"], data[p]
        if "run" in ref:
            if not ref_series or p not in ref_series:
                vals = compare(t, y, t, y, study.window, study.steady_fraction)
                vals = {k: v for k, v in vals.items() if k in ("steady", "mean", "amplitude", "frequency")}
            else:
                vals = compare(t, y, *ref_series[p], study.window, study.steady_fraction)
        elif "closed_form" in ref:
            form = (ref["closed_form"] or {}).get(p)
            if form is None:
                vals = signal_metrics(t, y, study.window, study.steady_fraction)
            else:
                tr = np.concatenate([[0.0], t]) if t[0] > 0 else t
                if form in SERIES_FORMS:
                    yr = SERIES_FORMS[form](rec["params"], tr)
                else:
                    yr = np.broadcast_to(np.asarray(evaluate(form, rec["params"], tr, f"closed form for {p}"), float),
                                         tr.shape)
                vals = compare(t, y, tr, yr, study.window, study.steady_fraction)
        elif "values" in ref:
            vals = compare_values(t, y, (ref["values"] or {}).get(p, {}), study.window, study.steady_fraction)
        else:
            vals = signal_metrics(t, y, study.window, study.steady_fraction)
        for k, v in vals.items():
            m[f"{p}.{k}"] = finite(v)
    return m


def stability_table(study, records):
    """Per (series..., x): largest parameter value whose run completed, the smallest above it that
    did not, and the closed form when named."""
    st = study.stability
    if not st:
        return []
    key, x = st["parameter"], st["x"]
    series = list(st.get("series", []))
    groups = {}
    for r in records:
        if r.get("is_reference"):
            continue
        g = tuple(r["params"].get(k) for k in series) + (r["params"].get(x),)
        others = tuple(sorted((k, v) for k, v in r["combo"].items() if k not in series and k not in (x, key)))
        groups.setdefault(g + others, []).append(r)
    rows = []
    for g, rs in sorted(groups.items(), key=lambda kv: tuple(str(v) for v in kv[0])):
        vals = sorted(rs, key=lambda r: float(r["params"][key]))
        ok = [float(r["params"][key]) for r in vals if r["outcome"] == "completed"]
        best = max(ok) if ok else None
        above = [float(r["params"][key]) for r in vals if r["outcome"] != "completed" and (best is None or
                                                                                     float(r["params"][key]) > best)]
        bad_below = [float(r["params"][key]) for r in vals if r["outcome"] != "completed" and best is not None and
                     float(r["params"][key]) < best]
        row = {k: v for k, v in zip(series + [x], g)}
        row.update({"runs": len(rs), "stable_max": best, "unstable_min": min(above) if above else None,
                    "monotonic": not bad_below})
        form = st.get("closed_form")
        if form:
            p = dict(rs[0]["params"])
            p.pop(key, None)
            v = SCALAR_FORMS[form](p) if form in SCALAR_FORMS else evaluate(form, p, what="stability.closed_form")
            row["closed_form"] = finite(v)
            row["closed_form_capped"] = finite(min(v, float(st.get("cap", 1.0)))) if finite(v) is not None else None
            if best is not None and row["closed_form"] is not None:
                row["error"] = best - row["closed_form_capped"]
                row["rel_error"] = row["error"] / row["closed_form_capped"] if row["closed_form_capped"] else None
        rows.append(row)
    return rows


def outcome_counts(records):
    c = {"cases": 0, "completed": 0, "diverged": 0, "diverged_by_reason": {}, "mesh_tangled": 0,
         "solver_failed": 0, "failed": 0, "failed_by_reason": {}, "timeouts": 0, "crashes": 0, "nan_cells": 0}
    for r in records:
        if r.get("is_reference"):
            continue
        c["cases"] += 1
        o = r["outcome"]
        if o == "completed":
            c["completed"] += 1
        elif o == "diverged":
            c["diverged"] += 1
            k = r["reason_kind"] or "other"
            c["diverged_by_reason"][k] = c["diverged_by_reason"].get(k, 0) + 1
        elif o == "mesh tangled":
            c["mesh_tangled"] += 1
        elif o == "solver failed":
            c["solver_failed"] += 1
        elif o == "failed":
            c["failed"] += 1
            k = r["reason_kind"] or "other"
            c["failed_by_reason"][k] = c["failed_by_reason"].get(k, 0) + 1
        elif o == "timeout":
            c["timeouts"] += 1
        elif o == "interrupted":
            c["interrupted"] = c.get("interrupted", 0) + 1
        else:
            c["crashes"] += 1
    return c


BASE_COLUMNS = ["name", "outcome", "status", "reason_kind", "stop_step", "stop_iteration", "exit_code", "wall_time",
                "elapsed", "steps", "coupling_iterations", "iterations_per_step"]


def write_tables(study, out, records, ref_rec):
    out = Path(out)
    param_keys = []
    for r in records:
        for k in r["combo"]:
            if k not in param_keys:
                param_keys.append(k)
    metric_keys = []
    for r in records:
        for k in r.get("metrics", {}):
            if k not in metric_keys:
                metric_keys.append(k)
    cols = ["name"] + param_keys + BASE_COLUMNS[1:] + metric_keys + ["reason"]
    rows = sorted(records, key=lambda r: (not r.get("is_reference"), r["name"]))
    tmp = out / "results.csv.tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in rows:
            line = []
            for c in cols:
                if c in param_keys:
                    v = r["combo"].get(c, r["params"].get(c))
                elif c in metric_keys:
                    v = r.get("metrics", {}).get(c)
                else:
                    v = r.get(c)
                line.append("" if v is None else (v if isinstance(v, str) else fmt_num(v)))
            w.writerow(line)
    os.replace(tmp, out / "results.csv")
    counts = outcome_counts(records)
    with open(out / "results.csv") as f:  # the promise: no NaN / inf cell, ever
        counts["nan_cells"] = sum(c.strip().lower() in ("nan", "-nan", "inf", "-inf", "+inf", "infinity")
                                  for row in csv.reader(f) for c in row)
    stab = stability_table(study, records)
    if stab:
        keys = list(stab[0].keys())
        for r in stab:
            for k in r:
                if k not in keys:
                    keys.append(k)
        with open(out / "stability.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(keys)
            for r in stab:
                w.writerow(["" if r.get(k) is None else fmt_num(r[k]) if not isinstance(r.get(k), str) else r[k]
                            for k in keys])

    def jclean(x):
        if isinstance(x, dict):
            return {k: jclean(v) for k, v in x.items() if not k.startswith("_")}
        if isinstance(x, (list, tuple)):
            return [jclean(v) for v in x]
        if isinstance(x, (bool, str)) or x is None:
            return x
        if isinstance(x, (int, np.integer)):
            return int(x)
        return finite(x)

    base = {k: v for k, v in study.base_params().items() if isinstance(v, (int, float, str, bool))}
    write_json(out / "results.json", jclean({
        "study": study.name, "description": study.description, "study_file": str(study.path),
        "scene": str(study.scene), "probes": study.probes, "reference": study.reference,
        "reference_run": ref_rec["name"] if ref_rec else None, "base_params": base,
        "varied": param_keys, "stability": study.stability, "stability_table": stab, "outcomes": counts,
        "runs": [{k: v for k, v in r.items() if k != "params"} for r in rows]}))
    write_json(out / "outcomes.json", jclean(counts))
    return counts, stab


def build_sources(study):
    combos = study.combos()
    st = study.stability or {}
    bis = st.get("bisection")
    if bis:
        lo, hi, tol = float(bis.get("lo", 0.0)), float(bis.get("hi", 1.0)), float(bis.get("tol", 0.005))
        return [BisectionSource(study, c, st["parameter"], lo, hi, tol) for c in combos], len(combos)
    specs = [study.spec(c) for c in combos]
    names = [s["name"] for s in specs]
    if len(set(names)) != len(names):
        raise StudyError("two runs of the study have the same parameters (check zip/derived)")
    return [GridSource(specs)], len(specs)


def reference_spec(study):
    """The reference run's spec, or None. A reference run with exactly the overrides of one of
    the sweep's runs *is* that run (it is run once, and plotted as the reference)."""
    ref = study.reference
    if "run" not in ref:
        return None
    combo = {k: clean_value(v) for k, v in flatten(ref["run"]).items()}
    spec = study.spec(combo, name="reference")
    if not (study.stability or {}).get("bisection"):
        for s in (study.spec(c) for c in study.combos()):
            if s["sets"] == spec["sets"]:
                return dict(s, shared=True)
    return spec


def analyse(study, out, runner_results, ref_spec):
    records = list(runner_results.values())
    ref_rec = runner_results.get(ref_spec["name"]) if ref_spec else None
    if ref_rec:
        # A run of its own is not one of the sweep's cases; a shared one is (results.json names it).
        ref_rec["is_reference"] = not ref_spec.get("shared")
    ref_series = reference_series(study, out, ref_spec) if ref_rec and ref_rec["outcome"] == "completed" else None
    for r in records:
        r["metrics"] = run_metrics(study, out, r, ref_series)
    return write_tables(study, out, records, ref_rec)


def print_counts(counts, stab, out):
    print(f"study results in {out}/results.csv ({counts['cases']} cases)", file=sys.stderr)
    parts = [f"completed {counts['completed']}", f"diverged {counts['diverged']}"]
    if counts["diverged_by_reason"]:
        parts[-1] += " (" + ", ".join(f"{k}: {v}" for k, v in sorted(counts["diverged_by_reason"].items())) + ")"
    parts += [f"mesh tangled {counts['mesh_tangled']}", f"solver failed {counts['solver_failed']}",
              f"failed {counts['failed']}", f"timeouts {counts['timeouts']}", f"crashes {counts['crashes']}"]
    print("outcomes: " + ", ".join(parts), file=sys.stderr)
    for r in stab:
        print("stability: " + ", ".join(f"{k}={fmt_num(v) if not isinstance(v, str) else v}" for k, v in r.items()),
              file=sys.stderr)


def cmd_run(args):
    study = Study(args.study)
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    copy = dict(study.raw)
    copy["scene"] = str(study.scene)  # the copy works from DIR (plot, analyse)
    (out / "study.yaml").write_text(f"# copy of {study.path}\n" + yaml.safe_dump(copy, sort_keys=False))
    fsi = args.fsi or os.environ.get("FSI_BIN") or str(REPO / "build" / "bin" / "fsi")
    if not os.access(fsi, os.X_OK):
        raise StudyError(f"fsi executable not found: {fsi} (build it, or pass --fsi)")
    jobs = max(1, args.jobs or os.cpu_count() or 1)
    runner = Runner(study, out, os.path.abspath(fsi), jobs, quiet=args.quiet)
    sources, n = build_sources(study)
    ref = reference_spec(study)
    if ref and not ref.get("shared"):
        sources.insert(0, GridSource([ref]))
        n += 1
    runner.total_hint = n if not (study.stability or {}).get("bisection") else 0
    print(f"study '{study.name}': {n} {'groups' if runner.total_hint == 0 else 'runs'} of {study.scene}, "
          f"{jobs} at a time, time limit {study.time_limit:g} s, results in {out}", file=sys.stderr)
    t0 = time.monotonic()
    interrupted = False

    def on_term(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGTERM, on_term)
    try:
        runner.execute(sources)
    except KeyboardInterrupt:
        interrupted = True
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        print(f"interrupted: stopping {len(runner.running)} running run(s)", file=sys.stderr)
        runner.kill_all("interrupted")
    finally:
        signal.signal(signal.SIGTERM, old)
    counts, stab = analyse(study, out, runner.results, ref)
    print(f"{runner.started} run(s) started, {runner.resumed} done before, {time.monotonic() - t0:.1f} s",
          file=sys.stderr)
    print_counts(counts, stab, out)
    return 130 if interrupted else 0


def cmd_analyse(args):
    out = Path(args.dir).resolve()
    study = Study(out / "study.yaml" if not args.study else args.study)
    runner = Runner(study, out, "", 1, quiet=True)
    sources, _ = build_sources(study)
    ref = reference_spec(study)
    specs = ([ref] if ref and not ref.get("shared") else [])
    for src in sources:  # grids: every spec; bisection: replay from the markers
        while not src.finished():
            s = src.next()
            if s is None:
                break
            m = read_json(out / "runs" / s["name"] / "study_run.json")
            if not m:
                break
            src.done(s, runner.record(s, m))
    for s in specs:
        m = read_json(out / "runs" / s["name"] / "study_run.json")
        if m:
            runner.record(s, m)
    counts, stab = analyse(study, out, runner.results, ref)
    print_counts(counts, stab, out)
    return 0


# ----------------------------------------------------------------------------------------------
# Plots
# ----------------------------------------------------------------------------------------------

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


def plot_work_precision(plt, d, rows, meta, cfg):
    """Error against wall time, one line per group of `lines`; `metric` is one column or a list
    of columns (one panel each, e.g. a displacement amplitude and a force frequency)."""
    probes = meta.get("probes") or []
    if not probes:
        return None
    metrics = cfg.get("metric", f"{probes[0]}.l2_rel")
    metrics = [metrics] if isinstance(metrics, str) else list(metrics)
    xkey = cfg.get("x", "wall_time")
    color_key = cfg.get("color", "coupling.algorithm")
    line_keys = cfg.get("lines", [k for k in meta.get("varied", []) if k not in ("time.dt", "fluid.mesh.size")])
    runs = [r for r in rows if r["name"] and not is_reference_row(r, meta) and num(r.get(xkey))]
    if not any(num(r.get(m)) for r in runs for m in metrics):
        return None
    fig, axes = plt.subplots(1, len(metrics), figsize=(7 if len(metrics) == 1 else 5.5 * len(metrics), 5),
                             squeeze=False)
    cyc = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    markers = "osD^v<>px*h"
    colors, mk = {}, {}
    for ax, metric in zip(axes[0], metrics):
        groups = {}
        for r in runs:
            if num(r.get(metric)) is not None:
                groups.setdefault(tuple(r.get(k, "") for k in line_keys), []).append(r)
        for g, rs in sorted(groups.items()):
            rs.sort(key=lambda r: num(r[xkey]))
            ckey = rs[0].get(color_key, "")
            colors.setdefault(ckey, cyc[len(colors) % len(cyc)])
            other = tuple(v for k, v in zip(line_keys, g) if k != color_key)
            mk.setdefault(other, markers[len(mk) % len(markers)])
            label = ", ".join(f"{ABBREV.get(k, k)}={v}" for k, v in zip(line_keys, g))
            ax.loglog([num(r[xkey]) for r in rs], [max(num(r[metric]), 1e-300) for r in rs], "-",
                      marker=mk[other], color=colors[ckey], label=label)
            for r in rs:
                if "time.dt" in r:
                    ax.annotate(f"dt={r['time.dt']}", (num(r[xkey]), num(r[metric])), fontsize=6, alpha=0.6,
                                textcoords="offset points", xytext=(3, 3))
        ax.set_xlabel("wall time [s]" if xkey == "wall_time" else xkey)
        ax.set_ylabel(metric)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, ncol=1 if len(metrics) > 1 else 2)
    title = cfg.get("title", f"{meta.get('study', '')}: error against wall time")
    if len(metrics) == 1:
        axes[0][0].set_title(title)
    else:
        fig.suptitle(title)
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
        ax.set_xlabel("time")
        ax.set_ylabel(p)
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


def main(argv=None):
    ap = argparse.ArgumentParser(prog="fsi_study.py", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run (or resume) a study")
    r.add_argument("study")
    r.add_argument("--out", default="runs/study", help="study folder (default: runs/study)")
    r.add_argument("--jobs", type=int, default=0, help="parallel runs (default: number of cores)")
    r.add_argument("--fsi", default="", help="the fsi executable (default: build/bin/fsi or $FSI_BIN)")
    r.add_argument("--quiet", action="store_true", help="no line per run")
    p = sub.add_parser("plot", help="PNGs from DIR/results.csv")
    p.add_argument("dir")
    a = sub.add_parser("analyse", help="recompute DIR/results.* from the runs on disk, running nothing")
    a.add_argument("dir")
    a.add_argument("--study", default="")
    args = ap.parse_args(argv)
    try:
        return {"run": cmd_run, "plot": cmd_plot, "analyse": cmd_analyse}[args.cmd](args)
    except StudyError as e:
        print(f"fsi_study: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
