#!/usr/bin/python3
"""The elastic tube's 2D analogue (configs/tube_2d.yaml) through the real processes: a planar
channel whose plane-strain wall rests on an elastic support k_s = E h / (2 R^2), so that its
distensibility is the tube's and the pressure wave travels at about the Moens-Korteweg speed
c = sqrt(E h / (2 rho_f R)) = 5.48 m/s.

Runs the scene to t = 6 ms with Algorithm 1 and with Algorithm 2 (both converged by IQN-ILS to
1e-8, gamma_N1 = 1000). Checks:
  - the front's speed between x = 1.25 and 2.5 cm (the time the axis pressure first reaches
    5000 dyn/cm^2, interpolated between steps) within 10 % of Moens-Korteweg;
  - Algorithms 1 and 2 converged agree: both arrival times and the wall's displacement at
    x = 1.25 cm at t = 6 ms within 0.5 %.
Measured (level 0, 100 x 4 wall cells): 5.6-5.8 m/s over the whole run (bench/fsi/tube_waves.py).
"""
import argparse
import math
import os
import sys
import tempfile

from fsi_run import run_scene

E, H, R, RHO_F = 3.0e6, 0.1, 0.5, 1.0
THRESHOLD = 5000.0  # dyn/cm^2


def arrival(rows, column):
    prev = None
    for r in rows:
        t, p = float(r["time"]), float(r[column])
        if p >= THRESHOLD:
            if prev is None:
                return t
            return prev[0] + (THRESHOLD - prev[1]) / (p - prev[1]) * (t - prev[0])
        prev = (t, p)
    return math.nan


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    failures = []
    result = {}
    with tempfile.TemporaryDirectory(prefix="tube_2d_") as tmp:
        for algorithm in (1, 2):
            out = os.path.join(tmp, f"a{algorithm}")
            code, output, summary, rows, _ = run_scene(
                a.bin, os.path.join(a.source, "configs", "tube_2d.yaml"), out,
                ["time.end=0.006", f"coupling.algorithm={algorithm}", "coupling.iterations.tolerance=1e-8"])
            if code != 0 or summary.get("status") != "completed":
                print(output[-4000:])
                print(f"FAIL: Algorithm {algorithm}: exit {code}, {summary.get('status')}: {summary.get('reason')}")
                return 1
            t1, t2 = arrival(rows, "fluid.p1"), arrival(rows, "fluid.p2")
            its = sum(float(x["coupling.iterations"]) for x in rows) / len(rows)
            result[algorithm] = (t1, t2, float(rows[-1]["solid.r1_y"]))
            print(f"Algorithm {algorithm}: {len(rows)} steps, {its:.2f} iterations per step; arrival at 1.25 cm "
                  f"{1e3 * t1:.4f} ms, at 2.5 cm {1e3 * t2:.4f} ms; wall at 1.25 cm {rows[-1]['solid.r1_y']} cm",
                  flush=True)
    c_mk = math.sqrt(E * H / (2 * RHO_F * R))
    t1, t2, _ = result[1]
    speed = 1.25 / (t2 - t1)
    print(f"front speed {speed / 100:.3f} m/s, Moens-Korteweg {c_mk / 100:.3f} m/s ({100 * (speed / c_mk - 1):+.1f} %)")
    if not abs(speed / c_mk - 1) < 0.10:
        failures.append(f"speed {speed:.4g} cm/s not within 10 % of {c_mk:.4g}")
    for i, what in enumerate(("arrival at 1.25 cm", "arrival at 2.5 cm", "wall displacement at 1.25 cm")):
        d = result[2][i] / result[1][i] - 1
        print(f"Algorithm 2 against 1, {what}: {100 * d:+.4f} %")
        if not abs(d) < 0.005:
            failures.append(f"{what}: Algorithms 1 and 2 differ by {100 * d:+.3f} %")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
