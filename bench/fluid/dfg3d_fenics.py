#!/usr/bin/env python3
"""DFG 3D-1Z (Schafer & Turek 1996, Re 20, steady) with legacy FEniCS, on our gmsh mesh.

A reference point for `fsi run configs/dfg_3d1z.yaml`: the same problem, the same mesh generator
and parameters, solved by Debian's python3-dolfin (2019.2), so that accuracy (C_D, C_L, dp against
Braack & Richter 2006) and whole-process wall time and memory can be put side by side with ours
(bench/fluid/dfg3d_engines.py measures our side).

Usage (from the repository root, with the system Python that has dolfin):
  /usr/bin/python3 bench/fluid/dfg3d_fenics.py --level 0                 # MUMPS LU, one run
  /usr/bin/python3 bench/fluid/dfg3d_fenics.py --level 0 --reps 3 --json out/fenics_l0.json
  /usr/bin/python3 bench/fluid/dfg3d_fenics.py --level 0.5 --solver gmres  # field-split GMRES
Options: --size H (far size, our fluid.mesh.size, default 0.1), --hc HC (cylinder size, default
0.025), --level L (our fluid.mesh.parameters.level: every size / 2^L; fractional levels work),
--out DIR (mesh files, reused when present), --reps N (N fresh processes, medians printed).

What is solved (configs/dfg_3d1z.yaml): channel [0, 2.5] x [0, 0.41]^2 around a cylinder of
diameter 0.1 at (0.5, 0.2); rho = 1, nu = 0.001; inflow u = 16 U_m y z (H - y)(H - z) / H^4 in x,
U_m = 0.45; no-slip on the walls and the cylinder; do-nothing outlet (nu grad u - p I) n = 0 (the
gradient form of the viscous term, like ours). Taylor-Hood P2/P1. One Stokes solve, then Newton
on the steady Navier-Stokes equations from it (relative residual tolerance 1e-8), like ours.
C = 2 F / (rho U_mean^2 D H), U_mean = 0.2, D H = 0.041; dp = p(0.45, 0.2, 0.205) - p(0.55, 0.2,
0.205). Each run prints: unknowns, Newton iterations, the solve's wall time (Stokes + Newton,
assembly included), the whole process's wall time (from the process start: Python and dolfin
imports, mesh reading, form compilation or cache look-up, solve, post-processing), peak RSS, and
C_D, C_L, dp with their relative errors. The mesh (gmsh + meshio conversion) is made once, by the
parent process, before the timed runs, like our mesh cache (~/.cache/fsi/meshes).

The mesh: `gmsh -3 -format msh22 -v 2 -order 1 -setnumber h SIZE -setnumber hc HC -setnumber
level L configs/meshes/dfg_3d_cylinder.geo`, the command our fluid builds (mesh_geo() in
fluid_server/core/src/navier_stokes_fluid.cpp) except for the order; meshio converts it to XDMF
(tetrahedra; boundary triangles with their gmsh physical ids, names from the .msh field data).

Honest differences from our solver:
* Faceted cylinder: legacy dolfin only takes affine (4-node) tetrahedra, so this mesh is the
  linear one (-order 1) and the cylinder is a polygonal prism with its vertices on the circle;
  ours meshes with -order 2 and isoparametric P2/P1 on 10-node tetrahedra (curved cylinder). The
  vertices, and so the unknown count, are the same.
* Forces: the volume (residual, reaction) form, like ours: F_x = -R(u, p; w_x), w_x the P2 field
  equal to e_x at the cylinder's velocity nodes (edges and corners where it meets the walls
  included) and 0 elsewhere (e_y for the lift). Not the surface integral of sigma n.
* Linear solver: MUMPS LU through dolfin's NonlinearVariationalSolver (default), or with
  --solver gmres our PETSc engine's field split (GMRES, right preconditioned, restart 200, rtol
  1e-10; Schur lower, selfp, block Jacobi ILU(0) on the velocity, BoomerAMG on the pressure)
  through a dolfin NewtonSolver subclass. Assembly is dolfin's (FFC-generated kernels); the
  quadrature degree is FFC's automatic one.
* Form compilation: the first run on a machine compiles the forms into ~/.cache (dijitso), which
  takes tens of seconds and is counted in that run's process time; later runs load them. Run
  once beforehand, or use --reps 3 and the median.
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

START = time.perf_counter()  # fallback origin of the process time when /proc is missing
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GEO = os.path.join(ROOT, "configs", "meshes", "dfg_3d_cylinder.geo")

# Problem data (configs/dfg_3d1z.yaml).
H = 0.41
U_MAX = 0.45
U_MEAN = 0.2
NU = 0.001
RHO = 1.0
REFERENCE_AREA = 0.1 * H  # D H
P_FRONT = (0.45, 0.2, 0.205)
P_BACK = (0.55, 0.2, 0.205)
NEWTON_RTOL = 1e-8
NEWTON_MAX_IT = 20
# Braack & Richter 2006.
REFERENCE = {"cd": 6.185333, "cl": 0.009401, "dp": 0.171007}
GROUPS = ("inlet", "outlet", "walls", "cylinder")
# Our PETSc engine's defaults (docs/fluid.md, Linear-algebra engines).
FIELDSPLIT_OPTIONS = {
    "ksp_type": "gmres", "ksp_pc_side": "right", "ksp_gmres_restart": 200, "ksp_rtol": 1e-10,
    "ksp_max_it": 1000, "pc_type": "fieldsplit", "pc_fieldsplit_type": "schur",
    "pc_fieldsplit_schur_fact_type": "lower", "pc_fieldsplit_schur_precondition": "selfp",
    "fieldsplit_u_ksp_type": "preonly", "fieldsplit_u_pc_type": "bjacobi",
    "fieldsplit_u_sub_pc_type": "ilu", "fieldsplit_p_ksp_type": "preonly",
    "fieldsplit_p_pc_type": "hypre", "fieldsplit_p_pc_hypre_type": "boomeramg",
}
FIELDSPLIT_PREFIX = "dfg_"


def process_wall_time():
    """Seconds since this process started (/proc: includes the interpreter's own start-up)."""
    try:
        with open("/proc/self/stat") as f:
            start_ticks = float(f.read().rsplit(")", 1)[1].split()[19])
        with open("/proc/uptime") as f:
            uptime = float(f.read().split()[0])
        return uptime - start_ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return time.perf_counter() - START


# --- mesh ---

def mesh_paths(out_dir, size, hc, level):
    stem = os.path.join(out_dir, f"dfg3d_h{size:g}_hc{hc:g}_level{level:g}")
    return {"msh": stem + ".msh", "cells": stem + "_cells.xdmf", "facets": stem + "_facets.xdmf",
            "groups": stem + "_groups.json"}


def make_mesh(paths, size, hc, level):
    """gmsh (linear tetrahedra) and meshio to XDMF, unless the files exist. Returns gmsh + conversion seconds."""
    if all(os.path.exists(paths[k]) for k in ("cells", "facets", "groups")):
        return 0.0
    t0 = time.perf_counter()
    os.makedirs(os.path.dirname(paths["msh"]), exist_ok=True)
    cmd = ["gmsh", "-3", "-format", "msh22", "-v", "2", "-order", "1",
           "-setnumber", "h", f"{size:.17g}", "-setnumber", "hc", f"{hc:.17g}",
           "-setnumber", "level", f"{level:.17g}", GEO, "-o", paths["msh"]]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0 or not os.path.exists(paths["msh"]):
        sys.exit(f"gmsh failed (exit {p.returncode}): {' '.join(cmd)}\n{p.stdout}{p.stderr}")
    convert_mesh(paths)
    return time.perf_counter() - t0


def convert_mesh(paths):
    """The .msh to two XDMF files (tetrahedra; boundary triangles with their physical ids)."""
    import meshio
    import numpy as np

    msh = meshio.read(paths["msh"])
    tags = msh.cell_data["gmsh:physical"]
    tets = [b.data for b in msh.cells if b.type == "tetra"]
    tris = [(b.data, t) for b, t in zip(msh.cells, tags) if b.type == "triangle"]
    if not tets or not tris:
        sys.exit(f"{paths['msh']}: expected 4-node tetrahedra and 3-node triangles, got "
                 f"{sorted({b.type for b in msh.cells})}")
    tets = np.concatenate(tets)
    tri_cells = np.concatenate([c for c, _ in tris])
    tri_tags = np.concatenate([t for _, t in tris])
    # Keep only the tetrahedra's nodes, renumbered.
    used = np.unique(tets)
    renumber = np.full(len(msh.points), -1, dtype=np.int64)
    renumber[used] = np.arange(len(used))
    points = msh.points[used]
    meshio.write(paths["cells"], meshio.Mesh(points, [("tetra", renumber[tets])]))
    meshio.write(paths["facets"], meshio.Mesh(points, [("triangle", renumber[tri_cells])],
                                              cell_data={"markers": [tri_tags]}))
    groups = {name: int(v[0]) for name, v in msh.field_data.items()}
    missing = [g for g in GROUPS if g not in groups]
    if missing:
        sys.exit(f"{paths['msh']}: physical groups {missing} missing (have {sorted(groups)})")
    with open(paths["groups"], "w") as f:
        json.dump(groups, f)


# --- solve (one process) ---

def read_mesh(dolfin, paths):
    mesh = dolfin.Mesh()
    with dolfin.XDMFFile(paths["cells"]) as f:
        f.read(mesh)
    markers = dolfin.MeshValueCollection("size_t", mesh, 2)
    with dolfin.XDMFFile(paths["facets"]) as f:
        f.read(markers, "markers")
    facets = dolfin.cpp.mesh.MeshFunctionSizet(mesh, markers)
    with open(paths["groups"]) as f:
        groups = json.load(f)
    return mesh, facets, groups


def navier_stokes_forms(dolfin, W, w, convection):
    """The residual R(w; v, q) (gradient form, do-nothing outlet), its Jacobian, and R as a function of the test field."""
    from ufl import derivative, div, dot, dx, grad, inner, split

    nu = dolfin.Constant(NU)

    def residual(test):
        u, p = split(w)
        v, q = split(test)
        return (convection * dot(dot(grad(u), u), v) + nu * inner(grad(u), grad(v))
                - p * div(v) - q * div(u)) * dx

    F = residual(dolfin.TestFunction(W))
    return F, derivative(F, w), residual


def boundary_conditions(dolfin, W, facets, groups):
    inflow = dolfin.Expression(
        ("16.0 * Um * x[1] * x[2] * (H - x[1]) * (H - x[2]) / pow(H, 4)", "0.0", "0.0"),
        Um=U_MAX, H=H, degree=4)
    zero = dolfin.Constant((0.0, 0.0, 0.0))
    return [dolfin.DirichletBC(W.sub(0), inflow, facets, groups["inlet"]),
            dolfin.DirichletBC(W.sub(0), zero, facets, groups["walls"]),
            dolfin.DirichletBC(W.sub(0), zero, facets, groups["cylinder"])]


def mumps_newton(dolfin, F, J, w, bcs):
    """dolfin's NonlinearVariationalSolver, Newton with MUMPS LU. Returns solve(): Newton iterations."""
    problem = dolfin.NonlinearVariationalProblem(F, w, bcs, J)
    solver = dolfin.NonlinearVariationalSolver(problem)
    prm = solver.parameters["newton_solver"]
    prm["linear_solver"] = "mumps"
    prm["relative_tolerance"] = NEWTON_RTOL
    prm["absolute_tolerance"] = 1e-14
    prm["maximum_iterations"] = NEWTON_MAX_IT
    prm["error_on_nonconvergence"] = True

    def solve():
        return solver.solve()[0]

    return solve, lambda: None


def fieldsplit_newton(dolfin, F, J, w, bcs, W):
    """A dolfin NewtonSolver with our PETSc engine's field-split GMRES. Returns solve() and krylov_iterations()."""
    from petsc4py import PETSc

    class Problem(dolfin.NonlinearProblem):
        def __init__(self):
            dolfin.NonlinearProblem.__init__(self)

        def F(self, b, x):
            dolfin.assemble(F, tensor=b)
            for bc in bcs:
                bc.apply(b, x)

        def J(self, A, x):
            dolfin.assemble(J, tensor=A)
            for bc in bcs:
                bc.apply(A)

    class Newton(dolfin.NewtonSolver):
        def __init__(self):
            self.krylov = dolfin.PETScKrylovSolver()
            dolfin.NewtonSolver.__init__(self, w.function_space().mesh().mpi_comm(), self.krylov,
                                         dolfin.PETScFactory.instance())
            self.configured = False
            self.iterations = 0

        def solver_setup(self, A, P, problem, iteration):
            self.krylov.set_operator(A)
            if self.configured:
                return
            ksp = self.krylov.ksp()
            ksp.setOptionsPrefix(FIELDSPLIT_PREFIX)
            options = PETSc.Options()
            for key, value in FIELDSPLIT_OPTIONS.items():
                options[FIELDSPLIT_PREFIX + key] = value
            ksp.setFromOptions()
            is_u = PETSc.IS().createGeneral(W.sub(0).dofmap().dofs())
            is_p = PETSc.IS().createGeneral(W.sub(1).dofmap().dofs())
            ksp.getPC().setFieldSplitIS(("u", is_u), ("p", is_p))
            ksp.setMonitor(self.count)
            self.configured = True

        def count(self, ksp, its, rnorm):
            if its > 0:
                self.iterations += 1

    newton = Newton()
    prm = newton.parameters
    prm["relative_tolerance"] = NEWTON_RTOL
    prm["absolute_tolerance"] = 1e-14
    prm["maximum_iterations"] = NEWTON_MAX_IT
    prm["error_on_nonconvergence"] = True
    problem = Problem()

    def solve():
        for bc in bcs:
            bc.apply(w.vector())
        return newton.solve(problem, w.vector())[0]

    return solve, lambda: newton.iterations


def force_coefficients(dolfin, W, w, residual, facets, cylinder):
    """C_D, C_L by the volume (reaction) form: F = -R(w; e_x resp. e_y on the cylinder's nodes)."""
    coefficients = []
    for direction in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)):
        test = dolfin.Function(W)
        dolfin.DirichletBC(W.sub(0), dolfin.Constant(direction), facets, cylinder).apply(test.vector())
        force = -dolfin.assemble(residual(test))
        coefficients.append(2.0 * force / (RHO * U_MEAN ** 2 * REFERENCE_AREA))
    return coefficients


def solve_single(args, paths):
    """One run in this process: the result dict."""
    import dolfin

    dolfin.set_log_level(dolfin.LogLevel.WARNING)
    t0 = time.perf_counter()
    mesh, facets, groups = read_mesh(dolfin, paths)
    t_mesh = time.perf_counter() - t0

    t0 = time.perf_counter()
    element = dolfin.MixedElement([dolfin.VectorElement("P", mesh.ufl_cell(), 2),
                                   dolfin.FiniteElement("P", mesh.ufl_cell(), 1)])
    W = dolfin.FunctionSpace(mesh, element)
    w = dolfin.Function(W)
    convection = dolfin.Constant(0.0)
    F, J, residual = navier_stokes_forms(dolfin, W, w, convection)
    bcs = boundary_conditions(dolfin, W, facets, groups)
    if args.solver == "mumps":
        solve, krylov_iterations = mumps_newton(dolfin, F, J, w, bcs)
    else:
        solve, krylov_iterations = fieldsplit_newton(dolfin, F, J, w, bcs, W)
    t_setup = time.perf_counter() - t0

    t0 = time.perf_counter()
    stokes_iterations = solve()        # convection off: Stokes, one Newton step
    convection.assign(1.0)
    newton_iterations = solve()
    t_solve = time.perf_counter() - t0

    cd, cl = force_coefficients(dolfin, W, w, residual, facets, groups["cylinder"])
    p = w.split(deepcopy=True)[1]
    dp = p(dolfin.Point(*P_FRONT)) - p(dolfin.Point(*P_BACK))
    result = {
        "solver": args.solver, "size": args.size, "hc": args.hc, "level": args.level,
        "unknowns": W.dim(), "cells": mesh.num_cells(),
        "stokes_iterations": stokes_iterations, "newton_iterations": newton_iterations,
        "linear_solves": stokes_iterations + newton_iterations,
        "krylov_iterations": krylov_iterations(),
        "mesh_read_s": t_mesh, "setup_s": t_setup, "solve_s": t_solve,
        "cd": cd, "cl": cl, "dp": dp,
    }
    for key, ref in REFERENCE.items():
        result[key + "_error"] = (result[key] - ref) / ref
    result["rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    result["process_s"] = process_wall_time()
    return result


# --- reporting and repetitions ---

def format_line(r, label):
    krylov = f", {r['krylov_iterations']:.0f} GMRES its" if r.get("krylov_iterations") else ""
    return (f"{label}: level {r['level']:g} ({r['solver']}), {r['unknowns']:,.0f} unknowns, "
            f"Newton {r['newton_iterations']:g} (+{r['stokes_iterations']:g} Stokes){krylov}, "
            f"solve {r['solve_s']:.2f} s, process {r['process_s']:.2f} s, RSS {r['rss_mb']:.0f} MB, "
            f"C_D {r['cd']:.6f} ({100 * r['cd_error']:+.3f} %), "
            f"C_L {r['cl']:.6g} ({100 * r['cl_error']:+.1f} %), "
            f"dp {r['dp']:.6f} ({100 * r['dp_error']:+.2f} %)")


def median_result(runs):
    """Medians of the numeric fields; the runs' solve and process times kept as lists."""
    out = dict(runs[0])
    for key, value in runs[0].items():
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            out[key] = statistics.median(r[key] for r in runs)
    out["reps"] = len(runs)
    out["solve_s_runs"] = [r["solve_s"] for r in runs]
    out["process_s_runs"] = [r["process_s"] for r in runs]
    return out


def run_reps(args):
    """Each rep in a fresh process (this script with --single); the median result."""
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        for rep in range(args.reps):
            out_json = os.path.join(tmp, f"rep{rep}.json")
            cmd = [sys.executable, os.path.abspath(__file__), "--single", "--json", out_json,
                   "--level", repr(args.level), "--size", repr(args.size), "--hc", repr(args.hc),
                   "--out", args.out, "--solver", args.solver]
            p = subprocess.run(cmd)
            if p.returncode != 0:
                sys.exit(f"rep {rep + 1} failed (exit {p.returncode}): {' '.join(cmd)}")
            with open(out_json) as f:
                runs.append(json.load(f))
    return median_result(runs)


def write_json(path, result):
    if path:
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        with open(path, "w") as f:
            json.dump(result, f, indent=2)


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--level", type=float, default=0.0, help="gmsh -setnumber level (every size / 2^level)")
    ap.add_argument("--size", type=float, default=0.1, help="element size far from the cylinder (gmsh h)")
    ap.add_argument("--hc", type=float, default=0.025, help="element size on the cylinder (gmsh hc)")
    ap.add_argument("--solver", choices=("mumps", "gmres"), default="mumps",
                    help="mumps: LU; gmres: our PETSc engine's field split (Schur, ILU / BoomerAMG)")
    ap.add_argument("--reps", type=int, default=1, help="runs, each a fresh process; medians printed")
    ap.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "dfg3d_fenics"),
                    help="folder of the mesh files (reused when present)")
    ap.add_argument("--json", help="write the result (the medians with --reps) to this file")
    ap.add_argument("--single", action="store_true", help=argparse.SUPPRESS)
    return ap.parse_args()


def main():
    args = parse_args()
    paths = mesh_paths(args.out, args.size, args.hc, args.level)
    mesh_s = make_mesh(paths, args.size, args.hc, args.level)
    if mesh_s > 0:
        print(f"mesh: {paths['msh']} (gmsh -order 1 and meshio, {mesh_s:.1f} s, not in the timings)", flush=True)
    if args.single:
        result = solve_single(args, paths)
        print(format_line(result, "dfg3d_fenics"), flush=True)
    else:
        result = run_reps(args)
        if args.reps > 1:
            runs = ", ".join(f"{t:.2f}" for t in result["process_s_runs"])
            print(format_line(result, f"median of {args.reps}") + f" [process s: {runs}]")
    result["mesh_s"] = mesh_s
    write_json(args.json, result)


if __name__ == "__main__":
    main()
