#!/usr/bin/python3
"""What a user gets to look at after a run:
  - `fsi run configs/sdof_model.yaml --plot`: the final values printed and in summary.json
    ("statistics"): the displacement is steady at the closed form F / k = 0.1282 (to 1e-5 at
    t = 10), the surrogate's force steady at F = 1.282 exactly; histories.png drawn;
  - `fsi plot` on a Turek-Hron FSI3 folder of 0.2 s (a synthetic history, scene fsi3): the
    comparison says the run is too short, the histories and turek_hron.png are still drawn;
  - bench/fsi/run_turek_hron.sh on that 0.2 s run (FSI_BIN: a stand-in fsi that writes it)
    says the run is too short and exits 3, without a table of errors;
  - `fsi plot` on a folder that is neither a run nor a study exits 1.

    test_final_values.py --bin BUILD/bin --source SRC WORK
"""
import argparse
import json
import math
import os
import shutil
import stat
import subprocess
import sys
from pathlib import Path

ap = argparse.ArgumentParser()
ap.add_argument("--bin", required=True)
ap.add_argument("--source", required=True)
ap.add_argument("work")
a = ap.parse_args()
SRC = Path(a.source).resolve()
BIN = Path(a.bin).resolve()
work = Path(a.work).resolve()
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
from checks import check, failures  # noqa: E402


env = dict(os.environ, MPLBACKEND="Agg")

# 1. sdof: steady at F / k
out = work / "sdof"
p = subprocess.run([str(BIN / "fsi"), "run", str(SRC / "configs" / "sdof_model.yaml"), "--out", str(out), "--plot"],
                   capture_output=True, text=True, timeout=120, env=env)
check(p.returncode == 0, f"fsi run sdof_model --plot: exit {p.returncode} {p.stderr[-400:]}")
print(p.stdout)
s = json.loads((out / "summary.json").read_text())
st = s.get("statistics", {})
d = st.get("solid.d_x", {})
check(d.get("kind") == "steady" and abs(d.get("final", 0) - 1.282 / 10.0) < 1e-5,
      f"summary.json: solid.d_x steady at {d.get('final')} = F / k = 0.1282 to 1e-5 ({d})")
f = st.get("fluid.force_x", {})
check(f.get("kind") == "steady" and f.get("final") == 1.282, f"fluid.force_x steady at F = 1.282 ({f})")
check(set(st) == set(open(out / "probes.csv").readline().strip().split(",")) - {"time"},
      f"statistics for every probe column ({len(st)})")
lines = [ln for ln in p.stdout.splitlines() if "solid.d_x" in ln]
check(len(lines) == 1 and abs(float(lines[0].split()[1]) - 0.1282) < 1e-5 and "steady" in lines[0],
      f"printed: {lines}")
check("final values at t = 10 (500 steps" in p.stdout, "the final values' heading names t and the steps")
check("coupling.work_solid" not in p.stdout, "the coupling's bookkeeping is not printed (only in summary.json)")
check((out / "histories.png").is_file() and (out / "histories.png").stat().st_size > 10000,
      "--plot drew histories.png")

# 2. A 0.2 s FSI3 run (synthetic: u_y at 5.46 Hz, u_x and drag at twice that)
fsi3 = work / "fsi3_short"
fsi3.mkdir()
rows = ["time,coupling.iterations,fluid.drag,fluid.lift,solid.A_x,solid.A_y"]
for i in range(1, 81):
    t = i * 0.0025
    w = 2 * math.pi * 5.46 * t
    rows.append(f"{t:.4f},5,{457.3 + 22.66 * math.sin(2 * w)},{2.22 + 149.78 * math.sin(w)},"
                f"{(-2.69 + 2.53 * math.sin(2 * w)) * 1e-3},{(1.48 + 34.38 * math.sin(w)) * 1e-3}")
(fsi3 / "probes.csv").write_text("\n".join(rows) + "\n")
(fsi3 / "summary.json").write_text(json.dumps({"scene": "fsi3", "status": "completed", "steps": 80}))
p = subprocess.run([str(BIN / "fsi"), "plot", str(fsi3)], capture_output=True, text=True, timeout=120, env=env)
check(p.returncode == 0, f"fsi plot FSI3 0.2 s: exit {p.returncode} {p.stderr[-400:]}")
check("the run is too short" in p.stdout and "at least 3" in p.stdout and "%" not in p.stdout,
      f"fsi plot: the Turek-Hron comparison says the run is too short, no errors in % ({p.stdout.strip()[-300:]})")
check((fsi3 / "histories.png").is_file() and (fsi3 / "turek_hron.png").is_file(),
      "histories.png and turek_hron.png drawn all the same")

# 3. run_turek_hron.sh on it, with a stand-in fsi that writes that history
fake_bin = work / "fake_bin"
fake_bin.mkdir()
fake = fake_bin / "fsi"
fake.write_text("#!/bin/sh\n# stand-in for `fsi run SCENE --out OUT`: copies the 0.2 s history\n"
                f"mkdir -p \"$4\" && cp {fsi3}/probes.csv {fsi3}/summary.json \"$4\"/\n")
fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
p = subprocess.run(["bash", str(SRC / "bench" / "fsi" / "run_turek_hron.sh"), "fsi3", str(work / "th_short")],
                   capture_output=True, text=True, timeout=120, env=dict(env, FSI_BIN=str(fake_bin)))
check(p.returncode == 3, f"run_turek_hron.sh on 0.2 s of FSI3: exit {p.returncode} (3: too short)")
check("too short" in p.stderr and "%" not in p.stdout and "nan" not in p.stdout,
      f"it says the run is too short and prints no errors ({p.stderr.strip()[-300:]})")
check((work / "th_short" / "fsi3.png").is_file(), "the histories plot is still drawn")

# 4. neither a run nor a study
(work / "empty").mkdir()
p = subprocess.run([str(BIN / "fsi"), "plot", str(work / "empty")], capture_output=True, text=True, timeout=60,
                   env=env)
check(p.returncode == 1 and "neither a run" in p.stderr, f"fsi plot on an empty folder: exit {p.returncode}")

print("FAILED: " + "; ".join(failures) if failures else "all passed")
sys.exit(1 if failures else 0)
