#!/usr/bin/python3
"""The scheme atlas: runs the atlas studies and writes docs/choosing-a-scheme.md and its plots,
every number on the page taken from the studies' results.csv.

  tools/atlas.py run --out runs/atlas [--page docs/choosing-a-scheme.md] [--jobs 2] [--only NAME ...]
  tools/atlas.py page --out runs/atlas [--page ...]          (from the runs on disk)
  tools/atlas.py run --out DIR --study FILE                  (one study into DIR, its section only)

The atlas studies (studies/atlas_*.yaml), each into OUT/NAME:
  added_mass   the added-mass model over the mass ratio, against the converged (monolithic) solution
  thick_beam   the paper's thick beam, t in [0, 2], against its converged run (IQN-ILS to 1e-10)
  thin_beam    the paper's thin beam, t in [0, 0.5], against its converged run
  fsi3         a short Turek-Hron FSI3 window forked from a developed state, against its converged run
  time_thin_beam  the thin beam's time step, the solid subcycled and Robin-Neumann, against a fine-dt run
  time_fsi3    the FSI3 window with 1, 2, 4 solid substeps per window (and both x2), against both x8
"""
import argparse
import csv
import math
import os
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1]
STUDY = SRC / "studies" / "atlas_added_mass.yaml"
ATLAS = {name: SRC / "studies" / f"atlas_{name}.yaml"
         for name in ("added_mass", "thick_beam", "thin_beam", "fsi3", "time_thin_beam", "time_fsi3")}
# Studies that fork from a developed state: the run that develops it (into OUT/NAME_developed).
DEVELOP = {"fsi3": ["configs/fsi3.yaml", "--set", "time.end=2.2525", "--set", "time.checkpoint_every=900",
                    "--set", "fluid.mesh.size=0.04", "--set", "fluid.mesh.parameters={hc: 0.006, hw: 0.016}"]}
DEVELOPED_BY = {"time_fsi3": "fsi3"}  # studies forking from another study's developed state
CONVERGED_ERROR = 1e-6  # a run this close to the converged solution counts as converged
CONVERGED_REF_ERROR = 1e-4  # the same against a converged reference run (iterated to 1e-6, the reference to 1e-10)


def develop(name, out, fsi):
    """The developed state a forked study starts from: run once (from rest), reused after."""
    name = DEVELOPED_BY.get(name, name)
    d = Path(out).parent / f"{name}_developed"
    if (d / "checkpoints").is_dir() and any((d / "checkpoints").iterdir()):
        return d
    scene, *sets = DEVELOP[name]
    subprocess.run([fsi or str(SRC / "build" / "bin" / "fsi"), "run", str(SRC / scene), "--out", str(d), "--force",
                    *sets], check=True)
    return d


def run_study(study, out, jobs, fsi, name=""):
    cmd = ["/usr/bin/python3", str(SRC / "tools" / "fsi_study.py"), "run", str(study), "--out", str(out),
           "--jobs", str(jobs), "--quiet"]
    if fsi:
        cmd += ["--fsi", fsi]
    if DEVELOPED_BY.get(name, name) in DEVELOP:
        cmd += ["--from", str(develop(name, out, fsi))]
    subprocess.run(cmd, check=True)


def number(row, key):
    try:
        v = float(row.get(key, ""))
    except ValueError:
        return math.nan
    return v


def fmt(v, digits=3):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if v == 0:
        return "0"
    if abs(v) >= 1e4 or abs(v) < 1e-2:
        return f"{v:.{digits - 1}e}"
    return f"{v:.{digits}g}"


def read_rows(out):
    with open(Path(out) / "results.csv") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        r["_ma"] = number(r, "fluid.added_mass")
        r["_err"] = number(r, "solid.d_x.l2_rel")
        r["_wall"] = number(r, "wall_time")
        r["_its"] = number(r, "iterations_per_step")
        r["_beta"] = number(r, "coupling.relaxation")
    return rows


def schemes_in_order(rows, study=None):
    """The schemes in the order of the study file's zip (else of results.csv)."""
    order = []
    if study:
        import yaml
        for group in yaml.safe_load(Path(study).read_text()).get("zip", []):
            order += [str(s) for s in group.get("scheme", [])]
    for r in rows:
        if r["scheme"] not in order:
            order.append(r["scheme"])
    return [s for s in order if any(r["scheme"] == s for r in rows)]


WALL_NOISE = 1.05  # wall times within 5 % of the fastest are a tie (shared, noisy machines)


def recommendation(group):
    """The converged scheme with the fewest iterations per step (each iteration one fluid and one
    solid solve; a parallel one runs them at the same time), and the most accurate loosely coupled
    one that completed. (Wall times of this model are milliseconds of process messaging: not a
    measure of cost here.)"""
    done = [r for r in group if r["outcome"] == "completed" and not math.isnan(r["_err"])]
    converged = [r for r in done if r["_err"] <= CONVERGED_ERROR]
    loose = [r for r in done if r["coupling.iterations.max"] in ("1", "1.0")]
    text = []
    if converged:
        best = min(converged, key=lambda r: (r["_its"], r["_wall"]))
        text.append(f"converged: **{best['scheme']}** ({fmt(best['_its'])} iterations per step, "
                    f"{fmt(best['_wall'])} s, error {fmt(best['_err'])})")
    else:
        text.append("converged: none reached the converged solution")
    if loose:
        best = min(loose, key=lambda r: r["_err"])
        text.append(f"loosely coupled: **{best['scheme']}** (error {fmt(best['_err'])})")
    else:
        text.append("loosely coupled: every one diverged")
    return "; ".join(text)


def plot(rows, png, study):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    markers = "osD^v<>phX*"
    for i, scheme in enumerate(schemes_in_order(rows, study)):
        pts = sorted((r for r in rows if r["scheme"] == scheme and r["outcome"] == "completed"), key=lambda r: r["_ma"])
        if not pts:
            continue
        mk = markers[i % len(markers)]
        ax.plot([r["_ma"] for r in pts], [r["_its"] * (1 + 0.02 * i) for r in pts], marker=mk, label=scheme)
        ax2.plot([r["_ma"] for r in pts], [max(r["_err"], 1e-16) for r in pts], marker=mk, label=scheme)
    for a in (ax, ax2):
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_xlabel("mass ratio m_a / m (missing points: diverged)")
    ax.set_ylabel("coupling iterations per step (offset 2 % per scheme)")
    ax.set_title("added-mass model: cost")
    ax2.set_ylabel("rel. L2 error of d_x against the converged solution")
    ax2.set_title("added-mass model: error (floor 1e-16)")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=110)
    plt.close(fig)


def section_added_mass(out, page, study):
    rows = read_rows(out)
    page = Path(page)
    png = page.parent / "img" / "atlas_added_mass.png"
    plot(rows, png, study)
    m = number(rows[0], "solid.mass") if "solid.mass" in rows[0] else 1.0
    lines = [
        "## The added-mass model (`configs/added_mass.yaml`, `studies/atlas_added_mass.yaml`)",
        "",
        "A point solid (m = 1, c = 0.5, k = 4) under a fluid that acts as an added mass m_a, dt 0.01,",
        "20 steps. Each scheme against the converged coupled solution (the monolithic BDF1 one,",
        "closed form `added_mass_monolithic`): loosely coupled schemes take one iteration per step",
        "with beta = 1; converged ones iterate to a relative change of 1e-10 (constant relaxation",
        "at 0.9 of its closed-form limit beta_c = 2 m_eff / (m_eff + m_a), the others from beta 0.5).",
        "Stability limits (docs/fsi.md): loosely coupled, Algorithm 1 needs m_a < m and Algorithm 2",
        "with the automatic Robin parameter m_a < 2 m (c = k = 0; serial and parallel alike).",
        "",
        f"![iterations per step over the mass ratio]({png.relative_to(page.parent)})",
        "",
    ]
    for ma in sorted({r["_ma"] for r in rows}):
        group = [r for r in rows if r["_ma"] == ma]
        lines += [f"### m_a / m = {fmt(ma / m, 3)}", "",
                  "| scheme | outcome | beta | iterations / step | wall s | rel. L2 error |",
                  "|---|---|---|---|---|---|"]
        for scheme in schemes_in_order(rows, study):
            for r in (r for r in group if r["scheme"] == scheme):
                outcome = r["outcome"] if r["outcome"] == "completed" else f"{r['outcome']} ({r.get('reason_kind', '')})"
                lines.append(f"| {scheme} | {outcome} | {fmt(r['_beta'])} | {fmt(r['_its'])} | {fmt(r['_wall'])} | "
                             f"{fmt(r['_err']) if r['outcome'] == 'completed' else '-'} |")
        lines += ["", "Recommended: " + recommendation(group) + ".", ""]
    return lines


TITLES = {"fsi3": ("Turek-Hron FSI3, a short window", "configs/fsi3.yaml",
                   "forked at t = 2.25 from a developed run on the coarse mesh of studies/fsi3.yaml"),
          "thick_beam": ("The thick beam", "configs/thick_beam.yaml", "the paper's example 1, a steady response"),
          "thin_beam": ("The thin beam", "configs/thin_beam.yaml", "the paper's example 2, the leaflet's first opening")}


def read_reference_rows(out, probe):
    with open(Path(out) / "results.csv") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        r["_err"] = number(r, f"{probe}.l2_rel")
        r["_wall"] = number(r, "wall_time")
        r["_its"] = number(r, "iterations_per_step")
        r["scheme"] = r.get("scheme") or ("converged reference" if r["name"].startswith("reference") else r["name"])
    return rows


def save_error_wall(fig, ax, png, title, ylabel):
    """Finishes an error-against-wall-time plot (log-log) and writes it to png."""
    import matplotlib.pyplot as plt
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time of the run (s)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(fontsize=7)
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return True


def plot_work_precision(rows, png, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pts = [r for r in rows if r["outcome"] == "completed" and not r["name"].startswith("reference")
           and math.isfinite(r["_err"]) and math.isfinite(r["_wall"]) and r["_wall"] > 0]
    if not pts:
        return False  # nothing to draw (no converged reference, or nothing completed)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    markers = "osD^v<>phX*"
    for i, r in enumerate(pts):
        ax.plot([r["_wall"]], [max(r["_err"], 1e-12)], marker=markers[i % len(markers)], linestyle="",
                label=f"{r['scheme']} ({fmt(r['_its'])} it/step)")
    return save_error_wall(fig, ax, png, title, "rel. L2 error of A_x against the converged run (floor 1e-12)")


def section_reference(name, out, page, study):
    """A problem with a converged reference run: every scheme's error, iterations and wall time."""
    import yaml
    rows = read_reference_rows(out, "solid.A_x")
    page = Path(page)
    title, scene, what = TITLES.get(name, (name, "", ""))
    spec = yaml.safe_load(Path(study).read_text())
    fixed = spec.get("fixed") or {}
    png = page.parent / "img" / f"atlas_{name}.png"
    drawn = plot_work_precision(rows, png, f"{title}: error against wall time")
    ref = [r for r in rows if r["name"].startswith("reference")]
    lines = [f"## {title} (`{scene}`, `{Path(study).relative_to(SRC) if Path(study).is_relative_to(SRC) else study}`)",
             "",
             f"{what[0].upper() + what[1:]}, up to t = {fixed.get('time.end', '?')}. Each scheme against the converged",
             "coupled solution: the reference run, IQN-ILS iterated far below the others' tolerance (with",
             "the consistent Robin terms every converged scheme and algorithm reaches the same solution).",
             "The schemes, their relaxation, iterations and tolerances: the header of the study file.",
             "Wall times: one run at a time with one core for it (`--jobs 1` beside another job), so a",
             "parallel (Jacobi) run's fluid and solid shared that core: not its two-core wall time.", "",
             f"![error against wall time]({png.relative_to(page.parent)})" if drawn else
             "(No plot: no run has an error against a completed reference.)", "",
             "| scheme | outcome | iterations / step | wall s | rel. L2 error A_x | rel. L2 error A_y |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        outcome = r["outcome"] if r["outcome"] == "completed" else f"{r['outcome']} ({r.get('reason_kind', '')})"
        done = r["outcome"] == "completed"
        lines.append(f"| {r['scheme']} | {outcome} | {fmt(r['_its'])} | {fmt(r['_wall'])} | "
                     f"{fmt(r['_err']) if done else '-'} | {fmt(number(r, 'solid.A_y.l2_rel')) if done else '-'} |")
    done = [r for r in rows if r["outcome"] == "completed" and not r["name"].startswith("reference")
            and not math.isnan(r["_err"])]
    converged = [r for r in done if r["_err"] <= CONVERGED_REF_ERROR and r["coupling.iterations.max"] not in ("1", "2")]
    loose = [r for r in done if r["coupling.iterations.max"] in ("1", "2")]
    rec = []
    if converged:
        fastest = min(r["_wall"] for r in converged)  # within the timing noise: the fewest iterations
        best = min((r for r in converged if r["_wall"] <= WALL_NOISE * fastest), key=lambda r: (r["_its"], r["_wall"]))
        rec.append(f"converged: **{best['scheme']}** ({fmt(best['_its'])} iterations per step, {fmt(best['_wall'])} s, "
                   f"error {fmt(best['_err'])})")
    if loose:
        best = min(loose, key=lambda r: r["_err"])
        rec.append(f"loosely coupled: **{best['scheme']}** (error {fmt(best['_err'])}, {fmt(best['_wall'])} s)")
    if ref:
        rec.append(f"the reference run took {fmt(ref[0]['_wall'])} s at {fmt(ref[0]['_its'])} iterations per step")
    lines += ["", "Recommended (fastest converged, ties within 5 % of wall time broken by iterations; most accurate "
              "loosely coupled): " + "; ".join(rec) + ".", ""]
    return lines


TIME_TITLES = {
    "time_thin_beam": ("The thin beam: time step, subcycling, Robin-Neumann", "configs/thin_beam.yaml", [
        "The thin beam up to t = 0.5 (BDF1 fluid and solid), every run against the converged run at",
        "dt 0.00125 (at dt 0.000625 the mesh motion tangles at t = 0.26): the error is the time",
        "discretisation's plus the scheme's. Rows: both solvers at a",
        "smaller dt; coupling windows of 0.005 and 0.0025 with the solid subcycled (`solid.substeps`,",
        "waveform iterations, IQN-ILS on the whole window); the explicit Robin-Neumann scheme."]),
    "time_fsi3": ("Turek-Hron FSI3: the solid subcycled", "configs/fsi3.yaml", [
        "The FSI3 window above (forked at t = 2.25, up to t = 2.75; coupling window 0.0025), converged,",
        "with 1, 2 and 4 solid substeps per window and with both solvers in 2 substeps (`fluid.substeps`),",
        "against both solvers in 8 substeps iterated to 1e-6 (both at the small step 0.0003125). A fork",
        "keeps the window; the substeps refine each solver's own step inside it."]),
}
TIME_DT = {"time_fsi3": "0.0025"}  # the window of a study whose rows do not set time.dt (a fork keeps the scene's)


def plot_time(rows, png, title):
    """Error against wall time, one line per series (dt refined, solid subcycled, ...)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pts = [r for r in rows if r["outcome"] == "completed" and not r["name"].startswith("reference")
           and math.isfinite(r["_err"]) and math.isfinite(r["_wall"]) and r["_wall"] > 0]
    if not pts:
        return False
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    markers = "osD^v<>phX*"
    series = []
    for r in pts:
        if r.get("series", "") not in series:
            series.append(r.get("series", ""))
    for i, s in enumerate(series):
        line = sorted((r for r in pts if r.get("series", "") == s), key=lambda r: r["_wall"])
        ax.plot([r["_wall"] for r in line], [max(r["_err"], 1e-12) for r in line], marker=markers[i % len(markers)],
                label=s or "runs")
        for r in line:
            ax.annotate(r["scheme"].split(" solid ")[-1] if " solid " in r["scheme"] else r["scheme"].split()[-1],
                        (r["_wall"], max(r["_err"], 1e-12)), fontsize=6, xytext=(3, 3), textcoords="offset points")
    return save_error_wall(fig, ax, png, title, "rel. L2 error of A_x against the reference run")


def section_time(name, out, page, study):
    """A time-resolution study: each row's window, substeps, cost and error against a finer run."""
    rows = read_reference_rows(out, "solid.A_x")
    page = Path(page)
    title, scene, text = TIME_TITLES[name]
    png = page.parent / "img" / f"atlas_{name}.png"
    drawn = plot_time(rows, png, f"{title}: error against wall time")
    rel = Path(study).relative_to(SRC) if Path(study).is_relative_to(SRC) else study
    lines = [f"## {title} (`{scene}`, `{rel}`)", "", *text,
             "Wall times: one run at a time with one core for it (`--jobs 1` beside another job).", "",
             f"![error against wall time]({png.relative_to(page.parent)})" if drawn else
             "(No plot: no run has an error against a completed reference.)", "",
             "| run | window dt | solid substeps | fluid substeps | outcome | iterations / window | wall s | rel. L2 error A_x | rel. L2 error A_y |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        done = r["outcome"] == "completed"
        outcome = r["outcome"] if done else f"{r['outcome']} ({r.get('reason_kind', '')})"
        lines.append(f"| {r['scheme']} | {r.get('time.dt') or TIME_DT.get(name, '-')} | {r.get('solid.substeps') or '-'} | {r.get('fluid.substeps') or '-'} | {outcome} | "
                     f"{fmt(r['_its'])} | {fmt(r['_wall'])} | {fmt(r['_err']) if done else '-'} | "
                     f"{fmt(number(r, 'solid.A_y.l2_rel')) if done else '-'} |")
    return lines + [""]


DECISION = """## Which scheme for my case

Place your case on the m_a / m axis first: m_a is the fluid mass the interface drags along, m
the structure's mass behind the same interface. For a wall or plate of thickness h and density
rho_s, wetted by a fluid of density rho_f over a length L (a tube's radius, a leaflet's or a
flag's length): **m_a / m ~ rho_f L / (rho_s h)**. Examples: the added-mass model's scene value;
Turek-Hron FSI3 (rho_f = rho_s, flag 0.35 long, 0.02 thick): ~17; a blood vessel (rho_s / rho_f
= 1.2, R / h = 5): ~4; a steel plate in air: far below 0.01. A run prints its own estimate for
Algorithm 2 (`coupling_estimate` in summary.json: gamma_N1 over the solid's interface impedance).

| your case | coupling block to start from | why |
|---|---|---|
| m_a / m < 0.1 (heavy or stiff solid, light fluid) | `{algorithm: 1, iterations: {max: 1}}` | loosely coupled Algorithm 1 is stable (m_a < m) and its error is O(dt); one fluid and one solid solve per step |
| 0.1 < m_a / m < 1, accuracy of a few % | `{algorithm: 1, iterations: {max: 1}}`, dt halved until the error is small enough | still stable; the splitting error grows with m_a / m (6 % at m_a = m on the model) |
| any m_a / m, converged answer wanted | `{algorithm: 1, acceleration: iqn-ils, relaxation: 0.5, iterations: {max: 50, tolerance: 1.0e-6}}` | 2 to 7 iterations per step in every row below, whatever m_a / m; iqn-imvj is its equal (the same or fewer iterations) |
| m_a / m > 1 (light wall, dense fluid: vessels, leaflets, flags in water) | the converged block above; never `iterations: {max: 1}` with Algorithm 1 | loosely coupled Algorithm 1 diverges above m_a = m |
| m_a / m up to 2 and you must stay loosely coupled | `{algorithm: 2, robin_auto: solid, iterations: {max: 1}}` | stable up to m_a = 2 m, but its error is large (30-60 % on the model at beta 1) |
| Algorithm 2 converged | `{algorithm: 2, robin_auto: solid, acceleration: iqn-ils}` | gamma_N1 at the solid's impedance; gamma_N1 far above it makes the iterations grow like that ratio |
| thin-walled solid, any m_a / m, one pass per step, small dt | `{scheme: robin-neumann, robin_neumann_order: 1, algorithm: 1, gamma_n1: 0, relaxation: 1, iterations: {max: 1, tolerance: 0}}` | stable at every m_a / m on the model; on the thin beam 28 % off at dt 0.005, 3.9 % at dt 0.001; on the FSI3 window 12 % off in A_x at dt 0.0025 (forked from another scheme's state); order 2, and order 1 on the thick beam, diverge (docs/fsi.md) |

Where the paper's loosely coupled Algorithm 2 (k_max 2, beta 0.02, gamma_N1 fixed) is far off:
with a small beta it under-relaxes each step, so the interface lags the solid; on the thin beam
its tip history misses the converged one by the margin of the "A2 paper" row below, and above
gamma_N1 ~ 100 at dt 0.005 the damping drags a leaflet flat onto its wall (the run stops, the
fluid gap closing). Prefer a converged scheme for a result you will publish. Ties: schemes within
the timing noise (a few % of wall time) are ranked by iterations per step, each iteration being
one fluid and one solid solve.

"""


def write_page(sections, page, command):
    """sections: [(name, study file, study folder)]; a folder without results.csv is listed as not run."""
    lines = ["# Choosing a coupling scheme", "",
             f"Generated by `{command}` from the study folders' results.csv: every number below is that",
             "command's. Do not edit by hand.", "", DECISION]
    missing = []
    for name, study, out in sections:
        if not (Path(out) / "results.csv").exists():
            missing.append(name)
            continue
        with open(Path(out) / "results.csv") as f:
            header = f.readline().split(",")
        if "fluid.added_mass" in header:  # the model problem, over the mass ratio
            lines += section_added_mass(out, page, study)
        elif name in TIME_TITLES:
            lines += section_time(name, out, page, study)
        else:
            lines += section_reference(name, out, page, study)
    lines += ["## Not in the atlas yet", ""]
    if missing:
        lines.append("Not run for this page: " + ", ".join(missing) + ".")
    lines += ["Finer meshes and longer windows: the atlas is a map of the schemes on small problems; the",
              "FSI levels are in docs/fsi.md.", ""]
    Path(page).write_text("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cmd", choices=["run", "page"])
    ap.add_argument("--out", default="runs/atlas")
    ap.add_argument("--page", default=str(SRC / "docs" / "choosing-a-scheme.md"))
    ap.add_argument("--study", default="", help="one study into --out (its section only)")
    ap.add_argument("--only", nargs="*", choices=sorted(ATLAS), default=None, help="run only these atlas studies")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--fsi", default=os.environ.get("FSI_BIN"))
    a = ap.parse_args()
    if a.study:  # one study, into --out itself
        name = Path(a.study).stem.replace("atlas_", "")
        sections = [(name, a.study, a.out)]
        command = f"tools/atlas.py run --out {a.out} --study {a.study}"
    else:
        sections = [(name, str(study), str(Path(a.out) / name)) for name, study in ATLAS.items()]
        command = f"tools/atlas.py run --out {a.out}"
    if a.cmd == "run":
        for name, study, out in sections:
            if a.only is None or name in a.only:
                run_study(study, out, a.jobs, a.fsi, name)
    write_page(sections, a.page, command)
    print(f"wrote {a.page}", file=sys.stderr)


if __name__ == "__main__":
    main()
