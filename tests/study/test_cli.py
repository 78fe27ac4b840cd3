#!/usr/bin/python3
"""fsi study's options: --dry-run (lists runs and folders, runs nothing), --set (an override of
every run: new names, the copy names it), an unknown key refused before anything runs (named,
with the close match), exit 1 when every case failed, the progress line with ETA, CPU time;
`bench/catalog.py study` records a finished study folder's total when it ran the shipped study
and refuses one run with other settings."""
import json
import os
import re
import subprocess

from common import FSI, SRC, check, results, run_tool, work_dir

w = work_dir("/tmp/study_test_cli")
study = w / "s.yaml"
study.write_text(f"""
study: s
scene: {SRC}/configs/sdof_model.yaml
fixed: {{time.end: 1.0}}
vary:
  coupling.algorithm: [1, 2]
  coupling.gamma_n1: [0, 10, 100]
time_limit: 30
probes: [solid.d_x]
reference:
  closed_form: {{solid.d_x: sdof_exact}}
""")
out = w / "out"
# The estimate: the scene's measured time per step (a catalog saying 500 steps took 5 s) times
# each run's steps (T = 1 / dt 0.01 = 100): 1 s a run, 6 s in all, 3 s with --jobs 2.
catalog = w / "catalog.json"
catalog.write_text('{"measured": {"machine": "test"}, "scenes": {"sdof_model": '
                   '{"wall_s": 5.0, "measured_steps": 500, "steps": 500}}}')
os.environ["FSI_CATALOG"] = str(catalog)
p = run_tool("run", str(study), "--out", str(out), "--fsi", FSI, "--dry-run", "--set", "time.dt=0.01", "--jobs", "2")
del os.environ["FSI_CATALOG"]
listed = re.findall(r"^\s+\d+\s+(\S+)$", p.stdout, re.M)
check(len(listed) == 6 and not out.exists(), f"--dry-run lists 6 runs and creates nothing ({listed[0]})")
check(p.stdout.count("--set time.dt=0.01") == 6, "each listed run shows its overrides, --set included")
check(p.stdout.count("      about 1 s") == 6 and "estimate: 6 s for 6 run(s) one after the other, about 3 s with "
      "--jobs 2" in p.stdout, f"--dry-run estimates 1 s per run from the catalog, 6 s in all:\n{p.stdout}")

# Through the launcher: fsi study passes every option on.
p = subprocess.run([FSI, "study", str(study), "--out", str(out), "--jobs", "2", "--set", "time.dt=0.01"],
                   capture_output=True, text=True, timeout=100)
check(p.returncode == 0, f"fsi study ... --set time.dt=0.01 exits 0 ({p.returncode})")
rows = results(out)
names = {r["name"] for r in rows}
check(names == {n.split("/")[-1] for n in listed}, "the runs are the ones --dry-run listed")
steps = {int(r["steps"]) for r in rows}
check(steps == {100}, f"--set time.dt=0.01 reached every run: {steps} steps of T = 1")
check("time.dt: 0.01" in (out / "study.yaml").read_text(), "the study copy names the --set override")
eta = re.findall(r"\[(\d+)/6\] .*\| (\d+) %, [\d.]+ s(, ETA \S+ s)?", p.stderr)
check(len(eta) == 6 and eta[-1][1] == "100" and any(e[2] for e in eta[:-1]),
      f"a progress line per run with the study's percentage and ETA ({len(eta)} lines)")
marker = json.loads((out / "runs" / rows[0]["name"] / "study_run.json").read_text())
check(0 < marker["cpu_time"] < 30, f"CPU time of the run's process tree recorded: {marker['cpu_time']:.3f} s")
p = run_tool("analyse", str(out))
check(results(out) == rows, "analyse (from the copy) finds the same runs")
p = run_tool("run", str(study), "--out", str(out), "--fsi", FSI)
check("6 run(s) started, 0 done before" in p.stderr and len(results(out)) == 6,
      "without --set the runs are other runs (their hash names their overrides): none of them is done")

# A key the scene does not have: refused before anything runs, named, with the close match.
bad = w / "bad.yaml"
bad.write_text(study.read_text().replace("coupling.gamma_n1:", "coupling.gama_n1:"))
p = run_tool("run", str(bad), "--out", str(w / "bad"), "--fsi", FSI, check=False)
check(p.returncode == 1 and not (w / "bad").exists(), "an unknown vary key: exit 1, nothing created")
# (The wording is fsi check's when the launcher has it, else the study tool's best-effort check.)
check("gama_n1'" in p.stderr and "did you mean" in p.stderr and "gamma_n1'" in p.stderr,
      f"named, with the close match: {p.stderr.strip().splitlines()[-1].strip()}")
p = run_tool("run", str(study), "--out", str(w / "bad"), "--fsi", FSI, "--set", "solid.stifness=3", check=False)
check(p.returncode == 1 and "stifness'" in p.stderr and "stiffness'" in p.stderr,
      "an unknown --set key: refused, with the close match")

# Every case failed: exit 1 (an fsi that exits 3 at once: every run crashed, no summary.json).
fake = w / "fake_fsi"
fake.write_text("#!/bin/sh\nexit 3\n")
fake.chmod(0o755)
p = run_tool("run", str(study), "--out", str(w / "fail"), "--fsi", str(fake), check=False)
c = json.loads((w / "fail" / "outcomes.json").read_text())
check(p.returncode == 1 and c["crashes"] == 6 and "every case failed" in p.stderr,
      f"every case failed: exit {p.returncode}, {c['crashes']} crashed")
p = run_tool("run", str(study), "--out", str(w / "out"), "--fsi", FSI, "--set", "solid.force=0.5")
check(p.returncode == 0, "a study with completed cases exits 0")

# An fsi with the `check` subcommand decides: its refusal (exit 1, stderr) stops the study.
wrap = w / "fsi_with_check"
wrap.write_text(f"""#!/bin/sh
if [ "$1" = check ]; then
  echo "$@" >> {w}/check_calls
  if [ "$2" = --help ]; then echo "Usage: fsi check [OPTIONS] SCENE"; exit 0; fi
  case "$*" in *relaxation=0.5*) echo "{SRC}/configs/sdof_model.yaml: 'coupling.relaxation' is out of range" >&2; exit 1;; esac
fi
exec {FSI} "$@"
""")
wrap.chmod(0o755)
p = run_tool("run", str(study), "--out", str(w / "chk"), "--fsi", str(wrap), "--set", "coupling.relaxation=0.5",
             check=False)
calls = (w / "check_calls").read_text().splitlines()
check(p.returncode == 1 and "out of range" in p.stderr and not (w / "chk").exists(),
      "fsi check's refusal stops the study before anything runs, with its message")
check(len(calls) == 2 and calls[1].startswith(f"check {SRC.resolve()}/configs/sdof_model.yaml --set coupling.algorithm=1"),
      f"fsi check SCENE --set ... called with the first run's overrides ({calls[1][:60]}...)")
p = run_tool("run", str(study), "--out", str(w / "chk"), "--fsi", str(wrap), "--dry-run")
check(p.returncode == 0 and "keys checked (fsi check)" in p.stdout, "accepted by fsi check: the dry run says so")

# bench/catalog.py study: a folder that ran the study as it is -> its runs' elapsed seconds summed
# into the catalog (fsi list shows them as measured); a folder run with --set -> refused.
shipped = w / "shipped"
shipped.mkdir(exist_ok=True)
(shipped / "s.yaml").write_text(study.read_text())
plain = w / "plain"
run_tool("run", str(study), "--out", str(plain), "--fsi", FSI)
catalog.write_text('{"measured": {"machine": "test"}, "scenes": {}}')
env = dict(os.environ, FSI_CATALOG=str(catalog))
cat = [("/usr/bin/python3"), str(SRC / "bench" / "catalog.py"), "study", "--studies", str(shipped)]
p = subprocess.run(cat + [str(plain)], capture_output=True, text=True, timeout=60, env=env)
want = sum(float(r["elapsed"]) for r in json.loads((plain / "results.json").read_text())["runs"])
got = json.loads(catalog.read_text()).get("studies", {}).get("s", {})
check(p.returncode == 0 and got.get("runs") == 6 and abs(got.get("wall_s", -1) - want) <= 0.05,
      f"catalog.py study records 6 runs, {want:.2f} s ({p.returncode}, {got}, {p.stdout.strip()})")
p = subprocess.run(cat + [str(out)], capture_output=True, text=True, timeout=60, env=env)
check(p.returncode == 1 and "not the study of" in p.stdout and "fixed" in p.stdout,
      f"a folder run with --set is refused, the differing key named: {p.stdout.strip()}")
