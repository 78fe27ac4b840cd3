#!/usr/bin/python3
"""A study with `from:` forks every run from a developed state (fsi run --from): each run starts
after the developed run's last checkpoint (its final step), the runs with the scene's own settings continue the developed run
exactly (byte-identical rows against running it on), and `from` is part of the runs' names."""
import csv
import json
import subprocess

from common import FSI, SRC, check, results, run_tool, work_dir

w = work_dir("/tmp/study_test_fork")
dev = w / "developed"
p = subprocess.run([FSI, "run", str(SRC / "configs/sdof_model.yaml"), "--out", str(dev), "--set", "time.end=1.02",  # checkpoints at step 50 and the final step 51
                    "--set", "time.checkpoint_every=25"], capture_output=True, text=True, timeout=60)
check(p.returncode == 0, f"developed run to t = 1.02, checkpointed at its end: exit {p.returncode} {p.stderr[-300:]}")
on = w / "continued"
p = subprocess.run([FSI, "run", str(SRC / "configs/sdof_model.yaml"), "--out", str(on), "--set", "time.end=2.0"],
                   capture_output=True, text=True, timeout=60)
check(p.returncode == 0, "the same run from rest to t = 2")
study = w / "fork.yaml"
study.write_text(f"""study: fork
scene: {SRC}/configs/sdof_model.yaml
from: developed
fixed: {{time.end: 2.0, time.checkpoint_every: 25}}
vary:
  coupling.relaxation: [1.0, 0.5]
time_limit: 30
probes: [solid.d_x]
""")
p = run_tool("run", str(study), "--out", str(w / "out"), "--fsi", FSI, "--jobs", "1")
rows = results(w / "out")
check(len(rows) == 2 and all(r["outcome"] == "completed" for r in rows), f"2 runs completed ({len(rows)})")


def table(path):
    with open(path) as f:
        return list(csv.reader(f))


full = table(on / "probes.csv")
scene_beta = [ln.split(":", 1)[1].split("#")[0].strip() for ln in (SRC / "configs/sdof_model.yaml").read_text()
              .splitlines() if ln.strip().startswith("relaxation:")][0]
for r in rows:
    t = table(w / "out" / "runs" / r["name"] / "probes.csv")
    first = float(t[1][0])
    check(abs(first - 1.04) < 1e-9, f"{r['name']}: the first row is the step after the final checkpoint (t = {first})")
    check(len(t) - 1 == 49, f"{r['name']}: 49 steps from t = 1.02 to 2 ({len(t) - 1})")
    if float(r["coupling.relaxation"]) == float(scene_beta):
        check(t[1:] == full[52:], f"{r['name']}: the scene's own settings continue the developed run exactly")
for r in rows:  # the run's own steps and iterations (the developed run's 51 steps are not counted)
    s = json.loads((w / "out" / "runs" / r["name"] / "summary.json").read_text())
    want = (s["coupling_iterations"] - s["forked_from"]["iterations"]) / 49
    check(int(r["steps"]) == 49 and abs(float(r["iterations_per_step"]) - want) < 1e-12,
          f"{r['name']}: results.csv counts the fork's own 49 steps, {want:.3f} iterations per step")
p = run_tool("run", str(study), "--out", str(w / "out"), "--fsi", FSI, "--jobs", "1")
check("0 run(s) started, 2 done before" in p.stderr, "a second invocation runs nothing")
names_without = {n.split("-")[-1] for n in (r["name"] for r in rows)}
study2 = w / "nofork.yaml"
study2.write_text(study.read_text().replace("from: developed\n", ""))
p = run_tool("run", str(study2), "--out", str(w / "out2"), "--fsi", FSI, "--jobs", "1", "--dry-run")
check(not any(h in p.stdout for h in names_without), "without `from` the runs are other runs (their hashes differ)")
bad = w / "bad.yaml"
bad.write_text(study.read_text().replace("from: developed", "from: nowhere"))
p = run_tool("run", str(bad), "--out", str(w / "bad"), "--fsi", FSI, check=False)
check(p.returncode == 1 and "from 'nowhere': no such run or checkpoint folder" in p.stderr,
      f"a missing `from` folder is refused: {p.stderr.strip()[-200:]}")
