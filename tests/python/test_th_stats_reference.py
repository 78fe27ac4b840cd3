#!/usr/bin/python3
"""bench/fsi/th_stats.py on FEATFLOW's own FSI3 level-4 history (a 1 ms subsample of
ref_fsi3.point, t in [5, 6.442]): over the last 5 whole u_y periods it reproduces FEATFLOW's
tabulated level-4 values (means, amplitudes, frequencies) to 0.5 %; a history shorter than
3 whole u_y periods is refused with exit code 3."""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

SRC = Path(__file__).resolve().parents[2]
SCRIPT = SRC / "bench" / "fsi" / "th_stats.py"
HISTORY = SRC / "bench" / "fsi" / "reference" / "featflow_fsi3_level4_history.csv"
from checks import check, failures  # noqa: E402


with tempfile.TemporaryDirectory() as tmp:
    out = Path(tmp) / "ref.json"
    p = subprocess.run([sys.executable, str(SCRIPT), "fsi3", str(HISTORY), "--periods", "5", "--json", str(out)],
                       capture_output=True, text=True, timeout=120)
    check(p.returncode == 0, f"th_stats on the reference history exits 0 ({p.returncode}: {p.stderr.strip()[-300:]})")
    if p.returncode == 0:
        r = json.loads(out.read_text())
        check(r["periods"] == 5, f"5 whole u_y periods used ({r['periods']})")
        for q in ("ux", "uy", "drag", "lift"):
            e = r[q]["errors_percent"]["level4"]
            for what in ("mean", "amplitude", "frequency"):
                check(abs(e[what]) <= 0.5, f"{q} {what}: {e[what]:+.3f} % of FEATFLOW's level 4 (within 0.5 %)")
    short = Path(tmp) / "short.csv"
    lines = HISTORY.read_text().splitlines(keepends=True)
    short.write_text("".join(lines[:400]))  # 5 comment lines, header, t in [5, 5.393]: 1 whole period
    p = subprocess.run([sys.executable, str(SCRIPT), "fsi3", str(short)], capture_output=True, text=True, timeout=60)
    check(p.returncode == 3 and "at least 3" in p.stderr, f"a 0.39 s history is refused, exit 3 ({p.returncode}: {p.stderr.strip()})")

sys.exit(1 if failures else 0)
