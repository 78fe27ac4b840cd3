#!/usr/bin/python3
"""What checkpoints cost: size and write time per checkpoint, and their share of the wall
time at `time.checkpoint_every: 50`, on the Turek-Hron FSI3 scene and the thin beam
(the seed paper's example 2), through `fsi run` with the real servers.

    /usr/bin/python3 bench/fsi/checkpoint_cost.py --out out/checkpoint_cost [--repeats 3]

Each scene runs `--repeats` times (sequentially) for a shortened end time with
checkpoint_every 50; the coupler's own timer (summary.json wall_time.checkpoint: saving both
servers' states, its own, writing and fsync'ing the files) gives the cost directly, so the
share does not depend on comparing two noisy runs. Medians are reported. Writes
results.json and results.md into --out.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

SCENES = {
    # name: (scene file, overrides): 200 steps each, so 3 checkpoints at every 50 (none at the end).
    "fsi3": ("configs/fsi3.yaml", ["time.end=0.5"]),          # dt 0.0025 -> 200 steps
    "thin_beam": ("configs/thin_beam.yaml", ["time.end=1.0"]),  # dt 0.005 -> 200 steps
}


def run(fsi, scene, sets, out):
    cmd = [fsi, "run", os.path.join(ROOT, scene), "--out", out, "--force", "--set", "time.checkpoint_every=50"]
    for s in sets:
        cmd += ["--set", s]
    t0 = time.time()
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=7200)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed ({r.returncode}):\n{r.stderr[-2000:]}")
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    c = s["checkpoints"]
    return {"wall": s["wall_time"]["total"], "checkpoint_seconds": s["wall_time"].get("checkpoint", 0.0),
            "written": c["written"], "bytes": c["last_bytes"], "parts_bytes": c["parts_bytes"],
            "steps": s["steps"], "elapsed": time.time() - t0}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--fsi", default=os.path.join(ROOT, "build", "bin", "fsi"))
    p.add_argument("--scenes", nargs="*", default=list(SCENES))
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    results = {}
    for name in a.scenes:
        scene, sets = SCENES[name]
        runs = []
        for i in range(a.repeats):
            r = run(a.fsi, scene, sets, os.path.join(a.out, f"{name}_{i}"))
            print(f"{name} run {i + 1}: {r['steps']} steps, wall {r['wall']:.1f} s, {r['written']} checkpoints, "
                  f"{r['checkpoint_seconds']:.3f} s in checkpoints, {r['bytes'] / 1e6:.2f} MB each", flush=True)
            runs.append(r)
        per = [r["checkpoint_seconds"] / r["written"] for r in runs]
        share = [r["checkpoint_seconds"] / r["wall"] for r in runs]
        results[name] = {"runs": runs, "bytes": runs[0]["bytes"], "parts_bytes": runs[0]["parts_bytes"],
                         "seconds_per_checkpoint_median": statistics.median(per),
                         "share_at_every_50_median": statistics.median(share),
                         "wall_per_step_median": statistics.median(r["wall"] / r["steps"] for r in runs)}
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(results, f, indent=2)
    lines = ["| scene | checkpoint size | solid / fluid / coupler parts | write time (median) | wall per step | "
             "share of wall time at every 50 |", "|---|---|---|---|---|---|"]
    for name, r in results.items():
        pb = r["parts_bytes"]
        lines.append(f"| {name} | {r['bytes'] / 1e6:.2f} MB | {pb['solid'] / 1e3:.0f} kB / {pb['fluid'] / 1e3:.0f} kB / "
                     f"{pb['coupler'] / 1e3:.1f} kB | {1e3 * r['seconds_per_checkpoint_median']:.1f} ms | "
                     f"{r['wall_per_step_median']:.3f} s | {100 * r['share_at_every_50_median']:.3f} % |")
    text = "\n".join(lines) + "\n"
    with open(os.path.join(a.out, "results.md"), "w") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main()
