#!/usr/bin/python3
"""Turek-Hron FSI2 / FSI3 on three mesh levels: runs, and the level table against FEATFLOW.

Usage:
  /usr/bin/python3 bench/fsi/levels.py run CASE [--element p2p1|p1p1] [--levels 1 2 3]
                                       [--out DIR] [--end T] [--solid-element q4_eas|q4] [--dry-run | --check]
  /usr/bin/python3 bench/fsi/levels.py table CASE [--element ...] [--out DIR] [--periods N]
                                       [--md FILE] [--json FILE] [--plot PNG]
      CASE: fsi2 | fsi3     DIR default: runs/levels

run: one `fsi run` per level, one after the other (one solver job: the fluid and the solid take
turns), into DIR/CASE_ELEMENT_L<n>, with checkpoints every 200 steps; a level that completed
is skipped, an interrupted one resumed from its last checkpoint. Levels (the fluid mesh sizes
of the scene's .geo scaled, the solid flag refined with them, dt with them):

  level 1: fluid h x 2 (about 12k unknowns), solid  80 x  4, dt x 2
  level 2: the scene's mesh (about 45k),     solid 160 x  8, dt x 1
  level 3: fluid h x 0.65 (about 105k),      solid 240 x 12, dt x 1/2

The solid element is the locking-free q4_eas unless --solid-element q4 (CSM1 on 80 x 4: the
Q4 is 11 % too stiff, q4_eas 0.06 %).

table: per level the unknowns, the statistics of bench/fsi/th_stats.py over the last N whole
u_y periods (default 4), each quantity's error against FEATFLOW's level 4 and against
FEATFLOW's level of about the same size (level 2: 11,232 unknowns, level 3: 44,288), the
self-convergence between our two finest levels (|ours_3 - ours_2| / |ours_3|), coupling
iterations per step and the wall time per simulated second (median over that window of
timing.csv's step times / dt), and FEATFLOW's own levels 2-4 Richardson-extrapolated where they
converge monotonically (FSI2's amplitudes: 1.2-4.8 % beyond level 4, at observed orders 0.35-1.0)
with our finest level against those limits. A level that is missing, still running or too short is listed as
such, never guessed.
"""
import argparse
import csv
import json
import os
import re
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "python"))
import fsi.interpreter  # noqa: E402

fsi.interpreter.require("numpy")
import th_stats  # noqa: E402
from fsi import stats as fstats  # noqa: E402

SCENES = {("fsi2", "p2p1"): "configs/fsi2_p2p1.yaml", ("fsi2", "p1p1"): "configs/fsi2.yaml",
          ("fsi3", "p2p1"): "configs/fsi3_p2p1.yaml", ("fsi3", "p1p1"): "configs/fsi3.yaml"}
# (far-field size, hc, hw) per element at level 2 = the scenes' own values
BASE_MESH = {"p2p1": (0.04, 0.005, 0.02), "p1p1": (0.025, 0.0035, 0.01)}
BASE_DT = {("fsi2", "p2p1"): 0.002, ("fsi2", "p1p1"): 0.004, ("fsi3", "p2p1"): 0.0025, ("fsi3", "p1p1"): 0.0025}
LEVELS = {1: {"h": 2.0, "solid": (80, 4), "dt": 2.0},
          2: {"h": 1.0, "solid": (160, 8), "dt": 1.0},
          3: {"h": 0.65, "solid": (240, 12), "dt": 0.5}}
QUANTITIES = ("ux", "uy", "drag", "lift")
# When each case is periodic (measured on levels 1 and 2 run to t = 20 / 15): FSI2's amplitudes
# overshoot at t ~ 6, dip up to 5 % below the periodic state at t ~ 9 and settle by t ~ 11;
# FSI3's have settled by t ~ 3.5. A window that starts earlier is refused, not tabulated.
PERIODIC_FROM = {"fsi2": 11.0, "fsi3": 3.5}


def level_overrides(case, element, level, solid_element, end):
    size, hc, hw = (x * LEVELS[level]["h"] for x in BASE_MESH[element])
    nx, ny = LEVELS[level]["solid"]
    dt = BASE_DT[(case, element)] * LEVELS[level]["dt"]
    sets = [f"time.dt={dt:.6g}", f"fluid.mesh.size={size:.6g}",
            f"fluid.mesh.parameters={{hc: {hc:.6g}, hw: {hw:.6g}}}",
            f"solid.mesh.elements=[{nx}, {ny}]", f"solid.element={solid_element}",
            "time.checkpoint_every=200"]
    if end:
        sets.append(f"time.end={end:g}")
    return sets


def run_dir(out, case, element, level):
    return os.path.join(out, f"{case}_{element}_L{level}")


def status(path):
    try:
        return json.load(open(os.path.join(path, "summary.json"))).get("status", "?")
    except (OSError, ValueError):
        return None


def scene_end(case, element):
    import yaml
    return float(yaml.safe_load(open(os.path.join(ROOT, SCENES[(case, element)])))["time"]["end"])


def run_end(path):
    """time.end of a run folder (its summary's parameters), 0 when unknown."""
    try:
        return float(json.load(open(os.path.join(path, "summary.json")))["parameters"]["time"]["end"])
    except (OSError, ValueError, KeyError, TypeError):
        return 0.0


def cmd_run(a):
    fsi_bin = os.environ.get("FSI_BIN", os.path.join(ROOT, "build", "bin"))
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_WAIT_POLICY="passive")
    worst = 0
    for lv in a.levels:
        d = run_dir(a.out, a.case, a.element, lv)
        st = status(d)
        end = a.end or scene_end(a.case, a.element)
        if st == "completed" and run_end(d) >= end - 1e-9:
            print(f"level {lv}: {d} completed, skipped")
            continue  # (a completed run with an earlier end is extended: --resume --set time.end)
        cmd = [os.path.join(fsi_bin, "fsi"), "run", SCENES[(a.case, a.element)], "--out", d]
        for s in level_overrides(a.case, a.element, lv, a.solid_element, end):
            cmd += ["--set", s]
        if st is not None and os.path.isdir(os.path.join(d, "checkpoints")):
            cmd.append("--resume")
        print(f"level {lv}: " + " ".join(f"'{c}'" if " " in c else c for c in cmd), flush=True)
        if a.check:
            check = [cmd[0], "check", cmd[2]] + [c for i, c in enumerate(cmd) if i > 4 and c != "--resume"]
            rc = subprocess.call(check, cwd=ROOT, env=env)
            worst = max(worst, rc)
            continue
        if a.dry_run:
            continue
        rc = subprocess.call(cmd, cwd=ROOT, env=env)
        worst = max(worst, rc)
    return worst


def unknowns(path):
    try:
        m = re.search(r"(\d+) unknowns", open(os.path.join(path, "fluid_server.log")).read())
    except OSError:
        return None
    return int(m.group(1)) if m else None


def wall_per_second(path, t0, t1):
    """Median over steps with t in [t0, t1] of (wall time of the step) / dt, from timing.csv."""
    p = os.path.join(path, "timing.csv")
    if not os.path.exists(p):
        return None
    rows = [(float(r["time"]), float(r["wall"])) for r in csv.DictReader(open(p))]
    rates = [(w1 - w0) / (t1_ - t0_) for (t0_, w0), (t1_, w1) in zip(rows, rows[1:])
             if t0 <= t1_ <= t1 and w1 > w0]
    return statistics.median(rates) if rates else None


def analyse(path, case, periods):
    if status(path) is None:
        return {"state": "missing"}
    t, d = th_stats.read(path)
    res = {"state": status(path), "t_end": t[-1], "unknowns": unknowns(path)}
    try:
        tab = fstats.turek_hron_table(t, {k: d[k] for k in QUANTITIES}, "uy", min_periods=3, periods=periods,
                                      smooth=0.005)
    except fstats.StatsError as e:
        res["refused"] = str(e)
        return res
    if tab["t0"] < PERIODIC_FROM[case]:
        res["refused"] = (f"the last {tab['periods']} u_y periods start at t = {tab['t0']:.3g}, before the periodic "
                          f"state (t >= {PERIODIC_FROM[case]:g}): run longer")
        return res
    res["window"] = [tab["t0"], tab["t1"]]
    res["periods"] = tab["periods"]
    res["stats"] = tab["columns"]
    res["errors"] = {f"level{lv}": th_stats.level_errors(tab["columns"], r) for lv, r in th_stats.LEVELS[case].items()}
    sel = [i for i, ti in enumerate(t) if tab["t0"] <= ti <= tab["t1"]]
    res["iterations_per_step"] = sum(d["iterations"][i] for i in sel) / len(sel)
    res["wall_per_simulated_second"] = wall_per_second(path, tab["t0"], tab["t1"])
    return res


def nearest_featflow(n):
    if not n:
        return None
    return min((lv for lv in (2, 3, 4)), key=lambda lv: abs(th_stats.LEVEL_UNKNOWNS[lv] - n) / th_stats.LEVEL_UNKNOWNS[lv])


def cmd_table(a):
    rows = {lv: analyse(run_dir(a.out, a.case, a.element, lv), a.case, a.periods) for lv in (1, 2, 3)}
    lines = [f"{a.case.upper()} with the {a.element} fluid, levels of bench/fsi/levels.py, statistics over the last "
             f"{a.periods} whole u_y periods; errors in % against FEATFLOW's level 4 (means of u_y and lift "
             "relative to the amplitude), in brackets against FEATFLOW's level of about the same size", "",
             "| level | unknowns | solid | dt | u_x mean / amp | u_y mean / amp / freq | drag mean / amp | "
             "lift mean / amp / freq | iterations per step | wall s per simulated s |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for lv, r in rows.items():
        dt = BASE_DT[(a.case, a.element)] * LEVELS[lv]["dt"]
        nx, ny = LEVELS[lv]["solid"]
        unfinished = f" ({r['state']}, t = {r['t_end']:.4g})" if r.get("state") not in ("completed", "missing") else ""
        head = f"| {lv}{unfinished} | {r.get('unknowns') or '-'} | {nx} x {ny} | {dt:g} |"
        if "errors" not in r:
            why = r.get("refused") or r["state"]
            lines.append(head + f" {why} |" + " |" * 5)
            continue
        e4 = r["errors"]["level4"]
        fl = nearest_featflow(r["unknowns"])
        en = r["errors"].get(f"level{fl}") if fl and fl < 4 else None

        def cell(q, parts):
            s = " / ".join(f"{e4[q][p]:+.1f}" for p in parts)
            if en:
                s += " (" + " / ".join(f"{en[q][p]:+.1f}" for p in parts) + ")"
            return s
        w = r["wall_per_simulated_second"]
        lines.append(head + f" {cell('ux', ('mean', 'amplitude'))} | {cell('uy', ('mean', 'amplitude', 'frequency'))} | "
                     f"{cell('drag', ('mean', 'amplitude'))} | {cell('lift', ('mean', 'amplitude', 'frequency'))} | "
                     f"{r['iterations_per_step']:.2f} | {f'{w:.0f}' if w else '-'} |")
    done = [lv for lv in (1, 2, 3) if "stats" in rows[lv]]
    if len(done) >= 2:
        f, c = done[-1], done[-2]
        sc = []
        for q in QUANTITIES:
            for p in ("mean", "amplitude"):
                if p == "mean" and q in th_stats.NEAR_ZERO_MEAN:
                    continue
                x3, x2 = rows[f]["stats"][q][p], rows[c]["stats"][q][p]
                sc.append(f"{q} {p} {100 * abs(x3 - x2) / abs(x3):.2f} %")
            if q in ("uy", "lift"):
                x3, x2 = rows[f]["stats"][q]["frequency"], rows[c]["stats"][q]["frequency"]
                sc.append(f"{q} frequency {100 * abs(x3 - x2) / abs(x3):.2f} %")
        lines += ["", f"Self-convergence, levels {c} -> {f}: " + ", ".join(sc)]
    limits = th_stats.featflow_limits(a.case)
    named = {"ux": "u_x", "uy": "u_y", "drag": "drag", "lift": "lift"}
    ext = [f"{named[q]} {p} {lim['limit']:.4g} ({lim['vs_level4']:+.1f} % from level 4, order {lim['order']:.2f})"
           for q in QUANTITIES for p, lim in limits[q].items() if lim]
    vs_limit = {}
    if ext:
        lines += ["", "FEATFLOW's levels 2, 3, 4 Richardson-extrapolated (monotone sequences only; observed order "
                  "in h): " + ", ".join(ext) + "."]
        if done:
            f = done[-1]
            vs_limit = {q: {p: fstats.relative_error_percent(rows[f]["stats"][q][p], lim["limit"])
                            for p, lim in limits[q].items() if lim} for q in QUANTITIES}
            lines.append(f"Our level {f} against those limits: " + ", ".join(
                f"{named[q]} {p} {e:+.1f} %" for q in QUANTITIES for p, e in vs_limit[q].items()) + ".")
    else:
        lines += ["", "FEATFLOW's levels 2, 3, 4 converge monotonically in no mean or amplitude here: no extrapolated "
                  "limit."]
    text = "\n".join(lines)
    print(text)
    if a.md:
        open(a.md, "w").write(text + "\n")
    if a.json:
        json.dump({"case": a.case, "element": a.element, "levels": rows, "featflow_limits": limits,
                   "finest_vs_limits": vs_limit}, open(a.json, "w"), indent=2)
    if a.plot and done:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4.5))
        for q in QUANTITIES:  # signed: FEATFLOW's coarse levels lie below its level 4
            xs = [rows[lv]["unknowns"] for lv in done]
            ys = [rows[lv]["errors"]["level4"][q]["amplitude"] for lv in done]
            line, = ax.semilogx(xs, ys, "o-", label=f"{q} amplitude (ours)")
            ref = th_stats.LEVELS[a.case]
            ax.semilogx([th_stats.LEVEL_UNKNOWNS[lv] for lv in (2, 3, 4)],
                        [100 * (ref[lv][q][1] - ref[4][q][1]) / ref[4][q][1] for lv in (2, 3, 4)],
                        "s--", color=line.get_color(), alpha=0.5)
            if limits[q]["amplitude"]:  # FEATFLOW's extrapolated limit
                ax.axhline(limits[q]["amplitude"]["vs_level4"], color=line.get_color(), ls=":", alpha=0.7)
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xlabel("fluid unknowns (velocity + pressure)")
        ax.set_ylabel("amplitude against FEATFLOW level 4 [%]")
        ax.set_title(f"{a.case.upper()} {a.element}: ours (o), FEATFLOW levels 2-4 (s, dashed),\n"
                     "FEATFLOW's levels extrapolated (dotted)", fontsize=10)
        ax.legend(fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print(f"plot: {a.plot}")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    for name in ("run", "table"):
        p = sub.add_parser(name)
        p.add_argument("case", choices=("fsi2", "fsi3"))
        p.add_argument("--element", choices=("p2p1", "p1p1"), default="p2p1")
        p.add_argument("--out", default=os.path.join("runs", "levels"))
        if name == "run":
            p.add_argument("--levels", type=int, nargs="+", choices=(1, 2, 3), default=[1, 2, 3])
            p.add_argument("--end", type=float, default=0.0, help="time.end (default: the scene's)")
            p.add_argument("--solid-element", choices=("q4_eas", "q4"), default="q4_eas")
            p.add_argument("--dry-run", action="store_true", help="print the commands only")
            p.add_argument("--check", action="store_true", help="validate every level's scene with `fsi check`, run nothing")
        else:
            p.add_argument("--periods", type=int, default=4)
            p.add_argument("--md")
            p.add_argument("--json")
            p.add_argument("--plot")
    a = ap.parse_args()
    if a.command == "run":
        a.out = os.path.abspath(a.out)
        return cmd_run(a)
    return cmd_table(a)


if __name__ == "__main__":
    sys.exit(main())
