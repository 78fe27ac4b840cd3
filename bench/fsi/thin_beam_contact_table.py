#!/usr/bin/env python3
"""The thin beam's runs against the reference (Algorithm 1, k_max 10): outcome, A_x errors, the
contact statistics (summary.json's solid_diagnostics), and the change of A_x between pairs of
runs that differ in the contact gap, in % of the reference's A_x amplitude.

Usage: python3 bench/fsi/thin_beam_contact_table.py REF_DIR LABEL=RUN_DIR ... [--pair LABEL_A,LABEL_B ...]
"""
import csv
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))
from fsi import stats  # noqa: E402


def history(run):
    rows = list(csv.DictReader(open(f"{run}/probes.csv")))
    return [float(r["time"]) for r in rows], [float(r["solid.A_x"]) for r in rows]


def main():
    args = sys.argv[1:]
    pairs = [args[i + 1].split(",") for i, a in enumerate(args) if a == "--pair"]
    args = [a for i, a in enumerate(args) if a != "--pair" and (i == 0 or args[i - 1] != "--pair")]
    ref, runs = args[0], dict(a.split("=", 1) for a in args[1:])
    tr, yr = history(ref)
    amp = stats.amplitude(stats.select_window(tr, yr, (0, 3))[1])
    print(f"reference {ref}: A_x amplitude {amp:.4f} on [0, 3]")
    print("| run | outcome | wall (s) | rel. L2 [0, 2] | rel. L2 [0, 3] | lag (s) | contact from t | contact time (s) "
          "| smallest gap | at x | largest force |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for label, run in runs.items():
        s = json.load(open(f"{run}/summary.json"))
        t, y = history(run)
        c2 = stats.compare(t, y, tr, yr, window=(0, 2))
        c3 = stats.compare(t, y, tr, yr, window=(0, 3))
        d = s.get("solid_diagnostics", {})
        outcome = s["status"] if s["status"] == "completed" else f"{s['status']} at t = {t[-1]:.3f}"
        contact = (f"{d['contact_first_time']:.3f} | {d['contact_active_time']:.3f} | {d['contact_min_gap']:.5f} | "
                   f"{d['contact_min_gap_x']:.3f} | {d['contact_max_force']:.3g}") if "contact_first_time" in d else \
            f"never | 0 | {d.get('contact_min_gap', float('nan')):.4f} | | 0"
        lag = c3.get("phase_lag")
        print(f"| {label} | {outcome} | {s['wall_time']['total']:.1f} | {100 * c2['l2_rel']:.2f} % | "
              f"{100 * c3['l2_rel']:.2f} % | {lag if lag is None else f'{lag:+.3f}'} | {contact} |")
    for a, b in pairs:
        ta, ya = history(runs[a])
        tb, yb = history(runs[b])
        n = min(len(ta), len(tb))
        assert all(abs(ta[i] - tb[i]) < 1e-9 for i in range(n))
        diff = max(abs(ya[i] - yb[i]) for i in range(n))
        at = max(range(n), key=lambda i: abs(ya[i] - yb[i]))
        print(f"{a} vs {b}: max |dA_x| = {diff:.5f} at t = {ta[at]:.3f} = {100 * diff / amp:.2f} % of the reference's "
              f"amplitude ({n} steps)")


if __name__ == "__main__":
    main()
