"""One coupled run through `fsi run` for the tests of tests/fsi: the command printed, the
solvers single-threaded, and the run folder's summary and tables read back."""
import csv
import json
import os
import subprocess


def table(out, name):
    """The rows of a run folder's CSV table (dicts; [] when the file is absent)."""
    path = os.path.join(out, name)
    return list(csv.DictReader(open(path))) if os.path.exists(path) else []


def run_scene(bin_dir, scene, out, sets=(), timeout=300):
    """`fsi run SCENE --out OUT --set S ...`; returns (exit code, output, summary, probes rows,
    iterations rows). The timeout is generous: a loaded machine is slower, never a failure."""
    cmd = [os.path.join(bin_dir, "fsi"), "run", scene, "--out", out]
    for s in sets:
        cmd += ["--set", s]
    print(" ".join(cmd), flush=True)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_WAIT_POLICY="passive")
    r = subprocess.run(cmd, env=env, timeout=timeout, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    path = os.path.join(out, "summary.json")
    summary = json.load(open(path)) if os.path.exists(path) else {}
    return r.returncode, r.stdout, summary, table(out, "probes.csv"), table(out, "iterations.csv")
