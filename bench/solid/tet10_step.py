#!/usr/bin/env python3
"""CSM1's static step (4 load steps, St. Venant-Kirchhoff) on a gmsh 10-node tetrahedron mesh,
solid_server (Tet10, CHOLMOD) against the FEniCS solid (python/examples/fenics_solid: P2 on the
same straight tetrahedra, DOLFIN's assembly, SciPy's SuperLU), side by side in one session,
alternately, each in a process of its own under /usr/bin/time -v. A benchmark, not a test.

Per solid and run: the wall time of the whole process (solid_server: `fsi run
configs/csm1_3d_tet.yaml --set solid.mesh.file=MESH`, standalone; FEniCS: fem.FlagSolid on the
same scene in a python3 process, DOLFIN's import included), the step alone, Newton iterations,
A, and the peak RSS; then one Newton iteration by phases (assembly, factorisation, solve:
`solid_bench phases` and the FEniCS solid's own calls, repeated, the first set apart).
Medians over the runs.

    /work/runs/slot /usr/bin/python3 bench/solid/tet10_step.py --bin build/bin --runs 3 --h 0.0035

(h 0.0035: 8948 cells, 43,473 free dofs). Prints markdown tables, the raw JSON lines on stderr.
Measured (this machine, 2 cores shared, load average ~4; 1 BLAS thread): python/examples/
fenics_solid/README.md and docs/coupling-your-code.md.
"""
import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
SCENE = os.path.join(SOURCE, "configs", "csm1_3d_tet.yaml")
GEO = os.path.join(SOURCE, "configs", "meshes", "csm_flag_3d.geo")


def fenics_side(mesh, phases):
    """In this process: the FEniCS solid on the scene with MESH, one static step; or (phases)
    one Newton iteration's phases repeated as fem.py runs them (splu = spsolve's factorisation)."""
    t_start = time.perf_counter()
    import numpy as np
    import scipy.sparse.linalg as spla
    import yaml
    sys.path.insert(0, os.path.join(SOURCE, "python", "examples", "fenics_solid"))
    import fem
    t_import = time.perf_counter() - t_start
    with open(SCENE) as f:
        scene = yaml.safe_load(f)
    scene["solid"]["mesh"]["file"] = mesh
    t = time.perf_counter()
    solid = fem.FlagSolid(scene["solid"], 1.0, 0.0, log=lambda *a: None, scene_path=SCENE)
    out = {"solver": "fenics", "free_dofs": int(solid.free.size), "import": t_import,
           "setup": time.perf_counter() - t}
    if phases:
        d, f = np.zeros(solid.n), solid.f_dead
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        from phases_3d import newton_phases  # one Newton iteration by phases, as for the hexahedra
        out.update(newton_phases(solid, d, f, phases))
    else:
        solid.solve(1.0, np.zeros(3 * len(solid.interface_nodes)))
        probes = solid.accept()
        out.update({"newton_iterations": solid.newton_iterations, "A_x": probes["A_x"], "A_y": probes["A_y"]},
                   **{k: solid.timings[k] for k in ("step", "assembly", "linear_solve")})
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(json.dumps(out))


def timed(cmd, env):
    """Run cmd under /usr/bin/time -v: (wall s, peak RSS MB, stdout)."""
    t0 = time.monotonic()
    p = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True, env=env)
    wall = time.monotonic() - t0
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {p.returncode}\n{p.stderr[-2000:]}")
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    return wall, int(rss.group(1)) / 1024.0 if rss else float("nan"), p.stdout


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bin", default=os.path.join(SOURCE, "build", "bin"))
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--h", type=float, default=0.0035, help="gmsh element size of csm_flag_3d.geo")
    p.add_argument("--mesh", help="a tet10 .msh of the flag instead of meshing csm_flag_3d.geo with --h")
    p.add_argument("--phases", type=int, default=3, help="Newton iterations by phases per run (0: none)")
    p.add_argument("--threads", type=int, default=1, help="OPENBLAS_NUM_THREADS and OMP_NUM_THREADS of both solids "
                   "(default 1: one /work/runs/slot is one core; both link the threaded OpenBLAS)")
    p.add_argument("--side", choices=("both", "fenics"), default="both")
    p.add_argument("--fenics-phases", type=int, default=0, help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.side == "fenics":
        fenics_side(a.mesh, a.fenics_phases)
        return
    work = tempfile.mkdtemp(prefix="tet10_step_")
    mesh = a.mesh
    if not mesh:
        mesh = os.path.join(work, f"flag_{a.h:g}.msh")
        subprocess.run(["gmsh", "-3", "-order", "2", "-format", "msh22", "-setnumber", "h", str(a.h), GEO, "-o", mesh],
                       check=True, capture_output=True)
    fsi = os.path.join(a.bin, "fsi")
    env = dict(os.environ, OPENBLAS_NUM_THREADS=str(a.threads), OMP_NUM_THREADS=str(a.threads))
    me = ["/usr/bin/python3", os.path.abspath(__file__), "--side", "fenics", "--mesh", mesh]
    rows = {"solid_server": [], "fenics": []}
    phases = {"solid_server": [], "fenics": []}
    for run in range(a.runs):
        out = os.path.join(work, f"solid_server_{run}")
        wall, rss, _ = timed([fsi, "run", SCENE, "--out", out, "--set", f"solid.mesh.file={mesh}", "--set",
                              "time.output_every=0"], env)
        s = json.load(open(os.path.join(out, "summary.json")))
        rows["solid_server"].append({"wall": wall, "peak_rss_mb": rss, "step": s["wall_time"]["solid"],
                                     "setup": s["setup_seconds"], "newton_iterations": s["solver_iterations"],
                                     "A_x": s["final"]["solid.A_x"], "A_y": s["final"]["solid.A_y"]})
        print(json.dumps({"solver": "solid_server", **rows["solid_server"][-1]}), file=sys.stderr, flush=True)
        wall, rss, stdout = timed(me, env)
        r = json.loads(stdout.strip().splitlines()[-1])
        r.update(wall=wall, peak_rss_mb_process=rss)
        rows["fenics"].append(r)
        print(json.dumps(r), file=sys.stderr, flush=True)
        if a.phases:
            bench = os.path.join(a.bin, "solid_bench")
            _, rss, stdout = timed([bench, "phases", SCENE, f"solid.mesh.file={mesh}"], env)
            phases["solid_server"].append(json.loads(stdout.strip().splitlines()[-1]))
            _, rss, stdout = timed(me + ["--fenics-phases", str(a.phases)], env)
            phases["fenics"].append(json.loads(stdout.strip().splitlines()[-1]))
            for name in phases:
                print(json.dumps(phases[name][-1]), file=sys.stderr, flush=True)

    def med(name, key):
        return statistics.median(r[key] for r in rows[name])

    free = phases["fenics"][0]["free_dofs"] if phases["fenics"] else rows["fenics"][0]["free_dofs"]
    print(f"\nCSM1 static step (4 load steps) on {os.path.basename(mesh)}: {free:,} free dofs; medians of "
          f"{a.runs} runs; "
          f"{a.threads} BLAS thread(s)\n")
    print("| solid | wall (process) | step | Newton iterations | A_x 1e-3 | A_y 1e-3 | peak RSS |")
    print("|---|---|---|---|---|---|---|")
    for name, label in (("solid_server", "solid_server (Tet10, CHOLMOD)"), ("fenics", "FEniCS (P2, SuperLU)")):
        print(f"| {label} | {med(name, 'wall'):.1f} s | {med(name, 'step'):.1f} s | "
              f"{med(name, 'newton_iterations'):.0f} | {1e3 * rows[name][0]['A_x']:.5f} | "
              f"{1e3 * rows[name][0]['A_y']:.4f} | "
              f"{med(name, 'peak_rss_mb_process' if name == 'fenics' else 'peak_rss_mb'):.0f} MB |")
    print(f"\nThe FEniCS step: assembly {med('fenics', 'assembly'):.1f} s, linear solves (spsolve) "
          f"{med('fenics', 'linear_solve'):.1f} s; DOLFIN's import {med('fenics', 'import'):.1f} s, setup "
          f"{med('fenics', 'setup'):.1f} s (solid_server's setup {med('solid_server', 'setup'):.1f} s).")
    if a.phases:
        def pmed(name, key, first=False):
            return statistics.median(x for r in phases[name] for x in (r[key][:1] if first else r[key][1:a.phases]))
        print(f"\nOne Newton iteration by phases (medians of the repeats after the first):\n")
        print("| solid | matrix nonzeros | assembly | factorisation | solve | first factorisation |")
        print("|---|---|---|---|---|---|")
        for name, label in (("solid_server", "solid_server (Tet10, CHOLMOD)"), ("fenics", "FEniCS (P2, SuperLU)")):
            r0 = phases[name][0]
            extra = f" (+ {pmed(name, 'extraction'):.2f} s free-block extraction)" if name == "fenics" else ""
            print(f"| {label} | {r0['nonzeros']:,} | {pmed(name, 'assembly'):.2f} s{extra} | "
                  f"{pmed(name, 'factorisation'):.2f} s | {pmed(name, 'solve'):.3f} s | "
                  f"{pmed(name, 'factorisation', first=True):.2f} s |")
        f0 = phases["fenics"][0]
        print(f"\nSuperLU's factor: {f0['factor_nonzeros']:,} nonzeros.")
    print(f"\nraw: {work}", flush=True)


if __name__ == "__main__":
    main()
