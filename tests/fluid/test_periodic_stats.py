#!/usr/bin/python3
"""bench/fluid/periodic_stats.py on signals with known statistics (no processes but the script).

drag = 440 + 5 sin(4 pi f t), lift = -12 + A(t) sin(2 pi f t) with f = 4.4 Hz and A(t) = 400
until t = 2, then 430: midrange, amplitude and frequency over whole periods are known in
closed form, and the per-period table must show the change of the lift amplitude.
"""
import csv
import json
import math
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[2]
SCRIPT = SRC / "bench" / "fluid" / "periodic_stats.py"
work = Path(sys.argv[1] if len(sys.argv) > 1 else "work_periodic_stats")
work.mkdir(parents=True, exist_ok=True)
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


f, dt = 4.4, 1e-4
rows = []
for i in range(int(4.0 / dt) + 1):
    t = i * dt
    amp = 400.0 if t < 2.0 else 430.0
    rows.append((t, 440.0 + 5.0 * math.sin(4 * math.pi * f * t), -12.0 + amp * math.sin(2 * math.pi * f * t)))
csv_path = work / "probes.csv"
with open(csv_path, "w", newline="") as fh:
    w = csv.writer(fh)
    w.writerow(["time", "drag", "lift"])
    w.writerows(rows)

out = work / "stats.json"
p = subprocess.run(["/usr/bin/python3", str(SCRIPT), str(csv_path), "--columns", "drag", "lift", "--window", "1.5",
                    "--by-period", "lift", "--reference", "cfd3", "--json", str(out)],
                   capture_output=True, text=True, timeout=60)
print(p.stdout)
check(p.returncode == 0, f"exit code {p.returncode} ({p.stderr.strip()[-300:]})")
r = json.load(open(out))
d, l = r["drag"], r["lift"]
check(abs(d["midrange"] - 440.0) < 1e-3, f"drag midrange {d['midrange']:.5f} = 440")
check(abs(d["amplitude"] - 5.0) < 1e-3, f"drag amplitude {d['amplitude']:.5f} = 5")
check(abs(l["midrange"] + 12.0) < 1e-2, f"lift midrange {l['midrange']:.4f} = -12")
check(abs(l["amplitude"] - 430.0) < 1e-2, f"lift amplitude {l['amplitude']:.4f} = 430 (window after the change)")
check(abs(l["frequency"] - f) < 1e-5, f"lift frequency {l['frequency']:.7f} = {f}")
e = d["errors"]
check(abs(e["amplitude_percent"] - 100 * (5.0 - 5.6183) / 5.6183) < 0.02,
      f"drag amplitude error {e['amplitude_percent']:.3f}% = {100 * (5.0 - 5.6183) / 5.6183:.3f}%")
check(abs(e["frequency_percent"] - 100 * (f - 4.3956) / 4.3956) < 1e-3,
      f"frequency error (the lift's) {e['frequency_percent']:.4f}% = {100 * (f - 4.3956) / 4.3956:.4f}%")

# Harmonics: the drag is all 2f (amplitude 5), the lift all f (430 after t = 2).
p4 = subprocess.run(["/usr/bin/python3", str(SCRIPT), str(csv_path), "--columns", "drag", "lift", "--window", "1.5",
                     "--harmonics", "3", "--json", str(out)], capture_output=True, text=True, timeout=60)
check(p4.returncode == 0, f"--harmonics: exit code {p4.returncode} ({p4.stderr.strip()[-300:]})")
h = json.load(open(out))
hd, hl = h["drag"]["harmonics"], h["lift"]["harmonics"]
check(abs(hd[0]) < 1e-3 and abs(hd[1] - 5.0) < 1e-3 and abs(hd[2]) < 1e-3, f"drag harmonics {hd} = [0, 5, 0]")
check(abs(hl[0] - 430.0) < 1e-2 and abs(hl[1]) < 1e-2, f"lift harmonics {hl} = [430, 0, 0]")

# Per period of the lift over the whole run: 400 before t = 2, 430 after (one period straddles).
p2 = subprocess.run(["/usr/bin/python3", str(SCRIPT), str(csv_path), "--columns", "drag", "lift", "--window", "4",
                     "--by-period", "lift", "--json", str(out)], capture_output=True, text=True, timeout=60)
check(p2.returncode == 0, f"exit code {p2.returncode}")
periods = json.load(open(out))["by_period"]
before = [q for q in periods if q["t1"] < 2.0]
after = [q for q in periods if q["t0"] > 2.0]
check(len(before) >= 7 and len(after) >= 7, f"{len(before)} periods before t = 2, {len(after)} after")
check(all(abs(q["lift"]["amplitude"] - 400.0) < 0.05 for q in before), "lift amplitude 400 in every period before t = 2")
check(all(abs(q["lift"]["amplitude"] - 430.0) < 0.05 for q in after), "lift amplitude 430 in every period after t = 2")
check(all(abs(q["frequency"] - f) < 1e-3 for q in before + after), "every period lasts 1/f")
check(all(abs(q["drag"]["amplitude"] - 5.0) < 1e-3 for q in before + after), "drag amplitude 5 in every period")

# A window of fewer than 3 whole periods: flagged; against a reference: refused (exit 3), no errors.
p5 = subprocess.run(["/usr/bin/python3", str(SCRIPT), str(csv_path), "--columns", "drag", "lift", "--window", "0.5"],
                    capture_output=True, text=True, timeout=60)
check(p5.returncode == 0 and "lift" in p5.stdout and p5.stdout.count("FLAGGED: fewer than 3") == 1,
      f"0.5 s window (2.2 lift periods, 4.4 of the drag): the lift is flagged, the drag not ({p5.stdout.strip()})")
p6 = subprocess.run(["/usr/bin/python3", str(SCRIPT), str(csv_path), "--columns", "drag", "lift", "--window", "0.5",
                     "--reference", "cfd3"], capture_output=True, text=True, timeout=60)
check(p6.returncode == 3 and "at least 3" in p6.stderr and "%" not in p6.stdout,
      f"0.5 s window with --reference: refused, exit {p6.returncode} ({p6.stderr.strip()})")

# Bad input: a column that does not exist is named, non-zero exit.
p3 = subprocess.run(["/usr/bin/python3", str(SCRIPT), str(csv_path), "--columns", "drag", "cd"],
                    capture_output=True, text=True, timeout=60)
check(p3.returncode != 0 and "no column cd" in p3.stderr, f"missing column: exit {p3.returncode}, '{p3.stderr.strip()}'")

sys.exit(1 if failures else 0)
