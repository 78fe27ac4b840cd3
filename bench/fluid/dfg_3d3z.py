#!/usr/bin/env python3
"""DFG 3D-3Z (configs/dfg_3d3z.yaml): c_D,max, c_L,min and c_L,max with their times, and dp(8),
from a run folder's probes.csv, against FeatFlow's finest (Bayraktar, Mierka & Turek 2012, as
collected in the project's references): c_D,max 3.2978, c_L,min -0.010999.

  /usr/bin/python3 bench/fluid/dfg_3d3z.py RUN [RUN ...] [--json OUT]

Extrema are refined by the parabola through the extreme sample and its neighbours (as
dfg_2d3_stats.py does for 2D-3); c_L,min is the maximum of -c_L. A run that stops before t = 8
gets the extrema of the rows it has (noted).
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dfg_2d3_stats import StatsError, percent_error, read_columns, refined_max, value_at  # noqa: E402

REF = {"cd_max": 3.2978, "cl_min": -0.010999}
T_FINAL = 8.0


def stats(run):
    path = os.path.join(run, "probes.csv") if os.path.isdir(run) else run
    c = read_columns(path)
    t = c["time"]
    t_cd, cd_max = refined_max(t, c["fluid.cd"])
    t_clmin, neg = refined_max(t, [-v for v in c["fluid.cl"]])
    t_clmax, cl_max = refined_max(t, c["fluid.cl"])
    complete = t[-1] >= T_FINAL - 1e-9
    return {"run": run, "t_end": t[-1], "complete": complete, "steps": len(t),
            "cd_max": cd_max, "t_cd_max": t_cd, "cl_min": -neg, "t_cl_min": t_clmin,
            "cl_max": cl_max, "t_cl_max": t_clmax,
            "dp_final": value_at(t, c["fluid.dp"], T_FINAL) if complete else None,
            "errors": {"cd_max_percent": percent_error(cd_max, REF["cd_max"]),
                       "cl_min_percent": percent_error(-neg, REF["cl_min"])},
            "reference": dict(REF)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--json", metavar="OUT")
    a = ap.parse_args(argv)
    out = []
    for run in a.runs:
        try:
            r = stats(run)
        except StatsError as e:
            print(f"dfg_3d3z: {e}", file=sys.stderr)
            return 1
        out.append(r)
        e = r["errors"]
        note = "" if r["complete"] else f" (ends at t = {r['t_end']:g} < 8: extrema of the rows present)"
        dp = "n/a" if r["dp_final"] is None else f"{r['dp_final']:.5f}"
        print(f"{run}: {r['steps']} steps{note}\n"
              f"  c_D,max {r['cd_max']:.5f} at t {r['t_cd_max']:.3f}  (ref {REF['cd_max']}: {e['cd_max_percent']:+.2f} %)\n"
              f"  c_L,min {r['cl_min']:.6f} at t {r['t_cl_min']:.3f}  (ref {REF['cl_min']}: {e['cl_min_percent']:+.2f} %)\n"
              f"  c_L,max {r['cl_max']:.6f} at t {r['t_cl_max']:.3f};  dp(8) {dp}")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(out, fh, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
