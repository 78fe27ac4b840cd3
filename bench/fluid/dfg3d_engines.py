#!/usr/bin/env python3
"""DFG 3D-1Z with the fluid's linear-algebra engines (docs/fluid.md, Linear-algebra engines).

Runs `fsi run configs/dfg_3d1z.yaml` per variant under /usr/bin/time -v, `--reps` times, and prints a
Markdown table of medians: wall time, max RSS (the largest process; with mpirun one rank), the peak
RSS of each fluid rank (rank 0 / the others, read from /proc while the run goes), Newton iterations,
preconditioner set-ups (factorisations), Krylov iterations, the assembly, set-up and solve seconds
(fluid_breakdown), C_D, C_L, dp.

  bench/fluid/dfg3d_engines.py --level 0 --reps 3 --variants umfpack,mumps,petsc,petsc_2ranks
  bench/fluid/dfg3d_engines.py --level 0 --reps 1 --variants study   # the preconditioner study
  --wrap /work/runs/slot   runs every run through a job-slot command (N ranks: wrapped N times)
"""
import argparse
import csv
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ITERATIVE = "fluid.linear_solver.engine=petsc"
VARIANTS = {
    "umfpack": ([], 1),
    "mumps": (["fluid.linear_solver.engine=mumps"], 1),
    "petsc": ([ITERATIVE], 1),
    "petsc_reuse": ([ITERATIVE, "fluid.linear_solver.petsc_reuse_preconditioner=true"], 1),
    "petsc_2ranks": ([ITERATIVE, "fluid.ranks=2"], 2),
    # The element matrices computed by rank 0 alone; by every rank and summed on rank 0 (the
    # default: partitioned, each rank keeps its cells and fills its rows of the matrix).
    "petsc_2ranks_rank0": ([ITERATIVE, "fluid.ranks=2", "fluid.mpi.assembly=rank0"], 2),
    "petsc_2ranks_summed": ([ITERATIVE, "fluid.ranks=2", "fluid.mpi.assembly=distributed"], 2),
    "mumps_2ranks": (["fluid.linear_solver.engine=mumps", "fluid.ranks=2"], 2),
    # Preconditioner study (fresh preconditioner every Newton iteration, so the counts compare).
    "schur_lower_ilu_amg": ([ITERATIVE, "fluid.linear_solver.petsc_reuse_preconditioner=false"], 1),
    "schur_full_ilu_amg": ([ITERATIVE, "fluid.linear_solver.petsc_reuse_preconditioner=false",
                            "fluid.linear_solver.petsc_options=-pc_fieldsplit_schur_fact_type full"], 1),
    "schur_upper_ilu_amg": ([ITERATIVE, "fluid.linear_solver.petsc_reuse_preconditioner=false",
                             "fluid.linear_solver.petsc_options=-pc_fieldsplit_schur_fact_type upper"], 1),
    "schur_diag_ilu_amg": ([ITERATIVE, "fluid.linear_solver.petsc_reuse_preconditioner=false",
                            "fluid.linear_solver.petsc_options=-pc_fieldsplit_schur_fact_type diag"], 1),
    "schur_lower_amg_amg": ([ITERATIVE, "fluid.linear_solver.petsc_reuse_preconditioner=false",
                             "fluid.linear_solver.petsc_options=-fieldsplit_u_pc_type hypre -ksp_max_it 400"], 1),
    "schur_lower_ilu1_amg": ([ITERATIVE, "fluid.linear_solver.petsc_reuse_preconditioner=false",
                              "fluid.linear_solver.petsc_options=-fieldsplit_u_sub_pc_factor_levels 1"], 1),
    "schur_lower_ilu_jacobi": ([ITERATIVE, "fluid.linear_solver.petsc_reuse_preconditioner=false",
                                "fluid.linear_solver.petsc_options=-fieldsplit_p_pc_type jacobi -ksp_max_it 400"], 1),
    "schur_lower_lu_amg": ([ITERATIVE, "fluid.linear_solver.petsc_reuse_preconditioner=false",
                            "fluid.linear_solver.petsc_options=-fieldsplit_u_pc_type lu "
                            "-fieldsplit_u_pc_factor_mat_solver_type mumps"], 1),
}
STUDY = ["schur_lower_ilu_amg", "schur_full_ilu_amg", "schur_upper_ilu_amg", "schur_diag_ilu_amg",
         "schur_lower_ilu1_amg", "schur_lower_lu_amg", "schur_lower_ilu_jacobi", "schur_lower_amg_amg"]


def watch_ranks(peaks, done):
    """Until `done`: the peak RSS (VmHWM, MB) of every fluid_server process by its MPI rank."""
    while not done.is_set():
        for pid in os.listdir("/proc"):
            if not pid.isdigit():
                continue
            try:
                with open(f"/proc/{pid}/comm") as f:
                    if f.read().strip() != "fluid_server":
                        continue
                with open(f"/proc/{pid}/environ", "rb") as f:
                    env = dict(e.split(b"=", 1) for e in f.read().split(b"\0") if b"=" in e)
                rank = int(env.get(b"OMPI_COMM_WORLD_RANK", b"0"))
                with open(f"/proc/{pid}/status") as f:
                    hwm = next(int(l.split()[1]) for l in f if l.startswith("VmHWM"))
                peaks[rank] = max(peaks.get(rank, 0), hwm / 1024)
            except (OSError, StopIteration, ValueError):
                continue
        time.sleep(0.2)


def run(name, sets, ranks, level, out_root, wrap, extra):
    out = os.path.join(out_root, name)
    shutil.rmtree(out, ignore_errors=True)
    cmd = ["/usr/bin/time", "-v", os.path.join(ROOT, "build/bin/fsi"), "run", os.path.join(ROOT, "configs/dfg_3d1z.yaml"),
           "--out", out, "--set", f"fluid.mesh.parameters.level={level}"]
    for s in sets + extra:
        cmd += ["--set", s]
    if wrap:
        cmd = [wrap] * ranks + cmd
    peaks, done = {}, threading.Event()
    watcher = threading.Thread(target=watch_ranks, args=(peaks, done))
    watcher.start()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True)
    finally:
        done.set()
        watcher.join()
    text = p.stdout + p.stderr
    row = {"name": name, "ok": p.returncode == 0}
    row["rank0_mb"] = peaks.get(0, float("nan"))
    row["others_mb"] = max((v for r, v in peaks.items() if r > 0), default=float("nan"))
    m = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", text)
    if m:
        parts = [float(x) for x in m.group(1).split(":")]
        row["wall"] = sum(v * 60 ** (len(parts) - 1 - i) for i, v in enumerate(parts))
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    row["rss_mb"] = int(m.group(1)) / 1024 if m else float("nan")
    if p.returncode != 0:
        errors = [l for l in text.splitlines() if "[error]" in l or "did not converge" in l]
        row["error"] = " / ".join(errors)[-600:] or text[-600:]
        return row
    with open(os.path.join(out, "probes.csv")) as f:
        last = list(csv.DictReader(f))[-1]
    for k in ("cd", "cl", "dp", "nonlinear_iterations", "factorisations", "linear_iterations"):
        row[k] = float(last.get("fluid." + k, "nan"))
    summary = json.load(open(os.path.join(out, "summary.json")))
    b = summary.get("fluid_breakdown", {})
    row["setup_s"] = b.get("factorisation", float("nan"))
    row["solve_s"] = b.get("linear_solve", float("nan"))
    row["assembly_s"] = b.get("assembly", float("nan"))
    row["dofs"] = summary.get("dofs")
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--level", default="0")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--variants", default="umfpack,mumps,petsc,petsc_2ranks")
    ap.add_argument("--out", default="/tmp/dfg3d_engines")
    ap.add_argument("--wrap", default="")
    ap.add_argument("--set", action="append", default=[], help="further --set KEY=VALUE for every run")
    a = ap.parse_args()
    names = STUDY if a.variants == "study" else a.variants.split(",")
    print(f"| variant | unknowns | wall s | RSS MB | fluid rank 0 / others MB | Newton its | PC set-ups | Krylov its | assembly s | set-up s | solve s | C_D | C_L | dp |")
    print("|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name in names:
        sets, ranks = VARIANTS[name]
        rows = [run(name, sets, ranks, a.level, a.out, a.wrap, a.set) for _ in range(a.reps)]
        good = [r for r in rows if r["ok"]]
        if not good:
            print(f"| {name} | failed: {rows[0].get('error', '')[-300:]!r} |", flush=True)
            continue
        med = lambda k: statistics.median(r[k] for r in good)
        walls = ", ".join(f"{r['wall']:.1f}" for r in good)
        print(f"| {name} | {good[0]['dofs']} | {med('wall'):.1f} ({walls}) | {med('rss_mb'):.0f} | "
              f"{med('rank0_mb'):.0f} / {med('others_mb'):.0f} | "
              f"{med('nonlinear_iterations'):.0f} | {med('factorisations'):.0f} | {med('linear_iterations'):.0f} | "
              f"{med('assembly_s'):.2f} | {med('setup_s'):.2f} | {med('solve_s'):.2f} | {good[0]['cd']:.9f} | "
              f"{good[0]['cl']:.9g} | {good[0]['dp']:.9f} |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
