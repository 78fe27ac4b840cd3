#!/usr/bin/python3
"""Conforming Turek-Hron interface: the fluid's flag nodes are the solid's.

th_cylinder_flag.geo with nflag = 100, nflagt = 6 puts 101 uniform nodes on each flag face
and 7 on the free end: the nodes of the solid's 100 x 6 rectangle mesh when that mesh starts
at the flag root, where the faces meet the cylinder, x0 = 0.2 + sqrt(0.05^2 - 0.01^2) =
0.24898979... (the scenes' solid origin 0.24899 is 2.05e-7 further right). Runs
`fsi run configs/fsi3.yaml` for a few steps, one run after the other (about 12 s in all):
  - P1/P1 fluid, solid from x0: summary.json interface.conforming true, 207 = 207 nodes, every
    one coinciding, max_gap < 1e-9 (measured 6e-16), H = P to 1e-9 (measured 1.4e-13);
  - the same with the scene's solid origin 0.24899: not conforming, max_gap 2.05e-7 (only the
    7 tip nodes coincide);
  - the scene itself (coarse fluid, 160 x 8 solid): not conforming;
  - the P2/P1 fluid (fsi3_p2p1.yaml) on the conforming mesh: its 207 vertices coincide with
    the solid's 207 nodes, its 206 edge midpoints do not (on the polyline: max_gap < 1e-9),
    so not conforming.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

X0 = 0.24898979485566358  # 0.2 + sqrt(0.0024): the flag root on the cylinder
CONFORMING = ["time.end=0.0075", "fluid.mesh.size=0.04",
              "fluid.mesh.parameters={hc: 0.0035, hw: 0.016, nflag: 100, nflagt: 6}",
              "solid.mesh.elements=[100, 6]"]
FROM_ROOT = [f"solid.mesh.origin=[{X0!r}, 0.19]", f"solid.mesh.size=[{0.6 - X0!r}, 0.02]"]


def run(a, out, scene, sets, failures):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_WAIT_POLICY="passive")
    cmd = [os.path.join(a.bin, "fsi"), "run", os.path.join(a.source, "configs", scene), "--out", out]
    for s in sets:
        cmd += ["--set", s]
    print(" ".join(cmd), flush=True)
    t0 = time.time()
    r = subprocess.run(cmd, env=env, timeout=120, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    summary = json.load(open(os.path.join(out, "summary.json")))
    if r.returncode != 0 or summary.get("status") != "completed":
        failures.append(f"{out}: status {summary.get('status')} (exit {r.returncode}): {summary.get('reason')}\n"
                        f"{r.stderr[-2000:]}")
    i = summary.get("interface", {})
    print(f"  {time.time() - t0:.1f} s: interface {json.dumps(i)}", flush=True)
    return i


def check(failures, what, ok):
    if not ok:
        failures.append(what)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    a = ap.parse_args()
    failures = []
    with tempfile.TemporaryDirectory(prefix="conforming_test_") as tmp:
        i = run(a, os.path.join(tmp, "p1p1"), "fsi3.yaml", CONFORMING + FROM_ROOT, failures)
        check(failures, f"P1/P1 from the root: not conforming ({i})",
              i.get("conforming") is True and i.get("fluid_nodes") == i.get("solid_nodes") == 207
              and i.get("coincident_nodes") == 207 and i.get("max_gap", 1) < 1e-9
              and i.get("permutation_error", 1) < 1e-9)

        i = run(a, os.path.join(tmp, "p1p1_0.24899"), "fsi3.yaml", CONFORMING + ["time.end=0.0025"], failures)
        check(failures, f"P1/P1, solid origin 0.24899: expected not conforming, gap 2.05e-7 ({i})",
              i.get("conforming") is False and i.get("fluid_nodes") == i.get("solid_nodes") == 207
              and 2.0e-7 < i.get("max_gap", 0) < 2.1e-7 and i.get("coincident_nodes") == 7)

        i = run(a, os.path.join(tmp, "scene"), "fsi3.yaml",
                ["time.end=0.0025", "fluid.mesh.size=0.04", "fluid.mesh.parameters={hc: 0.006, hw: 0.016}"], failures)
        check(failures, f"the scene: expected not conforming ({i})",
              i.get("conforming") is False and i.get("solid_nodes") == 329 and i.get("fluid_nodes") != 329)

        i = run(a, os.path.join(tmp, "p2p1"), "fsi3_p2p1.yaml", CONFORMING + FROM_ROOT + ["time.end=0.0025"], failures)
        check(failures, f"P2/P1: expected not conforming with every vertex on a solid node ({i})",
              i.get("conforming") is False and i.get("solid_nodes") == 207 and i.get("fluid_nodes") == 413
              and i.get("coincident_nodes") == 207 and i.get("max_gap", 1) < 1e-9)
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
