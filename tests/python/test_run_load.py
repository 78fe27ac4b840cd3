#!/usr/bin/python3
"""fsi.run and fsi.load on configs/sdof_model.yaml: the loaded arrays equal the CSV files value
for value (numpy and pandas), the summary's steps equal the rows; runs that do not complete
raise RunError with the summary's reason and keep the exit code (1 bad input, 2 diverged,
130 interrupted by the timeout, 1 for a non-empty --out before anything ran).

    test_run_load.py --bin BUILD/bin --source SRC WORK
"""
import argparse
import csv
import os
import shutil
import sys
from pathlib import Path

ap = argparse.ArgumentParser()
ap.add_argument("--bin", required=True)
ap.add_argument("--source", required=True)
ap.add_argument("work")
a = ap.parse_args()
SRC = Path(a.source).resolve()
sys.path.insert(0, str(SRC / "python"))
import numpy as np  # noqa: E402

import fsi  # noqa: E402

work = Path(a.work).resolve()
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
os.environ["FSI_BIN"] = str(Path(a.bin).resolve() / "fsi")
from checks import check, failures  # noqa: E402


scene = SRC / "configs" / "sdof_model.yaml"
r = fsi.run(scene, work / "g10", set={"coupling.gamma_n1": 10, "time.end": 2.0}, timeout=60)
check(r.exit_code == 0 and r.status == "completed", f"fsi.run: exit {r.exit_code}, status {r.status}")
g = r.summary["parameters"]["coupling"]["gamma_n1"]
check(g == 10, f"the --set value reached the run: parameters.coupling.gamma_n1 = {g}")
d = fsi.load(work / "g10")
with open(work / "g10" / "probes.csv", newline="") as fh:
    rows = list(csv.reader(fh))
header, rows = rows[0], rows[1:]
check(list(d.probes.dtype.names) == header, f"probe columns = the CSV header ({len(header)} columns)")
check(len(d.probes) == len(rows) == d.summary["steps"] == 100, f"{len(d.probes)} rows = summary steps {d.summary['steps']} = 100")
same = all(np.array_equal(d.probes[c], np.array([float(x[i]) for x in rows])) for i, c in enumerate(header))
check(same, "every probe column equals the CSV's values exactly")
with open(work / "g10" / "iterations.csv", newline="") as fh:
    irows = list(csv.reader(fh))
ih, irows = irows[0], irows[1:]
same = all(np.array_equal(d.iterations[c], np.array([float(x[i]) for x in irows])) for i, c in enumerate(ih))
check(same and d.iterations["step"].dtype == np.int64 and len(d.iterations) == len(irows),
      f"iterations.csv: {len(irows)} rows equal, integer columns int64 ({d.iterations.dtype})")
dd = d.to_dict()
check(list(dd) == header and all(np.array_equal(dd[c], d.probes[c]) for c in header)
      and set(d.to_dict("iterations")) == set(ih), "to_dict(): {column: array} of both tables")
# Run.probes reads the same folder
check(np.array_equal(r.probes["solid.d_x"], d["solid.d_x"]), "Run.probes = fsi.load(out).probes")
try:
    import pandas  # noqa: F401
    df = fsi.load(work / "g10", pandas=True)
    check(all(np.array_equal(df.probes[c].to_numpy(float), d.probes[c].astype(float)) for c in header),
          "pandas=True: a DataFrame with the same values")
except ImportError:
    print("skip pandas (not installed)")
try:
    d["solid.dx"]
    check(False, "an unknown probe raises KeyError")
except KeyError as e:
    check("solid.d_x" in str(e), f"an unknown probe raises KeyError naming the columns ({str(e)[:80]}...)")

# failures
try:
    fsi.run(scene, work / "bad", set={"coupling.relaxation": "fast"}, timeout=60)
    check(False, "a bad value raises RunError")
except fsi.RunError as e:
    # Refused before anything ran: no summary.json (status None), fsi's error line as the reason.
    check(e.exit_code == 1 and e.status is None and "'coupling.relaxation' must be a number, got 'fast'" in e.reason
          and e.reason in str(e), f"bad value: exit {e.exit_code}, status {e.status}, reason: {e.reason}")
try:
    fsi.run(work / "no_such_scene.yaml", work / "missing", timeout=60)
    check(False, "a missing scene raises RunError")
except fsi.RunError as e:
    # The command-line parser's message, not its "Run with --help" hint that follows it.
    check(e.exit_code == 1 and "File does not exist" in e.reason and "no_such_scene.yaml" in e.reason,
          f"missing scene: exit {e.exit_code}, reason: {e.reason}")
try:
    fsi.run(SRC / "configs" / "added_mass.yaml", work / "am", set={"coupling.relaxation": 0.5}, timeout=60)
    check(False, "a diverging run raises RunError")
except fsi.RunError as e:
    check(e.exit_code == 2 and e.status == "diverged" and "step" in e.reason,
          f"diverged: exit {e.exit_code}, status {e.status}, reason: {e.reason}")
    check(e.run.load().summary["status"] == "diverged", "the diverged run's folder is readable")
r2 = fsi.run(SRC / "configs" / "added_mass.yaml", work / "am", set={"coupling.relaxation": 0.5}, force=True,
             check=False, timeout=60)
check(r2.exit_code == 2 and r2.status == "diverged", f"check=False returns the Run (exit {r2.exit_code})")
try:
    fsi.run(scene, work / "g10", timeout=60)
    check(False, "a non-empty --out raises RunError")
except fsi.RunError as e:
    check(e.exit_code == 1 and e.status is None and "not empty" in e.reason,
          f"non-empty --out: exit {e.exit_code}, the earlier summary is not this run's (status {e.status}), reason: {e.reason}")
try:
    fsi.run(scene, work / "slow", set={"time.end": 1e6}, timeout=1.0)
    check(False, "the timeout raises RunError")
except fsi.RunError as e:
    check(e.exit_code == 130 and e.status == "interrupted" and "timeout" in str(e),
          f"timeout: exit {e.exit_code}, status {e.status}: {e}")
try:
    fsi.run(scene, work / "x", fsi=str(work / "no-such-fsi"))
    check(False, "a missing executable raises")
except OSError as e:
    check(True, f"a missing executable raises {type(e).__name__}")

sys.exit(1 if failures else 0)
