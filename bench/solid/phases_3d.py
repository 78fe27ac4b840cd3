#!/usr/bin/env python3
"""One Newton iteration of a 3D solid by phases (assembly, factorisation, solve) and the peak
memory: solid_server (Hex8, CHOLMOD; `solid_bench phases`) against the FEniCS solid
(python/examples/fenics_solid: DOLFIN's assembly, SciPy's SuperLU, the solver its Newton uses)
on the same box mesh, run alternately in one session, each in a process of its own; medians
over the runs of the repeated iterations after the first (CHOLMOD's symbolic analysis and
DOLFIN's first sparsity pattern are in the first: reported apart). A benchmark, not a test.

    /work/runs/slot /usr/bin/python3 bench/solid/phases_3d.py --bin build/bin --runs 3 \
        --divisions 64 8 32      # the cantilever strip, 57,024 free dofs

Prints a markdown table (docs/solid.md) and the raw JSON lines.
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
SCENE = os.path.join(SOURCE, "configs", "cantilever_strip_3d.yaml")


def newton_phases(solid, d, f, repeats):
    """One Newton iteration of the FEniCS solid (python/examples/fenics_solid), `repeats` times, by
    phases: DOLFIN's assembly, the free block's extraction, SuperLU (COLAMD) factorisation, solve.
    Lists of seconds per phase, the matrix's and the factors' nonzeros, the solve's residual."""
    import numpy as np
    import scipy.sparse.linalg as spla
    out = {key: [] for key in ("assembly", "extraction", "factorisation", "solve")}
    for _ in range(repeats):
        t0 = time.perf_counter()
        r, J = solid._assemble(d, f, 0.0, None, 0.0, None)
        t1 = time.perf_counter()
        Jff = J[solid.free][:, solid.free].tocsc()
        t2 = time.perf_counter()
        lu = spla.splu(Jff, permc_spec="COLAMD")
        t3 = time.perf_counter()
        x = lu.solve(-r)
        t4 = time.perf_counter()
        for key, v in zip(("assembly", "extraction", "factorisation", "solve"), (t1 - t0, t2 - t1, t3 - t2, t4 - t3)):
            out[key].append(v)
    out["nonzeros"] = int(Jff.nnz)
    out["factor_nonzeros"] = int(lu.L.nnz + lu.U.nnz)
    out["relative_residual"] = float(np.linalg.norm(Jff @ x + r) / np.linalg.norm(r))
    return out


def fenics_phases(divisions, repeats):
    """The FEniCS solid's FlagSolid on the scene, its Newton iteration's phases as fem.py runs
    them: DOLFIN assembles F_int and K, the free block is extracted, SuperLU (COLAMD)
    factorises (spsolve's factorisation, split from its solve by splu) and solves."""
    import numpy as np
    import scipy.sparse.linalg as spla
    import yaml
    sys.path.insert(0, os.path.join(SOURCE, "python", "examples", "fenics_solid"))
    import fem
    with open(SCENE) as f:
        scene = yaml.safe_load(f)
    scene["solid"]["mesh"]["divisions"] = list(divisions)
    t = time.perf_counter()
    solid = fem.FlagSolid(scene["solid"], scene["time"]["dt"], 0.0, log=lambda *a: None)
    setup = time.perf_counter() - t
    d, f = np.zeros(solid.n), np.ones(solid.n)
    out = {"solver": "fenics", "free_dofs": int(solid.free.size), "setup": setup, "assembly": [], "extraction": [],
           "factorisation": [], "solve": []}
    out.update(newton_phases(solid, d, f, repeats))
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(json.dumps(out))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bin", default=os.path.join(SOURCE, "build", "bin"))
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--repeats", type=int, default=3, help="Newton iterations per run (the first is set apart)")
    p.add_argument("--divisions", type=int, nargs=3, default=[64, 8, 32])
    p.add_argument("--side", choices=("both", "fenics"), default="both")
    a = p.parse_args()
    if a.side == "fenics":
        fenics_phases(a.divisions, a.repeats)
        return
    div = f"solid.mesh.divisions=[{', '.join(map(str, a.divisions))}]"
    commands = {
        "solid_server": [os.path.join(a.bin, "solid_bench"), "phases", SCENE, div],
        "fenics": ["/usr/bin/python3", os.path.abspath(__file__), "--side", "fenics", "--repeats", str(a.repeats),
                   "--divisions", *map(str, a.divisions)],
    }
    results = {k: [] for k in commands}
    for run in range(a.runs):
        for name, cmd in commands.items():  # alternately, so that both see the same machine
            line = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout.strip().splitlines()[-1]
            r = json.loads(line)
            for key in ("assembly", "factorisation", "solve"):
                r[key] = r[key][:a.repeats]  # solid_bench repeats 4 times
            results[name].append(r)
            print(line, file=sys.stderr)

    def med(name, key, first=False):
        values = [x for r in results[name] for x in (r[key][:1] if first else r[key][1:])]
        return statistics.median(values)

    print(f"| solid | free dofs | matrix nonzeros | assembly | factorisation | solve | first factorisation "
          f"(with analysis) | setup | peak memory |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, label in (("solid_server", "solid_server (Hex8 EAS, CHOLMOD)"),
                        ("fenics", "FEniCS (Q1 hexahedra, SuperLU)")):
        r0 = results[name][0]
        extra = f" (+ {med(name, 'extraction'):.2f} s free-block extraction)" if name == "fenics" else ""
        print(f"| {label} | {r0['free_dofs']:,} | {r0['nonzeros']:,} | {med(name, 'assembly'):.2f} s{extra} | "
              f"{med(name, 'factorisation'):.2f} s | {med(name, 'solve'):.3f} s | "
              f"{med(name, 'factorisation', first=True):.2f} s | "
              f"{statistics.median(r['setup'] for r in results[name]):.2f} s | "
              f"{statistics.median(r['peak_rss_mb'] for r in results[name]):.0f} MB |")


if __name__ == "__main__":
    main()
