#!/usr/bin/python3
"""Docs as tests: every shell command of README.md and docs/*.md runs, or is skipped for a
stated reason (ctest -L docs).

Every line of every ```bash block (continuation lines joined, comment lines dropped) is a
command. Each must be in exactly one of the two tables below, keyed by the command without
its trailing `# comment`:

  RUN   commands that run here: None = as documented, ("append", ARGS) = the documented
        command with ARGS appended (shortening overrides: fewer steps, smaller studies),
        ("replace", CMD) = CMD instead (placeholders such as [--jobs N] filled in);
  SKIP  commands that cannot run in CI, with the reason (installing packages, Docker,
        benchmarks of minutes to hours, commands that consume another's long output).

The commands of one document run in order (later ones may use earlier results) in a fresh
working folder that links the source tree's files and folders and `build` to the build
under test, with /usr/bin first on PATH (Debian's python3). The test fails when a command
exits non-zero, times out, or is in neither table (the docs changed: add it to a table).

  run_doc_commands.py --source SRC --build BUILD [--only FILE...] [--list] [--keep]
  run_doc_commands.py --source SRC --check-tables
"""
import argparse
import glob
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

DOCS = ["README.md", "docs/*.md"]
TIMEOUT = 180  # seconds per command

# Shortening overrides. thick_beam: 10 steps of dt 0.02; the two checkpoint commands share
# theirs (a resumed run must have the same parameters). Studies: every run ends after a few
# steps (fsi study --set goes to every run).
SHORT_TB = "--set time.end=0.6"
COARSE_DFG = "--set fluid.mesh.size=0.04 --set fluid.mesh.parameters.hc=0.005"  # 10k unknowns
INFLOW = '--set "fluid.inflow=[{group: inlet, profile: parabolic, mean_velocity: 2.0, direction: [1.0, 0.0], ramp_time: 0.5}]"'
COARSE_FSI3 = ('--set time.dt=0.004 --set time.end=3.5 --set fluid.mesh.size=0.04 --set "fluid.mesh.parameters={hc: 0.006, '
               'hw: 0.016}" --set coupling.iterations.max=15 --set coupling.relaxation=0.2 --set coupling.gamma_n1=30000')
FSI3_B = f"build/bin/fsi run configs/fsi3.yaml --out runs/fsi3_B {COARSE_FSI3} {INFLOW}"
FSI3_MAIN = f"build/bin/fsi run configs/fsi3.yaml --out runs/fsi3_main --set time.end=5.0 {INFLOW}"
FSI3_AITKEN_SHORT = ("build/bin/fsi run configs/fsi3.yaml --out runs/fsi3_aitken --set time.end=0.1 --set coupling.acceleration=aitken "
                     f"--set coupling.iterations.max=30 --set coupling.iterations.tolerance=1e-4 {INFLOW}")
FSI3_AITKEN = (f"build/bin/fsi run configs/fsi3.yaml --out runs/fsi3_aitken {COARSE_FSI3} --set coupling.acceleration=aitken "
               f"{INFLOW} --set fluid.interface.mesh_motion=elastic --set fluid.interface.mesh_incremental=true")
RUN = {
    "build/bin/fsi list": None,
    "build/bin/fsi study studies/thin_beam.yaml --dry-run": None,
    "build/bin/fsi run configs/sdof_model.yaml --out runs/sdof": None,
    "build/bin/fsi run configs/sdof_model.yaml --out runs/g100 --set coupling.gamma_n1=100": None,
    "build/bin/fsi run configs/added_mass.yaml --out runs/am --set coupling.relaxation=0.17": None,
    'build/bin/fsi run configs/sdof_model.yaml --out runs/py --solid-command "python3 python/sdof_solid.py"':
        ("append", "--set time.end=2"),
    "build/bin/fsi run configs/thick_beam.yaml --out runs/thick --set coupling.algorithm=2": ("append", "--set time.end=0.2"),
    "build/bin/fsi run configs/dfg_2d1.yaml --out runs/dfg_2d1": ("append", COARSE_DFG),
    "build/bin/fsi run configs/thick_beam.yaml --out runs/tb --set time.checkpoint_every=25": ("append", SHORT_TB),
    # The checkpoint holds time.end = 0.6: --resume alone finds the run complete (nothing to do).
    "build/bin/fsi run configs/thick_beam.yaml --out runs/tb --resume": None,
    "build/bin/fsi run configs/thick_beam.yaml --out runs/tb --resume --set time.end=4": ("append", "--set time.end=0.8"),
    # docs/fluid.md: a forced remesh of the steady DFG 2D-1 (a coarser mesh here).
    "build/bin/fsi run configs/dfg_2d1_p2p1.yaml --out runs/d21_remesh --set time.end=2 --set 'fluid.remesh.at_steps=[1]'":
        ("append", "--set fluid.mesh.size=0.08 --set fluid.mesh.parameters.hc=0.01"),
    "build/bin/fsi study studies/thin_beam.yaml --out runs/study_thin --jobs 2":
        ("append", "--set time.end=0.01 --quiet"),
    "build/bin/fsi study studies/thick_beam.yaml --out runs/study_thick --jobs 2": ("append", "--set time.end=0.04 --quiet"),
    "/usr/bin/python3 tools/fsi_study.py plot runs/study_thick": None,
    "/usr/bin/python3 tools/fsi_study.py plot runs/study_thin": None,
    "/usr/bin/python3 tools/fsi_study.py run studies/sdof_gamma.yaml --out runs/study_sdof [--jobs N] [--fsi build/bin/fsi] [--quiet]":
        ("replace", "/usr/bin/python3 tools/fsi_study.py run studies/sdof_gamma.yaml --out runs/study_sdof --jobs 2 "
                    "--fsi build/bin/fsi --quiet --set time.end=1"),
    "/usr/bin/python3 tools/fsi_study.py plot runs/study_sdof": None,
    "build/bin/fsi study studies/sdof_gamma.yaml --out runs/study_sdof --jobs 1": ("append", "--set time.end=1 --quiet"),
    "/usr/bin/python3 tools/fsi_study.py analyse runs/study_sdof": None,
    "build/bin/fsi study studies/sdof_gamma.yaml --out runs/study_sdof [--jobs N] [--set KEY=VALUE ...] [--dry-run]":
        ("replace", "build/bin/fsi study studies/sdof_gamma.yaml --out runs/study_sdof_dry --jobs 2 --set time.end=1 --dry-run"),
    "build/bin/fsi study studies/sdof_gamma.yaml --out runs/study_sdof --executor dask --jobs 2":
        ("append", "--set time.end=1 --quiet"),
    # docs/fluid.md: the fluid alone through fsi run, a few steps each.
    "build/bin/fsi run configs/dfg_2d1_p2p1.yaml --out runs/d21": None,
    "build/bin/fsi run configs/dfg_2d2_p2p1.yaml --out runs/d22": ("append", "--set time.end=0.01"),
    "build/bin/fsi run configs/dfg_2d3.yaml --out runs/d23": ("append", "--set time.end=0.00625"),
    "build/bin/fsi run configs/cfd1.yaml --out runs/cfd1": None,
    "/usr/bin/python3 bench/fluid/element_benchmark.py --out out/element_benchmark":
        ("append", "--cases 2d1 --levels 1 --repeat 1 --fsi build/bin/fsi"),  # its default: the source's build/
    "build/bin/fsi run configs/dfg_2d1.yaml --out out/dfg_2d1": ("append", COARSE_DFG),
    "python3 bench/fluid/dfg_2d1_refinement.py --fsi build/bin/fsi --out out/dfg_2d1_refinement": ("append", "--levels 1"),
    "OPENBLAS_NUM_THREADS=1 build/bin/fsi run configs/dfg_2d2.yaml --out out/dfg_2d2": ("append", "--set time.end=0.05"),
    # docs/fsi3d.md: the elastic tube, 6 of its 100 steps on a coarse mesh; the wave analysis of that run.
    "build/bin/fsi run configs/tube_3d.yaml --out runs/tube":
        ("append", "--set time.end=0.0006 --set fluid.mesh.size=0.5 --set 'solid.mesh.divisions=[12, 1, 10]'"),
    "/usr/bin/python3 bench/fsi/tube_waves.py runs/tube --plot tube.png": None,
    # docs/fluid.md: DFG 3D-3Z, 5 of its 800 steps; the statistics of that run.
    "build/bin/fsi run configs/dfg_3d3z.yaml --out runs/dfg_3d3z": ("append", "--set time.end=0.05"),
    "/usr/bin/python3 bench/fluid/dfg_3d3z.py runs/dfg_3d3z": None,
    # docs/fsi3d.md: the same coarse tube with the FEniCS solid as its wall, against the run above.
    'build/bin/fsi run configs/tube_3d.yaml --out runs/tube_fenics --solid-command '
    '"python3 python/examples/fenics_solid/fenics_solid.py"':
        ("append", "--set time.end=0.0006 --set fluid.mesh.size=0.5 --set 'solid.mesh.divisions=[12, 1, 10]'"),
    "/usr/bin/python3 bench/fsi/tube_waves.py runs/tube_fenics --reference runs/tube": None,
    # docs/fsi3d.md: the tube's 2D analogue, 10 of its 100 steps; the wave analysis of that run.
    "build/bin/fsi run configs/tube_2d.yaml --out runs/tube_2d": ("append", "--set time.end=0.001"),
    "/usr/bin/python3 bench/fsi/tube_waves.py runs/tube_2d": None,
    # docs/fsi.md: the explicit Robin-Neumann scheme on the thin beam (10 steps).
    "build/bin/fsi run configs/thin_beam.yaml --set time.end=2 --set coupling.scheme=robin-neumann --set "
    "coupling.robin_neumann_order=1 --set coupling.algorithm=1 --set coupling.gamma_n1=0 --set coupling.relaxation=1 "
    "--set coupling.iterations.max=1 --set coupling.iterations.tolerance=0 --out runs/thin_rn1":
        ("append", "--set time.end=0.05"),
}
SKIP = {
    # docs/solid.md: the flag's .geo meshed at run time (the test GeoMeshedAtTheStart runs the default h).
    'build/bin/fsi run configs/csm1_3d_tet.yaml --out runs/csm1_tet_h005 --set "solid.mesh={type: gmsh, geo: '
    'meshes/csm_flag_3d.geo, domain: flag, parameters: {h: 0.005}}"':
        "benchmark: a 17,509-dof tet10 flag, meshing and 20 Newton iterations, about 5 s; ctest -R GeoMeshedAtTheStart",
    # docs/fsi.md: the explicit Robin-Neumann scheme on the paper's beams.
    "build/bin/fsi run configs/thin_beam.yaml --set time.end=2 --out runs/thin_ref_t2":
        "benchmark: the thin beam's reference to t = 2, about 160 s",
    "build/bin/fsi run configs/thin_beam.yaml --set time.end=2 --set coupling.algorithm=2 --set "
    "coupling.iterations.max=2 --out runs/thin_a2_t2": "benchmark: the thin beam to t = 2, about 45 s",
    "build/bin/fsi run configs/thick_beam.yaml --set time.end=2 --set coupling.algorithm=2 --set "
    "coupling.fluid_penalty=100 --set fluid.interface.penalty_geometry=step_start --set coupling.acceleration=iqn-ils "
    "--set coupling.iterations.max=500 --set coupling.iterations.tolerance=1e-6 --out runs/thick_conv":
        "benchmark: the thick beam's converged coupling to t = 2, about 15 s (with the 3 runs above: minutes)",
    "/usr/bin/python3 bench/fsi/robin_neumann_table.py --window 0,2 --plot docs/img/robin_neumann_thin_beam.png "
    "\"reference=runs/thin_ref_t2\" \"Algorithm 2=runs/thin_a2_t2\" \"robin-neumann 1=runs/thin_rn1\" ...":
        "synopsis; reads the benchmark runs above (and it rewrites a committed figure)",
    "build/bin/fsi study studies/added_mass_map.yaml --out runs/study_am --jobs 1":
        "a 45 s stability map by bisection (hundreds of runs); ctest study.added_mass_map runs a reduced map of "
        "the same form against the closed form",
    "/usr/bin/python3 tools/fsi_study.py plot runs/study_am": "consumes the added-mass map above",
    "build/bin/fsi study studies/tube_3d.yaml --out runs/study_tube --jobs 1":
        "benchmark: 13 coupled 3D runs, 20 minutes (docs/fsi3d.md)",
    "scripts/quickstart.sh": "installs apt packages (sudo) and builds: the fresh-Debian check, not CI",
    "scripts/test.sh": "installs apt packages, builds and runs all of ctest, which runs this test",
    "build/bin/fsi study studies/thin_beam_beta.yaml --out runs/study_thin_beta --jobs 2":
        "22 runs whose point is where the beta limit lies: shortened they show nothing (~6 min)",
    "build/bin/fsi study studies/extreme_fem.yaml --out runs/study_extreme_fem --jobs 2":
        "108 runs (the extreme-case matrix); its CI cut is ctest study.extreme_ci",
    "build/bin/fsi study studies/sdof_gamma.yaml --out runs/study_sdof --executor dask [--scheduler tcp://HOST:PORT] "
    "[--shared-dir DIR]": "synopsis (placeholders); the LocalCluster command of docs/studies.md runs",
    "dask-scheduler --host 127.0.0.1 --port 8786 --no-dashboard &":
        "a long-lived scheduler in the background on a fixed port; the executor is covered by the LocalCluster command",
    "PYTHONPATH=$PWD/python dask-worker tcp://127.0.0.1:8786 --nthreads 1 &": "a long-lived worker of that scheduler",
    "build/bin/fsi study studies/sdof_gamma.yaml --out runs/study_sdof --executor dask --scheduler tcp://127.0.0.1:8786":
        "needs the scheduler and workers above (or the compose cluster)",
    "build/bin/fsi study studies/sdof_gamma.yaml --out runs/study_sdof --executor dask --scheduler tcp://127.0.0.1:8786 "
    "--shared-dir /runs/study_sdof": "needs the Docker compose cluster",
    "docker compose -f docker/compose.study.yaml up -d --build --scale worker=2": "Docker: no engine in CI",
    "docker compose -f docker/compose.study.yaml down": "Docker: no engine in CI",
    "/usr/bin/python3 bench/studies/dask_scaling.py --out /tmp/fsi_dask_scaling": "benchmark (scaling over workers)",
    "/usr/bin/python3 bench/solid/phases_3d.py --bin build/bin --runs 3 --repeats 3 --divisions 64 8 32":
        "benchmark: 57k-dof solids by phases, FEniCS's SuperLU about a minute per factorisation, 12 minutes",
    "build/bin/fsi study studies/extreme_sdof.yaml --out runs/study_extreme":
        "1440 runs, about 3 minutes on 2 cores; its CI cut is ctest study.extreme_ci",
    "python3 bench/fluid/periodic_stats.py out/dfg_2d2/probes.csv --columns fluid.cd fluid.cl fluid.dp --window 1.0 "
    "--strouhal-scale 0.1": "needs the 2000-step run (t in [8, 10]); a shortened run has no whole period",
    "OPENBLAS_NUM_THREADS=1 build/bin/fsi run configs/cfd3.yaml --out out/cfd3": "benchmark: 75k unknowns to T = 12, ~22 min",
    "python3 bench/fluid/periodic_stats.py out/cfd3/probes.csv --columns fluid.drag fluid.lift --window 1 "
    "--by-period fluid.lift --reference cfd3": "statistics of the 22-minute CFD3 run",
    # docs/fsi.md: Turek-Hron FSI1-3, coupled runs of minutes to hours.
    "bench/fsi/run_turek_hron.sh CASE [OUT] [fsi run args]": "synopsis (placeholders); the cases follow",
    "/usr/bin/python3 bench/fsi/th_stats.py CASE RUN [--periods N] [--smooth S] [--t-end T] [--plot PNG] [--json OUT]":
        "synopsis (placeholders); its ctest is python.stats",
    "bench/fsi/run_turek_hron.sh fsi1 runs/fsi1": "benchmark: Turek-Hron FSI1, minutes; CI: ctest fsi.fsi1",
    "build/bin/fsi run configs/fsi2_p2p1.yaml --out runs/fsi2_base --set time.end=7.6 --set time.checkpoint_every=250":
        "benchmark: FSI2 (P2/P1) to t = 7.6, about 11 minutes; --from is tested by ctest integration.resilience.fork",
    "build/bin/fsi run configs/fsi2_p2p1.yaml --out runs/fsi2_a1 --from runs/fsi2_base --set time.end=9.1 --set "
    "coupling.algorithm=1 --set coupling.iterations.tolerance=0 --set \"coupling.iterations.measures=[{quantity: traction, "
    "type: relative, limit: 1.0e-4}]\"": "benchmark: the fork of the FSI2 run above to t = 9.1, about 7 minutes",
    "bench/fsi/run_turek_hron.sh fsi3 runs/fsi3": "benchmark: Turek-Hron FSI3, 895 s",
    # docs/fluid.md (remeshing) and docs/paper_examples.md (the thin beam with remeshing).
    "build/bin/fsi run configs/dfg_2d2_p2p1.yaml --out runs/d22 --set time.end=7": "benchmark: DFG 2D-2 to t = 7, 433 s",
    "build/bin/fsi run configs/dfg_2d2_p2p1.yaml --out runs/d22_remesh --set time.end=7 --set 'fluid.remesh.at_steps=[2500]'":
        "benchmark: DFG 2D-2 to t = 7 with a remesh, 263 s",
    "/usr/bin/python3 bench/fluid/periodic_stats.py runs/d22/probes.csv --columns cd cl --window 1.0 --strouhal-scale 0.1":
        "statistics of the DFG 2D-2 benchmark run",
    "build/bin/fsi run configs/thin_beam.yaml --out runs/thin_a1 --set coupling.iterations.max=2":
        "benchmark: the thin beam to t = 3, about 70 s",
    "build/bin/fsi run configs/thin_beam.yaml --out runs/thin_a2_gG --set coupling.algorithm=2 --set "
    "coupling.iterations.max=2 --set coupling.gamma_n1=G": "synopsis (G = 10, 100, 1000): benchmarks of up to 2 minutes",
    "/usr/bin/python3 bench/fsi/thin_beam_remesh_plot.py docs/img/thin_beam_A_x_remesh.png \"Algorithm 1, gamma "
    "100=runs/thin_a1\" \"Algorithm 2, gamma 10=runs/thin_a2_g10\" ...": "synopsis; reads the thin-beam runs (benchmarks)",
    # docs/paper_examples.md (the thin beam with the channel wall as a contact obstacle).
    "build/bin/fsi run configs/thin_beam.yaml --out runs/thin_ref": "benchmark: the thin beam's reference, about 180 s",
    "/usr/bin/python3 bench/fsi/thin_beam_contact_table.py runs/thin_ref \"A2 g100=runs/thin_a2_g100\" ... --pair "
    "\"A2 g100,A2 g100 gc/2\" ...": "synopsis; reads the thin-beam runs (benchmarks)",
    "/usr/bin/python3 bench/fsi/thin_beam_remesh_plot.py docs/img/thin_beam_A_x_contact.png \"reference (Algorithm "
    "1, k_max 10)=runs/thin_ref\" \"Algorithm 2, gamma 100=runs/thin_a2_g100\" ...":
        "synopsis; reads the thin-beam runs (benchmarks)",
    "bench/fsi/run_turek_hron.sh fsi2 runs/fsi2": "benchmark: Turek-Hron FSI2, 708 s",
    FSI3_B: "benchmark: FSI3 to t = 3.5",
    "/usr/bin/python3 bench/fsi/th_stats.py fsi3 runs/fsi3_B --periods 4 --plot docs/img/fsi_fsi3.png":
        "statistics of the FSI3 benchmark run (and it rewrites a committed figure)",
    FSI3_MAIN: "benchmark: FSI3 to t = 5",
    FSI3_AITKEN_SHORT: "coupled FSI3 (36k-unknown fluid, up to 30 iterations per step): minutes even for 0.1 s",
    FSI3_AITKEN: "benchmark: FSI3 to t = 3.5",
    "/usr/bin/python3 bench/fsi/th_stats.py fsi3 runs/fsi3_aitken --plot docs/img/fsi_fsi3_aitken.png":
        "statistics of the FSI3 benchmark run (and it rewrites a committed figure)",
    "build/bin/fsi study studies/fsi3.yaml --out runs/study_fsi3 --jobs 1": "benchmark: 10 Turek-Hron FSI3 runs, about an hour",
    "mkdir -p runs/study_fsi3_published && ln -sfn ../study_fsi3/runs runs/study_fsi3_published/runs":
        "uses the fsi3 study above (benchmark)",
    "build/bin/fsi study studies/fsi3_published.yaml --out runs/study_fsi3_published": "reads the fsi3 study's runs (benchmark)",
    "/usr/bin/python3 tools/fsi_study.py plot runs/study_fsi3; /usr/bin/python3 tools/fsi_study.py plot runs/study_fsi3_published":
        "plots the fsi3 studies (benchmark)",
}


def strip_comment(line):
    """The command without a trailing `# comment` (a # that starts a word outside quotes)."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip()
    return line.rstrip()


def commands(source, patterns=DOCS):
    """[(file, line number, command)] of every ```bash block, in document order."""
    out = []
    for pattern in patterns:
        for path in sorted(glob.glob(str(source / pattern))):
            rel = os.path.relpath(path, source)
            lines = Path(path).read_text().splitlines()
            i = 0
            while i < len(lines):
                if lines[i].strip() == "```bash":
                    i += 1
                    pending, start = "", None
                    while i < len(lines) and lines[i].strip() != "```":
                        text = lines[i]
                        if start is None:
                            start = i + 1
                        if text.rstrip().endswith("\\"):
                            pending += text.rstrip()[:-1] + " "
                        else:
                            cmd = strip_comment(pending + text).strip()
                            cmd = re.sub(r"\s+", " ", cmd)
                            if cmd:
                                out.append((rel, start, cmd))
                            pending, start = "", None
                        i += 1
                i += 1
    return out


def planned(cmd):
    """The command to run for a documented command, or raise KeyError."""
    how = RUN[cmd]
    if how is None:
        return cmd
    kind, text = how
    return cmd + " " + text if kind == "append" else text


def workdir(source, build, root):
    """A folder with the source's entries linked (not build*, runs, out) and build -> BUILD."""
    root.mkdir(parents=True)
    for entry in source.iterdir():
        name = entry.name
        if name.startswith("build") or name in ("runs", "out", ".git"):
            continue
        (root / name).symlink_to(entry)
    (root / "build").symlink_to(build)
    return root


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--source", type=Path, default=Path(__file__).resolve().parents[2])
    ap.add_argument("--build", type=Path, help="build folder (holds bin/fsi)")
    ap.add_argument("--only", nargs="+", help="these documents only (e.g. README.md docs/runs.md)")
    ap.add_argument("--list", action="store_true", help="print each command and what happens to it; run nothing")
    ap.add_argument("--keep", action="store_true", help="keep the working folders")
    ap.add_argument("--check-tables", action="store_true",
                    help="run nothing; fail when a command of the documents is in neither table or in both, "
                         "or a table entry is in no document")
    a = ap.parse_args()
    source = a.source.resolve()
    found = commands(source, a.only or DOCS)
    unknown = [(f, n, c) for f, n, c in found if c not in RUN and c not in SKIP]
    both = [c for c in RUN if c in SKIP]
    seen = {c for _, _, c in found}
    if a.list:
        for f, n, c in found:
            what = "SKIP: " + SKIP[c] if c in SKIP else "RUN: " + planned(c) if c in RUN else "NOT IN A TABLE"
            print(f"{f}:{n}: {c}\n    {what}")
        return 0
    failures = []
    for f, n, c in unknown:
        failures.append(f"{f}:{n}: `{c}` is in neither table: add it to RUN (with shortening overrides "
                        f"so it takes seconds) or to SKIP (with the reason) in tests/docs/run_doc_commands.py")
    for c in both:
        failures.append(f"`{c}` is in both RUN and SKIP")
    stale = [c for c in list(RUN) + list(SKIP) if c not in seen] if not a.only else []
    for c in stale:
        print(f"note: table entry no longer in the docs: `{c}`")
    if a.check_tables:
        failures += [f"`{c}` is in a table but in no document: remove it" for c in stale]
        print("\n".join(["FAILED:"] + failures) if failures else
              f"{len(found)} documented commands, each in exactly one table; no stale entry")
        return 1 if failures else 0
    if a.build is None:
        ap.error("--build is required to run the commands")
    build = a.build.resolve()
    tmp = Path(tempfile.mkdtemp(prefix="fsi_docs_"))
    env = dict(os.environ, PATH="/usr/bin:" + os.environ.get("PATH", ""), OMP_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1")
    env.pop("FSI_SOURCE_DIR", None)
    t_all = time.time()
    skipped = 0
    by_doc = {}
    for f, n, c in found:
        by_doc.setdefault(f, []).append((n, c))
    for doc, cmds in by_doc.items():
        root = workdir(source, build, tmp / doc.replace("/", "_"))
        for n, c in cmds:
            if c in SKIP:
                skipped += 1
                print(f"skip {doc}:{n}: {c}\n     ({SKIP[c]})", flush=True)
                continue
            if c not in RUN:
                continue
            cmd = planned(c)
            t0 = time.time()
            try:
                p = subprocess.run(["/bin/bash", "-e", "-o", "pipefail", "-c", cmd], cwd=root, env=env,
                                   capture_output=True, text=True, timeout=TIMEOUT, start_new_session=True)
                code, output = p.returncode, (p.stdout + p.stderr)
            except subprocess.TimeoutExpired as e:
                code, output = "timeout", f"no exit within {TIMEOUT} s"
            dt = time.time() - t0
            status = "ok  " if code == 0 else "FAIL"
            print(f"{status} {doc}:{n} ({dt:.1f} s): {cmd}", flush=True)
            if code != 0:
                tail = "\n".join("     " + ln for ln in output.strip().splitlines()[-15:])
                print(tail, flush=True)
                failures.append(f"{doc}:{n}: `{cmd}` exited {code}")
    print(f"\n{len(found)} documented commands: {len(found) - skipped - len(unknown)} run, {skipped} skipped; "
          f"{time.time() - t_all:.0f} s")
    if failures:
        print("\n".join(["FAILED:"] + failures))
        print(f"working folders kept in {tmp}")
        return 1
    if a.keep:
        print(f"working folders kept in {tmp}")
    else:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
