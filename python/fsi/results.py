"""Run scenes and read run folders from Python.

    import fsi
    r = fsi.run("configs/sdof_model.yaml", "runs/g10", set={"coupling.gamma_n1": 10}, force=True)
    d = fsi.load("runs/g10")                 # or r.load()
    d.summary["status"], d.probes["time"], d.probes["solid.d_x"], d.iterations["residual"]
    cols = d.to_dict()                       # {column: array}; d.to_dict("iterations")
    df = fsi.load("runs/g10", pandas=True).probes   # a pandas DataFrame

``fsi.run`` starts ``fsi run`` as a subprocess and waits for it. The executable is the
``fsi=`` argument, else ``$FSI_BIN``, else ``build/bin/fsi`` of the source tree this package
belongs to (or of the working directory), else ``fsi`` on PATH. A run that does not complete
raises ``RunError`` with the status and reason from its summary.json and the exit code
(2 diverged, 1 failed, 130 interrupted); ``check=False`` returns the Run instead.
"""
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["run", "load", "Run", "Results", "RunError", "find_fsi"]

_SOURCE = Path(__file__).resolve().parents[2]  # <repo> when this is <repo>/python/fsi/results.py


class RunError(RuntimeError):
    """A run that did not complete. Attributes: exit_code, status, reason, run (the Run)."""

    def __init__(self, message, run=None, reason=None):
        super().__init__(message)
        self.run = run
        self.exit_code = run.exit_code if run else None
        self.status = run.status if run else None
        self.reason = reason or (run.reason if run else None)


def find_fsi(fsi=None):
    """Path of the `fsi` executable: fsi, else $FSI_BIN, else build/bin/fsi of this package's
    source tree (also when the package is installed: the tree it was built from), or under the
    working directory, else `fsi` on PATH."""
    if fsi:
        return str(fsi)
    env = os.environ.get("FSI_BIN")
    if env:
        return env
    trees = [_SOURCE]
    try:  # an installed package: the source tree it was built from (written by the build backend)
        from fsi._source_tree import SOURCE_TREE
        trees.append(Path(SOURCE_TREE))
    except ImportError:
        pass
    for cand in [t / "build" / "bin" / "fsi" for t in trees] + [Path.cwd() / "build" / "bin" / "fsi"]:
        if cand.is_file() and os.access(cand, os.X_OK):
            return str(cand)
    found = shutil.which("fsi")
    if found:
        return found
    raise FileNotFoundError("fsi executable not found: pass fsi=PATH, set FSI_BIN, build the project "
                            "(build/bin/fsi) or put fsi on PATH")


def _value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return str(v)


def _read_table(path, pandas=False):
    """A CSV written by the coupler: a structured numpy array (one field per column, int64 when
    every value of the column is an integer, else float64), or a pandas DataFrame."""
    path = Path(path)
    if pandas:
        import pandas as pd
        return pd.read_csv(path, float_precision="round_trip")
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows:
        return np.zeros(0, dtype=[])
    names, data = rows[0], [r for r in rows[1:] if r]
    cols = list(zip(*data)) if data else [() for _ in names]
    fields, arrays = [], []
    for name, col in zip(names, cols):
        try:
            a = np.array([int(x) for x in col], dtype=np.int64)
        except ValueError:
            a = np.array([float(x) for x in col], dtype=np.float64)
        fields.append((name, a.dtype))
        arrays.append(a)
    out = np.zeros(len(data), dtype=fields)
    for (name, _), a in zip(fields, arrays):
        out[name] = a
    return out


class Results:
    """A run folder: summary (dict), probes and iterations (structured arrays, or DataFrames
    with pandas=True; None when the file is missing). probes["solid.d_x"] is a column;
    columns(): the probe names."""

    def __init__(self, out, pandas=False):
        self.out = Path(out)
        if not self.out.is_dir():
            raise FileNotFoundError(f"{self.out}: no such run folder")
        sp = self.out / "summary.json"
        self.summary = json.loads(sp.read_text()) if sp.exists() else {}
        self.probes = _read_table(self.out / "probes.csv", pandas) if (self.out / "probes.csv").exists() else None
        it = self.out / "iterations.csv"
        self.iterations = _read_table(it, pandas) if it.exists() else None

    @property
    def status(self):
        return self.summary.get("status")

    @property
    def reason(self):
        return self.summary.get("reason")

    def columns(self):
        if self.probes is None:
            return []
        return list(self.probes.columns) if hasattr(self.probes, "columns") else list(self.probes.dtype.names)

    def to_dict(self, table="probes"):
        """{column: numpy array} of probes.csv (table="probes") or iterations.csv ("iterations")."""
        data = getattr(self, table)
        if data is None:
            return {}
        if hasattr(data, "columns"):
            return {c: data[c].to_numpy() for c in data.columns}
        return {c: np.array(data[c]) for c in data.dtype.names}

    def __getitem__(self, probe):
        """The probe's column; an unknown name raises KeyError listing the available ones."""
        if probe not in self.columns():
            raise KeyError(f"{self.out / 'probes.csv'}: no probe '{probe}' (columns: {', '.join(self.columns())})")
        return np.asarray(self.probes[probe])

    def __repr__(self):
        n = 0 if self.probes is None else len(self.probes)
        return f"<fsi results {str(self.out)!r}: {self.status}, {n} steps>"


def load(out, pandas=False):
    """Read a run folder (summary.json, probes.csv, iterations.csv): a Results object."""
    return Results(out, pandas=pandas)


class Run:
    """A finished `fsi run`: out, command, exit_code, status, reason, summary, output (its
    stdout and stderr), seconds (wall time); load() / probes / iterations read the folder."""

    def __init__(self, out, command, exit_code, output, seconds, stale=None):
        self.out = Path(out)
        self.command = command
        self.exit_code = exit_code
        self.output = output
        self.seconds = seconds
        sp = self.out / "summary.json"
        try:
            # an earlier run's summary (fsi refused to start) is not this run's
            self.summary = json.loads(sp.read_text()) if _stamp(sp) != stale or stale is None else {}
        except (OSError, ValueError):
            self.summary = {}
        self._results = None

    @property
    def status(self):
        return self.summary.get("status")

    @property
    def reason(self):
        return self.summary.get("reason")

    @property
    def ok(self):
        return self.exit_code == 0

    def load(self, pandas=False):
        return load(self.out, pandas=pandas)

    @property
    def results(self):
        if self._results is None:
            self._results = load(self.out)
        return self._results

    @property
    def probes(self):
        return self.results.probes

    @property
    def iterations(self):
        return self.results.iterations

    def __repr__(self):
        return f"<fsi run {str(self.out)!r}: exit {self.exit_code}, {self.status}>"


def _stamp(path):
    try:
        st = os.stat(path)
        return (st.st_mtime_ns, st.st_size, st.st_ino)
    except OSError:
        return None


def _stop(proc):
    """Ctrl-C to fsi (it stops its servers), then SIGTERM, then SIGKILL; bounded waits."""
    for sig, wait in ((signal.SIGINT, 10.0), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
        if proc.poll() is not None:
            return
        try:
            proc.send_signal(sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(wait)
            return
        except subprocess.TimeoutExpired:
            pass


def run(scene, out, set=None, force=False, resume=False, solid_command=None, fsi=None, timeout=None,
        fluid_command=None, reply_timeout=None, recover=None, args=(), check=True, echo=True, cwd=None):
    """Run `fsi run scene --out out` and wait for it; returns a Run.

    set: {dotted.key: value} overrides (--set key=value; bools as true/false, lists as [a, b]).
    force / resume: replace an earlier run in out / continue it from its newest checkpoint.
    solid_command / fluid_command: an external server command line (e.g. "python3 my_solid.py").
    fsi: the executable (default: find_fsi()). timeout: seconds for the whole run (then it is
    interrupted like Ctrl-C and RunError is raised); reply_timeout: fsi's --timeout (seconds the
    coupler waits for a reply). recover: --recover N. args: more command-line arguments.
    check: raise RunError unless the run completed (exit code 0). echo: print fsi's output (its
    progress) as it comes (default; echo=False keeps it quiet); it is also kept in Run.output.
    cwd: working directory of fsi (scene and out are
    relative to it).
    """
    cmd = [find_fsi(fsi), "run", str(scene), "--out", str(out)]
    for k, v in (set or {}).items():
        cmd += ["--set", f"{k}={_value(v)}"]
    if force:
        cmd.append("--force")
    if resume:
        cmd.append("--resume")
    if solid_command:
        cmd += ["--solid-command", solid_command]
    if fluid_command:
        cmd += ["--fluid-command", fluid_command]
    if reply_timeout is not None:
        cmd += ["--timeout", repr(float(reply_timeout))]
    if recover is not None:
        cmd += ["--recover", str(int(recover))]
    cmd += [str(a) for a in args]
    out_dir = Path(cwd or ".") / out
    before = _stamp(out_dir / "summary.json")
    t0 = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=cwd,
                            start_new_session=True, bufsize=1)
    lines, timed_out = [], False
    try:
        import threading

        def pump():
            for line in proc.stdout:
                lines.append(line)
                if echo:
                    sys.stdout.write(line)
                    sys.stdout.flush()

        reader = threading.Thread(target=pump, daemon=True)
        reader.start()
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            timed_out = True
            _stop(proc)
        reader.join(10.0)
    except BaseException:
        _stop(proc)
        raise
    r = Run(out_dir, cmd, proc.returncode, "".join(lines), time.monotonic() - t0, stale=before)
    if timed_out:
        raise RunError(f"fsi run {scene} --out {out}: stopped after the timeout of {timeout} s "
                       f"(exit {r.exit_code}, status {r.status})", r)
    if check and r.exit_code != 0:
        reason = r.reason
        if not reason:  # fsi stopped before writing a summary: its last error line
            # (CLI11's usage hint "Run with --help ..." follows the real message: skip it)
            out_lines = [ln for ln in r.output.strip().splitlines() if ln.strip() and not ln.startswith("Run with --help")]
            errors = [ln for ln in out_lines if "[error]" in ln] or out_lines or ["no output"]
            reason = re.sub(r"^(\[[^\]]*\] )+", "", errors[-1].strip())
        raise RunError(f"fsi run {scene} --out {out}: {r.status or 'failed'} (exit code {r.exit_code}): {reason}",
                       r, reason)
    return r
