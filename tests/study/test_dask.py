#!/usr/bin/python3
"""The Dask executor against a real cluster on 127.0.0.1: a scheduler and two single-threaded
workers (Debian's dask-scheduler / dask-worker). A 12-run SDOF study (gamma_N1 x relaxation)
gives the same metrics as the local executor, cell for cell; then one worker is killed with
SIGKILL while it runs a case: the study completes, every run is accounted for (completed, or
failed with a cause), the lost run was retried, no process is left behind. Every wait is
bounded; every process started here is stopped in `finally`."""
import csv
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from common import FSI, SRC, TOOL, check, outcomes, results, run_tool, work_dir

sys.path.insert(0, str(SRC / "python"))
from fsi.study.runner import descendants  # noqa: E402

T_START = time.monotonic()
w = work_dir("/tmp/study_test_dask")
env = dict(os.environ, PYTHONPATH=str(SRC / "python"), DASK_DISTRIBUTED__WORKER__DAEMON="False")
study = w / "sdof12.yaml"
study.write_text(f"""
study: sdof12
scene: {SRC}/configs/sdof_model.yaml
fixed: {{time.end: 2.0, time.dt: 0.01}}
vary:
  coupling.gamma_n1: [0, 1, 10, 100]
  coupling.relaxation: [0.6, 0.8, 1.0]
time_limit: 30
probes: [solid.d_x]
reference:
  closed_form: {{solid.d_x: sdof_exact}}
""")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


procs = []


def start(cmd, log):
    p = subprocess.Popen(cmd, stdout=open(w / log, "w"), stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                         env=env, start_new_session=True)
    procs.append(p)
    return p


def stop(p, sig=signal.SIGTERM):
    if p.poll() is None:
        try:
            os.killpg(p.pid, sig)
        except OSError:
            pass
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(timeout=10)


def workers_joined(addr, n, timeout=120):
    """Connects (the scheduler may still be starting on a loaded machine: retried until the
    deadline) and waits for n workers."""
    from distributed import Client
    deadline = time.time() + timeout
    while True:
        try:
            with Client(addr, timeout=min(30, max(1.0, deadline - time.time()))) as c:
                c.wait_for_workers(n, timeout=max(1.0, deadline - time.time()))
                return len(c.scheduler_info()["workers"])
        except (OSError, TimeoutError):
            if time.time() >= deadline:
                raise
            time.sleep(1)


def metric_table(d):
    """name -> every column but the times (wall_time, elapsed differ between runs)."""
    return {r["name"]: {k: v for k, v in r.items() if k not in ("wall_time", "elapsed")} for r in results(d)}


def leftovers(marker):
    ps = subprocess.run(["ps", "-eo", "pid,args"], capture_output=True, text=True).stdout
    return [l for l in ps.splitlines() if marker in l and "ps -eo" not in l]


try:
    port = free_port()
    addr = f"tcp://127.0.0.1:{port}"
    start(["dask-scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"], "scheduler.log")
    wk = [start(["dask-worker", addr, "--nthreads", "1", "--no-nanny", "--no-dashboard", "--host", "127.0.0.1",
                 "--name", f"w{i}", "--death-timeout", "60"], f"worker{i}.log") for i in (1, 2)]
    check(workers_joined(addr, 2) == 2, f"scheduler {addr} with 2 single-threaded workers")

    # 1. local and Dask: the same table.
    t0 = time.monotonic()
    run_tool("run", str(study), "--out", str(w / "local"), "--fsi", FSI, "--jobs", "2", "--quiet")
    t_local = time.monotonic() - t0
    t0 = time.monotonic()
    p = run_tool("run", str(study), "--out", str(w / "dask"), "--fsi", FSI, "--executor", "dask",
                 "--scheduler", addr, timeout=60)
    t_dask = time.monotonic() - t0
    loc, dsk = metric_table(w / "local"), metric_table(w / "dask")
    check(len(loc) == 12 and all(r["outcome"] == "completed" for r in loc.values()), "12 local runs completed")
    check(loc == dsk, f"Dask results.csv equals the local one in every cell but the times "
                      f"({len(next(iter(loc.values())))} columns; local {t_local:.1f} s, Dask {t_dask:.1f} s)")
    with open(w / "local" / "results.csv") as f:
        cols_local = next(csv.reader(f))
    with open(w / "dask" / "results.csv") as f:
        cols_dask = next(csv.reader(f))
    check(cols_local == cols_dask, "same columns in the same order")
    spread = {r["solid.d_x.l2_rel"] for r in loc.values()}
    check(len(spread) >= 4, f"the metrics differ between cases ({len(spread)} distinct relative L2 errors)")
    files = lambda d: sorted(str(p.relative_to(d)) for p in (d / "runs").rglob("*") if p.is_file())  # noqa: E731
    check(files(w / "local") == files(w / "dask"), f"same run folders and files ({len(files(w / 'local'))} files)")
    ex = json.loads((w / "dask" / "executor.json").read_text())
    check(len(ex["workers_seen"]) == 2 and not ex["workers_lost"] and ex["attempts"] == 12,
          f"executor.json: 2 workers, none lost, 12 attempts (overhead per task "
          f"{ex['overhead_per_task_s']['mean'] * 1e3:.1f} ms)")
    used = {json.loads((w / "dask" / "runs" / n / "study_run.json").read_text())["worker"] for n in dsk}
    check(len(used) == 2, "both workers ran cases")
    p = run_tool("run", str(study), "--out", str(w / "dask"), "--fsi", FSI, "--executor", "dask",
                 "--scheduler", addr, timeout=60)
    check("0 run(s) started, 12 done before" in p.stderr, "resumed through Dask: nothing runs again")
    from fsi import load_study
    tab = load_study(w / "dask")
    check(len(tab) == 12 and (tab["cpu_time"] > 0).all() and (tab["cpu_time"] < 60).all(),
          f"load_study: 12 rows, CPU time per run {tab['cpu_time'].min():.3f}..{tab['cpu_time'].max():.3f} s")

    # A run past its time limit: its whole process tree is killed on the worker: 'timeout'.
    slow = w / "slow.yaml"
    slow.write_text(f"""
study: slow
scene: {SRC}/configs/sdof_model.yaml
fixed: {{time.end: 100000.0, time.dt: 0.001}}
vary: {{coupling.gamma_n1: [1, 2]}}
time_limit: 1.5
""")
    t0 = time.monotonic()
    run_tool("run", str(slow), "--out", str(w / "slow"), "--fsi", FSI, "--executor", "dask", "--scheduler", addr,
             timeout=60)
    c = outcomes(w / "slow")
    # (runs of 100 000 s stopped: the count proves the limit; no bound on the seconds it took)
    check(c["timeouts"] == 2 and c["crashes"] == 0,
          f"time limit on the workers: 2 timeouts in {time.monotonic() - t0:.1f} s")
    check(not leftovers(str(w / "slow")), "no process of the timed-out runs is left")

    # 2. A worker killed (SIGKILL) while it runs a case.
    out = w / "killed"
    client = subprocess.Popen(["/usr/bin/python3", str(TOOL), "run", str(study), "--out", str(out), "--fsi", FSI,
                               "--executor", "dask", "--scheduler", addr], stdout=subprocess.PIPE,
                              stderr=open(w / "killed.log", "w"), stdin=subprocess.DEVNULL, env=env,
                              start_new_session=True)
    procs.append(client)
    victim, end = wk[0], time.monotonic() + 30
    while time.monotonic() < end and not any(
            "fsi" in Path(f"/proc/{c}/cmdline").read_text(errors="replace") if Path(f"/proc/{c}").exists() else False
            for c in descendants(victim.pid)):
        time.sleep(0.005)
    running = [c for c in descendants(victim.pid) if Path(f"/proc/{c}").exists()]
    check(running, f"worker 1 is running a case ({len(running)} process(es) under it)")
    os.kill(victim.pid, signal.SIGKILL)
    victim.wait(timeout=10)
    try:
        rc = client.wait(timeout=60)
    except subprocess.TimeoutExpired:
        rc = None
    log = (w / "killed.log").read_text()
    check(rc == 0, f"the study completes after a worker was killed (exit {rc}):\n{log[-1500:] if rc else ''}")
    rows = results(out)
    done = [r for r in rows if r["outcome"] == "completed"]
    failed = [r for r in rows if r["outcome"] == "failed" and r["reason"]]
    check(len(rows) == 12 and len(done) + len(failed) == 12,
          f"every run accounted for: {len(done)} completed, {len(failed)} failed with a cause")
    check(all(metric_table(out)[r["name"]] == loc[r["name"]] for r in done), "completed runs: the local metrics")
    ex = json.loads((out / "executor.json").read_text())
    retried = ex["runs_retried"]
    check(len(ex["workers_lost"]) == 1 and len(retried) >= 1,
          f"executor.json: 1 worker lost, {len(retried)} run(s) retried ({retried})")
    check("lost" in log and "1 lost" in log, "the printed summary names the lost worker")
    end = time.monotonic() + 10
    while leftovers(str(out)) and time.monotonic() < end:
        time.sleep(0.1)
    check(not leftovers(str(out)), "no process of the killed worker's run is left (PR_SET_PDEATHSIG)")

    # 3. The bound: a scheduler that gives a task up at its first lost worker (allowed-failures 0)
    # and no resubmission by the client (--retries 0): the lost run is failed, with the cause.
    for p in procs:
        stop(p)
    procs.clear()
    env["DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES"] = "0"
    port = free_port()
    addr = f"tcp://127.0.0.1:{port}"
    start(["dask-scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"], "scheduler3.log")
    wk = [start(["dask-worker", addr, "--nthreads", "1", "--no-nanny", "--no-dashboard", "--host", "127.0.0.1",
                 "--name", f"v{i}", "--death-timeout", "60"], f"worker3_{i}.log") for i in (1, 2)]
    workers_joined(addr, 2)
    out = w / "bound"
    client = subprocess.Popen(["/usr/bin/python3", str(TOOL), "run", str(study), "--out", str(out), "--fsi", FSI,
                               "--executor", "dask", "--scheduler", addr, "--retries", "0"],
                              stdout=subprocess.DEVNULL, stderr=open(w / "bound.log", "w"),
                              stdin=subprocess.DEVNULL, env=env, start_new_session=True)
    procs.append(client)
    victim, end = wk[0], time.monotonic() + 30
    while time.monotonic() < end and not any(
            "fsi" in Path(f"/proc/{c}/cmdline").read_text(errors="replace") if Path(f"/proc/{c}").exists() else False
            for c in descendants(victim.pid)):
        time.sleep(0.005)
    os.kill(victim.pid, signal.SIGKILL)
    victim.wait(timeout=10)
    try:
        rc = client.wait(timeout=60)
    except subprocess.TimeoutExpired:
        rc = None
    rows = results(out)
    lost = [r for r in rows if r["outcome"] == "failed" and r["reason_kind"] == "worker lost"]
    check(rc == 0 and len(rows) == 12 and len(lost) >= 1 and
          all(r["outcome"] == "completed" for r in rows if r not in lost),
          f"past the bound: {len(lost)} run(s) failed (worker lost), the other {12 - len(lost)} completed")
    check(all("KilledWorker" in r["reason"] for r in lost), f"the cause is in the reason: {lost[0]['reason'][:120]}")
    check(outcomes(out)["failed_by_reason"].get("worker lost") == len(lost), "outcomes.json counts them")
    check(time.monotonic() - T_START < 110, f"test time {time.monotonic() - T_START:.1f} s (ctest limit 120 s)")
finally:
    for p in reversed(procs):
        stop(p)
