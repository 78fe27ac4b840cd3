"""Refusing a study whose overrides name keys the scene does not have, before anything runs.

With an `fsi` that has the `check` subcommand (`fsi check SCENE --set k=v ...`: exit 0 = valid,
1 = the errors on stderr) the launcher's own validation decides (keys and values, of the first
run and of the reference run). Without it, a best-effort check here: every overridden key must
be a key of the scene, or of one of the scenes in <repo>/configs (optional keys a scene may
leave out), else it is refused naming the closest keys."""
import difflib
import json
import os
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


# ----------------------------------------------------------------------------------------------
# `fsi check STUDY`: every case of a study against the scene schema, at the study's lines
# ----------------------------------------------------------------------------------------------

def _at(shown, node):
    return f"{shown}:{node.start_mark.line + 1}:{node.start_mark.column + 1}"


def _text(node):
    """A value as `fsi check --set` takes it: a scalar as written, anything else in flow style."""
    if isinstance(node, yaml.ScalarNode):
        return node.value
    value = yaml.safe_load(yaml.serialize(node))
    return yaml.safe_dump(value, default_flow_style=True, width=1 << 30).strip()


def _top_level(path, shown, depth=0):
    """{top-level key: (file as shown, value node)} of a study file and its `extends` chain: a key
    of this file replaces the parent's whole key, as load_study_file merges them."""
    if depth > 8:
        raise StudyError(f"{shown}: 'extends' nests too deep")
    try:
        root = yaml.compose(Path(path).read_text())
    except OSError as e:
        raise StudyError(f"cannot open study file '{shown}': {e.strerror}") from None
    except yaml.MarkedYAMLError as e:
        m = e.problem_mark
        raise StudyError(f"{shown}:{m.line + 1}:{m.column + 1}: not valid YAML: {e.problem}") from None
    if not isinstance(root, yaml.MappingNode):
        raise StudyError(f"{shown}: a study must be a YAML map")
    out = {}
    for k, v in root.value:
        if k.value == "extends":
            parent = str(v.value)
            out.update(_top_level(Path(path).parent / parent,
                                  os.path.normpath(os.path.join(os.path.dirname(shown), parent)), depth + 1))
    for k, v in root.value:
        if k.value != "extends":
            out[k.value] = (shown, v)
    return out


def _flatten_nodes(node, prefix, shown, out):
    for k, v in node.value:
        key = prefix + k.value
        if isinstance(v, yaml.MappingNode):
            _flatten_nodes(v, key + ".", shown, out)
        else:
            out.append({"key": key, "value": _text(v), "where": _at(shown, k), "key_where": _at(shown, k)})


def _varied(k, values, shown, out):
    """The values a `vary` / `zip` entry takes (a linspace/geomspace/range by its two ends)."""
    key_where = _at(shown, k)
    if isinstance(values, yaml.SequenceNode):
        for item in values.value:
            out.append({"key": k.value, "value": _text(item), "where": _at(shown, item), "key_where": key_where})
    elif isinstance(values, yaml.MappingNode) and len(values.value) == 1:
        args = values.value[0][1]
        if isinstance(args, yaml.SequenceNode):
            for item in args.value[:2]:
                out.append({"key": k.value, "value": _text(item), "where": _at(shown, item), "key_where": key_where})
    elif isinstance(values, yaml.ScalarNode):
        out.append({"key": k.value, "value": values.value, "where": key_where, "key_where": key_where})


def study_places(path, shown):
    """Every scene key a study sets, with its value and where both are written: (fixed, varied,
    derived) lists of {key, value, where, key_where}."""
    top = _top_level(path, shown)
    fixed, varied, derived = [], [], []
    if "fixed" in top and isinstance(top["fixed"][1], yaml.MappingNode):
        _flatten_nodes(top["fixed"][1], "", top["fixed"][0], fixed)
    if "vary" in top and isinstance(top["vary"][1], yaml.MappingNode):
        for k, v in top["vary"][1].value:
            _varied(k, v, top["vary"][0], varied)
    if "zip" in top and isinstance(top["zip"][1], yaml.SequenceNode):
        for group in top["zip"][1].value:
            if isinstance(group, yaml.MappingNode):
                for k, v in group.value:
                    _varied(k, v, top["zip"][0], varied)
    if "derived" in top and isinstance(top["derived"][1], yaml.MappingNode):
        for k, _ in top["derived"][1].value:
            w = _at(top["derived"][0], k)
            derived.append({"key": k.value, "value": "1", "where": w, "key_where": w})
    return fixed, varied, derived


def _fsi_check(fsi, scene, sets, placed, cases):
    """One `fsi check SCENE --cases` process: the results of every case (a list of
    (assignment, where)) on top of sets and placed."""
    cmd = [fsi, "check", str(scene), "--cases"]
    for s in sets:
        cmd += ["--set", s]
    for assignment, where in placed:
        cmd += ["--set-at", assignment, where]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=120, input=json.dumps(cases))
    try:
        return json.loads(p.stdout)
    except ValueError:
        raise StudyError(f"`{' '.join(cmd)}` did not answer ({p.returncode}): {p.stderr.strip()}") from None


def check_study(path, fsi, cli_sets=()):
    """`fsi check STUDY`: the scene with the study's `fixed` keys (and --set), then every value of
    every varied key alone on top of them, and the names of the derived keys. Returns (problems as
    "where: message" lines, keys checked, the scene as shown)."""
    from .spec import Study
    shown = str(path)
    study = Study(path)  # the study's own keys, the scene found
    scene = study.scene
    rel = os.path.relpath(scene)
    scene_shown = rel if not rel.startswith("..") else str(scene)
    fixed, varied, derived = study_places(path, shown)
    placed = [(f"{f['key']}={f['value']}", f["where"]) for f in fixed if "." in f["key"]]
    keys = [k for k in varied + derived if "." in k["key"]]  # no dot: a study variable, not a scene key
    results = _fsi_check(fsi, scene, list(cli_sets), placed,
                         [[]] + [[[f"{k['key']}={k['value']}", k["where"]]] for k in keys])
    base = results[0]
    problems = [p["text"] for p in base["problems"]]
    seen = set(problems)
    for k, result in zip(keys, results[1:]):
        is_derived = k in derived
        for p in result["problems"]:
            if p["where"] != k["where"]:
                continue
            name = p["message"].startswith("unknown") or "is only used" in p["message"]
            if is_derived and not name:
                continue  # a derived value is an expression: only its name is checked here
            text = f"{k['key_where'] if name else p['where']}: {p['message']}"
            if text not in seen:
                seen.add(text)
                problems.append(text)
    return problems, base["keys_checked"], scene_shown
