#!/usr/bin/python3
"""Turek-Hron FSI3 start-up on a coarse mesh: the strongly coupled (density ratio 1) case.

Runs `fsi run configs/fsi3.yaml` (IQN-ILS to 1e-4, Algorithm 2, dt 0.0025) on a coarse fluid
mesh (4.6k nodes) for 0.15 s, twice:
  - with the scene's BDF2 solid: must complete, converge every step in few iterations
    (IQN-ILS; measured 2.6 per step on average), and keep the lift free of the period-2-dt
    oscillation (largest |L_n - (L_{n-1} + L_{n+1})/2| over the last 20 steps, measured
    0.05 N/m, bound 0.5);
  - with the trapezoidal (Newmark) solid and the consistent Robin terms (robin_mass:
    consistent): also stable (measured 0.04-0.07 N/m, 0.15 N/m by step 120);
  - with the Newmark solid and the solid's own reference interface mass (robin_mass: solid,
    the earlier coupling): the 2 dt interface mode grows (0.45 N/m by step 20, a solid element
    inverted at step 42): the run must stop with a classified reason (exit 2, "diverged") or
    show the oscillation above the bound. The uncancelled gamma_N1 (H^T M_f H - M_G) v_s feeds
    that mode: the instability the BDF2 solid was chosen against was the coupling's, not the
    trapezoidal rule's.
So the test fails if the BDF2 run or the consistent Newmark run is unstable, or if the earlier
coupling's instability can no longer be reproduced.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

COARSE = ["time.end=0.15", "fluid.mesh.size=0.04", "fluid.mesh.parameters={hc: 0.006, hw: 0.016}"]
SAW_BOUND = 0.5  # N/m


def run(a, out, extra):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_WAIT_POLICY="passive")
    cmd = [os.path.join(a.bin, "fsi"), "run", os.path.join(a.source, "configs", "fsi3.yaml"), "--out", out]
    for s in COARSE + extra:
        cmd += ["--set", s]
    print(" ".join(cmd), flush=True)
    r = subprocess.run(cmd, env=env, timeout=280, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    summary = json.load(open(os.path.join(out, "summary.json")))
    rows = list(csv.DictReader(open(os.path.join(out, "probes.csv"))))
    lift = [float(x["fluid.lift"]) for x in rows]
    last = lift[-21:]
    saw = max((abs(last[j] - 0.5 * (last[j - 1] + last[j + 1])) for j in range(1, len(last) - 1)), default=0.0)
    its = [float(x["coupling.iterations"]) for x in rows]
    print(f"  exit {r.returncode}, status {summary.get('status')}, {len(rows)} steps, iterations/step "
          f"{sum(its) / max(len(its), 1):.2f}, 2-dt lift oscillation {saw:.3g} N/m; {summary.get('reason', '')}",
          flush=True)
    return r.returncode, summary, its, saw


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    failures = []
    with tempfile.TemporaryDirectory(prefix="fsi3_test_") as tmp:
        code, summary, its, saw = run(a, os.path.join(tmp, "bdf2"), [])
        if code != 0 or summary.get("status") != "completed":
            failures.append(f"BDF2 solid: run {summary.get('status')} (exit {code}): {summary.get('reason')}")
        if len(its) != 60:
            failures.append(f"BDF2 solid: {len(its)} steps, expected 60")
        if its and sum(its) / len(its) > 5:
            failures.append(f"BDF2 solid: {sum(its) / len(its):.2f} IQN-ILS iterations per step (expected <= 5)")
        if not saw < SAW_BOUND:
            failures.append(f"BDF2 solid: 2-dt lift oscillation {saw:.3g} N/m >= {SAW_BOUND}")
        code, summary, its, saw = run(a, os.path.join(tmp, "newmark"), ["solid.time_scheme=newmark"])
        if code != 0 or summary.get("status") != "completed" or not saw < SAW_BOUND:
            failures.append(f"Newmark solid, consistent Robin terms: expected a stable run, got exit {code} "
                            f"({summary.get('status')}), 2-dt lift oscillation {saw:.3g} N/m")
        code, summary, its, saw = run(a, os.path.join(tmp, "newmark_solid_mass"),
                                      ["solid.time_scheme=newmark", "coupling.robin_mass=solid"])
        unstable = (code == 2 and summary.get("status") == "diverged") or saw >= SAW_BOUND
        if not unstable:
            failures.append(f"Newmark solid, robin_mass: solid: expected the 2-dt instability (exit 2 or oscillation "
                            f">= {SAW_BOUND}), got exit {code}, oscillation {saw:.3g}")
        if code not in (0, 2):
            failures.append(f"Newmark solid, robin_mass: solid: exit {code} is neither completed nor a classified "
                            f"divergence")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
