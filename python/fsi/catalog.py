"""What a checkout ships and what it costs: `fsi list` (the scenes and the studies with their
description, solvers, unknowns and measured wall time) and the estimates of `fsi study --dry-run`.

The wall times come from configs/catalog.json, written by `bench/catalog.py measure`: every
scene run as shipped, whole, one solver job per core (that machine, the commit and the date
are in the file); studies run whole are recorded by `bench/catalog.py study` and listed as
measured. An estimate for other settings scales the measured time per step:

    wall = start-up + (measured time per step) * steps * (h_scene / h)^2

start-up: processes, meshing, configuring (measured); steps = (time.end - start) / time.dt of the
run (start: 0, or the checkpoint's time of a run forked from one), h = fluid.mesh.size when a run overrides it (the fluid's
unknowns grow as 1/h^2; the fluid is most of the cost of every fluid scene), and by k_max / the
measured iterations per step when a run makes a fixed number of coupling iterations (tolerance 0).
Nothing else is scaled (converged iterations, solid mesh, schemes): an estimate, good to a factor
of about 2 for runs that iterate like the scene (not for other coupling schemes: constant
relaxation on FSI3 took 30x the scene's iterations; hence measured studies), and
a study's run never counts longer than its time limit (it is stopped there).
"""
import json
import math
import os
import sys
from pathlib import Path

import yaml

from .study.util import REPO

CATALOG = Path(os.environ.get("FSI_CATALOG") or REPO / "configs" / "catalog.json")  # FSI_CATALOG: tests


def load_catalog(path=None):
    """configs/catalog.json as a dict ({} when missing): {"measured": {...}, "scenes": {name: {...}}}."""
    p = Path(path) if path else CATALOG
    try:
        return json.loads(p.read_text())
    except (OSError, ValueError):
        return {}


def _get(d, dotted, default=None):
    for part in dotted.split("."):
        if not isinstance(d, dict) or part not in d:
            return default
        d = d[part]
    return d


def scene_info(path):
    """A scene file's name, description and solvers, from its YAML (nothing is meshed)."""
    path = Path(path)
    d = yaml.safe_load(path.read_text()) or {}
    fluid, solid = d.get("fluid") or {}, d.get("solid") or {}
    dt, end = _get(d, "time.dt"), _get(d, "time.end")
    steps = int(round(float(end) / float(dt))) if dt and end else None

    def solver(section, default_element):
        if not section:
            return "-"
        model = section.get("model", "?")
        if model != "fem":
            return model
        element = section.get("element", default_element)
        return f"{element}"

    return {"name": path.stem, "file": str(path), "description": str(d.get("description", "")),
            "fluid": solver(fluid, "p1p1"), "solid": solver(solid, "q4"), "steps": steps,
            "dt": dt, "end": end, "mesh_size": _get(d, "fluid.mesh.size")}


def _flat(d, prefix=""):
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(_flat(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


def scene_files():
    return sorted((REPO / "configs").glob("*.yaml"))


def study_files():
    return sorted((REPO / "studies").glob("*.yaml"))


def _number(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def estimate(scene_name, scene_values, overrides, catalog, start_time=None):
    """Estimated wall seconds of one run of `scene_name` with `overrides` ({dotted key: value}),
    or None when the scene was not measured. scene_values: the scene's own flattened values;
    start_time: where a forked run starts (its checkpoint's time)."""
    entry = (catalog.get("scenes") or {}).get(scene_name)
    if not entry or not entry.get("measured_steps"):
        return None
    startup = float(entry.get("startup_s") or 0.0)
    per_step = float(entry.get("step_s") or (float(entry["wall_s"]) - startup) / float(entry["measured_steps"]))
    dt = _number(overrides.get("time.dt", scene_values.get("time.dt")))
    end = _number(overrides.get("time.end", scene_values.get("time.end")))
    start = _number(start_time) or 0.0
    steps = max(1, int(round((end - start) / dt))) if dt and end else int(entry.get("steps") or entry["measured_steps"])
    scale = 1.0
    h0, h = _number(scene_values.get("fluid.mesh.size")), _number(overrides.get("fluid.mesh.size"))
    if h0 and h and h > 0:
        scale = (h0 / h) ** 2
    measured_its = _number(entry.get("iterations_per_step"))
    kmax = _number(overrides.get("coupling.iterations.max"))
    tolerance = _number(overrides.get("coupling.iterations.tolerance", scene_values.get("coupling.iterations.tolerance")))
    if measured_its and kmax and tolerance == 0:  # a fixed number of coupling iterations: cost in proportion
        scale *= min(kmax, max(measured_its, kmax)) / measured_its
    return startup + per_step * steps * scale


def study_estimate(study, catalog):
    """(number of runs, estimated wall seconds of all of them run one at a time, how) of a
    fsi.study.Study. A bisection counts its worst case, 2 + log2((hi - lo) / tol) runs per group."""
    from .study.spec import build_sources, reference_spec
    scene_values = study.scene_values
    name = Path(study.scene).stem
    limit = float(study.time_limit)
    st = study.stability or {}
    bis = st.get("bisection")
    runs, total, unknown = 0, 0.0, 0
    start = fork_time(study.fork)
    specs = []
    if bis:
        lo, hi, tol = float(bis.get("lo", 0.0)), float(bis.get("hi", 1.0)), float(bis.get("tol", 0.005))
        per_group = 2 + max(0, math.ceil(math.log2(max((hi - lo) / tol, 1.0))))
        for combo in study.combos():
            spec = study.spec(dict(combo, **{st["parameter"]: hi}))
            specs += [spec] * per_group
    else:
        sources, _ = build_sources(study)
        for src in sources:
            while (s := src.next()) is not None:
                specs.append(s)
                src.done(s, {"outcome": "completed"})
    ref = reference_spec(study)
    if ref and not ref.get("shared"):
        specs.append(ref)
    for s in specs:
        overrides = dict(kv.split("=", 1) for kv in s["sets"])
        overrides = {k: _yaml_value(v) for k, v in overrides.items()}
        e = estimate(name, scene_values, overrides, catalog, start)
        runs += 1
        if e is None:
            unknown += 1
            continue
        total += min(e, limit)
    how = "bisection worst case" if bis else "grid"
    return runs, (None if unknown == runs else total), unknown, how


def fork_time(path):
    """The time of the checkpoint a run forked from `path` starts at (a run folder: its newest
    checkpoint), or None."""
    if not path:
        return None
    p = Path(path)
    manifests = [p / "manifest.json"] if (p / "manifest.json").exists() else \
        sorted((p / "checkpoints").glob("step_*/manifest.json"))
    for m in reversed(manifests):
        try:
            return float(json.loads(m.read_text())["time"])
        except (OSError, ValueError, KeyError):
            continue
    return None


def _yaml_value(v):
    try:
        return yaml.safe_load(v)
    except yaml.YAMLError:
        return v


def duration(seconds):
    """12 s, 3.4 min, 1.2 h."""
    if seconds is None:
        return "not measured"
    if seconds < 1:
        return "< 1 s"
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def _unknowns(entry):
    if not entry:
        return ""
    parts = []
    if entry.get("fluid_unknowns"):
        parts.append(f"{entry['fluid_unknowns']:,} fluid")
    if entry.get("solid_unknowns"):
        parts.append(f"{entry['solid_unknowns']:,} solid")
    return " + ".join(parts)


def rows(catalog):
    """The scenes and the studies as dicts (`fsi list --json`)."""
    from .study.spec import Study
    from .study.util import StudyError
    scenes = []
    for f in scene_files():
        info = scene_info(f)
        entry = (catalog.get("scenes") or {}).get(info["name"])
        values = _flat(yaml.safe_load(Path(f).read_text()) or {})
        info["wall_s"] = estimate(info["name"], values, {}, catalog)  # the scene as it is now (its steps)
        info["measured"] = entry
        scenes.append(info)
    studies = []
    for f in study_files():
        row = {"name": f.stem, "file": str(f)}
        try:
            s = Study(f)
            runs, total, unknown, how = study_estimate(s, catalog)
            row.update(description=s.description, scene=Path(s.scene).stem, runs=runs, estimate_s=total,
                       not_measured=unknown, count=how, time_limit=s.time_limit)
            whole = (catalog.get("studies") or {}).get(f.stem)
            if whole and (how != "grid" or whole.get("runs") == runs):  # measured whole (bench/catalog.py study)
                row["measured_s"] = whole.get("wall_s")
        except StudyError as e:
            row.update(description="", error=str(e))
        studies.append(row)
    return {"measured": catalog.get("measured"), "scenes": scenes, "studies": studies}


def _short(text, n):
    return text if len(text) <= n else text[: n - 3] + "..."


def print_list(data, out=sys.stdout):
    m = data.get("measured") or {}
    where = f"measured on {m.get('machine', '?')}, {m.get('date', '?')}" if m else "configs/catalog.json missing"
    print(f"Scenes (configs/; fsi run configs/NAME.yaml; wall time of the whole run {where}):", file=out)
    print(f"  {'NAME':<14} {'FLUID':<9} {'SOLID':<7} {'UNKNOWNS':<26} {'STEPS':>6} {'WALL':>12}  DESCRIPTION",
          file=out)
    for s in data["scenes"]:
        wall = duration(s["wall_s"]) + ("*" if (s["measured"] or {}).get("extrapolated") else "")
        print(f"  {s['name']:<14} {s['fluid']:<9} {s['solid']:<7} {_unknowns(s['measured']):<26} "
              f"{s['steps'] or '':>6} {wall:>12}  {_short(s['description'], 70)}", file=out)
    if any((s["measured"] or {}).get("extrapolated") for s in data["scenes"]):
        print("  * extrapolated from the run's first minutes: a long coupled run's developed phase costs more per "
              "step (FSI2 P2/P1: 2.3x), so these are low", file=out)
    print("\nStudies (studies/; fsi study studies/NAME.yaml --out DIR; estimate: the runs one after the other, "
          "each capped at the study's time limit; divide by --jobs):", file=out)
    print(f"  {'NAME':<18} {'SCENE':<12} {'RUNS':>5} {'ESTIMATE':>12}  DESCRIPTION", file=out)
    for s in data["studies"]:
        if "error" in s:
            print(f"  {s['name']:<18} invalid: {s['error']}", file=out)
            continue
        runs = f"<={s['runs']}" if s["count"] != "grid" else str(s["runs"])
        if s.get("measured_s") is not None:
            est = duration(s["measured_s"]) + " m"
        else:
            est = duration(s["estimate_s"]) + ("*" if s["not_measured"] and s["estimate_s"] is not None else "")
        print(f"  {s['name']:<18} {s['scene']:<12} {runs:>5} {est:>12}  {_short(s['description'], 70)}", file=out)
    if any(s.get("measured_s") is not None for s in data["studies"]):
        print("  m: the whole study measured on the catalog's machine (bench/catalog.py study), not estimated",
              file=out)
    if any(s.get("not_measured") and s.get("estimate_s") is not None for s in data["studies"]):
        print("  * some runs of the study have no measured scene and are not counted", file=out)


def main(argv=None):
    import argparse
    ap = argparse.ArgumentParser(prog="fsi list", description="the scenes and studies of this checkout, with "
                                 "their solvers, unknowns and measured wall times")
    ap.add_argument("--json", action="store_true", help="print JSON instead of the table")
    ap.add_argument("--catalog", default="", help="the measured durations (default: configs/catalog.json)")
    args = ap.parse_args(argv)
    data = rows(load_catalog(args.catalog or None))
    if args.json:
        json.dump(data, sys.stdout, indent=1, default=str)
        print()
    else:
        print_list(data)
    return 0
