#!/usr/bin/python3
"""Measure what every shipped scene costs, for `fsi list` and `fsi study --dry-run`: writes
configs/catalog.json.

Usage:
  /usr/bin/python3 bench/catalog.py measure [SCENE ...] [--out DIR] [--max-wall S] [--fsi PATH]
  /usr/bin/python3 bench/catalog.py study STUDY_DIR ...      whole studies measured (their folders)
  /usr/bin/python3 bench/catalog.py compare RUN_DIR ...     estimates against runs' measured wall times

measure: each scene (default: every configs/*.yaml) run as shipped (`fsi run configs/S.yaml
--out DIR/S --force`, one after the other: one solver job), its wall time, steps, coupling
iterations and unknowns (from the servers' logs) written into configs/catalog.json with the
machine, the commit and the date. A scene still running after --max-wall seconds (default 600)
is stopped (Ctrl-C, its folder stays consistent) and its whole-run time extrapolated from the
steps done (marked `extrapolated`). Run it on an otherwise idle machine.

refit: the cost model (start-up, seconds per step) of the entries from their run folders in --out.

study: whole studies measured from their finished folders (`fsi study ... --out DIR`): the runs'
elapsed seconds summed, recorded when the folder ran the study that studies/ holds now; `fsi
list` shows those instead of an estimate.

compare: for finished runs (summary.json with the scene and its overrides), the catalog's
estimate against the run's own wall time (a fork's own segment), and the ratio.
"""
import argparse
import csv
import datetime
import json
import os
import platform
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))
from fsi import catalog  # noqa: E402


def machine():
    model = platform.processor() or "?"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores"


def commit():
    try:
        return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.TimeoutExpired):
        return "?"


def unknowns(run):
    """(fluid unknowns, solid unknowns) from the servers' logs, None where there is no such server."""
    def find(log, pattern):
        try:
            m = re.search(pattern, (run / log).read_text(errors="replace"))
            return int(m.group(1)) if m else None
        except OSError:
            return None
    fluid = find("fluid_server.log", r"(\d+) unknowns")
    solid = find("solid_server.log", r"(\d+) free dofs")
    if solid is None and (run / "solid_server.log").exists():
        solid = find("solid_server.log", r"(\d+) dofs?\b") or 1
    return fluid, solid


def cost_model(run, elapsed, steps_done):
    """(start-up seconds, seconds per step) of a finished or stopped run: the mean step of
    timing.csv after the first (coupled runs) and the rest of the elapsed time as start-up
    (processes, meshing, configuring); a standalone run without timing.csv: the summary's
    setup_seconds."""
    try:
        with open(run / "timing.csv") as f:
            walls = [float(r["wall"]) for r in csv.DictReader(f)]
    except (OSError, KeyError, ValueError):
        walls = []
    if len(walls) >= 3:  # the mean step after the first (which carries the start-up)
        step = (walls[-1] - walls[0]) / (len(walls) - 1)
        return max(0.0, elapsed - step * steps_done), step
    try:
        setup = float(json.loads((run / "summary.json").read_text()).get("setup_seconds") or 0.0)
    except (OSError, ValueError):
        setup = 0.0
    setup = min(setup, elapsed)
    return setup, (elapsed - setup) / max(1, steps_done)


def measure_one(fsi, scene, out, max_wall):
    run = out / scene.stem
    cmd = [fsi, "run", str(scene), "--out", str(run), "--force"]
    print(f"{scene.stem}: {' '.join(cmd)}", flush=True)
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
                         start_new_session=True)
    stopped = False
    try:
        p.wait(timeout=max_wall)
    except subprocess.TimeoutExpired:
        stopped = True
        os.killpg(p.pid, signal.SIGINT)  # a clean stop: the run writes its summary
        try:
            p.wait(timeout=120)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
    wall = time.monotonic() - t0
    try:
        summary = json.loads((run / "summary.json").read_text())
    except (OSError, ValueError):
        print(f"  no summary.json: not recorded", flush=True)
        return None
    info = catalog.scene_info(scene)
    steps_done = int(summary.get("steps") or 0)
    if steps_done == 0:
        print(f"  {summary.get('status')}, no step: not recorded", flush=True)
        return None
    total_steps = info["steps"] or steps_done
    fluid, solid = unknowns(run)
    iterations = summary.get("coupling_iterations")
    startup, step = cost_model(run, wall, steps_done)
    entry = {"wall_s": round(wall if not stopped else startup + step * total_steps, 2),
             "startup_s": round(startup, 3), "step_s": round(step, 6),
             "measured_steps": steps_done if not stopped else total_steps,
             "steps": total_steps, "status": summary.get("status"),
             "iterations_per_step": round(iterations / steps_done, 2) if iterations else None,
             "fluid_unknowns": fluid, "solid_unknowns": solid}
    if stopped:
        entry["extrapolated"] = f"from {steps_done} of {total_steps} steps in {wall:.0f} s"
    print(f"  {entry}", flush=True)
    return entry


def cmd_measure(a):
    scenes = [ROOT / "configs" / (s if s.endswith(".yaml") else s + ".yaml") for s in a.scenes] or \
        catalog.scene_files()
    out = Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    data = catalog.load_catalog()
    data.setdefault("scenes", {})
    for scene in scenes:
        entry = measure_one(a.fsi, scene, out, a.max_wall)
        if entry is None:
            continue
        data["scenes"][scene.stem] = entry
        data["measured"] = {"machine": machine(), "date": datetime.date.today().isoformat(), "commit": commit(),
                            "how": "bench/catalog.py measure: each scene as shipped, one solver job per core"}
        catalog.CATALOG.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")  # after every scene
    return 0


def _resolved(study_dir, key, value):
    """A study's scene / from path made absolute (a study folder's copy holds them resolved)."""
    if key in ("scene", "from") and isinstance(value, str):
        return str((Path(study_dir) / value).resolve())  # an absolute value stays itself, normalised
    return value


def cmd_study(a):
    """Whole studies measured: each folder's runs (results.json, their elapsed seconds summed:
    one run after the other) recorded under studies.NAME when the folder's study is the one in
    studies/ now (the same keys and values, paths resolved); otherwise refused and left out."""
    import yaml
    data = catalog.load_catalog()
    data.setdefault("studies", {})
    rc = 0
    for folder in a.folders:
        folder = Path(folder)
        ran = yaml.safe_load((folder / "study.yaml").read_text())
        name = ran.get("study")
        shipped = Path(a.studies) / f"{name}.yaml"
        if not shipped.exists():
            print(f"{folder}: study '{name}' is not in {a.studies}")
            rc = 1
            continue
        now = yaml.safe_load(shipped.read_text())
        differ = sorted(k for k in set(ran) | set(now)
                        if _resolved(shipped.parent, k, now.get(k)) != _resolved(folder, k, ran.get(k)))
        if differ:
            print(f"{folder}: not the study of {shipped} now (keys {', '.join(differ)} differ): not recorded")
            rc = 1
            continue
        runs = json.loads((folder / "results.json").read_text())["runs"]
        wall = sum(float(r.get("elapsed") or 0.0) for r in runs)
        data["studies"][name] = {"runs": len(runs), "wall_s": round(wall, 1), "date": datetime.date.fromtimestamp(
            (folder / "results.json").stat().st_mtime).isoformat(), "commit": commit()}
        print(f"{name}: {len(runs)} runs, {wall:.1f} s one after the other")
    catalog.CATALOG.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    return rc


def cmd_refit(a):
    """The cost model (start-up, time per step) of catalog entries from their run folders in --out
    (a catalog measured before the model was recorded)."""
    data = catalog.load_catalog()
    out = Path(a.out)
    for name, e in data.get("scenes", {}).items():
        run = out / name
        if not (run / "summary.json").exists():
            continue
        m = re.search(r"from (\d+) of \d+ steps in ([\d.]+) s", e.get("extrapolated", ""))
        elapsed, done = (float(m.group(2)), int(m.group(1))) if m else (float(e["wall_s"]), int(e["measured_steps"]))
        startup, step = cost_model(run, elapsed, done)
        e["startup_s"], e["step_s"] = round(startup, 3), round(step, 6)
        if m:
            e["wall_s"] = round(startup + step * int(e["steps"]), 2)
        print(f"{name:14s} start-up {startup:7.2f} s, {step:.4g} s per step, whole run {e['wall_s']:.1f} s")
    catalog.CATALOG.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    return 0


def cmd_compare(a):
    data = catalog.load_catalog()
    import yaml
    print(f"{'run':<50} {'scene':<14} {'measured':>10} {'estimate':>10} {'ratio':>6}")
    for r in a.runs:
        s = json.loads((Path(r) / "summary.json").read_text())
        scene = Path(s["scene_file"])
        if not scene.is_absolute():
            scene = ROOT / scene
        values = catalog._flat(yaml.safe_load(scene.read_text()))
        overrides = {k: yaml.safe_load(v) for k, v in (o.split("=", 1) for o in s.get("overrides", []))}
        forked = Path(r) / "forked_from.json"
        own_from = json.loads(forked.read_text()).get("step", 0) if forked.exists() else 0
        # a fork: its own segment only (its summary also carries the original's time and steps)
        wall = s["wall_time"]["total"] + (0.0 if forked.exists() else float(s.get("wall_time_earlier_segments") or 0))
        e = catalog.estimate(scene.stem, values, overrides, data)
        if e is not None and s.get("steps"):
            dt = float(overrides.get("time.dt", values.get("time.dt")))
            end = float(overrides.get("time.end", values.get("time.end")))
            e *= (s["steps"] - own_from) / max(1, round(end / dt))  # the steps this run made
        ratio = f"{e / wall:.2f}" if e else "-"
        print(f"{r[-50:]:<50} {scene.stem:<14} {wall:>9.1f}s {e or 0:>9.1f}s {ratio:>6}")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    m = sub.add_parser("measure")
    m.add_argument("scenes", nargs="*")
    m.add_argument("--out", default=str(ROOT / "runs" / "catalog"))
    m.add_argument("--max-wall", type=float, default=600.0)
    m.add_argument("--fsi", default=os.environ.get("FSI_BIN", str(ROOT / "build" / "bin")) + "/fsi")
    r = sub.add_parser("refit")
    r.add_argument("--out", default=str(ROOT / "runs" / "catalog"))
    st = sub.add_parser("study")
    st.add_argument("folders", nargs="+")
    st.add_argument("--studies", default=str(ROOT / "studies"), help="where the shipped studies are")
    c = sub.add_parser("compare")
    c.add_argument("runs", nargs="+")
    a = ap.parse_args()
    return {"measure": cmd_measure, "compare": cmd_compare, "refit": cmd_refit, "study": cmd_study}[a.cmd](a)


if __name__ == "__main__":
    sys.exit(main())
