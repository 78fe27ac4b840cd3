#!/usr/bin/python3
"""The CI extreme case matrix through `fsi study`: every case classified, no crash, no timeout,
no NaN/inf anywhere in results.csv, every stop has a reason."""
import math
import subprocess
import time

from common import FSI, SRC, check, outcomes, results, work_dir

w = work_dir("/tmp/study_test_extreme")
t0 = time.monotonic()
p = subprocess.run([FSI, "study", str(SRC / "studies" / "extreme_ci.yaml"), "--out", str(w / "out"), "--jobs", "2"],
                   capture_output=True, text=True, timeout=110)
print(p.stderr[-1500:])
check(p.returncode == 0, f"fsi study exited {p.returncode}")
c = outcomes(w / "out")
rows = results(w / "out")
check(c["cases"] == 48 and len(rows) == 48, f"48 cases ({c['cases']})")
check(c["crashes"] == 0, "zero crashes")
check(c["timeouts"] == 0, "zero timeouts")
check(c["nan_cells"] == 0, "zero NaN/inf cells")
check(c["completed"] + c["diverged"] + c["failed"] + c["mesh_tangled"] + c["solver_failed"] == 48,
      f"every case classified: {c}")
check(all(r["outcome"] in ("completed", "diverged", "failed", "mesh tangled", "solver failed") for r in rows),
      "every row has an outcome")
check(all(r["reason"] and r["reason_kind"] for r in rows if r["outcome"] != "completed"), "every stop has a reason")
check(c["completed"] > 0 and c["diverged"] > 0, "the matrix has both outcomes (near the limit)")
for r in rows:
    for k, v in r.items():
        if v not in ("", None) and k not in ("name", "reason", "outcome", "status", "reason_kind"):
            check(math.isfinite(float(v)), f"{r['name']} {k} finite") if not math.isfinite(float(v)) else None
text = (w / "out" / "results.csv").read_text().lower()
check("nan" not in text.replace("nanos", "") and ",inf" not in text, "no 'nan' or 'inf' text in results.csv")
print(f"extreme_ci: {c} in {time.monotonic() - t0:.1f} s")
