#!/usr/bin/python3
"""Mesh self-convergence of the elastic tube (configs/tube_3d.yaml) or its 2D analogue
(configs/tube_2d.yaml): runs the scene on a sequence of mesh levels (the fluid's
`fluid.mesh.parameters.level` and the wall's cells together), then prints a Markdown table of the
mid-length station (z = 2.5 cm): the pressure's and the wall's peak and half-peak arrival
(bench/fsi/tube_waves.py's definitions), and each level's difference from the next finer one
(the self-convergence measure: two successive levels within a few per cent).

  /usr/bin/python3 bench/fsi/tube_levels.py --scene configs/tube_2d.yaml --levels 0,1,2,3 --out runs/tube2d_levels
  /usr/bin/python3 bench/fsi/tube_levels.py --scene configs/tube_3d.yaml --levels 0,1,1.5 --out runs/tube3d_levels
  --split FLUID:WALL   also a run with the fluid of level FLUID on the wall of level WALL (repeatable)
  --wrap /work/runs/slot   each run through a job-slot command

Wall cells per level: 2D (solid.mesh.elements) [100, 4] x 2^level; 3D (solid.mesh.divisions)
level 0 [24, 2, 20], 1 [48, 4, 40], 1.5 [68, 4, 56] (in-plane refined by sqrt 2; four cells through
the 0.1 cm wall are 2.6 to 5 times finer than the in-plane ones already), other levels
[24, 2, 20] x 2^level rounded, or --wall LEVEL=N,N[,N]. A level folder that already has its
summary.json is read, not run again (--force runs it anew).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import tube_waves  # noqa: E402

WALL_3D = {"0": [24, 2, 20], "1": [48, 4, 40], "1.5": [68, 4, 56]}


def wall_cells(level, dim, given):
    if level in given:
        return given[level]
    if dim == 2:
        return [round(100 * 2 ** float(level)), round(4 * 2 ** float(level))]
    return WALL_3D.get(level) or [round(n * 2 ** float(level)) for n in (24, 2, 20)]


def dimension(scene):
    with open(scene) as f:
        return 3 if re.search(r"^\s*dimension:\s*3", f.read(), re.M) else 2


def run(scene, out, fluid_level, wall, dim, wrap, force):
    if os.path.exists(os.path.join(out, "summary.json")) and not force:
        return
    shutil.rmtree(out, ignore_errors=True)
    key = "solid.mesh.divisions" if dim == 3 else "solid.mesh.elements"
    cmd = [os.path.join(ROOT, "build/bin/fsi"), "run", scene, "--out", out, "--set",
           f"fluid.mesh.parameters.level={fluid_level}", "--set", f"{key}=[{', '.join(map(str, wall))}]"]
    if wrap:
        cmd = [wrap] + cmd
    print("running:", " ".join(cmd), flush=True)
    with open(out + ".log", "w") as log:
        if subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT).returncode != 0:
            sys.exit(f"{out}: the run failed (see {out}.log)")


def facts(out):
    """Fluid unknowns, wall dofs, iterations per step, wall time of a run folder."""
    text = open(os.path.join(out, "fluid_server.log")).read()
    m = re.search(r"(\d+) unknowns", text)
    solid = re.search(r"(\d+) free dofs", open(os.path.join(out, "solid_server.log")).read())
    summary = json.load(open(os.path.join(out, "summary.json")))
    its = [int(line.split(",")[-1]) for line in open(os.path.join(out, "timing.csv")).read().split("\n")[1:] if line]
    return {"fluid": int(m.group(1)) if m else 0, "solid": int(solid.group(1)) if solid else 0,
            "iterations": sum(its) / max(1, len(its)), "wall_s": summary["wall_time"]["total"],
            "solid_s": summary["wall_time"].get("solid_compute", float("nan")),
            "fluid_s": summary["wall_time"].get("fluid_compute", float("nan"))}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", required=True)
    ap.add_argument("--levels", default="0,1")
    ap.add_argument("--split", action="append", default=[], metavar="FLUID:WALL")
    ap.add_argument("--wall", action="append", default=[], metavar="LEVEL=N,N[,N]")
    ap.add_argument("--out", required=True)
    ap.add_argument("--wrap", default="")
    ap.add_argument("--force", action="store_true")
    ap.add_argument("--json")
    a = ap.parse_args()
    scene = os.path.abspath(a.scene)
    dim = dimension(scene)
    given = {w.split("=")[0]: [int(x) for x in w.split("=")[1].split(",")] for w in a.wall}
    os.makedirs(a.out, exist_ok=True)
    levels = a.levels.split(",")
    runs = [(f"level {L}", L, L) for L in levels] + [
        (f"fluid {s.split(':')[0]}, wall {s.split(':')[1]}", s.split(":")[0], s.split(":")[1]) for s in a.split]
    rows = []
    for name, fl, wl in runs:
        wall = wall_cells(wl, dim, given)
        out = os.path.join(a.out, f"f{fl}_w{wl}")
        run(scene, out, fl, wall, dim, a.wrap, a.force)
        res = tube_waves.analyse(out)[0]
        p, r = res["stations"]["p2"], res["stations"]["r2"]
        rows.append({"name": name, "fluid_level": fl, "wall": wall, **facts(out), "p_peak": p["peak"],
                     "p_arrival": p["arrival_s"], "r_peak": r["peak"], "r_arrival": r["arrival_s"],
                     "speed_p": res["speed_p_cm_per_s"], "speed_r": res["speed_r_cm_per_s"]})

    def rel(x, ref):
        return f"{100 * (x / ref - 1):+.2f} %"

    print(f"\n{os.path.basename(scene)}, mid-length station (z = 2.5 cm); differences from the next finer level")
    print("| mesh | fluid unknowns | wall cells | wall dofs | p peak | p arrival (ms) | u_r peak (cm) | u_r arrival (ms) "
          "| speed p / wall (m/s) | iterations / step | wall time (s) (fluid / solid) |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    n = len(levels)
    for k, row in enumerate(rows):
        finer = rows[k + 1] if k < n - 1 else (rows[n - 1] if k >= n else None)
        d = (lambda key: f" ({rel(row[key], finer[key])})") if finer else (lambda key: "")
        print(f"| {row['name']} | {row['fluid']:,} | {' x '.join(map(str, row['wall']))} | {row['solid']:,} | "
              f"{row['p_peak']:,.0f}{d('p_peak')} | {1e3 * row['p_arrival']:.3f}{d('p_arrival')} | "
              f"{row['r_peak']:.4e}{d('r_peak')} | {1e3 * row['r_arrival']:.3f}{d('r_arrival')} | "
              f"{row['speed_p'] / 100:.2f} / {row['speed_r'] / 100:.2f} | {row['iterations']:.2f} | "
              f"{row['wall_s']:.0f} ({row['fluid_s']:.0f} / {row['solid_s']:.0f}) |")
    if a.split:
        print(f"(the split runs' differences are from the finest level, {rows[n - 1]['name']})")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
