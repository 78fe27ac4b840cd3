"""Running the cases of a study on this machine: one `fsi run` process tree per run, at most
`jobs` at a time, time limits, resume, outcome classification."""
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

from .util import FINISHED, finite, read_json, write_json


def descendants(pid):
    children = {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as f:
                s = f.read()
            ppid = int(s[s.rindex(")") + 2:].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        children.setdefault(ppid, []).append(int(d))
    out, pending = [], [pid]
    while pending:
        for c in children.get(pending.pop(), []):
            out.append(c)
            pending.append(c)
    return out


def reap(proc, block=False, timeout=None):
    """The exit code of proc if it ended (None if not), reaping it with wait4 so that
    proc.cpu_time = user + system time of the process and of every descendant it waited for
    (the launcher waits for its servers and coupler: the run's whole process tree)."""
    if proc.returncode is not None:
        return proc.returncode
    end = None if timeout is None else time.monotonic() + timeout
    while True:
        try:
            pid, status, ru = os.wait4(proc.pid, 0 if block and end is None else os.WNOHANG)
        except ChildProcessError:
            return proc.poll()
        if pid:
            proc.returncode = os.waitstatus_to_exitcode(status)
            proc.cpu_time = ru.ru_utime + ru.ru_stime
            return proc.returncode
        if not block or (end is not None and time.monotonic() >= end):
            return None
        time.sleep(0.01)


def start_run_process(fsi, scene, d, sets, log, parent_death_signal=None, fork=None):
    """`fsi run SCENE --out D --force [--from CHECKPOINT] --set ...` in its own session, output to
    the open file log.
    parent_death_signal: the signal the launcher gets when the thread that started it dies (a
    Dask worker killed with SIGKILL: the launcher then stops its servers and coupler)."""
    cmd = [fsi, "run", str(scene), "--out", str(d), "--force"]
    if fork:
        cmd += ["--from", str(fork)]
    for s in sets:
        cmd += ["--set", s]
    pre = None
    if parent_death_signal is not None:
        def pre():
            try:
                import ctypes
                ctypes.CDLL(None, use_errno=True).prctl(1, int(parent_death_signal), 0, 0, 0)  # PR_SET_PDEATHSIG
            except (OSError, AttributeError):
                pass
    return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                            start_new_session=True, preexec_fn=pre)


def kill_tree(proc, grace=3.0):
    """Stops a run's whole process tree: SIGTERM to the launcher's group (it stops its children),
    then SIGKILL to every process and process group of the tree that is left."""
    tree = set(descendants(proc.pid))
    try:
        os.killpg(proc.pid, signal.SIGTERM)
    except OSError:
        pass
    end = time.monotonic() + grace
    while reap(proc) is None and time.monotonic() < end:
        tree |= set(descendants(proc.pid))
        time.sleep(0.02)
    tree |= set(descendants(proc.pid)) if reap(proc) is None else set()
    for pid in [proc.pid] + sorted(tree):
        for kill in (lambda p: os.killpg(os.getpgid(p), signal.SIGKILL), lambda p: os.kill(p, signal.SIGKILL)):
            try:
                if pid == proc.pid or Path(f"/proc/{pid}").exists():
                    kill(pid)
            except OSError:
                pass
    reap(proc, block=True, timeout=10)


REASON_KINDS = [
    ("tangled", "mesh tangled"), ("inverted", "mesh tangled"), ("solver failed", "solver failed"),
    ("exceeds force_limit", "force limit"), ("residual grew", "residual growth"),
    ("tolerance", "tolerance not reached"), ("not finite", "non-finite"), ("non-finite", "non-finite"),
    ("configuration", "configuration"), ("interrupted", "interrupted"), ("dead", "dead peer"),
    ("did not reply", "no reply"), ("timed out", "no reply"),
]


def classify(summary, exit_code, marker_state, log_tail=""):
    """outcome (completed / diverged / mesh tangled / solver failed / failed / timeout / crashed),
    reason kind, reason, step and iteration of a stop."""
    r = {"status": "", "outcome": "", "reason_kind": "", "reason": "", "stop_step": None, "stop_iteration": None}
    if marker_state == "interrupted":
        r.update(status=(summary or {}).get("status", ""), outcome="interrupted", reason_kind="study interrupted",
                 reason="stopped by Ctrl-C / SIGTERM of the study; run again to resume")
        return r
    if marker_state in ("worker lost", "executor error"):  # Dask: the task, not the run, failed
        r.update(status=(summary or {}).get("status", ""), outcome="failed", reason_kind=marker_state,
                 reason=log_tail or "the run's Dask task failed on every attempt; run again to retry")
        return r
    if marker_state == "timeout":
        r.update(status=(summary or {}).get("status", ""), outcome="timeout", reason_kind="time limit")
        r["reason"] = "killed after the study's time limit"
        return r
    signalled = exit_code is None or exit_code < 0 or (exit_code >= 128)
    if summary is None or signalled:
        if summary is None and exit_code == 1 and not signalled and log_tail:
            # The launcher refused the scene before any process ran (bad key or value): no summary.
            r.update(outcome="failed", reason_kind="configuration", reason=log_tail)
            return r
        r.update(outcome="crashed", reason_kind="signal" if signalled else "no summary.json",
                 reason=f"exit code {exit_code}" + ("" if summary else ", no summary.json"))
        return r
    status, reason = summary.get("status", ""), summary.get("reason", "") or ""
    r.update(status=status, reason=reason)
    for needle, kind in REASON_KINDS:
        if needle in reason:
            r["reason_kind"] = kind
            break
    m = re.search(r"at step (\d+)", reason)
    r["stop_step"] = int(m.group(1)) if m else None
    m = re.search(r"iteration (\d+)", reason)
    r["stop_iteration"] = int(m.group(1)) if m else None
    if status == "completed":
        r["outcome"] = "completed"
    elif status == "diverged":
        r["outcome"] = r["reason_kind"] if r["reason_kind"] in ("mesh tangled", "solver failed") else "diverged"
    elif status == "failed":
        r["outcome"] = "failed"
    else:
        r["outcome"] = "crashed"
        r["reason_kind"] = "bad summary"
    return r


def log_tail(path):
    try:
        lines = [l.strip() for l in Path(path).read_text(errors="replace").splitlines() if l.strip()]
    except OSError:
        return ""
    errors = [l for l in lines if "[error]" in l]
    return re.sub(r"^\[[^]]*\] \[[^]]*\] \[error\] ", "", (errors or lines or [""])[-1])[:300]


class Runner:
    def __init__(self, study, out, fsi, jobs, quiet=False):
        self.study, self.out, self.fsi, self.jobs, self.quiet = study, Path(out), fsi, jobs, quiet
        self.runs_dir = self.out / "runs"
        self.runs_dir.mkdir(parents=True, exist_ok=True)
        self.results = {}  # name -> record
        self.running = {}  # name -> (proc, spec, start, logfile)
        self.started = 0
        self.resumed = 0
        self.total_hint = 0
        self.finished_here = 0  # runs started and finished by this invocation
        self.order = []  # run names in the order the sources handed them out
        self.t0 = time.monotonic()

    def marker(self, spec):
        return {"name": spec["name"], "scene": str(self.study.scene), "scene_sha256": self.study.scene_sha,
                "sets": spec["sets"], "combo": spec["combo"]}

    def resumable(self, spec):
        d = self.runs_dir / spec["name"]
        m = read_json(d / "study_run.json")
        s = read_json(d / "summary.json")
        if not m or not s or m.get("state") != "finished":
            return None
        if m.get("sets") != spec["sets"] or m.get("scene_sha256") != self.study.scene_sha:
            return None
        if s.get("status") not in FINISHED or sorted(s.get("overrides", [])) != sorted(spec["sets"]):
            return None
        return m

    def record(self, spec, marker):
        d = self.runs_dir / spec["name"]
        summary = read_json(d / "summary.json")
        c = classify(summary, marker.get("exit_code"), marker.get("state"), log_tail(d / "fsi.log"))
        wall = finite(((summary or {}).get("wall_time") or {}).get("total"))
        if marker.get("state") in ("worker lost", "executor error"):
            c = classify(summary, marker.get("exit_code"), marker["state"], marker.get("cause", ""))
        rec = {"name": spec["name"], "combo": spec["combo"], "params": spec["params"], **c,
               "exit_code": marker.get("exit_code"), "elapsed": finite(marker.get("elapsed")),
               "cpu_time": finite(marker.get("cpu_time")),
               "wall_time": wall if wall is not None else finite(marker.get("elapsed")),
               "steps": (summary or {}).get("steps"), "coupling_iterations": (summary or {}).get("coupling_iterations")}
        fork = (summary or {}).get("forked_from")
        if isinstance(fork, dict) and rec["steps"] is not None and rec["coupling_iterations"] is not None:
            # a forked run (study `from`): its own steps and iterations, not the developed run's
            rec["steps"] = rec["steps"] - int(fork.get("step", 0))
            rec["coupling_iterations"] = rec["coupling_iterations"] - int(fork.get("iterations", 0))
        if rec["steps"] and rec["coupling_iterations"] is not None:
            rec["iterations_per_step"] = rec["coupling_iterations"] / rec["steps"]
        for k in ("worker", "attempts"):  # Dask executor: where it ran, how many tries it took
            if marker.get(k) is not None:
                rec[k] = marker[k]
        self.results[spec["name"]] = rec
        return rec

    def prepare(self, spec):
        """The run folder, emptied of a previous attempt's results, with a 'running' marker."""
        d = self.runs_dir / spec["name"]
        d.mkdir(parents=True, exist_ok=True)
        for f in ("summary.json", "probes.csv", "iterations.csv"):
            (d / f).unlink(missing_ok=True)
        m = self.marker(spec)
        m["state"] = "running"
        write_json(d / "study_run.json", m)
        return d

    def start(self, spec):
        d = self.prepare(spec)
        log = open(d / "fsi.log", "w")
        proc = start_run_process(self.fsi, self.study.scene, d, spec["sets"], log, fork=self.study.fork)
        self.running[spec["name"]] = (proc, spec, time.monotonic(), log)
        self.started += 1

    def finish(self, name, state):
        proc, spec, t0, log = self.running.pop(name)
        log.close()
        return self.conclude(spec, {"state": state, "exit_code": proc.returncode, "elapsed": time.monotonic() - t0,
                                    "cpu_time": getattr(proc, "cpu_time", None)})

    def conclude(self, spec, fields):
        """Writes the run's final marker (its state, exit code, times), records and reports it."""
        m = self.marker(spec)
        m.update(fields)
        write_json(self.runs_dir / spec["name"] / "study_run.json", m)
        rec = self.record(spec, m)
        self.finished_here += 1
        self.progress(rec)
        return rec

    def progress(self, rec, resumed=False):
        if self.quiet:
            return
        n = len(self.results)
        extra = f" ({rec['reason_kind']})" if rec["reason_kind"] and rec["outcome"] != "completed" else ""
        wt = "%.2f s" % rec["wall_time"] if rec["wall_time"] is not None else "-"
        print(f"[{n}{'/' + str(self.total_hint) if self.total_hint else ''}] {rec['name']}: "
              f"{rec['outcome']}{extra}, {wt}{' (done before)' if resumed else ''}{self.eta(n)}",
              file=sys.stderr, flush=True)

    def eta(self, n):
        """' | 40 %, 12.3 s, ETA 18 s': the study's progress (runs done of the total, the time
        since it started, the time left at the rate of this invocation's finished runs)."""
        el = time.monotonic() - self.t0
        if not self.total_hint:
            return f" | {el:.1f} s"
        left = max(self.total_hint - n, 0)
        s = f" | {100.0 * min(n, self.total_hint) / self.total_hint:.0f} %, {el:.1f} s"
        if left == 0:
            return s
        if self.finished_here == 0:
            return s + ", ETA -"
        return s + f", ETA {el / self.finished_here * left:.0f} s"

    def kill_all(self, state):
        for name in list(self.running):
            kill_tree(self.running[name][0])
            self.finish(name, state)

    def ordered_results(self):
        """The records in the order the runs were handed out (not the order they finished in): the
        column order of results.csv does not depend on which run finished first."""
        out = {n: self.results[n] for n in self.order if n in self.results}
        out.update({n: r for n, r in self.results.items() if n not in out})
        return out

    def capacity(self):
        return self.jobs

    def poll_running(self):
        """Concludes the runs that ended or passed the time limit; True if any did."""
        progressed = False
        for name in list(self.running):
            proc, spec, t0, _ = self.running[name]
            if reap(proc) is not None:
                spec["_source"].done(spec, self.finish(name, "finished"))
                progressed = True
            elif time.monotonic() - t0 > self.study.time_limit:
                kill_tree(proc)
                spec["_source"].done(spec, self.finish(name, "timeout"))
                progressed = True
        return progressed

    def idle(self):
        time.sleep(0.01)

    def execute(self, sources):
        """Runs every spec the sources hand out, at most `capacity()` at a time."""
        while True:
            progressed = False
            while len(self.running) < self.capacity():
                spec = None
                for src in sources:
                    spec = src.next()
                    if spec is not None:
                        break
                if spec is None:
                    break
                progressed = True
                if spec["name"] not in self.order:
                    self.order.append(spec["name"])
                if spec["name"] in self.results:
                    src.done(spec, self.results[spec["name"]])
                    continue
                m = self.resumable(spec)
                if m is not None:
                    rec = self.record(spec, m)
                    self.resumed += 1
                    self.progress(rec, resumed=True)
                    src.done(spec, rec)
                    continue
                spec["_source"] = src
                self.start(spec)
            if self.poll_running():
                progressed = True
            if not self.running and all(s.finished() for s in sources):
                return
            if not progressed:
                self.idle()
