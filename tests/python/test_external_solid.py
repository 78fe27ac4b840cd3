#!/usr/bin/python3
"""An external solid written with fsi.server (python/sdof_solid.py) replaces the C++
solid_server: configs/sdof_model.yaml with gamma_N1 = 0, 10, 100 run once with solid_server
and once with the Python solid, (a) the fsi package installed offline into a venv
(`python3 -m venv --system-site-packages V && V/bin/pip install ./python`, the script copied
alone so only the installed package can be imported) and (b) from the source tree with
PYTHONPATH. The displacement and velocity histories in probes.csv agree to 1e-12 absolute
(|d| <= 0.19 here, so also about 1e-11 relative to the peak).

    test_external_solid.py --bin BUILD/bin --source SRC --python FSI_PYTHON WORK
"""
import argparse
import csv
import json
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
ap.add_argument("work")
a = ap.parse_args()
SRC = Path(a.source).resolve()
FSI = str(Path(a.bin).resolve() / "fsi")
work = Path(a.work).resolve()
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
from checks import check, failures  # noqa: E402
TOL = 1e-12


def sh(cmd, timeout, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, **kw)


def probes(out):
    with open(out / "probes.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}


# (a) the package installed into a venv, offline, from a copy of python/ (pip builds in the tree)
t0 = time.monotonic()
pkg = work / "pkg"
shutil.copytree(SRC / "python", pkg, ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
venv = work / "V"
p = sh([a.python, "-m", "venv", "--system-site-packages", str(venv)], 60)
check(p.returncode == 0, f"python3 -m venv --system-site-packages: exit {p.returncode} {p.stderr[-300:]}")
env = dict(os.environ, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
env.pop("PYTHONPATH", None)
p = sh([str(venv / "bin" / "pip"), "install", "-q", str(pkg)], 120, env=env)
check(p.returncode == 0, f"V/bin/pip install ./python, offline: exit {p.returncode} {p.stderr[-500:]}")
p = sh([str(venv / "bin" / "python"), "-c", "import fsi, fsi.server, fsi.stats; print(fsi.__file__)"], 30, cwd=work, env=env)
where = p.stdout.strip()
check(p.returncode == 0 and where.startswith(str(venv)), f"the venv imports the installed package: {where or p.stderr[-300:]}")
print(f"venv and install: {time.monotonic() - t0:.1f} s")
solo = work / "solo"
solo.mkdir()
shutil.copy(SRC / "python" / "sdof_solid.py", solo / "sdof_solid.py")  # no fsi/ beside it

variants = {
    "venv": f"{venv / 'bin' / 'python'} {solo / 'sdof_solid.py'}",
    "pythonpath": f"env PYTHONPATH={SRC / 'python'} {a.python} {solo / 'sdof_solid.py'}",
}
worst = {}
for gamma in (0, 10, 100):
    sets = ["--set", f"coupling.gamma_n1={gamma}"]
    ref_out = work / f"cpp_g{gamma}"
    p = sh([FSI, "run", str(SRC / "configs" / "sdof_model.yaml"), "--out", str(ref_out), *sets], 120, cwd=work, env=env)
    ref_solid = json.load(open(ref_out / "summary.json"))["servers"]["solid"]["name"] if p.returncode == 0 else None
    check(p.returncode == 0 and "solid_server" in ref_solid, f"gamma {gamma}, C++: exit {p.returncode}, solid '{ref_solid}'")
    ref = probes(ref_out)
    for name, command in variants.items():
        out = work / f"{name}_g{gamma}"
        p = sh([FSI, "run", str(SRC / "configs" / "sdof_model.yaml"), "--out", str(out), *sets,
                "--solid-command", command], 120, cwd=work, env=env)
        if p.returncode != 0:
            check(False, f"gamma {gamma}, {name}: exit {p.returncode} {(p.stdout + p.stderr)[-500:]}")
            continue
        solid = json.load(open(out / "summary.json"))["servers"]["solid"]["name"]
        got = probes(out)
        n_ok = len(got["time"]) == len(ref["time"]) == 500 and got["time"] == ref["time"]
        diffs = {}
        for key in ("solid.d_x", "solid.v_x", "solid.d_y"):
            diffs[key] = max(abs(x - y) for x, y in zip(got[key], ref[key]))
        peak = max(abs(x) for x in ref["solid.d_x"])
        rel = diffs["solid.d_x"] / peak
        worst[name] = max(worst.get(name, 0.0), max(diffs.values()))
        check(solid == "python sdof_solid.py" and n_ok and all(d <= TOL for d in diffs.values()),
              f"gamma {gamma}, {name}: solid '{solid}', 500 steps, max |C++ - Python|: "
              + ", ".join(f"{k} {v:.1e}" for k, v in diffs.items()) + f" (d_x relative to its peak {rel:.1e}) <= {TOL:g}")
print("max |C++ - Python| over gamma 0, 10, 100: " + ", ".join(f"{k} {v:.1e}" for k, v in worst.items()))
sys.exit(1 if failures else 0)
