#!/usr/bin/python3
"""fsi.load_study on a study folder written by hand (no processes): columns, types, empty cells,
CPU time from results.json and (older folders) from the runs' markers, pandas and numpy forms."""
import json
import math
import sys

from common import SRC, check, work_dir

sys.path.insert(0, str(SRC / "python"))
import fsi  # noqa: E402

w = work_dir("/tmp/study_test_load")
(w / "results.csv").write_text(
    "name,coupling.gamma_n1,solid.model,outcome,status,reason_kind,stop_step,stop_iteration,exit_code,wall_time,"
    "elapsed,steps,coupling_iterations,iterations_per_step,solid.d_x.l2_rel,reason\n"
    "reference-aa,0,sdof,completed,completed,,,,0,0.5,0.7,100,100,1,0,\n"
    "g10-bb,10,sdof,completed,completed,,,,0,0.25,0.4,100,200,2,0.0125,\n"
    "g100-cc,100,sdof,diverged,diverged,force limit,7,,0,0.1,0.3,7,7,1,,\"|F| exceeds force_limit, at step 7\"\n")
(w / "results.json").write_text(json.dumps({"reference_run": None, "runs": [
    {"name": "reference-aa", "cpu_time": 0.61}, {"name": "g10-bb", "cpu_time": 0.33}, {"name": "g100-cc"}]}))
(w / "runs" / "g100-cc").mkdir(parents=True)
(w / "runs" / "g100-cc" / "study_run.json").write_text(json.dumps({"cpu_time": 0.12}))

t = fsi.load_study(w, frame=False)
check(isinstance(t, dict) and list(t)[:4] == ["name", "coupling.gamma_n1", "solid.model", "outcome"],
      "numpy form: a dict, columns in the file's order")
check(t["coupling.gamma_n1"].dtype.kind == "f" and list(t["coupling.gamma_n1"]) == [0.0, 10.0, 100.0],
      "a numeric parameter is a float array")
check(t["solid.model"].dtype == object and t["outcome"][2] == "diverged", "text columns stay text")
check(t["solid.d_x.l2_rel"][1] == 0.0125 and math.isnan(t["solid.d_x.l2_rel"][2]), "an empty metric is NaN")
check(list(t["cpu_time"]) == [0.61, 0.33, 0.12], "CPU time from results.json, else from the run's marker")
check(list(t).index("cpu_time") == list(t).index("elapsed") + 1, "cpu_time next to elapsed")
check(list(t["is_reference"]) == [True, False, False] and t["reason"][2].startswith("|F|"),
      "is_reference (the reference-<hash> run) and the reason last")
check(t["stop_step"][2] == 7 and math.isnan(t["stop_step"][0]), "stop_step: 7 for the diverged run, NaN else")
try:
    import pandas  # noqa: F401
    df = fsi.load_study(w)
    check(type(df).__name__ == "DataFrame" and df.shape == (3, len(t)), f"pandas form: a DataFrame {df.shape}")
    check(abs(df.loc[df["outcome"] == "completed", "wall_time"].sum() - 0.75) < 1e-12,
          "DataFrame numbers: completed wall time 0.75 s")
except ImportError:
    print("pandas not installed: the DataFrame form is not tested")
