#!/usr/bin/python3
"""The README's Python commands with another python3 first on PATH (one without numpy, zmq,
protobuf, matplotlib: a bare venv stands in for pyenv's): the scripts say in one line that they
re-run with FSI_PYTHON and work; the example solid from any working directory gives the same
probes.csv byte for byte as from the repository; plot_probes.py on a misspelt probe prints the
columns, no traceback, exit 1.

    test_other_python.py --bin BUILD/bin --source SRC --python FSI_PYTHON WORK
"""
import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

ap = argparse.ArgumentParser()
ap.add_argument("--bin", required=True)
ap.add_argument("--source", required=True)
ap.add_argument("--python", required=True, help="the interpreter the build found (FSI_PYTHON)")
ap.add_argument("work")
a = ap.parse_args()
SRC = Path(a.source).resolve()
FSI = str(Path(a.bin).resolve() / "fsi")
work = Path(a.work).resolve()
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
from checks import check, failures  # noqa: E402


bare = work / "bare"
subprocess.run([a.python, "-m", "venv", "--without-pip", str(bare)], check=True, timeout=60)
p = subprocess.run([str(bare / "bin" / "python3"), "-c", "import numpy"], capture_output=True, text=True, timeout=30)
check(p.returncode != 0, "the bare python3 has no numpy (it stands in for another python3 first on PATH)")

env = dict(os.environ)
env["PATH"] = f"{bare / 'bin'}{os.pathsep}{env['PATH']}"
env.pop("PYTHONPATH", None)
env_cache = dict(env)
env_cache.pop("FSI_PYTHON", None)  # the interpreter from build/CMakeCache.txt
env["FSI_PYTHON"] = a.python


def run(cmd, cwd, e=env, timeout=120):
    return subprocess.run(cmd, cwd=cwd, env=e, capture_output=True, text=True, timeout=timeout)


# The README line, from the repository root.
cmd = [FSI, "run", "configs/sdof_model.yaml", "--out", str(work / "py"), "--solid-command", "python3 python/sdof_solid.py"]
p = run(cmd, SRC)
check(p.returncode == 0, f"README: fsi run ... --solid-command \"python3 python/sdof_solid.py\": exit {p.returncode} "
      f"{(p.stdout + p.stderr)[-400:] if p.returncode else ''}")
log = (work / "py" / "solid_server.log").read_text() if (work / "py" / "solid_server.log").exists() else ""
first = log.splitlines()[0] if log else ""
check(f"running with {a.python} ($FSI_PYTHON)" in first, f"the solid says it re-runs: {first!r}")
check("Traceback" not in log and log.count("has no module") == 1, "exactly one such line, no traceback")

# From another working directory (absolute paths), and with FSI_PYTHON from the CMake cache.
cache = SRC / "build" / "CMakeCache.txt"
e2 = env_cache if cache.exists() else env
p = run([FSI, "run", str(SRC / "configs" / "sdof_model.yaml"), "--out", str(work / "py2"), "--solid-command",
         f"python3 {SRC / 'python' / 'sdof_solid.py'}"], work, e2)
check(p.returncode == 0, f"from {work}: exit {p.returncode}")
if p.returncode == 0:
    same = (work / "py" / "probes.csv").read_bytes() == (work / "py2" / "probes.csv").read_bytes()
    check(same, "same probes.csv, byte for byte, from another working directory")
    if cache.exists():
        line = (work / "py2" / "solid_server.log").read_text().splitlines()[0]
        check("(FSI_PYTHON in build/CMakeCache.txt)" in line, f"without $FSI_PYTHON: {line!r}")

# plot_probes.py: the README's reproduction line, then a misspelt probe.
png = work / "sdof.png"
p = run(["python3", str(SRC / "scripts" / "plot_probes.py"), "--probe", "solid.d_x", "--out", str(png),
         str(work / "py"), str(work / "py2") + ":again"], work)
check(p.returncode == 0 and png.exists() and png.stat().st_size > 10000 and png.read_bytes()[:4] == b"\x89PNG",
      f"plot_probes.py writes a PNG: exit {p.returncode} {p.stderr[-300:] if p.returncode else ''}")
p = run(["python3", str(SRC / "scripts" / "plot_probes.py"), "--probe", "solid.dx", "--out", str(work / "x.png"),
         str(work / "py")], work)
msg = p.stderr.strip().splitlines()[-1] if p.stderr.strip() else ""
check(p.returncode == 1 and "Traceback" not in p.stderr and "no probe 'solid.dx'" in msg and "did you mean 'solid.d_x'" in msg
      and "solid.v_x" in msg and not (work / "x.png").exists(), f"misspelt probe: exit {p.returncode}, {msg!r}")

# proto/README.md's minimal external solid (a point mass on fsi.server), run as documented
# (PYTHONPATH=python, python3 first on PATH being the bare one): the C++ sdof solid with
# stiffness 0 and damping 0 is the same point mass, so the histories agree.
text = (SRC / "proto" / "README.md").read_text()
block = text[text.index("## A minimal external solid (Python)"):]
block = block[block.index("```python\n") + 10:]
block = block[:block.index("```")]
check(len(block.strip().splitlines()) <= 25, f"the minimal solid is {len(block.strip().splitlines())} lines (<= 25)")
(work / "my_solid.py").write_text(block)
pm = ["--set", "solid.stiffness=0", "--set", "solid.damping=0", "--set", "coupling.gamma_n1=10"]
e3 = dict(env, PYTHONPATH=str(SRC / "python"))
p = run([FSI, "run", "configs/sdof_model.yaml", "--out", str(work / "pm_py"), *pm, "--solid-command",
         f"python3 {work / 'my_solid.py'}"], SRC, e3)
check(p.returncode == 0, f"the minimal solid runs: exit {p.returncode} {(p.stdout + p.stderr)[-400:] if p.returncode else ''}")
p = run([FSI, "run", "configs/sdof_model.yaml", "--out", str(work / "pm_cpp"), *pm], SRC)
if (work / "pm_py" / "probes.csv").exists() and (work / "pm_cpp" / "probes.csv").exists():
    import csv
    a_, b_ = (list(csv.DictReader(open(work / n / "probes.csv"))) for n in ("pm_py", "pm_cpp"))
    # different but equivalent formulas (v first, then d; the C++ solves for d): round-off only
    err = max(abs(float(x["solid.d_x"]) - float(y["solid.d_x"])) for x, y in zip(a_, b_))
    scale = max(abs(float(y["solid.d_x"])) for y in b_)
    check(len(a_) == len(b_) == 500 and err <= 2e-12 * scale,
          f"minimal solid = C++ sdof with k = c = 0: max |d_x difference| {err:.1e} = {err / scale:.1e} of max |d_x| "
          f"{scale:.3g} (<= 2e-12 relative) over {len(a_)} steps")

# The statistics CLIs too.
p = run(["python3", str(SRC / "bench" / "fluid" / "periodic_stats.py"), str(work / "py" / "probes.csv"),
         "--columns", "solid.d_x", "--window", "10"], work)
check(p.returncode == 0 and "solid.d_x: mean" in p.stdout, f"periodic_stats.py: exit {p.returncode}")

sys.exit(1 if failures else 0)
