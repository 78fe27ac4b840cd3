"""Shared helpers of the study tests: paths, running the tool, reading results."""
import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

SRC = Path(os.environ.get("FSI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
FSI = os.environ.get("FSI_BIN", str(SRC / "build" / "bin" / "fsi"))
TOOL = SRC / "tools" / "fsi_study.py"
sys.path.insert(0, str(SRC / "tools"))


def work_dir(default):
    d = Path(sys.argv[1] if len(sys.argv) > 1 else default)
    shutil.rmtree(d, ignore_errors=True)
    d.mkdir(parents=True)
    return d


def run_tool(*args, timeout=100, check=True):
    p = subprocess.run(["/usr/bin/python3", str(TOOL), *args], capture_output=True, text=True, timeout=timeout)
    if check and p.returncode != 0:
        raise AssertionError(f"fsi_study.py {' '.join(args)} exited {p.returncode}:\n{p.stderr[-3000:]}")
    return p


def results(d):
    with open(Path(d) / "results.csv") as f:
        return list(csv.DictReader(f))


def outcomes(d):
    return json.loads((Path(d) / "outcomes.json").read_text())


def check(cond, msg):
    if not cond:
        raise AssertionError(msg)
    print("ok:", msg)
