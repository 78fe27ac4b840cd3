#!/usr/bin/python3
"""The FEniCS solid (python/examples/fenics_solid, legacy DOLFIN) replaces solid_server
through the protocol: `fsi run SCENE --solid-command "PYTHON fenics_solid.py ..."` with the
coupler and a fluid that exerts no force (python/examples/fenics_solid/scenes/).

--part static (ctest python.fenics_csm):
  - CSM1 and CSM2 with P2 triangles on 40 x 2 crossed rectangles (1450 dofs): point A within
    1 % of Turek & Hron (measured +0.08 / +0.03 % and +0.06 / +0.05 %);
  - CSM1 with the default element (Q1, 2 x 2 Gauss points) on 80 x 4: solid_server's numbers
    on the same scene, to 1e-9 relative (measured 4e-15), St. Venant-Kirchhoff and neo-Hookean
    (the same element: a check of the interface, the probes, the laws and Newton);
  - the same with the fsi package installed offline into a venv made with
    --system-site-packages (DOLFIN from Debian), the example folder copied alone;
  - checkpoints: 40 dynamic steps (Newmark) with checkpoints every 20; a run forked from the
    step-20 checkpoint (`fsi run --from`) gives steps 21-40 exactly; a checkpoint of another
    mesh is refused naming the difference.
--part csm3 (ctest python.fenics_csm3):
  - CSM3 to t = 10 (dt 0.005, Newmark, P2 on 40 x 2 'right', 810 dofs): mean, amplitude and
    frequency of A's u_x and u_y over the last period within 1 % of Turek & Hron (measured
    within 0.35 %).

--part block3d (ctest python.fenics_block3d):
  - configs/block_3d.yaml (the 3D surrogate's plate of 4 x 4 quadrilaterals pressing an elastic
    block on rollers) with the FEniCS solid's default 3D element (Q1 hexahedra, from
    `mesh.type: box`): the interface goes over the sockets as 16 four-node faces, 3 values per
    node, node for node onto the plate; u_z(front) and u_x(x = 0.5) equal the closed form of
    uniaxial stress to 1e-8 relative (measured 3e-13);
  - checkpoints in 3D: a fork from the oldest checkpoint kept (step 2) reproduces step 3 exactly.
  - CSM1 extruded (scenes/csm1_3d.yaml), neo-Hookean, 20 x 2 x 1: Q1 hexahedra = solid_server's
    hex8 to 1e-9 (measured ~1e-14 on 40 x 2 x 1);
  - the faces of the six face sets (Q1 hexahedra, P2 tetrahedra), built without the coupler:
    counter-clockwise seen from outside, P2 midside nodes in gmsh order, mass = area;
  - the tube (`mesh.type: tube`, solid_server's tube_mesh, 24 x 2 x 20 Q1 hexahedra), without
    the coupler: the faces of inner / outer / start / end counter-clockwise seen from outside,
    their mass = the polygonal areas; under an internal pressure, clamped at both ends, the
    radial displacement at mid-length within 2 % of Lame's thick-walled cylinder (measured
    -0.23 % at the inner and +0.01 % at the outer radius);
  - dynamics (Newmark) with Algorithm 2's interface damping on the faces (gamma_N1 2000, 5
    steps): the same numbers and coupling iterations as solid_server's plain hex8 (the same
    element) to 1e-9 relative (measured 1.5e-15).

--part gmsh3d (ctest python.fenics_gmsh3d):
  - gmsh's 10-node tetrahedra read from a .msh (solid.mesh.type: gmsh): CSM1 on the shipped
    configs/meshes/csm_flag_3d.msh (697 cells, 4005 free dofs) through the coupler
    (scenes/csm1_3d_tet.yaml, the mesh found relative to the scene file): the FEniCS solid's P2
    on the straight tetrahedra is the space of solid_server's Tet10, and both integrate the St.
    Venant-Kirchhoff forms exactly (integrands of degree 4: FEniCS's degree-4 rule, solid_server's
    degree-5 rule), so they solve the same discrete equations: A equals solid_server's
    (configs/csm1_3d_tet.yaml, run here) to 1e-9 relative, the bound of the other same-element
    checks (measured 2e-14: round-off);
  - scenes/block_3d_tet.yaml (the block on block_3d_tet.msh, dynamic, Algorithm 2, the 3D
    surrogate's plate; 3 steps here): the probe histories of both solids to 1e-9 relative
    (measured 4.8e-15) with the same coupling iterations;
  - without the coupler: the interface faces of the file's group 'wet' (6-node, counter-clockwise
    seen from outside, midpoints in gmsh order, mass = area); the same mesh as 4-node
    tetrahedra: P1 by default with 3-node faces, and P2 on it gives the 10-node file's A_y
    bit for bit; the files and keys refused with the file and group named (a 2D mesh, a curved
    mid-edge node, hexahedra, MSH 4.1, binary MSH, a face in two groups, a face group or domain
    not in the file, a missing file).

Exit 77 (ctest: skipped) when the Python has no dolfin (scripts/install-deps.sh installs
python3-dolfin).

    test_fenics_solid.py --bin BUILD/bin --source SRC --python PYTHON --part static|csm3|block3d|gmsh3d WORK
"""
import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

ap = argparse.ArgumentParser()
ap.add_argument("--bin", required=True)
ap.add_argument("--source", required=True)
ap.add_argument("--python", required=True)
ap.add_argument("--part", choices=("static", "csm3", "block3d", "gmsh3d"), required=True)
ap.add_argument("work")
a = ap.parse_args()
SRC = Path(a.source).resolve()
FSI = str(Path(a.bin).resolve() / "fsi")
SCENES = SRC / "python" / "examples" / "fenics_solid" / "scenes"
SOLID = SRC / "python" / "examples" / "fenics_solid" / "fenics_solid.py"
work = Path(a.work).resolve()
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
failures = []

p = subprocess.run([a.python, "-c", "import dolfin"], capture_output=True, text=True)
if p.returncode != 0:
    print(f"skipped: {a.python} cannot import dolfin (apt-get install python3-dolfin; scripts/install-deps.sh)")
    sys.exit(77)

REFERENCE = {"csm1": (-7.187e-3, -66.10e-3), "csm2": (-0.469e-3, -16.97e-3)}
CSM3_REFERENCE = {"A_x": (-14.305, 14.305, 1.0995), "A_y": (-63.607, 65.160, 1.0995)}  # 1e-3 m, Hz


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def fsi_run(scene, out, *sets, solid=None, extra=(), timeout=600):
    cmd = [FSI, "run", str(scene), "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    if solid:
        cmd += ["--solid-command", solid]
    t0 = time.monotonic()
    p = subprocess.run(cmd + list(extra), capture_output=True, text=True, timeout=timeout, cwd=work)
    wall = time.monotonic() - t0
    summary = {}
    if (out / "summary.json").exists():
        summary = json.load(open(out / "summary.json"))
    return p, summary, wall


def probes(out):
    with open(out / "probes.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def rel(x, ref):
    """The error as the repository's tables give it: x / ref - 1 (+ = larger in magnitude)."""
    return x / ref - 1.0


def log_tail(out):
    try:
        return (out / "solid_server.log").read_text()[-800:]
    except OSError:
        return ""


def last_period(t, y):
    """solid_bench's statistic (bench/solid/solid_bench.cpp): the period between the last two
    upward crossings of the midrange of the second half (10 % hysteresis); over it mean =
    (max + min) / 2, amplitude = (max - min) / 2, frequency = 1 / period."""
    n = len(t)
    lo, hi = min(y[n // 2:]), max(y[n // 2:])
    level, band = 0.5 * (hi + lo), 0.1 * (hi - lo)
    ups, below = [], False
    for i in range(1, n):
        if y[i] < level - band:
            below = True
        if below and y[i - 1] < level <= y[i]:
            ups.append(t[i - 1] + (level - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]))
            below = False
    t0, t1 = ups[-2], ups[-1]
    ys = [v for s, v in zip(t, y) if t0 <= s <= t1]
    return 0.5 * (max(ys) + min(ys)), 0.5 * (max(ys) - min(ys)), 1.0 / (t1 - t0)


P2 = f"{a.python} {SOLID} --cell triangle --degree 2"
timings = {}

if a.part == "static":
    # 1. CSM1 and CSM2 against Turek & Hron, P2 on 40 x 2 crossed.
    for case in ("csm1", "csm2"):
        out = work / f"{case}_p2"
        p, summary, wall = fsi_run(SCENES / f"{case}.yaml", out, solid=P2)
        timings[case] = wall
        if p.returncode != 0:
            check(False, f"{case}, FEniCS P2: exit {p.returncode} {(p.stderr + log_tail(out))[-800:]}")
            continue
        pr = probes(out)
        ux, uy = pr["solid.A_x"][-1], pr["solid.A_y"][-1]
        ex, ey = rel(ux, REFERENCE[case][0]), rel(uy, REFERENCE[case][1])
        check(summary["servers"]["solid"]["name"].startswith("python fenics_solid.py") and abs(ex) < 0.01
              and abs(ey) < 0.01,
              f"{case}, FEniCS P2 40 x 2 crossed: A = ({ux:.5e}, {uy:.5e}) m, errors {100 * ex:+.2f} % / "
              f"{100 * ey:+.2f} % (< 1 %), {wall:.1f} s")

    # 2. The default element (Q1, 2 x 2 Gauss) = solid_server's, same scene, 80 x 4; the
    #    neo-Hookean law too.
    nh = ["solid.mesh.elements=[80, 4]", "solid.material.law=neo_hookean"]
    p, _, _ = fsi_run(SCENES / "csm1.yaml", work / "csm1_nh_cpp", *nh)
    p2, _, wall = fsi_run(SCENES / "csm1.yaml", work / "csm1_nh_q1", *nh, solid=f"{a.python} {SOLID}")
    if p.returncode == 0 and p2.returncode == 0:
        ref, got = probes(work / "csm1_nh_cpp"), probes(work / "csm1_nh_q1")
        d = max(abs(rel(got[k][-1], ref[k][-1])) for k in ("solid.A_x", "solid.A_y"))
        check(d <= 1e-9, f"csm1 neo-Hookean, FEniCS Q1 80 x 4 = solid_server 80 x 4: A_y {got['solid.A_y'][-1]:.10e} "
              f"vs {ref['solid.A_y'][-1]:.10e}, max relative difference {d:.1e} (<= 1e-9), {wall:.1f} s")
    else:
        check(False, f"csm1 neo-Hookean: exit {p.returncode} / {p2.returncode} "
              f"{(p.stderr + p2.stderr + log_tail(work / 'csm1_nh_q1'))[-800:]}")
    q1 = ["solid.mesh.elements=[80, 4]"]
    p, _, wall = fsi_run(SCENES / "csm1.yaml", work / "csm1_cpp", *q1)
    ref = probes(work / "csm1_cpp") if p.returncode == 0 else None
    check(ref is not None, f"csm1, solid_server 80 x 4: exit {p.returncode} {p.stderr[-300:] if ref is None else ''}")
    p, _, wall = fsi_run(SCENES / "csm1.yaml", work / "csm1_q1", *q1, solid=f"{a.python} {SOLID}")
    timings["csm1_q1"] = wall
    got = probes(work / "csm1_q1") if p.returncode == 0 else None
    if ref and got:
        d = max(abs(rel(got[k][-1], ref[k][-1])) for k in ("solid.A_x", "solid.A_y"))
        check(d <= 1e-9, f"csm1, FEniCS Q1 80 x 4 = solid_server 80 x 4: A_y {got['solid.A_y'][-1]:.10e} vs "
              f"{ref['solid.A_y'][-1]:.10e}, max relative difference {d:.1e} (<= 1e-9), {wall:.1f} s")
    else:
        check(False, f"csm1, FEniCS Q1: exit {p.returncode} {(p.stderr + log_tail(work / 'csm1_q1'))[-800:]}")

    # 3. The same from a venv with --system-site-packages and the package installed offline.
    t0 = time.monotonic()
    pkg, venv, solo = work / "pkg", work / "V", work / "solo"
    shutil.copytree(SRC / "python", pkg, ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    shutil.copytree(SOLID.parent, solo / "fenics_solid", ignore=shutil.ignore_patterns("__pycache__"))
    env = dict(os.environ, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    env.pop("PYTHONPATH", None)
    p = subprocess.run([a.python, "-m", "venv", "--system-site-packages", str(venv)], capture_output=True, text=True)
    p2 = subprocess.run([str(venv / "bin" / "pip"), "install", "-q", str(pkg)], capture_output=True, text=True,
                        env=env, timeout=300)
    check(p.returncode == 0 and p2.returncode == 0, f"venv --system-site-packages and pip install ./python: "
          f"{p.stderr[-200:]} {p2.stderr[-300:]}")
    out = work / "csm1_q1_venv"
    p, summary, wall = fsi_run(SCENES / "csm1.yaml", out, *q1,
                               solid=f"{venv / 'bin' / 'python'} {solo / 'fenics_solid' / 'fenics_solid.py'}")
    timings["venv"] = time.monotonic() - t0
    if p.returncode == 0 and got:
        v = probes(out)
        log = (out / "solid_server.log").read_text()
        same = all(v[k] == got[k] for k in ("solid.A_x", "solid.A_y"))
        check(same and "re-run" not in log and "running with" not in log,
              f"csm1 Q1 from the venv: the same A ({v['solid.A_y'][-1]:.10e}), run by the venv's python, {wall:.1f} s")
    else:
        check(False, f"csm1 from the venv: exit {p.returncode} {(p.stderr + log_tail(out))[-800:]}")

    # 4. Checkpoints: a fork from step 20 reproduces steps 21-40.
    short = ["time.end=0.2", "time.checkpoint_every=20"]
    P2R = P2 + " --diagonal right"
    full, fork = work / "csm3_full", work / "csm3_fork"
    p, _, wall = fsi_run(SCENES / "csm3.yaml", full, *short, solid=P2R)
    timings["checkpoint_full"] = wall
    ok = p.returncode == 0 and (full / "checkpoints" / "step_00000020").is_dir()
    check(ok, f"csm3 to t = 0.2 with checkpoints every 20 steps: exit {p.returncode} "
              f"{(p.stderr + log_tail(full))[-500:] if not ok else ''}")
    if ok:
        p, summary, wall = fsi_run(SCENES / "csm3.yaml", fork, *short, solid=P2R,
                                   extra=["--from", str(full / "checkpoints" / "step_00000020")])
        timings["checkpoint_fork"] = wall
        if p.returncode == 0:
            A, B = probes(full), probes(fork)
            tail = {k: A[k][-len(B[k]):] if k in A else None for k in B}
            n = len(B["time"])
            diff = max(abs(x - y) for k in ("solid.A_x", "solid.A_y") for x, y in zip(tail[k], B[k]))
            check(n >= 20 and B["time"][-20:] == A["time"][-20:] and diff == 0.0,
                  f"forked from step 20: {n} rows, steps 21-40 of A equal the uninterrupted run's "
                  f"(max |difference| {diff:.1e})")
        else:
            check(False, f"fork from step 20: exit {p.returncode} {(p.stderr + log_tail(fork))[-600:]}")
        bad = work / "csm3_bad"
        p, summary, wall = fsi_run(SCENES / "csm3.yaml", bad, *short, "solid.mesh.elements=[20, 1]", solid=P2R,
                                   extra=["--from", str(full / "checkpoints" / "step_00000020")])
        reason = summary.get("reason", "") + p.stderr
        check(p.returncode == 1 and "this configuration is" in reason,
              f"a checkpoint of another mesh is refused: exit {p.returncode}, "
              f"{[line for line in reason.splitlines() if 'checkpoint' in line][:1]}")
elif a.part == "block3d":
    # The closed form of configs/block_3d.yaml: uniaxial stress, St. Venant-Kirchhoff, dead load
    # P = F / A = lambda Y (lambda^2 - 1) / 2, Y = 2 mu (1 + nu); lateral Green-Lagrange strain
    # -nu times the axial one.
    mu, nu, L, F_over_A = 1.0e6, 0.3, 0.2, -2.0e5
    Y = 2 * mu * (1 + nu)
    lo, hi = 0.5, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if Y * mid * (mid * mid - 1) / 2 < F_over_A else (lo, mid)
    stretch = 0.5 * (lo + hi)
    uz = L * (stretch - 1)
    ux = 1.0 * (math.sqrt(1 - nu * (stretch * stretch - 1)) - 1)  # x = 0.5: 1 m from the rollers x = -0.5
    scene = SRC / "configs" / "block_3d.yaml"
    out = work / "block_q1"
    ck = ["time.checkpoint_every=1"]
    p, summary, wall = fsi_run(scene, out, *ck, solid=f"{a.python} {SOLID}")
    timings["block_q1"] = wall
    if p.returncode != 0:
        check(False, f"block_3d, FEniCS Q1: exit {p.returncode} {(p.stderr + log_tail(out))[-800:]}")
    else:
        pr = probes(out)
        itf = summary.get("interface", {})
        check(summary["servers"]["solid"]["name"].startswith("python fenics_solid.py")
              and itf.get("solid_nodes") == 25 and itf.get("coincident_nodes") == 25 and itf.get("conforming"),
              f"block_3d: the FEniCS faces meet the plate node for node (solid nodes {itf.get('solid_nodes')}, "
              f"coincident {itf.get('coincident_nodes')}, conforming {itf.get('conforming')})")
        expect = {"solid.corner_z": uz, "solid.centre_z": uz, "solid.corner_x": ux, "solid.corner_y": ux,
                  "solid.centre_x": ux / 2, "solid.centre_y": ux / 2}
        err = max(abs(rel(v, expect[k])) for k in expect for v in pr[k])
        check(len(pr["time"]) == 3 and err < 1e-8,
              f"block_3d, FEniCS Q1 4 x 4 x 1: u_z(front) {pr['solid.corner_z'][-1]:.9e} (closed form {uz:.9e}), "
              f"u_x(x = 0.5) {pr['solid.corner_x'][-1]:.9e} (closed form {ux:.9e}), max relative error {err:.1e} "
              f"(< 1e-8), {wall:.1f} s")
        fork = work / "block_fork"
        steps = sorted((out / "checkpoints").glob("step_*"))
        p, _, wall = fsi_run(scene, fork, *ck, solid=f"{a.python} {SOLID}",
                             extra=["--from", str(steps[0])] if steps else [])
        if steps and p.returncode == 0:
            B = probes(fork)
            same = all(B[k] == pr[k][-len(B[k]):] for k in expect) and B["time"] == pr["time"][-len(B["time"]):]
            rows = 3 - int(steps[0].name.split("_")[1])  # the coupler keeps the last checkpoints only
            check(rows >= 1 and len(B["time"]) == rows and same,
                  f"block_3d forked from {steps[0].name}: {len(B['time'])} row(s), equal to the uninterrupted run's: "
                  f"{same}")
        else:
            check(False, f"block_3d fork: {len(steps)} checkpoints, exit {p.returncode} "
                         f"{(p.stderr + log_tail(fork))[-600:]}")
    # The faces themselves, for every face set and cell (Q1 hexahedra: 4 nodes; P2 tetrahedra:
    # 6 nodes in gmsh order), without the coupler: counter-clockwise seen from outside, the
    # quadrilaterals convex in cyclic order, midside nodes at the middle of edges 0-1, 1-2, 2-0,
    # and the interface mass summing to the area.
    faces_check = r"""
import math, sys, numpy as np
sys.path.insert(0, sys.argv[1])
import fem
out = {"left": [-1, 0, 0], "right": [1, 0, 0], "bottom": [0, -1, 0], "top": [0, 1, 0], "back": [0, 0, -1],
       "front": [0, 0, 1]}
area = {"left": .125, "right": .125, "bottom": .25, "top": .25, "back": .5, "front": .5}
for cell, degree in (("hexahedron", 1), ("tetrahedron", 2)):
    for name, normal in out.items():
        section = {"model": "fem", "mesh": {"type": "box", "origin": [0, 0, 0], "size": [1.0, 0.5, 0.25],
                   "divisions": [3, 2, 1]}, "material": {"shear_modulus": 1e6, "poisson_ratio": 0.3},
                   "density": 1.0, "analysis": "static", "interface": name}
        m = fem.FlagSolid(section, 1.0, 0.0, element={"cell": cell, "degree": degree}, log=lambda *a: None)
        bad = 0
        for f in m.faces:
            P = m.interface_xy[f]
            k = len(f)
            if k == 4:
                bad += sum(np.dot(np.cross(P[(i + 1) % 4] - P[i], P[(i + 2) % 4] - P[(i + 1) % 4]), normal) <= 0
                           for i in range(4))
            else:
                bad += np.dot(np.cross(P[1] - P[0], P[2] - P[0]), normal) <= 0
                bad += sum(not np.allclose(P[3 + i], 0.5 * (P[a] + P[b])) for i, (a, b) in enumerate(((0, 1), (1, 2), (2, 0))))
            bad += k != (4 if cell == "hexahedron" else 6)
        if bad or abs(m.M_G.sum() - area[name]) > 1e-12:
            print(f"{cell} P{degree} {name}: {bad} bad faces of {len(m.faces)}, M_G sum {m.M_G.sum()}")
            sys.exit(1)
# The tube (solid_server's tube_mesh, 24 x 2 x 20 Q1 hexahedra): the faces of inner / outer /
# start / end counter-clockwise seen from outside (outward -r, +r, -z, +z), the interface mass
# summing to the 24-sided inner surface's area; Lame's thick-walled cylinder under an internal
# pressure P at mid-length of the tube clamped at both ends (plane strain there):
# u_r(r) = (1 + nu) P ri^2 / (E (ro^2 - ri^2)) ((1 - 2 nu) r + ro^2 / r).
P, RI, RO, E, NU, L, NT = 1000.0, 0.5, 0.6, 3.0e6, 0.3, 5.0, 24
for name in ("inner", "outer", "start", "end"):
    section = {"model": "fem", "mesh": {"type": "tube", "origin": [0, 0, 0], "inner_radius": RI, "outer_radius": RO,
               "length": L, "divisions": [NT, 2, 20]}, "material": {"youngs_modulus": E, "poisson_ratio": NU},
               "density": 1.0, "analysis": "static", "clamp": ["start", "end"], "interface": name,
               "probes": [{"name": "I", "point": [RI, 0, L / 2]}, {"name": "O", "point": [RO, 0, L / 2]}]}
    m = fem.FlagSolid(section, 1.0, 0.0, log=lambda *a: None)
    bad = 0
    for f in m.faces:
        Q = m.interface_xy[f]
        c = Q.mean(axis=0)
        radial = np.array([c[0], c[1], 0.0]) / np.hypot(c[0], c[1])
        normal = {"inner": -radial, "outer": radial, "start": [0, 0, -1], "end": [0, 0, 1]}[name]
        bad += len(f) != 4
        bad += sum(np.dot(np.cross(Q[(i + 1) % 4] - Q[i], Q[(i + 2) % 4] - Q[(i + 1) % 4]), normal) <= 0
                   for i in range(4))
    r = {"inner": RI, "outer": RO}.get(name)
    area = NT * 2 * r * math.sin(math.pi / NT) * L if r else 0.5 * NT * math.sin(2 * math.pi / NT) * (RO**2 - RI**2)
    if bad or len(m.faces) != (NT * 20 if r else NT * 2) or abs(m.M_G.sum() / area - 1) > 1e-12:
        print(f"tube {name}: {bad} bad faces of {len(m.faces)}, M_G sum {m.M_G.sum()} (area {area})")
        sys.exit(1)
    if name != "inner":
        continue
    force = np.zeros((len(m.interface_nodes), 3))  # P on the planar faces: P A / 4 per corner, along -n
    for f in m.faces:
        Q = m.interface_xy[f]
        force[f] -= P * 0.5 * np.cross(Q[2] - Q[0], Q[3] - Q[1]) / 4
    m.solve(1.0, force.ravel())
    u = m.accept()
    lame = lambda r: (1 + NU) * P * RI * RI / (E * (RO * RO - RI * RI)) * ((1 - 2 * NU) * r + RO * RO / r)
    err = [u["I_x"] / lame(RI) - 1, u["O_x"] / lame(RO) - 1]
    print(f"tube: u_r(ri) {u['I_x']:.6e}, u_r(ro) {u['O_x']:.6e}: Lame {100 * err[0]:+.3f} %, {100 * err[1]:+.3f} %")
    if max(abs(e) for e in err) > 0.02:
        sys.exit(1)
print("ok")
"""
    p = subprocess.run([a.python, "-c", faces_check, str(SOLID.parent)], capture_output=True, text=True, timeout=300,
                       env=dict(os.environ, DIJITSO_CACHE_DIR=os.environ.get(
                           "DIJITSO_CACHE_DIR", os.path.join(os.path.expanduser("~"), ".cache", "dijitso"))))
    check(p.returncode == 0 and p.stdout.strip().endswith("ok"),
          f"3D faces of the six face sets (Q1 hexahedra 4 nodes, P2 tetrahedra 6 nodes) and of the tube's four: "
          f"counter-clockwise from outside, midside nodes in gmsh order, mass = area; "
          f"{(p.stdout.splitlines() or [''])[0] if p.returncode == 0 else (p.stdout + p.stderr)[-400:]}")

    # Dynamics (Newmark) with Algorithm 2's interface damping (gamma_N1 M_G on the faces):
    # solid_server's plain hexahedron (hex8) is this solid's Q1, so the runs must agree.
    a2 = ["solid.analysis=dynamic", "solid.element=hex8", "coupling.gamma_n1=2000", "coupling.iterations.max=30",
          "coupling.iterations.tolerance=1e-10", "time.end=0.5"]
    p, _, _ = fsi_run(scene, work / "block_a2_cpp", *a2)
    p2, _, wall = fsi_run(scene, work / "block_a2_q1", *a2, solid=f"{a.python} {SOLID}")
    timings["block_a2_q1"] = wall
    if p.returncode == 0 and p2.returncode == 0:
        ref, got = probes(work / "block_a2_cpp"), probes(work / "block_a2_q1")
        keys = [k for k in ref if k.startswith("solid.c")]
        d = max(abs(rel(y, x)) for k in keys for x, y in zip(ref[k], got[k]))
        its, its2 = ref["coupling.iterations"], got["coupling.iterations"]
        check(len(got["time"]) == 5 and d <= 1e-9 and its == its2,
              f"block_3d dynamic, Algorithm 2 (gamma_N1 2000): FEniCS Q1 = solid_server hex8, max relative difference "
              f"{d:.1e} (<= 1e-9), coupling iterations {sum(its2):.0f} vs {sum(its):.0f}, {wall:.1f} s")
    else:
        check(False, f"block_3d dynamic: exit {p.returncode} / {p2.returncode} "
                     f"{(p.stderr + p2.stderr + log_tail(work / 'block_a2_q1'))[-800:]}")
    # The 3D laws: CSM1 extruded, neo-Hookean, Q1 hexahedra = solid_server's hex8 (20 x 2 x 1).
    nh = ["solid.material.law=neo_hookean", "solid.mesh.divisions=[20, 2, 1]"]
    p, _, _ = fsi_run(SCENES / "csm1_3d.yaml", work / "csm1_3d_nh_cpp", *nh, "solid.element=hex8")
    p2, _, wall = fsi_run(SCENES / "csm1_3d.yaml", work / "csm1_3d_nh_q1", *nh, solid=f"{a.python} {SOLID}")
    timings["csm1_3d_nh_q1"] = wall
    if p.returncode == 0 and p2.returncode == 0:
        ref, got = probes(work / "csm1_3d_nh_cpp"), probes(work / "csm1_3d_nh_q1")
        d = max(abs(rel(got[k][-1], ref[k][-1])) for k in ("solid.A_x", "solid.A_y"))
        check(d <= 1e-9 and got["solid.A_z"][-1] == 0.0,
              f"csm1_3d neo-Hookean, FEniCS Q1 20 x 2 x 1 = solid_server hex8: A_y {got['solid.A_y'][-1]:.10e} vs "
              f"{ref['solid.A_y'][-1]:.10e}, max relative difference {d:.1e} (<= 1e-9), {wall:.1f} s")
    else:
        check(False, f"csm1_3d neo-Hookean: exit {p.returncode} / {p2.returncode} "
                     f"{(p.stderr + p2.stderr + log_tail(work / 'csm1_3d_nh_q1'))[-800:]}")
elif a.part == "gmsh3d":
    fen = f"{a.python} {SOLID}"
    # 1. CSM1 on the shipped tet10 flag: solid_server alone, the FEniCS solid through the coupler.
    p, _, wall_ss = fsi_run(SRC / "configs" / "csm1_3d_tet.yaml", work / "csm1_tet_cpp")
    p2, summary, wall = fsi_run(SCENES / "csm1_3d_tet.yaml", work / "csm1_tet_fenics", solid=fen)
    timings["csm1_tet_fenics"] = wall
    if p.returncode == 0 and p2.returncode == 0:
        ref, got = probes(work / "csm1_tet_cpp"), probes(work / "csm1_tet_fenics")
        d = max(abs(rel(got[k][-1], ref[k][-1])) for k in ("solid.A_x", "solid.A_y"))
        check(summary["servers"]["solid"]["name"].startswith("python fenics_solid.py") and d <= 1e-9
              and summary["interface"]["solid_nodes"] == 743,
              f"csm1 on csm_flag_3d.msh (tet10): FEniCS P2 A = ({got['solid.A_x'][-1]:.10e}, "
              f"{got['solid.A_y'][-1]:.10e}),"
              f" solid_server ({ref['solid.A_x'][-1]:.10e}, {ref['solid.A_y'][-1]:.10e}), max relative difference "
              f"{d:.1e} (<= 1e-9), {summary['interface']['solid_nodes']} interface nodes (743), {wall:.1f} s")
    else:
        check(False, f"csm1 tet10: exit {p.returncode} / {p2.returncode} "
                     f"{(p.stderr + p2.stderr + log_tail(work / 'csm1_tet_fenics'))[-800:]}")
    # 2. Coupled, dynamic: the block on gmsh tetrahedra pressed by the surrogate's plate.
    p, _, _ = fsi_run(SCENES / "block_3d_tet.yaml", work / "block_tet_cpp", "time.end=0.3")
    p2, _, wall = fsi_run(SCENES / "block_3d_tet.yaml", work / "block_tet_fenics", "time.end=0.3", solid=fen)
    timings["block_tet_fenics"] = wall
    if p.returncode == 0 and p2.returncode == 0:
        ref, got = probes(work / "block_tet_cpp"), probes(work / "block_tet_fenics")
        keys = [k for k in ref if k.startswith("solid.c")]
        d = max(abs(rel(y, x)) for k in keys for x, y in zip(ref[k], got[k]))
        its, its2 = ref["coupling.iterations"], got["coupling.iterations"]
        check(len(got["time"]) == 3 and d <= 1e-9 and its == its2,
              f"block_3d_tet dynamic (3 steps), Algorithm 2: FEniCS P2 = solid_server Tet10, max relative difference "
              f"{d:.1e} "
              f"(<= 1e-9), coupling iterations {sum(its2):.0f} vs {sum(its):.0f}, {wall:.1f} s")
    else:
        check(False, f"block_3d_tet: exit {p.returncode} / {p2.returncode} "
                     f"{(p.stderr + p2.stderr + log_tail(work / 'block_tet_fenics'))[-800:]}")
    # 3. Faces and refusals, without the coupler.
    gmsh_check = r"""
import os, sys, numpy as np
sys.path.insert(0, sys.argv[1])
import fem
src, work = sys.argv[2], sys.argv[3]
msh = os.path.join(src, "configs", "meshes", "csm_flag_3d.msh")
def section(**mesh):
    m = {"type": "gmsh", "file": msh, "domain": "flag"}
    m.update(mesh)
    return {"model": "fem", "mesh": {k: v for k, v in m.items() if v is not None}, "density": 1000.0,
            "material": {"shear_modulus": 0.5e6, "poisson_ratio": 0.4}, "analysis": "static", "clamp": "clamped",
            "supports": [{"boundary": "sides", "fixed": ["z"]}], "interface": "wet"}
m = fem.FlagSolid(section(), 1.0, 0.0, log=lambda *a: None)
bad = 0
for f in m.faces:
    P = m.interface_xy[f]
    c = P[:3].mean(axis=0)
    normal = [1, 0, 0] if abs(c[0] - 0.6) < 1e-9 else [0, 1 if c[1] > 0.2 else -1, 0]
    bad += len(f) != 6 or np.dot(np.cross(P[1] - P[0], P[2] - P[0]), normal) <= 0
    bad += sum(not np.allclose(P[3 + i], 0.5 * (P[a] + P[b]), atol=1e-15)
               for i, (a, b) in enumerate(((0, 1), (1, 2), (2, 0))))
area = (2 * 0.35101 + 0.02) * 0.01
if bad or len(m.interface_nodes) != 743 or abs(m.M_G.sum() / area - 1) > 1e-12 or m.degree != 2 or m.free.size != 4005:
    print(f"wet faces: {bad} bad of {len(m.faces)}, {len(m.interface_nodes)} nodes, M_G sum {m.M_G.sum()} "
          f"(area {area}), "
          f"P{m.degree}, {m.free.size} free dofs")
    sys.exit(1)
text = open(msh).read()
def write(name, body):
    path = os.path.join(work, name)
    open(path, "w").write(body)
    return path
lines = text.split("\n")
k = lines.index("$Nodes") + 1 + 1211  # node 1211: the middle of edge 0-1 of element 605, a tet10 of 'flag'
x = lines[k].split()
assert x[0] == "1211"
lines[k] = f"1211 {float(x[1]) + 1e-4!r} {x[2]} {x[3]}"
curved = write("curved.msh", "\n".join(lines))
hexa = write("hexa.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 \"cube\"\n$EndPhysicalNames\n"
             "$Nodes\n8\n" + "".join(f"{i + 1} {i & 1} {i >> 1 & 1} {i >> 2}\n" for i in range(8)) + "$EndNodes\n"
             "$Elements\n1\n1 5 2 1 1 1 2 4 3 5 6 8 7\n$EndElements\n")
msh41 = write("v41.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")
binary = write("binary.msh", "$MeshFormat\n2.2 1 8\n$EndMeshFormat\n")
# a face in two groups: the first 6-node triangle of 'wet' (physical 4) again in 'sides' (3)
lines = text.split("\n")
i = lines.index("$Elements")
n = int(lines[i + 1])
first = next(line.split() for line in lines[i + 2:i + 2 + n] if line.split()[1:5:2] == ["9", "4"])
lines[i + 1] = str(n + 1)
lines.insert(i + 2 + n, " ".join([str(10 ** 6), "9", "2", "3", "3"] + first[5:]))
twice = write("twice.msh", "\n".join(lines))
# the same mesh as 4-node tetrahedra and 3-node triangles: P1 by default, 3-node faces; P2 on it
# is the 10-node file's solid (the same vertices): A_y of the run through the coupler above to the last bit
lines = text.split("\n")
for j in range(i + 2, i + 2 + n):
    p = lines[j].split()
    keep = {"11": ("4", 4), "9": ("2", 3)}.get(p[1])
    if keep:
        lines[j] = " ".join([p[0], keep[0]] + p[2:3 + int(p[2])] + p[3 + int(p[2]):3 + int(p[2]) + keep[1]])
p1 = write("p1.msh", "\n".join(lines))
A = {}
for name, path, degree in (("tet4", p1, None), ("tet4 P2", p1, 2)):
    s = section(file=path)
    s["gravity"] = [0.0, -2.0, 0.0]
    s["load_steps"] = 4
    s["probes"] = [{"name": "A", "point": [0.6, 0.2, 0.005]}]
    q = fem.FlagSolid(s, 1.0, 0.0, log=lambda *a: None, element={"degree": degree})
    q.solve(1.0, np.zeros(3 * len(q.interface_nodes)))
    A[name] = (q.degree, {len(f) for f in q.faces}, round(q.M_G.sum(), 12), q.accept()["A_y"])
if (A["tet4"][:3] != (1, {3}, round(area, 12)) or A["tet4 P2"][:2] != (2, {6})
        or A["tet4 P2"][3] != float(sys.argv[4])):
    print(f"4-node file: {A}, the 10-node file's A_y {sys.argv[4]}")
    sys.exit(1)
flat = os.path.join(src, "configs", "meshes", "csm_flag.msh")
cases = [(dict(file=flat, domain=None), [flat, "no 3D elements"]),
         (dict(file=curved), [curved, "group 'flag', element 605", "mid-edge node"]),
         (dict(file=hexa, domain=None), [hexa, "group 'cube'", "8-node hexahedra"]),
         (dict(file=msh41), [msh41, "MSH 4.1", "MSH 2.2"]),
         (dict(file=binary), [binary, "MSH 2.2 binary", "ASCII"]),
         (dict(file=twice), [twice, "element 1000000", "'wet'", "'sides'"]),
         (dict(domain="plate"), [msh, "'plate'", "flag"]),
         (dict(file="nowhere.msh"), ["nowhere.msh", "not found"])]
for mesh, words in cases:
    try:
        fem.FlagSolid(section(**mesh), 1.0, 0.0, log=lambda *a: None)
        print(f"{mesh}: accepted"); sys.exit(1)
    except fem.SceneError as e:
        if not all(w in str(e) for w in words):
            print(f"{mesh}: {e} (expected {words})"); sys.exit(1)
s = section()
s["clamp"] = "root"
try:
    fem.FlagSolid(s, 1.0, 0.0, log=lambda *a: None)
    print("clamp root: accepted"); sys.exit(1)
except fem.SceneError as e:
    if not all(w in str(e) for w in ("'solid.clamp'", "root", msh, "clamped, sides, wet")):
        print(f"clamp root: {e}"); sys.exit(1)
print(f"ok: {len(m.faces)} wet faces, area {m.M_G.sum():.10g}; 4-node file P1 (A_y {A['tet4'][3]:.5e}, 3-node "
      f"faces), P2 on it = the 10-node file's; {len(cases) + 1} refusals named")
"""
    a_y = probes(work / "csm1_tet_fenics")["solid.A_y"][-1] if (work / "csm1_tet_fenics" / "probes.csv").exists() else 0
    p = subprocess.run([a.python, "-c", gmsh_check, str(SOLID.parent), str(SRC), str(work), repr(a_y)],
                       capture_output=True, text=True, timeout=300)
    # The last line: with a cold form cache DOLFIN prints its JIT notices on stdout first.
    last = (p.stdout.strip().splitlines() or [""])[-1]
    check(p.returncode == 0 and last.startswith("ok"),
          f"gmsh tet10 without the coupler: the wet faces (6-node, counter-clockwise from outside, midpoints in gmsh "
          f"order, mass = area) and bad files / keys refused naming the file and group: "
          f"{(p.stdout + p.stderr)[-600:]}")
else:
    out = work / "csm3_p2"
    p, summary, wall = fsi_run(SCENES / "csm3.yaml", out, solid=P2 + " --diagonal right", timeout=900)
    timings["csm3"] = wall
    if p.returncode != 0:
        check(False, f"csm3: exit {p.returncode} {(p.stderr + log_tail(out))[-800:]}")
    else:
        pr = probes(out)
        t = pr["time"]
        check(abs(t[-1] - 10.0) < 1e-9 and len(t) == 2000, f"csm3: {len(t)} steps to t = {t[-1]}")
        for k, (m_ref, a_ref, f_ref) in CSM3_REFERENCE.items():
            m, amp, f = last_period(t, [1e3 * v for v in pr[f"solid.{k}"]])
            errs = (rel(m, m_ref), rel(amp, a_ref), rel(f, f_ref))
            check(all(abs(e) < 0.01 for e in errs),
                  f"csm3 {k}: {m:.3f} +/- {amp:.3f} [{f:.4f} Hz] (1e-3 m), errors "
                  + ", ".join(f"{100 * e:+.2f} %" for e in errs) + " (< 1 %)")

print("wall times: " + ", ".join(f"{k} {v:.1f} s" for k, v in timings.items()))
sys.exit(1 if failures else 0)
