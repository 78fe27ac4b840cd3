#!/usr/bin/env python3
"""Error against wall time of the two fluid elements, P1/P1 SUPG/PSPG and Taylor-Hood P2/P1,
on DFG 2D-1 (steady), DFG 2D-2 (periodic) and DFG 2D-3 (John 2004).

Usage (from anywhere; paths default to the repository of this script):
  python3 bench/fluid/element_benchmark.py [--fsi build/bin/fsi] [--out out/element_benchmark]
      [--cases 2d1 2d2 2d3] [--elements p1p1 p2p1] [--levels 3] [--repeat 3] [--window 2.0]
      [--end T] [--set KEY=VALUE ...] [--reuse] [--plot-only]

Runs: one `fsi run SCENE --out OUT/RUN --force` at a time, OPENBLAS_NUM_THREADS=1, each in its
own subdirectory of OUT (its output in OUT/RUN/fsi_run.log). The wall time is that of the whole process,
measured here:
  2d1  P1/P1 configs/dfg_2d1.yaml and P2/P1 configs/dfg_2d1_p2p1.yaml at three meshes each
       (--levels N: the N coarsest); one run meshes (the mesh cache, ~/.cache/fsi/meshes),
       then --repeat N timed runs, median. Errors of C_D, C_L, dp against Schafer-Turek.
  2d2  configs/dfg_2d2.yaml / dfg_2d2_p2p1.yaml to t = 10; C_D,max, C_L,max and
       St = f_lift D / U_bar over the last --window seconds (periodic_stats.py). Wall time also
       per simulated second.
  2d3  configs/dfg_2d3.yaml (P2/P1) and the same scene with P1/P1 settings (see SCENES); the
       maxima, their times and dp(8) from dfg_2d3_stats.py.
--end T shortens 2d2 and 2d3 (smoke tests; their run directories get an _endT suffix);
--set KEY=VALUE goes to every run (after the benchmark's own --set, so it wins).
--reuse takes a run whose directory holds a completed summary.json, a probes.csv reaching the
end time and this script's benchmark_run.json with the same command (its recorded wall times).

Writes OUT/table.md (printed too), OUT/results.json and OUT/error_vs_wall_time.png (needs
matplotlib, e.g. the system /usr/bin/python3; without it the plot is skipped with a message),
each holding the runs of this invocation only: after runs of subsets, one invocation of the
whole set with --reuse gathers them without running again.
--plot-only rewrites the table and the plot from OUT/results.json without running anything.
Progress goes to stderr.
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
import dfg_2d3_stats  # noqa: E402
import periodic_stats  # noqa: E402

ELEMENTS = ("p1p1", "p2p1")
CASES = ("2d1", "2d2", "2d3")
ELEMENT_LABEL = {"p1p1": "P1/P1", "p2p1": "P2/P1"}
CASE_TITLE = {"2d1": "DFG 2D-1 (Re 20, steady)", "2d2": "DFG 2D-2 (Re 100, periodic)",
              "2d3": "DFG 2D-3 (John 2004)"}

# DFG 2D-1: the reference values of dfg_2d1_refinement.py.
REF_2D1 = {"cd": 5.57953523384, "cl": 0.010618948146, "dp": 0.11752016697}
# (far size h, cylinder size hc) per element, coarse to fine.
LEVELS_2D1 = {"p1p1": [(0.04, 0.005), (0.02, 0.0025), (0.01, 0.00125)],
              "p2p1": [(0.06, 0.008), (0.04, 0.005), (0.02, 0.0025)]}

# DFG 2D-2: the 1996 paper (Schafer & Turek) gives only intervals, centred at C_D,max 3.23,
# C_L,max 1.00, St 0.300. The primary reference here is the FEATFLOW level-6 series as
# extracted by third parties (not a number printed in the 1996 paper, nor one published with
# the FEATFLOW data by its authors); the errors against the interval centres are given too.
REF_2D2 = {"cd_max": 3.22739, "cl_max": 0.98658, "strouhal": 0.30184}
CENTRES_2D2 = {"cd_max": 3.23, "cl_max": 1.00, "strouhal": 0.300}
STROUHAL_SCALE = 0.1  # D / U_bar = 0.1 / 1.0
END = {"2d2": 10.0, "2d3": 8.0}  # simulated time of the scenes

# (scene relative to the repository, the benchmark's own --set) per (case, element).
SCENES = {
    ("2d1", "p1p1"): ("configs/dfg_2d1.yaml", ["fluid.output.vtk_every=0"]),
    ("2d1", "p2p1"): ("configs/dfg_2d1_p2p1.yaml", ["fluid.output.vtk_every=0"]),
    ("2d2", "p1p1"): ("configs/dfg_2d2.yaml", []),
    ("2d2", "p2p1"): ("configs/dfg_2d2_p2p1.yaml", []),
    ("2d3", "p2p1"): ("configs/dfg_2d3.yaml", []),
    ("2d3", "p1p1"): ("configs/dfg_2d3.yaml", ["fluid.element=p1p1", "fluid.mesh.size=0.02",
                                              "fluid.mesh.parameters.hc=0.0025", "time.dt=0.0025"]),
}

# Quantities per case: (key, label, kind); kind "%" = percent error of a value (plotted),
# "s" = absolute error of a time in seconds (table only).
QUANTITIES = {
    "2d1": [("cd", "C_D", "%"), ("cl", "C_L", "%"), ("dp", "dp", "%")],
    "2d2": [("cd_max", "C_D,max", "%"), ("cl_max", "C_L,max", "%"), ("strouhal", "St", "%"),
            ("cd_max_centre", "C_D,max vs 3.23", "%"), ("cl_max_centre", "C_L,max vs 1.00", "%"),
            ("strouhal_centre", "St vs 0.300", "%")],
    "2d3": [("cd_max", "C_D,max", "%"), ("t_cd_max", "t(C_D,max)", "s"), ("cl_max", "C_L,max", "%"),
            ("t_cl_max", "t(C_L,max)", "s"), ("dp_final", "dp(8)", "%")],
}


class BenchmarkError(Exception):
    pass


def log(msg):
    print(f"element_benchmark: {msg}", file=sys.stderr, flush=True)


# ---------------------------------------------------------------- pure functions

def percent_error(value, ref):
    """100 (value - ref) / |ref|; None when the value is missing or not finite."""
    if value is None or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return 100.0 * (value - ref) / abs(ref)


def steady_errors(summary):
    """DFG 2D-1 values (final fluid.cd, fluid.cl, fluid.dp of a summary.json) and their percent errors."""
    final = summary.get("final", {})
    missing = [k for k in ("fluid.cd", "fluid.cl", "fluid.dp") if k not in final] + \
              [k for k in ("dofs",) if k not in summary]
    if missing:
        raise BenchmarkError(f"summary.json has no {', '.join(missing)}")
    values = {k: float(final["fluid." + k]) for k in REF_2D1}
    errors = {k: percent_error(values[k], REF_2D1[k]) for k in REF_2D1}
    return values, errors


def periodic_errors(t, cd, cl, window):
    """DFG 2D-2: C_D,max, C_L,max (periodic_stats.stats over whole periods of the last `window`
    seconds) and St = f_lift * D / U_bar, with percent errors against REF_2D2 (key) and the 1996
    interval centres (key_centre)."""
    t_end = t[-1]
    idx = [i for i, ti in enumerate(t) if ti >= t_end - window - 1e-12]
    tw = [t[i] for i in idx]
    s_cd = periodic_stats.stats(tw, [cd[i] for i in idx])
    s_cl = periodic_stats.stats(tw, [cl[i] for i in idx])
    values = {"cd_max": s_cd["max"], "cl_max": s_cl["max"], "strouhal": s_cl["frequency"] * STROUHAL_SCALE,
              "frequency": s_cl["frequency"], "periods": s_cl["periods"], "window": window, "t_end": t_end}
    # The maxima refined by a parabola through the top sample and its neighbours (information only).
    values["cd_max_refined"] = dfg_2d3_stats.refined_max(tw, [cd[i] for i in idx])[1]
    values["cl_max_refined"] = dfg_2d3_stats.refined_max(tw, [cl[i] for i in idx])[1]
    errors = {}
    for k in REF_2D2:
        errors[k] = percent_error(values[k], REF_2D2[k])
        errors[k + "_centre"] = percent_error(values[k], CENTRES_2D2[k])
    return values, errors


def john_errors(r):
    """DFG 2D-3 values and errors from a dfg_2d3_stats.compute() result."""
    values = {k: r[k] for k in ("cd_max", "t_cd_max", "cl_max", "t_cl_max", "dp_final", "dp_time", "t_end")}
    e = r["errors"]
    errors = {"cd_max": e["cd_max_percent"], "t_cd_max": e["t_cd_max"], "cl_max": e["cl_max_percent"],
              "t_cl_max": e["t_cl_max"], "dp_final": e["dp_final_percent"]}
    return values, errors


def _cell(v, spec):
    return "n/a" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, spec)


def format_table(results):
    """Markdown: one table per case (columns: case, element, mesh, unknowns, wall s, for the
    time-dependent cases s per simulated s, then every error)."""
    out = []
    for case in CASES:
        rows = [r for r in results if r["case"] == case]
        if not rows:
            continue
        q = QUANTITIES[case]
        timed = case != "2d1"
        head = ["case", "element", "mesh", "unknowns", "wall s" if timed else "wall s (median)"]
        if timed:
            head.append("s per simulated s")
        head += [f"err {label} [{'%' if kind == '%' else 's'}]" for _, label, kind in q]
        out.append(f"### {CASE_TITLE[case]}\n")
        out.append("| " + " | ".join(head) + " |")
        out.append("|" + "---|" * len(head))
        for r in rows:
            cells = [case, ELEMENT_LABEL.get(r["element"], r["element"]), r.get("mesh", "")]
            if r.get("status") != "ok":
                cells += ["failed: " + str(r.get("error", "?")).splitlines()[0][:120]]
                cells += [""] * (len(head) - len(cells))
            else:
                cells += [str(r["unknowns"]), _cell(r["wall_seconds"], ".2f")]
                if timed:
                    cells.append(_cell(r.get("wall_per_simulated_second"), ".2f"))
                for k, _, kind in q:
                    cells.append(_cell(r["errors"].get(k), "+.3f" if kind == "%" else "+.5f"))
            out.append("| " + " | ".join(cells) + " |")
        out.append("")
    return "\n".join(out)


def _json_clean(x):
    """NaN / inf -> None, so results.json is standard JSON."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _json_clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_json_clean(v) for v in x]
    return x


# ---------------------------------------------------------------- runs

def scene_value(scene, sets, dotted):
    """A scene value after the --set overrides (for the mesh label); None if unknown."""
    for kv in reversed(sets):
        k, _, v = kv.partition("=")
        if k == dotted:
            return v
    try:
        import yaml
        node = yaml.safe_load(open(scene))
        for part in dotted.split("."):
            node = node[part]
        return node
    except Exception:
        return None


def plan(a):
    """The runs: dicts with case, element, name, scene, sets, mesh, end (None when steady)."""
    runs = []
    for case in a.cases:
        for element in a.elements:
            rel, own = SCENES[(case, element)]
            scene = str(ROOT / rel)
            if case == "2d1":
                for h, hc in LEVELS_2D1[element][: a.levels]:
                    sets = own + [f"fluid.mesh.size={h}", f"fluid.mesh.parameters.hc={hc}"] + a.set
                    runs.append({"case": case, "element": element, "name": f"2d1_{element}_h{h:g}_hc{hc:g}",
                                 "scene": scene, "sets": sets, "mesh": f"h {h:g}, hc {hc:g}", "end": None})
            else:
                sets = list(own)
                end = END[case]
                name = f"{case}_{element}"
                if a.end is not None:
                    end = a.end
                    sets.append(f"time.end={a.end:g}")
                    name += f"_end{a.end:g}"
                sets += a.set
                h = scene_value(scene, sets, "fluid.mesh.size")
                hc = scene_value(scene, sets, "fluid.mesh.parameters.hc")
                mesh = f"h {h}, hc {hc}" if h is not None and hc is not None else "scene mesh"
                runs.append({"case": case, "element": element, "name": name, "scene": scene, "sets": sets,
                             "mesh": mesh, "end": end})
    return runs


def command(fsi, run, run_dir):
    cmd = [fsi, "run", run["scene"], "--out", str(run_dir), "--force"]
    for kv in run["sets"]:
        cmd += ["--set", kv]
    return cmd


def run_once(cmd, run_dir):
    """One `fsi run` process (OPENBLAS_NUM_THREADS=1); its wall time in seconds."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    log_path = run_dir / "fsi_run.log"
    t0 = time.perf_counter()
    with open(log_path, "w") as fh:
        p = subprocess.run(cmd, stdout=fh, stderr=subprocess.STDOUT, env=env)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        tail = log_path.read_text(errors="replace").strip().splitlines()[-5:]
        raise BenchmarkError(f"fsi run exit {p.returncode} in {run_dir} (log {log_path}): " + " / ".join(tail))
    return wall


def read_probes(path, columns):
    rows = list(csv.DictReader(open(path)))
    if not rows:
        raise BenchmarkError(f"{path}: no data rows")
    missing = [c for c in columns if c not in rows[0]]
    if missing:
        raise BenchmarkError(f"{path}: no column {', '.join(missing)} (columns: {', '.join(rows[0])})")
    return {c: [float(r[c]) for r in rows] for c in columns}


def completed(run_dir, end):
    """The summary.json of a completed run, or None."""
    try:
        s = json.load(open(run_dir / "summary.json"))
        if s.get("status") != "completed" or "fluid.cd" not in s.get("final", {}) or "dofs" not in s:
            return None
        if end is not None:
            t = read_probes(run_dir / "probes.csv", ["time"])["time"]
            if abs(t[-1] - end) > 1e-6 * max(1.0, end):
                return None
        return s
    except (OSError, ValueError, BenchmarkError):
        return None


def execute(run, a, out):
    """Runs (or reuses) one benchmark run; its row for results.json."""
    run_dir = out / run["name"]
    run_dir.mkdir(parents=True, exist_ok=True)
    cmd = command(a.fsi, run, run_dir)
    record_path = run_dir / "benchmark_run.json"
    row = {k: run[k] for k in ("case", "element", "name", "mesh")}
    row["run_dir"] = str(run_dir)
    row["command"] = cmd
    label = f"{run['case']} {ELEMENT_LABEL[run['element']]} {run['mesh']}"
    record = None
    if a.reuse and record_path.exists():
        try:
            rec = json.load(open(record_path))
        except ValueError:
            rec = {}
        if rec.get("command") == cmd and rec.get("wall_samples") and completed(run_dir, run["end"]):
            record = rec
            log(f"{label}: reusing {run_dir}")
    if record is None:
        for f in ("summary.json", "probes.csv", "benchmark_run.json"):
            (run_dir / f).unlink(missing_ok=True)  # a failed run must not look finished
        record = {"command": cmd}
        if run["end"] is None:
            log(f"{label}: meshing run ({run_dir})")
            record["first_run_seconds"] = run_once(cmd, run_dir)
            samples = []
            for i in range(a.repeat):
                log(f"{label}: timed run {i + 1}/{a.repeat}")
                samples.append(run_once(cmd, run_dir))
                log(f"{label}: timed run {i + 1}/{a.repeat} done, {samples[-1]:.2f} s")
        else:
            log(f"{label}: run to t = {run['end']:g} ({run_dir})")
            samples = [run_once(cmd, run_dir)]
            log(f"{label}: done, {samples[0]:.1f} s")
        record["wall_samples"] = samples
        if not completed(run_dir, run["end"]):
            raise BenchmarkError(f"{run_dir}: fsi run exited 0 but summary.json / probes.csv are incomplete")
        json.dump(record, open(record_path, "w"), indent=2)
    s = json.load(open(run_dir / "summary.json"))
    row.update({"status": "ok", "unknowns": s["dofs"], "wall_samples": record["wall_samples"],
                "wall_seconds": statistics.median(record["wall_samples"]),
                "solver_wall_seconds": s.get("wall_time", {}).get("total"), "setup_seconds": s.get("setup_seconds"),
                "steps": s.get("steps"), "linear_solves": s.get("solver_iterations"),
                "fluid_breakdown": s.get("fluid_breakdown", {})})
    if "first_run_seconds" in record:
        row["first_run_seconds"] = record["first_run_seconds"]
    if run["case"] == "2d1":
        row["values"], row["errors"] = steady_errors(s)
    else:
        c = {k.removeprefix("fluid."): v
             for k, v in read_probes(run_dir / "probes.csv", ["time", "fluid.cd", "fluid.cl", "fluid.dp"]).items()}
        t_end = c["time"][-1]
        row["end_time"] = t_end
        row["dt"] = t_end / s["steps"] if s.get("steps") else None
        if row["dt"]:
            row["mesh"] += f", dt {row['dt']:.4g}"
        row["wall_per_simulated_second"] = row["wall_seconds"] / t_end
        if run["case"] == "2d2":
            window = min(a.window, t_end)
            if window < a.window:
                log(f"{label}: window {a.window:g} s longer than the run; using {window:g} s")
            row["values"], row["errors"] = periodic_errors(c["time"], c["cd"], c["cl"], window)
        else:
            r = dfg_2d3_stats.compute(c["time"], c["cd"], c["cl"], c["dp"])
            if not r["complete"]:
                log(f"{label}: run ends at t = {t_end:g} < 8: no dp(8) error")
            row["values"], row["errors"] = john_errors(r)
    return row


def progress_line(row):
    if row.get("status") != "ok":
        return f"{row['case']} {ELEMENT_LABEL[row['element']]} {row['mesh']}: FAILED {row.get('error')}"
    v, e = row["values"], row["errors"]
    parts = []
    for k, label, kind in QUANTITIES[row["case"]]:
        if k.endswith("_centre"):
            continue
        err = e.get(k)
        err = "n/a" if err is None else (f"{err:+.3f}%" if kind == "%" else f"{err:+.5f} s")
        parts.append(f"{label} {_cell(v.get(k), '.6g')} ({err})")
    return (f"{row['case']} {ELEMENT_LABEL[row['element']]} {row['mesh']}: {row['unknowns']} unknowns, "
            f"wall {row['wall_seconds']:.2f} s: " + ", ".join(parts))


# ---------------------------------------------------------------- output

def write_outputs(results, out):
    table = format_table(results)
    (out / "table.md").write_text(table + "\n")
    print(table)
    return plot(results, out)


def plot(results, out):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("element_benchmark: matplotlib missing: no plot (try /usr/bin/python3 ... --plot-only)", file=sys.stderr)
        return 0
    cases = [c for c in CASES if any(r["case"] == c and r.get("status") == "ok" for r in results)]
    if not cases:
        log("no finished runs: no plot")
        return 0
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 4.2), squeeze=False)
    style = {"p1p1": "-", "p2p1": "--"}
    markers = "osD^v<>"
    for ax, case in zip(axes[0], cases):
        rows = [r for r in results if r["case"] == case and r.get("status") == "ok"]
        qs = [(k, label) for k, label, kind in QUANTITIES[case] if kind == "%" and not k.endswith("_centre")]
        drawn = False
        for element in ELEMENTS:
            er = sorted((r for r in rows if r["element"] == element), key=lambda r: r["wall_seconds"])
            for j, (k, label) in enumerate(qs):
                pts = [(r["wall_seconds"], abs(r["errors"][k])) for r in er
                       if r["errors"].get(k) is not None and r["errors"][k] != 0]
                if not pts:
                    continue
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], style[element], marker=markers[j % len(markers)],
                          color=f"C{j}", mfc=f"C{j}" if element == "p1p1" else "none",
                          label=f"{ELEMENT_LABEL[element]} {label}")
                drawn = True
            for r in er:
                e0 = r["errors"].get(qs[0][0])
                if e0:
                    ax.annotate(f"{r['unknowns']}", (r["wall_seconds"], abs(e0)), fontsize=6, alpha=0.7)
        ax.set_title(CASE_TITLE[case], fontsize=10)
        ax.set_xlabel("wall time [s] (median of the timed runs)" if case == "2d1" else "wall time [s] (whole run)")
        ax.set_ylabel("|relative error| [%]")
        ax.grid(True, which="both", alpha=0.3)
        if drawn:
            ax.legend(fontsize=7)
    fig.suptitle("P1/P1 SUPG/PSPG (solid, filled) vs Taylor-Hood P2/P1 (dashed, open); labels: unknowns", fontsize=9)
    fig.tight_layout()
    path = out / "error_vs_wall_time.png"
    fig.savefig(path, dpi=120)
    log(f"plot: {path}")
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--fsi", "--runner", dest="fsi", default=str(ROOT / "build" / "bin" / "fsi"),
                    help="the fsi executable (default: build/bin/fsi)")
    ap.add_argument("--out", default=str(ROOT / "out" / "element_benchmark"))
    ap.add_argument("--cases", nargs="+", choices=CASES, default=list(CASES))
    ap.add_argument("--elements", nargs="+", choices=ELEMENTS, default=list(ELEMENTS))
    ap.add_argument("--levels", type=int, default=3, help="2d1: the N coarsest of the three meshes per element")
    ap.add_argument("--repeat", type=int, default=3, help="2d1: timed runs after the meshing run (median)")
    ap.add_argument("--window", type=float, default=2.0, help="2d2: statistics over the last WINDOW seconds")
    ap.add_argument("--end", type=float, help="end time of 2d2 and 2d3 (shortened smoke runs)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="extra scene override for every run (repeatable)")
    ap.add_argument("--reuse", action="store_true", help="reuse completed runs with the same command")
    ap.add_argument("--plot-only", action="store_true", help="table and plot from OUT/results.json")
    a = ap.parse_args(argv)
    out = Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    if a.plot_only:
        path = out / "results.json"
        if not path.exists():
            sys.exit(f"element_benchmark: {path}: no such file (run without --plot-only first)")
        return write_outputs(json.load(open(path))["runs"], out)
    if a.levels < 1 or a.repeat < 1:
        sys.exit("element_benchmark: --levels and --repeat must be at least 1")
    if a.end is not None and not a.end > 0:
        sys.exit("element_benchmark: --end must be positive")
    bad = [kv for kv in a.set if "=" not in kv or kv.startswith("=")]
    if bad:
        sys.exit(f"element_benchmark: --set {bad[0]!r}: expected KEY=VALUE")
    a.fsi = str(Path(a.fsi).resolve())
    if not os.access(a.fsi, os.X_OK):
        sys.exit(f"element_benchmark: {a.fsi} is not an executable (build fsi or pass --fsi)")
    runs = plan(a)
    results = []
    for i, run in enumerate(runs, 1):
        log(f"[{i}/{len(runs)}] {run['name']}")
        try:
            row = execute(run, a, out)
        except (BenchmarkError, OSError, ValueError, KeyError, dfg_2d3_stats.StatsError) as e:
            row = {k: run[k] for k in ("case", "element", "name", "mesh")}
            row.update({"status": "failed", "error": str(e), "run_dir": str(out / run["name"])})
        log(progress_line(row))
        results.append(row)
    doc = {"references": {"2d1": REF_2D1, "2d2": REF_2D2, "2d2_interval_centres": CENTRES_2D2,
                          "2d3": dfg_2d3_stats.REF},
           "settings": {"fsi": a.fsi, "repeat": a.repeat, "window": a.window, "end": a.end, "set": a.set,
                        "OPENBLAS_NUM_THREADS": 1},
           "runs": results}
    with open(out / "results.json", "w") as fh:
        json.dump(_json_clean(doc), fh, indent=2)
    write_outputs(results, out)
    failed = [r["name"] for r in results if r.get("status") != "ok"]
    if failed:
        log(f"{len(failed)} run(s) failed: {', '.join(failed)}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
