#!/usr/bin/python3
"""The added-mass stability map by bisection reproduces the closed-form limit:
for each (algorithm, gamma_N1) the bracket [largest stable, smallest unstable] found by bisection
lies within the bisection tolerance of beta_c, up to the band in which 3000 iterations cannot
reach the tolerance (beta_c (1 - 0.6 %) .. beta_c)."""
import csv

from common import FSI, SRC, check, outcomes, run_tool, work_dir

w = work_dir("/tmp/study_test_am")
study = w / "am.yaml"
tol = 0.004
study.write_text(f"""
study: am_test
scene: {SRC}/configs/added_mass.yaml
fixed: {{time.end: 0.02, coupling.iterations.max: 3000, coupling.iterations.tolerance: 1.0e-10}}
vary:
  coupling.algorithm: [1, 2]
  coupling.gamma_n1: [0, 100, 300]
where: "not (coupling_algorithm == 1 and coupling_gamma_n1 == 300)"
time_limit: 60
stability:
  parameter: coupling.relaxation
  x: coupling.gamma_n1
  series: [coupling.algorithm, time.dt]
  closed_form: added_mass_beta_c
  bisection: {{lo: 0.0, hi: 1.0, tol: {tol}}}
""")
run_tool("run", str(study), "--out", str(w / "out"), "--fsi", FSI, "--jobs", "2")
c = outcomes(w / "out")
check(c["crashes"] == 0 and c["timeouts"] == 0 and c["failed"] == 0, "no crash, timeout or failure")
rows = list(csv.DictReader(open(w / "out" / "stability.csv")))
check(len(rows) == 5, f"5 (algorithm, gamma) groups ({len(rows)})")
band = 0.006
for r in rows:
    bc, lo, hi = float(r["closed_form"]), float(r["stable_max"]), float(r["unstable_min"])
    what = f"alg {r['coupling.algorithm']} gamma {r['coupling.gamma_n1']}: stable {lo:.5f} < unstable {hi:.5f}"
    check(hi - lo <= tol + 1e-12, f"{what}: bracket within the bisection tolerance {tol}")
    check(lo <= bc * (1 + 1e-9), f"{what}: nothing above beta_c = {bc:.5f} is stable")
    check(hi >= bc * (1 - band), f"{what}: beta up to beta_c (1 - {band}) is stable")
    check(abs(lo - bc) <= tol + band * bc, f"{what}: |largest stable - beta_c| <= tol + band")
print("added-mass map reproduces the closed form")
