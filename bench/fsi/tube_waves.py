#!/usr/bin/python3
"""The pressure wave in the elastic tube (configs/tube_3d.yaml): arrival times, peaks and wave
speed from a run's probes.csv, and the differences between runs.

  /usr/bin/python3 bench/fsi/tube_waves.py RUN [RUN ...] [--reference RUN] [--json OUT] [--plot PNG]

Probes (the scene's): fluid.p0 .. p4, the pressure on the axis at z = 0, 1.25, 2.5, 3.75, 5 cm;
solid.r0_x .. r4_x, the wall's radial displacement at (r_i, 0, z) (x is radial there); in the 2D
analogue (configs/tube_2d.yaml) solid.r0_y .. r4_y, the wall's displacement across the channel.
Definitions (CGS, as the scene):
  peak      the largest value of the probe over the run and the time it is reached;
  arrival   the first time the probe reaches half of its peak, interpolated linearly between
            the two samples around it (the pulse's half-height front);
  speed     the least-squares slope of z over the arrival times at z = 1.25, 2.5, 3.75 cm
            (z = 0 is the prescribed inlet, z = 5 the traction-free outlet, where p ~ 0).
Printed beside it: the Moens-Korteweg speed c_MK = sqrt(E h / (2 rho_f R)) (inner and mid-wall
radius) and the long-wave speed with the wall's inertia at the pulse's wave number k,
c^2 = (E h / R^2) / (2 rho_f / R + rho_s h k^2): a 3 ms pulse is short enough for the wall's
mass to slow it. With --reference, each run's relative difference of every peak and arrival
time from the reference run's (the acceptance measure: Algorithm 1 against 2, dt, mesh).
"""
import argparse
import csv
import json
import math
import os
import sys

Z = [0.0, 1.25, 2.5, 3.75, 5.0]
INNER = [1, 2, 3]  # the stations used for the speed


def read(run):
    path = os.path.join(run, "probes.csv") if os.path.isdir(run) else run
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no rows")
    t = [float(r["time"]) for r in rows]
    cols = {}
    radial = "x" if "solid.r0_z" in rows[0] else "y"  # the tube: x is radial at (r, 0, z); tube_2d: y
    for i in range(5):
        for name, key in ((f"p{i}", f"fluid.p{i}"), (f"r{i}", f"solid.r{i}_{radial}")):
            if key not in rows[0]:
                sys.exit(f"{path}: no column {key} (a run of configs/tube_3d.yaml or tube_2d.yaml?)")
            cols[name] = [float(r[key]) for r in rows]
    return t, cols


def front(t, v):
    """(peak, time of the peak, arrival: first time v reaches half the peak)."""
    peak = max(v)
    tp = t[v.index(peak)]
    half = 0.5 * peak
    for j in range(len(v)):
        if v[j] >= half:
            if j == 0:
                return peak, tp, t[0]
            a = (half - v[j - 1]) / (v[j] - v[j - 1])
            return peak, tp, t[j - 1] + a * (t[j] - t[j - 1])
    return peak, tp, float("nan")


def slope(x, y):
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    return sum((a - mx) * (b - my) for a, b in zip(x, y)) / sum((a - mx) ** 2 for a in x)


def analyse(run):
    t, cols = read(run)
    out = {"run": run, "steps": len(t), "stations": {}}
    for i in range(5):
        for q in ("p", "r"):
            peak, tp, arrival = front(t, cols[f"{q}{i}"])
            out["stations"][f"{q}{i}"] = {"z_cm": Z[i], "peak": peak, "peak_time_s": tp, "arrival_s": arrival}
    for q in ("p", "r"):
        times = [out["stations"][f"{q}{i}"]["arrival_s"] for i in INNER]
        out[f"speed_{q}_cm_per_s"] = 1.0 / slope([Z[i] for i in INNER], times) if all(map(math.isfinite, times)) \
            else float("nan")
    return out, t, cols


def theory(E=3.0e6, h=0.1, rho_f=1.0, rho_s=1.2, ri=0.5, pulse=3.0e-3):
    c_in = math.sqrt(E * h / (2 * rho_f * ri))
    c_mid = math.sqrt(E * h / (2 * rho_f * (ri + h / 2)))
    # the pulse's wave number at that speed: the half-period of a sine of its length
    k = math.pi / (c_in * pulse)
    c_inertia = math.sqrt((E * h / ri ** 2) / (2 * rho_f / ri + rho_s * h * k * k))
    return {"moens_korteweg_inner_cm_per_s": c_in, "moens_korteweg_mid_cm_per_s": c_mid,
            "with_wall_inertia_cm_per_s": c_inertia, "pulse_wave_number_per_cm": k}


def plot(results, png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    styles = ["-", "--", ":", "-."]
    for k, (res, t, cols) in enumerate(results):
        ms = [1e3 * x for x in t]
        for i in range(1, 5):
            label = f"z = {Z[i]:g} cm" if k == 0 else None
            ax1.plot(ms, [v / 1e3 for v in cols[f"p{i}"]], styles[k % 4], color=f"C{i}", lw=1.2, label=label)
            ax2.plot(ms, [1e3 * v for v in cols[f"r{i}"]], styles[k % 4], color=f"C{i}", lw=1.2, label=label)
    ax1.set_ylabel("pressure on the axis (10$^3$ dyn/cm$^2$)")
    ax2.set_ylabel("radial wall displacement (10$^{-3}$ cm)")
    ax2.set_xlabel("t (ms)")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.ticklabel_format(useOffset=False, axis="y")
    ax1.legend(fontsize=8, ncol=4, loc="upper right")
    names = "; ".join(f"{styles[k % 4]!r}: {os.path.basename(os.path.normpath(r[0]['run']))}"
                      for k, r in enumerate(results))
    first = results[0][0]
    fig.suptitle("Pressure wave in an elastic tube (3D FSI): axis pressure and wall displacement\n"
                 f"speed {first['speed_p_cm_per_s'] / 100:.2f} m/s from the half-peak arrivals ({names})",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    print(f"wrote {png}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--reference", help="a run to measure the others against")
    ap.add_argument("--json")
    ap.add_argument("--plot")
    a = ap.parse_args()
    results = [analyse(r) for r in a.runs]
    th = theory()
    ref = analyse(a.reference)[0] if a.reference else None
    report = {"theory": th, "runs": []}
    for res, _, _ in results:
        line = (f"{res['run']}: {res['steps']} steps; speed {res['speed_p_cm_per_s'] / 100:.3f} m/s (pressure), "
                f"{res['speed_r_cm_per_s'] / 100:.3f} m/s (wall)")
        print(line)
        for i in range(1, 4):
            p, r = res["stations"][f"p{i}"], res["stations"][f"r{i}"]
            print(f"  z = {Z[i]:4g} cm: p peak {p['peak']:.5g} at {1e3 * p['peak_time_s']:.2f} ms, arrival "
                  f"{1e3 * p['arrival_s']:.3f} ms; u_r peak {r['peak']:.5g} cm at {1e3 * r['peak_time_s']:.2f} ms, "
                  f"arrival {1e3 * r['arrival_s']:.3f} ms")
        if ref:
            diff = {}
            for key, s in res["stations"].items():
                rs = ref["stations"][key]
                if key[1] in "0" or key in ("p4", "r4"):
                    continue
                diff[key] = {"peak_rel": s["peak"] / rs["peak"] - 1, "arrival_rel": s["arrival_s"] / rs["arrival_s"] - 1}
            worst_peak = max(abs(d["peak_rel"]) for d in diff.values())
            worst_arrival = max(abs(d["arrival_rel"]) for d in diff.values())
            res["against_reference"] = {"reference": a.reference, "stations": diff,
                                        "max_peak_rel": worst_peak, "max_arrival_rel": worst_arrival}
            print(f"  against {a.reference}: peaks within {100 * worst_peak:.2g} %, arrival times within "
                  f"{100 * worst_arrival:.2g} % (z = 1.25, 2.5, 3.75 cm; pressure and wall)")
        report["runs"].append(res)
    print(f"theory: Moens-Korteweg {th['moens_korteweg_inner_cm_per_s'] / 100:.2f} m/s (inner radius), "
          f"{th['moens_korteweg_mid_cm_per_s'] / 100:.2f} m/s (mid-wall); with the wall's inertia at the pulse's "
          f"k = {th['pulse_wave_number_per_cm']:.2f} /cm: {th['with_wall_inertia_cm_per_s'] / 100:.2f} m/s")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(report, f, indent=1)
    if a.plot:
        plot(results, a.plot)


if __name__ == "__main__":
    main()
