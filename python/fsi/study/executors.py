"""The Dask executor: each run of a study is one Dask task that runs the same `fsi run` process
tree as the local executor, on a worker of a Dask cluster (`--scheduler tcp://HOST:PORT`) or of a
LocalCluster started here (`--jobs` single-threaded worker processes on 127.0.0.1).

- The worker writes the run folder into a temporary folder and returns it as bytes (a tar),
  which the client unpacks into DIR/runs/<name>; with `--shared-dir DIR2` (the study folder as
  the workers see it) the worker writes there directly and returns no bytes.
- The time limit is applied on the worker (its whole process tree is killed: `timeout`).
- A worker that dies mid-run (killed, out of memory): the scheduler runs the task again on
  another worker; after `allowed-failures` lost attempts (2 for a LocalCluster started here,
  the scheduler's setting otherwise) Dask raises KilledWorker and the client submits the run
  again itself, up to `--retries` times; then the run is `failed` (reason_kind `worker lost`,
  the cause in `reason`). The launcher of a run whose worker died gets SIGTERM
  (PR_SET_PDEATHSIG) and stops its servers and coupler.
- The client's own accounting (DIR/executor.json, printed at the end): workers seen and lost,
  attempts per run, and per run the task's wall time on the worker minus the run's own time
  (the scheduling and shipping overhead).

Workers must import this module (PYTHONPATH=<repo>/python, or `pip install ./python`) and find
the fsi executable: the client's `--fsi` path if it exists there, else $FSI_BIN, else `fsi` on
PATH (the Docker image: /opt/fsi/bin/fsi).
"""
import io
import os
import shutil
import signal
import socket
import sys
import tarfile
import tempfile
import threading
import time
import uuid
from pathlib import Path

from .runner import Runner, kill_tree, reap, start_run_process
from .util import StudyError, write_json

# Worker side: study id -> stop requested (Ctrl-C of the client), shared by the task threads of
# one worker process.
_STOP = {}
_STOP_LOCK = threading.Lock()


def _worker_fsi(path):
    if path and os.access(path, os.X_OK):
        return path
    env = os.environ.get("FSI_BIN")
    if env and os.access(env, os.X_OK):
        return env
    found = shutil.which("fsi")
    if found:
        return found
    raise RuntimeError(f"no fsi executable on worker {socket.gethostname()} ({path} does not exist there; "
                       "set FSI_BIN on the worker or put fsi on its PATH)")


def stop_study(study_id):
    """Runs on every worker (Client.run) when the client is interrupted: its runs stop."""
    with _STOP_LOCK:
        _STOP[study_id] = True
    return True


def run_case_task(payload):
    """One run on a worker: `fsi run` as the local executor starts it, within the time limit.
    Returns the state, exit code, times, the worker and (unless the folder is shared) the run
    folder as a tar."""
    t_start = time.time()
    try:
        from distributed import get_worker
        worker = get_worker().address
    except (ImportError, ValueError):
        worker = ""
    name, study_id = payload["name"], payload["study_id"]
    tmp = Path(tempfile.mkdtemp(prefix="fsi-study-"))
    try:
        scene = Path(payload["scene"])
        if not scene.is_file():  # not on a shared path (a container): the scene's own text
            scene = tmp / Path(payload["scene"]).name
            scene.write_text(payload["scene_text"])
        if payload.get("shared_dir"):
            d = Path(payload["shared_dir"]) / "runs" / name
            d.mkdir(parents=True, exist_ok=True)
            for f in ("summary.json", "probes.csv", "iterations.csv"):
                (d / f).unlink(missing_ok=True)
        else:
            d = tmp / "run" / name
            d.mkdir(parents=True)
        fsi = _worker_fsi(payload["fsi"])
        state = "finished"
        t0 = time.monotonic()
        with open(d / "fsi.log", "w") as log:
            proc = start_run_process(fsi, scene, d, payload["sets"], log, parent_death_signal=signal.SIGTERM,
                                     fork=payload.get("from"))
            try:
                while reap(proc) is None:
                    if time.monotonic() - t0 > payload["time_limit"]:
                        kill_tree(proc)
                        state = "timeout"
                        break
                    if _STOP.get(study_id):
                        kill_tree(proc)
                        state = "interrupted"
                        break
                    time.sleep(0.01)
            finally:
                if proc.returncode is None:
                    kill_tree(proc)
        elapsed = time.monotonic() - t0
        data = None
        if not payload.get("shared_dir"):
            buf = io.BytesIO()
            with tarfile.open(fileobj=buf, mode="w:gz", compresslevel=1) as tar:
                tar.add(d, arcname=name)
            data = buf.getvalue()
        return {"name": name, "state": state, "exit_code": proc.returncode, "elapsed": elapsed,
                "cpu_time": getattr(proc, "cpu_time", None), "worker": worker, "host": socket.gethostname(),
                "task_start": t_start, "task_end": time.time(), "tar": data}
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _safe_extract(data, dest):
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        for m in tar.getmembers():
            p = (dest / m.name).resolve()
            if not str(p).startswith(str(dest.resolve()) + os.sep) or m.issym() or m.islnk():
                raise StudyError(f"refusing tar member {m.name}")
        tar.extractall(dest)


class DaskRunner(Runner):
    """Runner whose runs are Dask tasks (same sources, resume, markers and records)."""

    def __init__(self, study, out, fsi, jobs, quiet=False, scheduler="", shared_dir="", retries=2):
        super().__init__(study, out, fsi, jobs, quiet)
        try:
            import dask
            import distributed
        except ImportError as e:
            raise StudyError(f"--executor dask needs Dask distributed (Debian: python3-distributed): {e}") from None
        self.distributed = distributed
        self.shared_dir = shared_dir
        self.retries = max(0, int(retries))
        self.study_id = uuid.uuid4().hex
        self.cluster = None
        # Workers import fsi.study from here (LocalCluster processes inherit the environment).
        pkg = str(Path(__file__).resolve().parents[2])
        os.environ["PYTHONPATH"] = pkg + (os.pathsep + os.environ["PYTHONPATH"] if os.environ.get("PYTHONPATH") else "")
        if scheduler:
            try:
                self.client = distributed.Client(scheduler, timeout=15)
            except (OSError, TimeoutError) as e:
                raise StudyError(f"cannot reach the Dask scheduler {scheduler}: {e}") from None
            self.where = scheduler
        else:
            with dask.config.set({"distributed.scheduler.allowed-failures": 2,
                                  "distributed.worker.daemon": False}):
                self.cluster = distributed.LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True,
                                                        host="127.0.0.1", dashboard_address=None,
                                                        memory_limit=0, silence_logs=40)
            self.client = distributed.Client(self.cluster)
            self.where = f"LocalCluster {self.cluster.scheduler_address}"
        self.scene_text = Path(study.scene).read_text()
        self.futures = {}  # name -> (future, spec, submitted at)
        self.attempts = {}  # name -> attempts (Dask lost-worker reschedules + our resubmissions)
        self.workers_seen, self.workers_lost, self.lost_at = set(), set(), {}
        self.overheads = []  # per run: task wall on the worker - the run's own elapsed time
        self.queue_waits = []
        self.resubmitted = 0
        self._resubmitted = {}  # name -> submissions by the client after a KilledWorker
        self._last_worker_check = 0.0
        self._check_workers(force=True)
        if not self.workers_seen:
            self._wait_for_workers()

    def _wait_for_workers(self, timeout=60):
        try:
            self.client.wait_for_workers(1, timeout=timeout)
        except Exception as e:  # noqa: BLE001 - distributed raises TimeoutError variants
            raise StudyError(f"no Dask worker joined {self.where} within {timeout} s: {e}") from None
        self._check_workers(force=True)

    def _check_workers(self, force=False):
        now = time.monotonic()
        if not force and now - self._last_worker_check < 0.5:
            return
        self._last_worker_check = now
        try:
            workers = set(self.client.scheduler_info().get("workers", {}))
        except Exception:  # noqa: BLE001
            return
        for w in self.workers_seen - workers:
            if w not in self.workers_lost:
                self.workers_lost.add(w)
                self.lost_at[w] = time.monotonic() - self.t0
                if not self.quiet:
                    print(f"dask: worker {w} lost", file=sys.stderr, flush=True)
        self.workers_seen |= workers

    def capacity(self):
        return 1 << 30  # every run the sources hand out goes to the scheduler at once

    def describe(self):
        n = len(self.client.scheduler_info().get("workers", {}))
        return f"Dask {self.where}, {n} worker(s)"

    def _submit(self, spec):
        payload = {"name": spec["name"], "study_id": self.study_id, "scene": str(self.study.scene),
                   "scene_text": self.scene_text, "sets": spec["sets"], "fsi": self.fsi,
                   "time_limit": self.study.time_limit, "shared_dir": self.shared_dir,
                   "from": str(self.study.fork) if self.study.fork else None}
        key = f"fsi-run-{spec['name']}-{uuid.uuid4().hex[:8]}"
        fut = self.client.submit(run_case_task, payload, key=key, pure=False)
        self.futures[spec["name"]] = (fut, spec, time.time())

    def start(self, spec):
        self.prepare(spec)
        self.attempts[spec["name"]] = 0
        self._submit(spec)
        self.running[spec["name"]] = spec
        self.started += 1

    def _suspicious(self, keys):
        """Attempts the scheduler lost to dead workers, per task key."""
        def count(dask_scheduler, keys):
            return {k: (dask_scheduler.tasks[k].suspicious if k in dask_scheduler.tasks else 0) for k in keys}
        try:
            return self.client.run_on_scheduler(count, keys=list(keys))
        except Exception:  # noqa: BLE001 - an older/newer scheduler: no count
            return {}

    def poll_running(self):
        self._check_workers()
        done = [(n, f) for n, (f, _, _) in self.futures.items() if f.status in ("finished", "error", "cancelled")]
        if not done:
            return False
        lost = self._suspicious(f.key for _, f in done)
        for name, fut in done:
            _, spec, submitted = self.futures.pop(name)
            self.attempts[name] += 1 + int(lost.get(fut.key, 0))
            if fut.status == "finished":
                try:
                    res = fut.result()
                except Exception as e:  # noqa: BLE001
                    res, err = None, e
                else:
                    err = None
            else:
                res = None
                try:
                    err = fut.exception()
                except Exception as e:  # noqa: BLE001 - cancelled
                    err = e
            fut.release()
            if res is None:
                cause = f"{type(err).__name__}: {err}"
                if isinstance(err, ImportError):
                    cause += " (the workers must import fsi.study: PYTHONPATH=<repo>/python, pip install ./python, or the image)"
                if self._resubmitted.get(name, 0) < self.retries:
                    self._resubmitted[name] = self._resubmitted.get(name, 0) + 1
                    self.resubmitted += 1
                    if not self.quiet:
                        print(f"dask: {name}: {cause}; submitting it again "
                              f"({self._resubmitted[name]}/{self.retries})", file=sys.stderr, flush=True)
                    self._submit(spec)
                    continue
                self.running.pop(name)
                lost_worker = type(err).__name__ in ("KilledWorker", "CommClosedError")
                spec["_source"].done(spec, self.conclude(spec, {
                    "state": "worker lost" if lost_worker else "executor error", "exit_code": None, "elapsed": None,
                    "attempts": self.attempts[name], "cause": f"{cause} (after {self.attempts[name]} attempt(s))"}))
                continue
            d = self.runs_dir / name
            if res["tar"] is not None:  # the run folder as the worker wrote it (conclude writes the marker)
                shutil.rmtree(d, ignore_errors=True)
                _safe_extract(res["tar"], self.runs_dir)
            wall = res["task_end"] - res["task_start"]
            self.overheads.append(wall - res["elapsed"])
            self.queue_waits.append(res["task_start"] - submitted)
            self.running.pop(name)
            fields = {"state": res["state"], "exit_code": res["exit_code"], "elapsed": res["elapsed"],
                      "cpu_time": res["cpu_time"], "worker": res["worker"], "attempts": self.attempts[name],
                      "task_wall": wall}
            spec["_source"].done(spec, self.conclude(spec, fields))
        return True

    def idle(self):
        futs = [f for f, _, _ in self.futures.values()]
        if not futs:
            time.sleep(0.01)
            return
        try:
            self.distributed.wait(futs, timeout=0.2, return_when="FIRST_COMPLETED")
        except Exception:  # noqa: BLE001 - dask's TimeoutError
            pass

    def kill_all(self, state):
        """Ctrl-C: every worker stops this study's runs; what does not come back in time is
        cancelled. The runs are marked `state` (interrupted)."""
        try:
            self.client.run(stop_study, self.study_id)
        except Exception:  # noqa: BLE001
            pass
        futs = [f for f, _, _ in self.futures.values()]
        try:
            self.distributed.wait(futs, timeout=10)
        except Exception:  # noqa: BLE001
            pass
        for name in list(self.running):
            fut, spec, _ = self.futures.pop(name)
            fut.cancel()
            self.running.pop(name)
            self.conclude(spec, {"state": state, "exit_code": None, "elapsed": None})

    def summary(self):
        import statistics
        self._check_workers(force=True)
        retried = {n: a for n, a in self.attempts.items() if a > 1}
        s = {"executor": "dask", "scheduler": self.where, "study_id": self.study_id,
             "workers_seen": sorted(self.workers_seen), "workers_lost": sorted(self.workers_lost),
             "runs_submitted": len(self.attempts), "attempts": sum(self.attempts.values()),
             "runs_retried": retried, "resubmitted_by_client": self.resubmitted,
             "shared_dir": self.shared_dir or None}
        if self.overheads:
            s["overhead_per_task_s"] = {"mean": statistics.fmean(self.overheads), "median": statistics.median(self.overheads),
                                        "max": max(self.overheads)}
        return s

    def report(self, out):
        s = self.summary()
        write_json(Path(out) / "executor.json", s)
        oh = s.get("overhead_per_task_s")
        print(f"dask: {len(s['workers_seen'])} worker(s) seen, {len(s['workers_lost'])} lost"
              f"{' (' + ', '.join(s['workers_lost']) + ')' if s['workers_lost'] else ''}; "
              f"{s['attempts']} attempt(s) for {s['runs_submitted']} run(s), {len(s['runs_retried'])} run(s) retried"
              + (f"; overhead per task (task wall - run) mean {oh['mean']:.3f} s, max {oh['max']:.3f} s" if oh else ""),
              file=sys.stderr, flush=True)

    def close(self):
        try:
            self.client.close(timeout=10)
        except Exception:  # noqa: BLE001
            pass
        if self.cluster is not None:
            try:
                self.cluster.close(timeout=20)
            except Exception:  # noqa: BLE001
                pass
