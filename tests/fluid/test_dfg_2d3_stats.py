#!/usr/bin/python3
"""bench/fluid/dfg_2d3_stats.py and the pure parts of bench/fluid/element_benchmark.py on
closed-form signals (no solver runs).

dfg_2d3_stats: cd = 2.95 - (t - 3.93625)^2, cl = 0.47 - 3 (t - 5.693125)^2 (parabolas, so the
refined maxima and their times are exact to rounding), dp = -0.11 + 0.002 (t - 8) (linear, so
dp(8) is exact when interpolated), sampled at dt 0.01 and, with no row at t = 8, at dt 0.03.
element_benchmark: errors from a fake summary.json, DFG 2D-2 statistics of sinusoids with the
reference maxima and Strouhal number, the markdown table and the plot / --plot-only.
"""
import csv
import importlib.util
import json
import math
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[2]
BENCH = SRC / "bench" / "fluid"
SCRIPT = BENCH / "dfg_2d3_stats.py"
BENCHMARK = BENCH / "element_benchmark.py"
work = Path(sys.argv[1] if len(sys.argv) > 1 else "work_dfg_2d3_stats")
work.mkdir(parents=True, exist_ok=True)
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def load(name, path):
    sys.path.insert(0, str(path.parent))
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def write_csv(path, dt, t_last, columns=("time", "fluid.cd", "fluid.cl", "fluid.dp", "fluid.drag")):
    n = int(round(t_last / dt))
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        for i in range(n + 1):
            t = i * dt
            v = {"time": t, "fluid.cd": 2.95 - (t - 3.93625) ** 2, "fluid.cl": 0.47 - 3 * (t - 5.693125) ** 2,
                 "fluid.dp": -0.11 + 0.002 * (t - 8.0), "fluid.drag": 0.0}
            w.writerow([repr(v[c]) for c in columns])


def run(*args):
    return subprocess.run(["/usr/bin/python3", *map(str, args)], capture_output=True, text=True, timeout=60)


s23 = load("dfg_2d3_stats", SCRIPT)

# --- refined_max on its own
t = [0.0, 0.3, 0.45, 0.9, 1.2]  # uneven spacing, the vertex of 1 - (t - 0.5)^2 lies between samples
tm, ym = s23.refined_max(t, [1 - (x - 0.5) ** 2 for x in t])
check(abs(tm - 0.5) < 1e-12 and abs(ym - 1.0) < 1e-12, f"refined_max, uneven samples: ({tm:.12f}, {ym:.12f}) = (0.5, 1)")
tm, ym = s23.refined_max([0.0, 1.0, 2.0], [0.0, 1.0, 3.0])
check(tm == 2.0 and ym == 3.0, "refined_max at the last sample: the sample itself")

# --- the CLI on a full run sampled at dt 0.01 (t = 8 is a row)
full = work / "full.csv"
write_csv(full, 0.01, 8.0)
out = work / "full.json"
p = run(SCRIPT, full, "--json", out)
print(p.stdout)
check(p.returncode == 0, f"exit code {p.returncode} ({p.stderr.strip()[-300:]})")
r = json.load(open(out))
check(abs(r["cd_max"] - 2.95) < 1e-10, f"C_D,max {r['cd_max']:.12f} = 2.95")
check(abs(r["t_cd_max"] - 3.93625) < 1e-9, f"t(C_D,max) {r['t_cd_max']:.12f} = 3.93625 (between samples)")
check(abs(r["cl_max"] - 0.47) < 1e-10, f"C_L,max {r['cl_max']:.12f} = 0.47")
check(abs(r["t_cl_max"] - 5.693125) < 1e-9, f"t(C_L,max) {r['t_cl_max']:.12f} = 5.693125")
check(abs(r["dp_final"] + 0.11) < 1e-12 and r["complete"], f"dp(8) {r['dp_final']:.12f} = -0.11")
e = r["errors"]
check(abs(e["cd_max_percent"] - 100 * (2.95 - 2.950921575) / 2.950921575) < 1e-8,
      f"C_D,max error {e['cd_max_percent']:.6f}% = {100 * (2.95 - 2.950921575) / 2.950921575:.6f}%")
check(abs(e["cl_max_percent"] - 100 * (0.47 - 0.47795) / 0.47795) < 1e-8, f"C_L,max error {e['cl_max_percent']:.5f}%")
check(abs(e["t_cd_max"]) < 1e-9 and abs(e["t_cl_max"]) < 1e-9, "time errors 0 (absolute, seconds)")
check(abs(e["dp_final_percent"] - 100 * (-0.11 + 0.1116) / 0.1116) < 1e-8,
      f"dp(8) error {e['dp_final_percent']:.5f}% = (v - ref) / |ref| = {100 * 0.0016 / 0.1116:.5f}%")
check("C_D,max 2.950000 at t 3.93625" in p.stdout, "printed C_D,max and its time")

# --- dt 0.03: rows at 7.98 and 8.01, dp(8) interpolated; the same through stats(path)
coarse = work / "coarse.csv"
write_csv(coarse, 0.03, 8.01)
r = s23.stats(str(coarse))
check(abs(r["dp_final"] + 0.11) < 1e-12, f"dp(8) interpolated between 7.98 and 8.01: {r['dp_final']:.12f}")
check(abs(r["t_cd_max"] - 3.93625) < 1e-9 and abs(r["cd_max"] - 2.95) < 1e-10, "stats(path): refined C_D,max at dt 0.03")

# --- a run stopped at t = 5: no dp(8) error, exit 0, a note
short = work / "short.csv"
write_csv(short, 0.01, 5.0)
p = run(SCRIPT, short, "--json", out)
r = json.load(open(out)) if p.returncode == 0 else {}
check(p.returncode == 0 and r.get("complete") is False and r["errors"]["dp_final_percent"] is None
      and "ends at t = 5" in p.stderr, f"short run: exit {p.returncode}, no dp error, note '{p.stderr.strip()}'")

# --- bad input: the missing column and the file are named, non-zero exit
nocl = work / "nocl.csv"
write_csv(nocl, 0.01, 8.0, columns=("time", "fluid.cd", "fluid.dp"))
p = run(SCRIPT, nocl)
check(p.returncode != 0 and "no column fluid.cl" in p.stderr and "nocl.csv" in p.stderr,
      f"missing column: exit {p.returncode}, '{p.stderr.strip()}'")
p = run(SCRIPT, work / "does_not_exist.csv")
check(p.returncode != 0 and "does_not_exist.csv" in p.stderr, f"missing file: exit {p.returncode}, '{p.stderr.strip()}'")

# --- element_benchmark: pure functions on fake data
eb = load("element_benchmark", BENCHMARK)
ref = eb.REF_2D1
summary = {"dofs": 1234, "final": {"fluid.cd": ref["cd"] * 1.01, "fluid.cl": ref["cl"] * 0.98, "fluid.dp": ref["dp"]}}
values, errors = eb.steady_errors(summary)
check(abs(errors["cd"] - 1.0) < 1e-9 and abs(errors["cl"] + 2.0) < 1e-9 and abs(errors["dp"]) < 1e-12,
      f"2D-1 errors from a fake summary: {errors}")
try:
    eb.steady_errors({"dofs": 1, "final": {"fluid.cd": 1.0}})
    check(False, "summary without fluid.cl / fluid.dp raises")
except eb.BenchmarkError as ex:
    check("fluid.cl" in str(ex) and "fluid.dp" in str(ex), f"summary without fluid.cl / fluid.dp: '{ex}'")
check(eb.percent_error(float("nan"), 1.0) is None and eb.percent_error(None, 1.0) is None
      and abs(eb.percent_error(-0.12, -0.1) - (-20.0)) < 1e-9, "percent_error: None for NaN / None, (v - ref) / |ref|")

# DFG 2D-2: drag at 2f, lift at f with the reference maxima and St = 0.1 f.
f = 3.0184
dt = 1e-3
ts = [i * dt for i in range(int(10.0 / dt) + 1)]
cd = [3.2 + 0.02739 * math.sin(4 * math.pi * f * x + 0.3) for x in ts]
cl = [0.98658 * math.sin(2 * math.pi * f * x + 0.1) for x in ts]
values, errors = eb.periodic_errors(ts, cd, cl, 2.0)
check(abs(errors["cd_max"]) < 1e-3 and abs(errors["cl_max"]) < 1e-3, f"2D-2 maxima errors {errors['cd_max']:.2e}%, "
      f"{errors['cl_max']:.2e}% ~ 0 ({values['periods']} periods)")
check(abs(values["strouhal"] - 0.30184) < 1e-5 and abs(errors["strouhal"]) < 1e-2,
      f"2D-2 St {values['strouhal']:.6f} = 0.30184")
check(abs(errors["cl_max_centre"] - 100 * (0.98658 - 1.0)) < 1e-2 and abs(errors["strouhal_centre"] - 100 * (0.30184 / 0.3 - 1)) < 1e-2,
      f"2D-2 errors against the 1996 centres: C_L,max {errors['cl_max_centre']:.3f}%, St {errors['strouhal_centre']:.3f}%")

# DFG 2D-3 through dfg_2d3_stats.compute.
c = s23.read_columns(str(full))
v3, e3 = eb.john_errors(s23.compute(c["time"], c["fluid.cd"], c["fluid.cl"], c["fluid.dp"]))
check(abs(v3["t_cd_max"] - 3.93625) < 1e-9 and e3["dp_final"] is not None, "2D-3 values / errors via john_errors")

rows = [
    {"case": "2d1", "element": "p1p1", "mesh": "h 0.04, hc 0.005", "status": "ok", "unknowns": 1234,
     "wall_seconds": 2.5, "errors": {"cd": 1.0, "cl": -2.0, "dp": None}},
    {"case": "2d1", "element": "p2p1", "mesh": "h 0.06, hc 0.008", "status": "ok", "unknowns": 999,
     "wall_seconds": 1.5, "errors": {"cd": 0.01, "cl": 0.5, "dp": 0.02}},
    {"case": "2d2", "element": "p2p1", "mesh": "h 0.05, hc 0.006", "status": "ok", "unknowns": 5000,
     "wall_seconds": 100.0, "wall_per_simulated_second": 10.0, "errors": errors},
    {"case": "2d3", "element": "p1p1", "mesh": "h 0.02, hc 0.0025", "status": "failed",
     "error": "fsi run exit 1: fluid.stabilisation.grad_div: is a P2/P1 setting"},
    {"case": "2d3", "element": "p2p1", "mesh": "h 0.05, hc 0.006", "status": "ok", "unknowns": 7000,
     "wall_seconds": 80.0, "wall_per_simulated_second": 10.0, "errors": e3},
]
table = eb.format_table(rows)
print(table)
lines = [ln for ln in table.splitlines() if ln.startswith("|")]
check("| 2d1 | P1/P1 | h 0.04, hc 0.005 | 1234 | 2.50 | +1.000 | -2.000 | n/a |" in table, "2D-1 row: errors, n/a for None")
check("| 2d2 | P2/P1 | h 0.05, hc 0.006 | 5000 | 100.00 | 10.00 |" in table, "2D-2 row: wall and s per simulated s")
check("failed: fsi run exit 1" in table, "failed run shown in the table")
by_table = {}
for ln in table.splitlines():
    if ln.startswith("### "):
        cur = ln
    elif ln.startswith("|"):
        by_table.setdefault(cur, set()).add(ln.count("|"))
check(all(len(n) == 1 for n in by_table.values()) and len(by_table) == 3,
      f"3 tables, every row of a table has its header's columns ({by_table})")
check("err St vs 0.300 [%]" in table and "err t(C_D,max) [s]" in table, "columns for the 1996 centres and the times")

# --plot-only on a fake results.json; a missing runner is refused before any run.
eb_out = work / "element_benchmark"
eb_out.mkdir(exist_ok=True)
(eb_out / "error_vs_wall_time.png").unlink(missing_ok=True)
json.dump({"runs": rows}, open(eb_out / "results.json", "w"))
p = run(BENCHMARK, "--out", eb_out, "--plot-only")
check(p.returncode == 0 and (eb_out / "table.md").exists() and (eb_out / "error_vs_wall_time.png").exists()
      and "| 2d1 | P2/P1 |" in p.stdout, f"--plot-only: exit {p.returncode}, table and plot ({p.stderr.strip()[-300:]})")
p = run(BENCHMARK, "--out", work / "eb_norunner", "--fsi", work / "no_fsi", "--cases", "2d1")
check(p.returncode != 0 and "no_fsi" in p.stderr, f"missing runner: exit {p.returncode}, '{p.stderr.strip()}'")

sys.exit(1 if failures else 0)
