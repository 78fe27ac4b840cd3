"""The study file: parameters, combinations, run names and hashes, run sources (grid,
bisection), the reference run."""
import hashlib
import itertools
import json
import math
import re
from pathlib import Path

import numpy as np
import yaml

from .forms import evaluate
from .util import ABBREV, REPO, STUDY_KEYS, StudyError, clean_value, set_value


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
    def __init__(self, path, fork=None):
        self.path = Path(path).resolve()
        d = load_study_file(self.path)
        if fork:
            d["from"] = str(Path(fork).resolve())
        unknown = sorted(set(d) - STUDY_KEYS)
        if unknown:
            raise StudyError(f"{path}: unknown key(s) {unknown}; known: {sorted(STUDY_KEYS)}")
        self.raw = d
        self.name = str(d.get("study", self.path.stem))
        self.description = str(d.get("description", ""))
        if "scene" not in d:
            raise StudyError(f"{path}: 'scene' is required")
        self.scene = self._find(d["scene"])
        self.fork_given = d.get("from")
        self.fork = self._find_checkpoint(self.fork_given) if self.fork_given else None
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

    def _find_checkpoint(self, given):
        """`from`: a run folder (its newest checkpoint) or one checkpoint folder, relative to the
        study file or the working folder; every run of the study forks from it (fsi run --from)."""
        p = Path(str(given))
        for c in ([p] if p.is_absolute() else [self.path.parent / p, Path.cwd() / p]):
            if c.is_dir():
                return c.resolve()
        return None  # checked before running (require_fork): `fsi check` and listings do without it

    def require_fork(self):
        if self.fork_given and self.fork is None:
            raise StudyError(f"{self.path}: from '{self.fork_given}': no such run or checkpoint folder")

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
        key = {"scene": self.scene.name, "sets": sets}
        if self.fork:  # another starting state: other runs (names without `from` unchanged)
            key["from"] = str(self.fork)
        key = json.dumps(key, sort_keys=True)
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

