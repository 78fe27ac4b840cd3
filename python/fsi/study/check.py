"""Refusing a study whose overrides name keys the scene does not have, before anything runs.

With an `fsi` that has the `check` subcommand (`fsi check SCENE --set k=v ...`: exit 0 = valid,
1 = the errors on stderr) the launcher's own validation decides (keys and values, of the first
run and of the reference run). Without it, a best-effort check here: every overridden key must
be a key of the scene, or of one of the scenes in <repo>/configs (optional keys a scene may
leave out), else it is refused naming the closest keys."""
import difflib
import re
import subprocess
from pathlib import Path

import yaml

from .spec import flatten
from .util import REPO, StudyError

_HAS_CHECK = {}


def fsi_has_check(fsi):
    """True when `fsi check --help` exits 0 and is the help of a `check` subcommand (an fsi
    without it prints its general help with exit 0 too)."""
    if fsi not in _HAS_CHECK:
        try:
            p = subprocess.run([fsi, "check", "--help"], capture_output=True, text=True, timeout=20,
                               stdin=subprocess.DEVNULL)
            text = p.stdout + p.stderr
            _HAS_CHECK[fsi] = p.returncode == 0 and bool(re.search(r"^Usage:.*\bcheck\b", text, re.M))
        except (OSError, subprocess.TimeoutExpired):
            _HAS_CHECK[fsi] = False
    return _HAS_CHECK[fsi]


def known_keys(scene_values):
    keys = set(scene_values)
    for f in sorted((REPO / "configs").glob("*.yaml")):
        try:
            keys |= set(flatten(yaml.safe_load(f.read_text()) or {}))
        except (OSError, yaml.YAMLError, AttributeError):
            continue
    return keys


def origin(study, key, cli_sets):
    if key in cli_sets:
        return "--set"
    for what in ("vary", "derived"):
        if key in getattr(study, what):
            return what
    if any(key in g for g in study.zip):
        return "zip"
    if key in study.fixed:
        return "fixed"
    return "reference.run"


def check_overrides(study, specs, fsi, cli_sets=()):
    """Raises StudyError when an override of the specs is not a key of the scene. Returns how
    the check was made: 'fsi check' or 'best effort'."""
    if fsi and fsi_has_check(fsi):
        for spec in specs:
            cmd = [fsi, "check", str(study.scene)]
            for s in spec["sets"]:
                cmd += ["--set", s]
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=60, stdin=subprocess.DEVNULL)
            if p.returncode != 0:
                raise StudyError(f"`fsi check` refuses the overrides of run {spec['name']} on {study.scene}:\n"
                                 + (p.stderr or p.stdout).strip())
        return "fsi check"
    keys = sorted({s.split("=", 1)[0] for spec in specs for s in spec["sets"]})
    known = known_keys(study.scene_values)
    problems = []
    for k in keys:
        if k in known:
            continue
        close = difflib.get_close_matches(k, sorted(study.scene_values), n=3, cutoff=0.6) or \
            difflib.get_close_matches(k, sorted(known), n=3, cutoff=0.6)
        hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
        problems.append(f"{origin(study, k, cli_sets)} key '{k}' is not a key of the scene {Path(study.scene).name}{hint}")
    if problems:
        raise StudyError("unknown key(s), nothing was run:\n  " + "\n  ".join(problems))
    return "best effort"
