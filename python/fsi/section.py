"""A strict reader of a scene section for external solvers: every key read with its type and
range checked, and the keys nobody read named (as solid_server and fluid_server refuse them).

    from fsi.section import Section, SceneError
    s = Section(section, "solid")            # the dict configure() gets, and its scene path
    E = s.child("material").number("youngs_modulus", required=True, positive=True)
    s.check_all_used(ignored=("model",))     # SceneError: unknown key(s) in 'solid': ...

A SceneError is a ValueError whose message names the key by its scene path; fsi.server
answers it as INVALID_ARGUMENT, so the user sees the key. Pure Python: no protocol imported.
"""
import math


class SceneError(ValueError):
    """A bad key in a scene section; the message names it by its scene path (the server answers
    INVALID_ARGUMENT with it)."""


def _as_number(v):
    """A YAML number; PyYAML (YAML 1.1) reads 0.5e6 or 1e-8 as a string where yaml-cpp reads a
    number, so a string that is a plain decimal number counts as one."""
    if isinstance(v, str):
        try:
            return float(v)
        except ValueError:
            return v
    return v


class Section:
    """A dict with the path of its keys for messages, and a record of the keys read."""

    def __init__(self, data, where):
        if not isinstance(data, dict):
            raise SceneError(f"'{where}' must be a mapping, got {data!r}")
        self.data, self.where, self.used = data, where, set()

    def key(self, name):
        return f"{self.where}.{name}"

    def get(self, name, default=None, required=False):
        self.used.add(name)
        if name not in self.data or self.data[name] is None:
            if required:
                raise SceneError(f"'{self.key(name)}' is required but missing")
            return default
        return self.data[name]

    def number(self, name, default=None, required=False, positive=False, minimum=None):
        v = self.get(name, default, required)
        if v is None:
            return None
        v = _as_number(v)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise SceneError(f"'{self.key(name)}' must be a finite number, got {v!r}")
        if positive and not v > 0:
            raise SceneError(f"'{self.key(name)}' must be positive, got {v!r}")
        if minimum is not None and v < minimum:
            raise SceneError(f"'{self.key(name)}' must be >= {minimum}, got {v!r}")
        return float(v)

    def integer(self, name, default=None, minimum=None):
        v = self.get(name, default)
        if isinstance(v, bool) or not isinstance(v, int) or (minimum is not None and v < minimum):
            raise SceneError(f"'{self.key(name)}' must be an integer" + (f" >= {minimum}" if minimum is not None else "")
                             + f", got {v!r}")
        return v

    def vector(self, name, dim, default=None, required=False):
        """A list of `dim` finite numbers ([x, y] in 2D, [x, y, z] in 3D)."""
        v = self.get(name, default, required)
        if isinstance(v, (list, tuple)):
            v = [_as_number(x) for x in v]
        if (not isinstance(v, (list, tuple)) or len(v) != dim
                or any(isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x) for x in v)):
            what = "[x, y] (two finite numbers)" if dim == 2 else "[x, y, z] (three finite numbers)"
            raise SceneError(f"'{self.key(name)}' must be {what}, got {v!r}")
        return [float(x) for x in v]

    def choice(self, name, default, allowed):
        v = self.get(name, default)
        if v not in allowed:
            raise SceneError(f"'{self.key(name)}' must be one of {', '.join(map(str, allowed))}, got {v!r}")
        return v

    def names(self, name):
        v = self.get(name, [])
        v = [v] if isinstance(v, str) else v
        if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
            raise SceneError(f"'{self.key(name)}' must be a facet set name or a list of names, got {v!r}")
        return v

    def child(self, name):
        v = self.get(name, {})
        return Section(v or {}, self.key(name))

    def check_all_used(self, ignored=()):
        unknown = sorted(set(self.data) - self.used - set(ignored))
        if unknown:
            raise SceneError(f"unknown key(s) in '{self.where}': {', '.join(unknown)}")
