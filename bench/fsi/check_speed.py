#!/usr/bin/env python3
"""How fast `fsi check` is: every scene in configs/ and every study in studies/, checked
without meshing or a process. Goal: under 1 s each on the 2-core development machine (a
benchmark, not a test: the tests do not depend on the machine's speed).

    python3 bench/fsi/check_speed.py [--fsi build/bin/fsi] [--goal 1.0]
"""
import argparse
import glob
import os
import subprocess
import sys
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--fsi", default=os.path.join(ROOT, "build", "bin", "fsi"))
    p.add_argument("--goal", type=float, default=1.0, help="seconds per file")
    a = p.parse_args()
    files = sorted(glob.glob("configs/*.yaml", root_dir=ROOT)) + sorted(glob.glob("studies/*.yaml", root_dir=ROOT))
    times = []
    for f in files:
        t0 = time.monotonic()
        r = subprocess.run([a.fsi, "check", f], cwd=ROOT, capture_output=True, text=True, timeout=120)
        times.append((time.monotonic() - t0, f, r.returncode))
    times.sort(reverse=True)
    for seconds, f, code in times[:5]:
        print(f"{seconds:7.3f} s  {f}  (exit {code})")
    slowest = times[0][0]
    print(f"{len(files)} files, slowest {slowest:.3f} s, goal {a.goal} s: {'met' if slowest < a.goal else 'MISSED'}")
    return 0 if slowest < a.goal else 1


if __name__ == "__main__":
    sys.exit(main())
