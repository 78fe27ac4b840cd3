#!/usr/bin/python3
"""Serial against parallel (Jacobi) coupling on one scene: wall time, iterations per step,
where the time goes, and how far the two converged solutions lie apart.

Usage:
  /usr/bin/python3 bench/fsi/parallel_wall.py SCENE [--set KEY=VALUE ...] [--repeat N] [--out DIR]
                                              [--fsi PATH]

Runs `fsi run SCENE --set coupling.scheme=serial|parallel` N times each (default 3),
alternating, and prints per scheme the median wall time (summary.json's wall_time.total), the
coupling iterations per step, the fluid's and the solid's compute seconds (medians), and the
largest relative difference of every probe between the two schemes' last rows (the same
solution within the coupling tolerance, or not). The parallel scheme solves fluid and solid at
once: it needs two free cores, so run this with nothing else on the machine (it is a
benchmark, never a test). Exit 0 when every run completed, 1 otherwise.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def last_row(run):
    with open(run / "probes.csv") as f:
        rows = list(csv.DictReader(f))
    return {k: float(v) for k, v in rows[-1].items() if v not in ("", None)}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene")
    p.add_argument("--set", action="append", default=[], dest="sets")
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--out", default=str(ROOT / "runs" / "parallel_wall"))
    p.add_argument("--fsi", default=os.environ.get("FSI_BIN", str(ROOT / "build" / "bin")) + "/fsi")
    a = p.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {"serial": [], "parallel": []}
    ok = True
    for r in range(a.repeat):
        for scheme in ("serial", "parallel"):
            run = out / f"{scheme}_{r + 1}"
            cmd = [a.fsi, "run", a.scene, "--out", str(run), "--force", "--set", f"coupling.scheme={scheme}"]
            for s in a.sets:
                cmd += ["--set", s]
            proc = subprocess.run(cmd, capture_output=True, text=True)
            s = json.load(open(run / "summary.json"))
            if proc.returncode != 0 or s.get("status") != "completed":
                print(f"{scheme} run {r + 1}: {s.get('status')} ({s.get('reason', proc.stderr[-300:])})")
                ok = False
                continue
            w = s["wall_time"]
            results[scheme].append({"wall": w["total"], "fluid": w["fluid_compute"], "solid": w["solid_compute"],
                                    "iterations": s["coupling_iterations"] / s["steps"], "last": last_row(run)})
            print(f"{scheme} run {r + 1}: {w['total']:.2f} s, {s['coupling_iterations'] / s['steps']:.2f} iterations "
                  f"per step (fluid {w['fluid_compute']:.2f} s, solid {w['solid_compute']:.2f} s)", flush=True)
    if not (results["serial"] and results["parallel"]):
        return 1
    print("\n| scheme | runs | wall s (median) | iterations / step | fluid s | solid s |")
    print("|---|---|---|---|---|---|")
    med = {}
    for scheme, rs in results.items():
        med[scheme] = statistics.median(x["wall"] for x in rs)
        print(f"| {scheme} | {len(rs)} | {med[scheme]:.2f} | {statistics.median(x['iterations'] for x in rs):.2f} | "
              f"{statistics.median(x['fluid'] for x in rs):.2f} | {statistics.median(x['solid'] for x in rs):.2f} |")
    print(f"\nparallel / serial wall time: {med['parallel'] / med['serial']:.3f}")
    a_last, b_last = results["serial"][0]["last"], results["parallel"][0]["last"]
    diffs = {}
    for k, v in a_last.items():
        if k == "time" or k.startswith("coupling.") or k not in b_last or "iterations" in k or "factorisations" in k:
            continue
        scale = max(abs(v), 1e-12)
        diffs[k] = abs(b_last[k] - v) / scale
    worst = sorted(diffs.items(), key=lambda kv: -kv[1])[:6]
    print("largest relative differences of the last row (parallel against serial): " +
          ", ".join(f"{k} {d:.2e}" for k, d in worst))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
