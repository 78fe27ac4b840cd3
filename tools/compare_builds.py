#!/usr/bin/python3
"""Are two builds' results byte-identical? Runs the short 2D scenes (and any given) with each
build's `fsi` and compares probes.csv and iterations.csv byte for byte.

  /usr/bin/python3 tools/compare_builds.py BUILD_A BUILD_B [--out DIR] [--scene NAME:ARGS ...]

BUILD_A, BUILD_B: build folders (holding bin/fsi), e.g. one of an older commit in a git worktree
and the current one. Keys that only label (`units`) are left out of both runs' scenes, so a
build older than them runs the same scenes. Run both on the same machine: the tables are reproducible bit for bit on
one machine and library set, not across CPUs (BLAS kernels differ). Exit 0 when every table is
identical, 1 otherwise (the first differing line is printed). A regression guard for changes
that must not move a 2D number (a restructuring, a new dimension), as the 3D plug-ins were.
"""
import argparse
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

SRC = Path(__file__).resolve().parents[1]
# name: the scene and the overrides that make it a few seconds long
SHORT = {
    "sdof_model": "configs/sdof_model.yaml --set time.end=2",
    "added_mass": "configs/added_mass.yaml --set coupling.relaxation=0.17",
    "thick_beam": "configs/thick_beam.yaml --set time.end=0.2",
    "thick_beam_a2": "configs/thick_beam.yaml --set time.end=0.2 --set coupling.algorithm=2",
    "thin_beam": "configs/thin_beam.yaml --set time.end=0.05",
    "fsi3": "configs/fsi3.yaml --set time.end=0.02 --set fluid.mesh.size=0.04",
    "fsi3_p2p1": "configs/fsi3_p2p1.yaml --set time.end=0.02 --set fluid.mesh.size=0.04",
    "dfg_2d1": "configs/dfg_2d1.yaml --set fluid.mesh.size=0.04 --set fluid.mesh.parameters.hc=0.005",
    "csm1": "configs/csm1.yaml",
}


def run(fsi, args, out):
    cmd = [str(fsi), "run", *shlex.split(args), "--out", str(out), "--force"]
    p = subprocess.run(cmd, cwd=SRC, capture_output=True, text=True, timeout=1800,
                       env=dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1"))
    return p.returncode, p.stdout + p.stderr


# Top-level keys that change no number (labels only): an older build refuses them, so both
# builds get a copy of the scene without them when the scene has them.
LABEL_KEYS = ("units",)


def without_label_keys(args):
    """(args, temporary scene or None): args with the scene file replaced by a copy beside it
    (relative mesh paths still resolve) that lacks LABEL_KEYS, when the scene has any."""
    words = shlex.split(args)
    scene = SRC / words[0]
    lines = scene.read_text().splitlines(keepends=True)
    kept = [ln for ln in lines if not any(ln.startswith(k + ":") for k in LABEL_KEYS)]
    if len(kept) == len(lines):
        return args, None
    copy = scene.with_name(f".compare_{os.getpid()}_{scene.name}")
    copy.write_text("".join(kept))
    return shlex.join([str(copy.relative_to(SRC))] + words[1:]), copy


def first_difference(a, b):
    la, lb = a.read_text().splitlines(), b.read_text().splitlines()
    for i, (x, y) in enumerate(zip(la, lb)):
        if x != y:
            return f"line {i + 1}:\n    {x[:160]}\n    {y[:160]}"
    return f"{len(la)} against {len(lb)} lines"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("build_a", type=Path)
    ap.add_argument("build_b", type=Path)
    ap.add_argument("--out", type=Path, help="keep the runs here (default: a temporary folder)")
    ap.add_argument("--scene", action="append", default=[], help="NAME:ARGS, e.g. 'cfd1:configs/cfd1.yaml'")
    ap.add_argument("--only", nargs="*", help="only these of the short scenes")
    a = ap.parse_args()
    cases = {k: v for k, v in SHORT.items() if not a.only or k in a.only}
    for s in a.scene:
        name, args = s.split(":", 1)
        cases[name] = args
    out = a.out or Path(tempfile.mkdtemp(prefix="fsi_compare_"))
    bad = 0
    for name, args in cases.items():
        results = []
        args, copy = without_label_keys(args)
        try:
            for tag, build in (("a", a.build_a), ("b", a.build_b)):
                folder = out / name / tag
                code, log = run(build.resolve() / "bin" / "fsi", args, folder)
                if code != 0:
                    print(f"{name}: build {tag} exited {code}:\n{log[-1500:]}")
                results.append(folder)
        finally:
            if copy is not None:
                copy.unlink()
        same = []
        for table in ("probes.csv", "iterations.csv"):
            pa, pb = results[0] / table, results[1] / table
            if not pa.exists() and not pb.exists() and table == "iterations.csv":
                same.append(f"{table} absent in both (an uncoupled run)")
            elif not (pa.exists() and pb.exists()):
                same.append(f"{table} missing")
                bad += 1
            elif pa.read_bytes() != pb.read_bytes():
                same.append(f"{table} DIFFERS at {first_difference(pa, pb)}")
                bad += 1
            else:
                same.append(f"{table} identical ({len(pa.read_bytes().splitlines()) - 1} rows)")
        print(f"{name}: " + "; ".join(same), flush=True)
    print(f"{len(cases)} scenes, {bad} table(s) differ; runs in {out}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
