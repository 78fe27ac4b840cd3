#!/usr/bin/env python3
"""`fsi run` with fluid.ranks: the 3D fluid under mpirun on 2 ranks gives the 1-rank values.

A coarse DFG 3D-1Z (6,840 unknowns): MUMPS on 1 and 2 ranks equal to 1e-10, the field-split GMRES
(rtol 1e-12) on 2 ranks equal to them to 1e-7 (the forces: the reactions, each rank's share of
them with the partitioned assembly); a coarse coupled elastic tube (5 steps, Nitsche interface
terms and an inlet pressure added by rank 0 to the distributed matrix) on 2 ranks, partitioned,
equal to rank 0's assembly alone to 1e-9; a missing MPI launcher is a clear error. Prints
SKIPPED (ctest: skipped) without mpirun.
  test_mpi_run.py --bin build/bin --source .
"""
import argparse
import csv
import os
import shutil
import subprocess
import sys
import tempfile

ap = argparse.ArgumentParser()
ap.add_argument("--bin", required=True)
ap.add_argument("--source", required=True)
a = ap.parse_args()
if not shutil.which("mpirun"):
    print("SKIPPED: no mpirun on PATH (Debian: apt-get install openmpi-bin)")
    sys.exit(0)

COARSE = ["fluid.mesh.size=0.2", "fluid.mesh.parameters.hc=0.05"]


def run(out, sets):
    cmd = [os.path.join(a.bin, "fsi"), "run", os.path.join(a.source, "configs/dfg_3d1z.yaml"), "--out", out, "--force"]
    for s in COARSE + sets:
        cmd += ["--set", s]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    return p


def final(out):
    with open(os.path.join(out, "probes.csv")) as f:
        row = list(csv.DictReader(f))[-1]
    return {k: float(row["fluid." + k]) for k in ("cd", "cl", "dp")}


failures = []
with tempfile.TemporaryDirectory() as tmp:
    values = {}
    for name, sets in [("mumps1", ["fluid.linear_solver.engine=mumps"]),
                       ("mumps2", ["fluid.linear_solver.engine=mumps", "fluid.ranks=2"]),
                       ("petsc2", ["fluid.linear_solver.engine=petsc", "fluid.ranks=2",
                                   "fluid.linear_solver.petsc_options=-ksp_rtol 1e-12"])]:
        out = os.path.join(tmp, name)
        p = run(out, sets)
        if p.returncode != 0:
            sys.exit(f"{name}: fsi run failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
        if name.endswith("2") and "on 2 rank(s)" not in p.stdout + p.stderr:
            failures.append(f"{name}: the log does not say the solve ran on 2 ranks")
        values[name] = final(out)
        print(name, values[name])
    for name, tol in [("mumps2", 1e-10), ("petsc2", 1e-7)]:
        for k, v in values[name].items():
            ref = values["mumps1"][k]
            if abs(v - ref) > tol * abs(ref):
                failures.append(f"{name} {k} {v!r} differs from 1 rank {ref!r} by more than {tol} relative")
    # The coupled tube: partitioned against rank 0's assembly, both on 2 ranks with MUMPS.
    tube = {}
    for mode in ("partitioned", "rank0"):
        out = os.path.join(tmp, "tube_" + mode)
        cmd = [os.path.join(a.bin, "fsi"), "run", os.path.join(a.source, "configs/tube_3d.yaml"), "--out", out]
        for s in ["fluid.mesh.size=0.5", "solid.mesh.divisions=[12, 1, 10]", "time.end=0.0005", "fluid.ranks=2",
                  "fluid.linear_solver.engine=mumps", "fluid.mpi.assembly=" + mode]:
            cmd += ["--set", s]
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
        if p.returncode != 0:
            sys.exit(f"tube_{mode}: fsi run failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
        with open(os.path.join(out, "probes.csv")) as f:
            tube[mode] = list(csv.DictReader(f))
    columns = [k for k in tube["rank0"][0] if k.startswith(("fluid.p", "solid.r"))]
    if len(tube["partitioned"]) != 5 or len(columns) < 10:
        failures.append(f"tube: {len(tube['partitioned'])} steps, {len(columns)} probe columns (expected 5, >= 10)")
    worst = 0.0
    for k in columns:
        scale = max(abs(float(r[k])) for r in tube["rank0"]) or 1.0
        worst = max(worst, max(abs(float(x[k]) - float(y[k])) for x, y in zip(tube["partitioned"], tube["rank0"])) / scale)
    print(f"tube on 2 ranks, partitioned against rank 0's assembly: {worst:.2e} (largest relative difference)")
    if not worst < 1e-9:
        failures.append(f"tube: the partitioned assembly differs from rank 0's by {worst:.3g} relative (> 1e-9)")
    p = run(os.path.join(tmp, "nompi"), ["fluid.ranks=2", "fluid.mpi.command=no-such-mpirun"])
    if p.returncode == 0 or "no-such-mpirun" not in p.stdout + p.stderr:
        failures.append(f"a missing MPI launcher was not refused by name:\n{p.stdout}\n{p.stderr}")
for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
