#!/usr/bin/python3
"""Benchmark (not a test): a 24-run SDOF study (configs/sdof_model.yaml, gamma_N1 x relaxation)
through `fsi study --executor dask` against a Dask scheduler on 127.0.0.1 with 1 and with 2
single-threaded workers (Debian's dask-scheduler / dask-worker, started and stopped here).

Reported per worker count:
- wall: the study's execution time (the tool's "N run(s) started, ..., X s": submission to the
  last result, without connecting to the scheduler), and the whole command's time;
- speed-up: wall(1 worker) / wall(W workers);
- run time: the sum of the runs' own elapsed times (process start to exit, on the worker);
- overhead per task, two ways: inside the task (the task's wall on the worker minus the run's
  elapsed time: temporary folder, tar of the run folder) from DIR/executor.json, and for the
  whole pipeline (W x wall - sum of run elapsed) / runs: scheduling, result transfer, the
  client's unpacking and bookkeeping, and idle workers at the end;
- the load average (uptime) before and after: this machine has 2 cores and runs other jobs;
- for comparison, the local executor with --jobs 1 and 2 on the same study.

  /usr/bin/python3 bench/studies/dask_scaling.py [--out DIR] [--fsi build/bin/fsi] [--workers 1 2]
"""
import argparse
import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

SRC = Path(__file__).resolve().parents[2]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def uptime():
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="/tmp/fsi_dask_scaling")
    ap.add_argument("--fsi", default=str(SRC / "build" / "bin" / "fsi"))
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    args = ap.parse_args()
    out = Path(args.out)
    subprocess.run(["rm", "-rf", str(out)], check=True)
    out.mkdir(parents=True)
    study = out / "sdof24.yaml"
    study.write_text(f"""
study: sdof24
scene: {SRC}/configs/sdof_model.yaml
fixed: {{time.end: 5.0, time.dt: 0.005}}
vary:
  coupling.gamma_n1: [0, 1, 10, 100]
  coupling.relaxation: [0.5, 0.6, 0.7, 0.8, 0.9, 1.0]
time_limit: 60
probes: [solid.d_x]
reference:
  closed_form: {{solid.d_x: sdof_exact}}
""")
    env = dict(os.environ, PYTHONPATH=str(SRC / "python"))
    rows = []
    for nw in args.workers:
        procs = []
        try:
            port = free_port()
            addr = f"tcp://127.0.0.1:{port}"
            procs.append(subprocess.Popen(["dask-scheduler", "--host", "127.0.0.1", "--port", str(port),
                                           "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                          env=env, start_new_session=True))
            for i in range(nw):
                procs.append(subprocess.Popen(["dask-worker", addr, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                                               "--host", "127.0.0.1", "--death-timeout", "60"],
                                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
                                              start_new_session=True))
            sys.path.insert(0, str(SRC / "python"))
            from distributed import Client
            with Client(addr, timeout=30) as c:
                c.wait_for_workers(nw, timeout=60)
            d = out / f"w{nw}"
            load_before = uptime()
            t0 = time.monotonic()
            p = subprocess.run(["/usr/bin/python3", str(SRC / "tools" / "fsi_study.py"), "run", str(study), "--out",
                                str(d), "--fsi", args.fsi, "--executor", "dask", "--scheduler", addr, "--quiet"],
                               capture_output=True, text=True, timeout=600, env=env)
            command = time.monotonic() - t0
            load_after = uptime()
            if p.returncode != 0:
                sys.exit(f"study failed ({p.returncode}):\n{p.stderr[-2000:]}")
            wall = float(re.search(r"run\(s\) started, \d+ done before, ([\d.]+) s", p.stderr).group(1))
            ex = json.loads((d / "executor.json").read_text())
            elapsed = [json.loads((r / "study_run.json").read_text())["elapsed"] for r in (d / "runs").iterdir()]
            n = len(elapsed)
            row = {"workers": nw, "runs": n, "wall_s": wall, "command_s": command, "sum_run_elapsed_s": sum(elapsed),
                   "mean_run_elapsed_s": sum(elapsed) / n,
                   "in_task_overhead_ms": 1e3 * ex["overhead_per_task_s"]["mean"],
                   "pipeline_overhead_per_task_ms": 1e3 * (nw * wall - sum(elapsed)) / n,
                   "load_before": load_before, "load_after": load_after}
            rows.append(row)
        finally:
            for p in reversed(procs):
                if p.poll() is None:
                    os.killpg(p.pid, signal.SIGTERM)
                    try:
                        p.wait(timeout=10)
                    except subprocess.TimeoutExpired:
                        os.killpg(p.pid, signal.SIGKILL)
                        p.wait()
    local = []
    for jobs in args.workers:  # the local executor on the same study, for comparison
        d = out / f"local{jobs}"
        p = subprocess.run(["/usr/bin/python3", str(SRC / "tools" / "fsi_study.py"), "run", str(study), "--out", str(d),
                            "--fsi", args.fsi, "--jobs", str(jobs), "--quiet"], capture_output=True, text=True,
                           timeout=600, env=env)
        wall = float(re.search(r"run\(s\) started, \d+ done before, ([\d.]+) s", p.stderr).group(1))
        elapsed = [json.loads((r / "study_run.json").read_text())["elapsed"] for r in (d / "runs").iterdir()]
        local.append({"jobs": jobs, "wall_s": wall, "sum_run_elapsed_s": sum(elapsed), "load_after": uptime()})
    base = rows[0]["wall_s"]
    for r in rows:
        r["speedup"] = base / r["wall_s"]
    (out / "dask_scaling.json").write_text(json.dumps({"dask": rows, "local": local}, indent=1) + "\n")
    print(f"{'workers':>7} {'runs':>4} {'wall [s]':>8} {'command [s]':>11} {'speed-up':>8} {'sum runs [s]':>12} "
          f"{'mean run [s]':>12} {'in-task ovh [ms]':>16} {'pipeline ovh/task [ms]':>22}")
    for r in rows:
        print(f"{r['workers']:>7} {r['runs']:>4} {r['wall_s']:>8.2f} {r['command_s']:>11.2f} {r['speedup']:>8.2f} "
              f"{r['sum_run_elapsed_s']:>12.2f} {r['mean_run_elapsed_s']:>12.3f} {r['in_task_overhead_ms']:>16.1f} "
              f"{r['pipeline_overhead_per_task_ms']:>22.1f}")
    for r in local:
        print(f"local executor --jobs {r['jobs']}: wall {r['wall_s']:.2f} s, sum of runs {r['sum_run_elapsed_s']:.2f} s, "
              f"speed-up {local[0]['wall_s'] / r['wall_s']:.2f}; load after: {r['load_after']}")
    for r in rows:
        print(f"load ({r['workers']} worker(s)): before: {r['load_before']} | after: {r['load_after']}")
    print(f"table: {out / 'dask_scaling.json'}")


if __name__ == "__main__":
    main()
