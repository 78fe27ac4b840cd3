#!/usr/bin/python3
"""bench/fsi/parallel_wall.py on the added-mass model (IQN-ILS converged to 1e-10): both
schemes complete, the table lists both, and the two converged solutions agree (the largest
relative difference of a probe's last value below 1e-8)."""
import re
import subprocess
import sys
import tempfile
from pathlib import Path

SRC = Path(__file__).resolve().parents[2]
bin_dir = sys.argv[1] if len(sys.argv) > 1 else str(SRC / "build" / "bin")
from checks import check, failures  # noqa: E402


with tempfile.TemporaryDirectory() as tmp:
    p = subprocess.run([sys.executable, str(SRC / "bench" / "fsi" / "parallel_wall.py"), str(SRC / "configs" / "added_mass.yaml"),
                        "--set", "coupling.acceleration=iqn-ils", "--set", "coupling.relaxation=0.1",
                        "--repeat", "1", "--out", tmp, "--fsi", bin_dir + "/fsi"],
                       capture_output=True, text=True, timeout=120)
    print(p.stdout[-1500:], p.stderr[-500:])
    check(p.returncode == 0, f"exit 0 ({p.returncode})")
    check("| serial | 1 |" in p.stdout and "| parallel | 1 |" in p.stdout, "both schemes in the table")
    m = re.search(r"parallel / serial wall time: ([0-9.]+)", p.stdout)
    check(m is not None and float(m.group(1)) > 0, "the wall-time ratio is printed")
    diffs = [float(x) for x in re.findall(r" ([0-9.]+e[-+][0-9]+)", p.stdout.split("largest relative differences")[-1])]
    check(bool(diffs) and max(diffs) < 1e-8, f"the same converged solution: largest relative difference {max(diffs) if diffs else None}")

sys.exit(1 if failures else 0)
