#!/usr/bin/env python3
"""DFG 2D-1 mesh refinement: DOFs, errors of C_D, C_L, dp against Schafer-Turek, wall time.

Usage (from the repository root, after building; each level runs `fsi run SCENE --out OUT/hH --force`):
  python3 bench/fluid/dfg_2d1_refinement.py --fsi build/bin/fsi --out out/dfg_2d1_refinement

Writes OUT/table.md, OUT/results.json and OUT/error_vs_wall_time.png (the plot needs
matplotlib: the system /usr/bin/python3 has it; re-plot with --plot-only).
"""
import argparse
import json
import os
import subprocess
import time

REF = {"cd": 5.57953523384, "cl": 0.010618948146, "dp": 0.11752016697}
# (far size h, cylinder size hc): each level halves both.
LEVELS = [(0.04, 0.005), (0.02, 0.0025), (0.01, 0.00125)]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--fsi", "--runner", dest="fsi", default="build/bin/fsi", help="the fsi executable")
    ap.add_argument("--scene", default="configs/dfg_2d1.yaml")
    ap.add_argument("--out", default="out/dfg_2d1_refinement")
    ap.add_argument("--levels", type=int, default=len(LEVELS))
    ap.add_argument("--plot-only", action="store_true", help="re-plot OUT/results.json")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="extra scene override for every level (repeatable)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.plot_only:
        return plot(json.load(open(os.path.join(a.out, "results.json"))), a.out)
    results = []
    for h, hc in LEVELS[: a.levels]:
        run_dir = os.path.join(a.out, f"h{h:g}")
        cmd = [a.fsi, "run", a.scene, "--out", run_dir, "--force", "--set", f"fluid.mesh.size={h}",
               "--set", f"fluid.mesh.parameters.hc={hc}", "--set", "fluid.output.vtk_every=0"]
        for kv in a.set:
            cmd += ["--set", kv]
        # Mesh first (cached), so the timed run measures the solver only.
        t0 = time.time()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        t_first = time.time() - t0
        t0 = time.time()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall = time.time() - t0
        s = json.load(open(os.path.join(run_dir, "summary.json")))
        final = s["final"]  # the last row of probes.csv
        row = {"h": h, "hc": hc, "dofs": s["dofs"], "wall_seconds": wall, "first_run_seconds": t_first,
               "solves": s["solver_iterations"], "factorisations": final.get("fluid.factorisations", float("nan"))}
        for k in REF:
            row[k] = final["fluid." + k]
            row[k + "_error_percent"] = 100 * (final["fluid." + k] / REF[k] - 1)
        results.append(row)
        print(f"h {h:<6g} hc {hc:<8g} dofs {row['dofs']:>7d}  C_D {row['cd']:.5f} ({row['cd_error_percent']:+.3f}%)  "
              f"C_L {row['cl']:.6f} ({row['cl_error_percent']:+.2f}%)  dp {row['dp']:.5f} ({row['dp_error_percent']:+.3f}%)  "
              f"wall {wall:.1f}s", flush=True)
    json.dump(results, open(os.path.join(a.out, "results.json"), "w"), indent=2)
    with open(os.path.join(a.out, "table.md"), "w") as f:
        f.write("| h | h_cyl | DOFs | C_D | err C_D | C_L | err C_L | dp | err dp | Picard solves | LU factorisations | wall s |\n")
        f.write("|---|---|---|---|---|---|---|---|---|---|---|---|\n")
        for r in results:
            f.write(f"| {r['h']:g} | {r['hc']:g} | {r['dofs']} | {r['cd']:.5f} | {r['cd_error_percent']:+.3f}% | "
                    f"{r['cl']:.6f} | {r['cl_error_percent']:+.2f}% | {r['dp']:.5f} | {r['dp_error_percent']:+.3f}% | "
                    f"{r['solves']} | {r['factorisations']:g} | {r['wall_seconds']:.1f} |\n")
    return plot(results, a.out)


def plot(results, out):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        w = [r["wall_seconds"] for r in results]
        for k, label in (("cd", "C_D"), ("cl", "C_L"), ("dp", "dp")):
            ax.loglog(w, [abs(r[k + "_error_percent"]) for r in results], "o-", label=label)
        for r in results:
            ax.annotate(f"{r['dofs']} DOFs", (r["wall_seconds"], abs(r["cd_error_percent"])), fontsize=7)
        ax.set_xlabel("wall time [s] (2 cores)")
        ax.set_ylabel("relative error [%]")
        ax.set_title("DFG 2D-1, P1/P1 SUPG/PSPG/LSIC")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(out, "error_vs_wall_time.png"), dpi=120)
    except ImportError:
        print("matplotlib missing: no plot")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
