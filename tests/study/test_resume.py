#!/usr/bin/python3
"""Resumability (a second invocation runs nothing), the time limit (a run past it is killed with
its whole process tree and classified 'timeout'), and Ctrl-C (everything stops, exit 130)."""
import json
import os
import signal
import subprocess
import time

from common import FSI, SRC, TOOL, check, outcomes, results, run_tool, work_dir

w = work_dir("/tmp/study_test_resume")
study = w / "small.yaml"
study.write_text(f"""
study: small
scene: {SRC}/configs/sdof_model.yaml
fixed: {{time.end: 1.0}}
vary:
  coupling.algorithm: [1, 2]
  coupling.gamma_n1: [0, 100]
time_limit: 30
probes: [solid.d_x]
reference:
  closed_form: {{solid.d_x: sdof_exact}}
""")
out = w / "out"
p = run_tool("run", str(study), "--out", str(out), "--fsi", FSI, "--jobs", "2")
check("4 run(s) started, 0 done before" in p.stderr, "first invocation runs the 4 runs")
rows = results(out)
check(len(rows) == 4 and all(r["outcome"] == "completed" for r in rows), "4 rows, all completed")
err = {(r["coupling.algorithm"], r["coupling.gamma_n1"]): float(r["solid.d_x.l2_rel"]) for r in rows}
check(err[("1", "0")] < 0.05 and err[("1", "0")] == err[("1", "100")],
      f"Alg 1 (gamma-independent) {err[('1', '0')]:.4f} within 5 % of the exact solution at dt = 0.02")
check(err[("2", "100")] > 3 * err[("1", "0")], f"Alg 2, gamma 100 lags: error {err[('2', '100')]:.3f}")
mtimes = {r["name"]: os.path.getmtime(out / "runs" / r["name"] / "summary.json") for r in rows}
p = run_tool("run", str(study), "--out", str(out), "--fsi", FSI)
check("0 run(s) started, 4 done before" in p.stderr, "second invocation runs nothing")
check(all(os.path.getmtime(out / "runs" / n / "summary.json") == t for n, t in mtimes.items()),
      "no summary.json was rewritten")
check(results(out) == rows, "the table is identical after resuming")
# Changing one parameter value reruns exactly the runs it touches.
study.write_text(study.read_text().replace("[0, 100]", "[0, 10]"))
p = run_tool("run", str(study), "--out", str(out), "--fsi", FSI)
check("2 run(s) started, 2 done before" in p.stderr, "a changed value reruns only the 2 new runs")
# A reference run equal to one of the sweep's runs is that run: nothing is run again, the run
# stays one of the cases, and every error is measured against it.
study.write_text(study.read_text().replace(
    "reference:\n  closed_form: {solid.d_x: sdof_exact}",
    "reference:\n  run: {coupling.algorithm: 1, coupling.gamma_n1: 0}"))
p = run_tool("run", str(study), "--out", str(out), "--fsi", FSI)
check("0 run(s) started, 4 done before" in p.stderr, "a shared reference run is not run again")
rows = results(out)
meta = json.loads((out / "results.json").read_text())
ref = [r for r in rows if r["name"] == meta["reference_run"]]
check(len(rows) == 4 and len(ref) == 1 and ref[0]["coupling.algorithm"] == "1" and ref[0]["coupling.gamma_n1"] == "0",
      f"the reference is the sweep's Alg 1, gamma 0 run ({meta['reference_run']})")
check(outcomes(out)["cases"] == 4, "the shared reference is still counted as a case")
err = {(r["coupling.algorithm"], r["coupling.gamma_n1"]): float(r["solid.d_x.l2_rel"]) for r in rows}
check(err[("1", "0")] == 0.0 and err[("1", "10")] < 1e-12, "Alg 1 runs coincide with the reference")
check(err[("2", "10")] > 1e-3, f"Alg 2, gamma 10 differs from it ({err[('2', '10')]:.4f})")

# Time limit: a long run is killed and classified 'timeout', leaving no process behind.
slow = w / "slow.yaml"
slow.write_text(f"""
study: slow
scene: {SRC}/configs/sdof_model.yaml
fixed: {{time.end: 100000.0, time.dt: 0.001}}
vary: {{coupling.gamma_n1: [1]}}
time_limit: 1.5
""")
t0 = time.monotonic()
run_tool("run", str(slow), "--out", str(w / "slow"), "--fsi", FSI)
check(time.monotonic() - t0 < 60, f"the time limit stops the run ({time.monotonic() - t0:.1f} s)")
c = outcomes(w / "slow")
check(c["timeouts"] == 1 and c["crashes"] == 0, "classified timeout, not a crash")
name = results(w / "slow")[0]["name"]


def leftovers(marker):
    ps = subprocess.run(["ps", "-eo", "pid,args"], capture_output=True, text=True).stdout
    return [l for l in ps.splitlines() if marker in l and "ps -eo" not in l]


check(not leftovers(str(w / "slow" / "runs")), "no process of the timed-out run is left")

# Ctrl-C: the study stops its runs and exits 130; the next invocation resumes.
proc = subprocess.Popen(["/usr/bin/python3", str(TOOL), "run", str(slow), "--out", str(w / "int"), "--fsi", FSI],
                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
# Ctrl-C once the study is running a case (its process exists): not during the interpreter's start.
deadline = time.monotonic() + 60
while not leftovers(str(w / "int" / "runs")) and proc.poll() is None and time.monotonic() < deadline:
    time.sleep(0.05)
check(proc.poll() is None and leftovers(str(w / "int" / "runs")), "the study started its run within 60 s")
proc.send_signal(signal.SIGINT)
_, err = proc.communicate(timeout=20)
check(proc.returncode == 130, f"Ctrl-C: exit code {proc.returncode} = 130")
deadline = time.monotonic() + 10
while leftovers(str(w / "int" / "runs")) and time.monotonic() < deadline:
    time.sleep(0.05)
check(not leftovers(str(w / "int" / "runs")), "Ctrl-C leaves no process behind")
check(outcomes(w / "int").get("interrupted") == 1, "the interrupted run is reported as interrupted")
print("all resume/time-limit tests passed")
