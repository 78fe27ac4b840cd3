"""Closed forms (added-mass relaxation limit, exact SDOF solution) and the expressions of
study files (derived keys, where, closed forms, plot selections)."""
import math

import numpy as np

from .util import StudyError


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


def added_mass_monolithic(params, t):
    """The added-mass model's converged coupled solution: BDF1 of (m + m_a) a + c v + k d = F
    (F = fluid.force + solid.force) from rest, at the steps t / dt."""
    m, c, k = _p(params, "solid.mass"), _p(params, "solid.damping", 0.0), _p(params, "solid.stiffness", 0.0)
    M, dt = m + _p(params, "fluid.added_mass", 0.0), _p(params, "time.dt")
    F = _p(params, "fluid.force", 0.0) + _p(params, "solid.force", 0.0)
    steps = np.rint(np.asarray(t, float) / dt).astype(int)
    d, v, out = 0.0, 0.0, [0.0]
    for _ in range(int(steps.max(initial=0))):
        dn = (F + M * (d / (dt * dt) + v / dt) + c * d / dt) / (M / (dt * dt) + c / dt + k)
        v, d = (dn - d) / dt, dn
        out.append(d)
    return np.asarray(out)[steps]


SCALAR_FORMS = {"added_mass_beta_c": added_mass_beta_c}
SERIES_FORMS = {"sdof_exact": sdof_exact, "added_mass_monolithic": added_mass_monolithic}


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

