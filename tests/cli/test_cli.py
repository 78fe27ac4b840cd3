#!/usr/bin/python3
"""Users' side of the executables (ctest -L cli). Cases:

version           every executable's --version prints `NAME fsi-cosim VERSION (git HASH, BUILD_TYPE)`
                  with this build's CMake project version, build type and the source's git hash;
                  the servers, the coupler and bench_messaging add the protocol version of
                  proto/fsi/v1/coupling.proto.
install           `cmake --install BUILD --prefix TMP`, then TMP/bin/fsi run
                  TMP/share/fsi/configs/sdof_model.yaml: exit 0, 500 rows (= summary steps),
                  probes.csv identical to the build tree's run; `fsi study` of the installed fsi
                  uses TMP/share/fsi/tools/fsi_study.py.
fluid_standalone  a fluid-only scene (DFG 2D-1, coarse mesh) through `fsi run`: probes.csv
                  columns fluid.cd/cl/dp, time written as 12 significant digits, summary.json
                  (dofs, final, solver_iterations), OUT/fluid_server.log with the one progress
                  line format, C_D within 1 % of Schafer-Turek; `fluid_run` prints a deprecation
                  line and writes the same probes.csv.
Every process is bounded by a timeout; the temporary folder is removed on success.
"""
import argparse
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def run(cmd, timeout=120, **kw):
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=timeout, **kw)


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.reader(fh))


def protocol_version(source):
    m = re.search(r"PROTOCOL_VERSION_CURRENT\s*=\s*(\d+)", (source / "proto/fsi/v1/coupling.proto").read_text())
    return int(m.group(1))


def case_version(a, tmp):
    bindir = a.build / "bin"
    def built_from(h):
        """The hash names HEAD or one of its ancestors (others may commit after the build)."""
        if run(["git", "-C", a.source, "rev-parse", "--git-dir"]).returncode != 0:
            return h == "unknown"
        return re.fullmatch(r"[0-9a-f]{7,40}", h) is not None and \
            run(["git", "-C", a.source, "merge-base", "--is-ancestor", h, "HEAD"]).returncode == 0
    proto = protocol_version(a.source)
    with_protocol = {"coupler", "solid_server", "fluid_server", "bench_messaging"}
    names = ["fsi", "coupler", "solid_server", "fluid_server", "bench_messaging", "solid_bench", "fluid_run"]
    for name in names:
        exe = bindir / name
        if not exe.exists():
            check(name in ("solid_bench", "fluid_run"), f"{name}: built (optional ones may be missing)")
            continue
        p = run([exe, "--version"], timeout=20)
        lines = p.stdout.strip().splitlines()
        m = re.fullmatch(rf"{re.escape(name)} fsi-cosim {re.escape(a.version)} \(git (\S+), "
                         rf"{re.escape(a.build_type or 'no build type')}\)", lines[0] if lines else "")
        check(p.returncode == 0 and m is not None and built_from(m.group(1)),
              f"{name} --version: exit {p.returncode}, {lines[:1]} = NAME fsi-cosim {a.version} (git HASH of HEAD or "
              f"an ancestor, {a.build_type})")
        if name in with_protocol:
            check(lines[1:] == [f"protocol fsi.v1, version {proto}"], f"{name} --version: protocol line {lines[1:]}")
        else:
            check(len(lines) == 1, f"{name} --version: one line ({len(lines)})")


def case_install(a, tmp):
    prefix = tmp / "prefix"
    p = run([a.cmake, "--install", a.build, "--prefix", prefix], timeout=120)
    check(p.returncode == 0, f"cmake --install: exit {p.returncode} {p.stderr.strip()[-400:]}")
    for rel in ("bin/fsi", "bin/coupler", "bin/solid_server", "bin/fluid_server", "share/fsi/configs/sdof_model.yaml",
                "share/fsi/configs/meshes/dfg_cylinder.geo", "share/fsi/tools/fsi_study.py",
                "share/fsi/python/fsi/__init__.py", "share/fsi/python/fsi/study/cli.py", "share/fsi/studies/sdof_gamma.yaml"):
        check((prefix / rel).exists(), f"installed {rel}")
    fsi = prefix / "bin/fsi"
    out = tmp / "run_installed"
    # Run from an unrelated folder, so nothing is found relative to the working directory.
    p = run([fsi, "run", prefix / "share/fsi/configs/sdof_model.yaml", "--out", out], timeout=120, cwd=tmp)
    check(p.returncode == 0, f"installed fsi run sdof_model: exit {p.returncode} {p.stderr.strip()[-400:]}")
    if p.returncode == 0:
        table = rows(out / "probes.csv")
        summary = json.load(open(out / "summary.json"))
        check(len(table) - 1 == 500 and summary["steps"] == 500 and summary["status"] == "completed",
              f"installed run: {len(table) - 1} rows, summary steps {summary['steps']} ({summary['status']}) == 500")
        ref = tmp / "run_build"
        q = run([a.build / "bin/fsi", "run", a.source / "configs/sdof_model.yaml", "--out", ref], timeout=120)
        check(q.returncode == 0 and (ref / "probes.csv").read_bytes() == (out / "probes.csv").read_bytes(),
              "installed and build-tree runs write the same probes.csv")
    p = run([fsi, "--version"], timeout=20)
    check(p.returncode == 0 and p.stdout.startswith(f"fsi fsi-cosim {a.version} "), f"installed fsi --version: {p.stdout.strip()}")
    env = dict(os.environ, FSI_LOG_LEVEL="debug")
    p = run([fsi, "study", prefix / "share/fsi/studies/sdof_gamma.yaml", "--help"], timeout=60, env=env, cwd=tmp)
    tool = str(prefix / "share/fsi/tools/fsi_study.py")
    check(p.returncode == 0 and tool in p.stderr, f"installed fsi study uses {tool}: exit {p.returncode} "
          f"{(p.stderr.strip().splitlines() or [''])[0][:300]}")
    p = run([fsi, "list"], timeout=60, cwd=tmp)
    check(p.returncode == 0 and "fsi3_p2p1" in p.stdout and "not measured" not in p.stdout,
          f"installed fsi list: every scene with its measured wall time (exit {p.returncode})")


def case_list(a, tmp):
    """`fsi list --json`: every shipped scene and study, each scene with a measured wall time and
    its unknowns, each study with its number of runs and an estimate."""
    p = run([a.build / "bin/fsi", "list", "--json"], timeout=60)
    check(p.returncode == 0, f"fsi list --json: exit {p.returncode} {p.stderr.strip()[-300:]}")
    data = json.loads(p.stdout)
    scenes = {s["name"]: s for s in data["scenes"]}
    studies = {s["name"]: s for s in data["studies"]}
    shipped = {f.stem for f in (a.source / "configs").glob("*.yaml")}
    check(set(scenes) == shipped, f"every scene of configs/ listed ({len(scenes)} of {len(shipped)})")
    check(set(studies) == {f.stem for f in (a.source / "studies").glob("*.yaml")}, "every study of studies/ listed")
    unmeasured = [n for n, s in scenes.items() if not s["wall_s"] or s["wall_s"] <= 0]
    check(not unmeasured, f"every scene has a measured wall time (missing: {unmeasured})")
    no_unknowns = [n for n, s in scenes.items() if s["fluid"] in ("p1p1", "p2p1")
                   and not (s["measured"] or {}).get("fluid_unknowns")]
    check(not no_unknowns, f"every FEM fluid scene has its unknowns (missing: {no_unknowns})")
    check(all(s["description"] for s in scenes.values()), "every scene has a description")
    bad = {n: s.get("error") or "no estimate" for n, s in studies.items()
           if s.get("error") or not s.get("runs") or s.get("estimate_s") is None}
    check(not bad, f"every study is read, counted and estimated ({bad})")
    check(data["measured"] and data["measured"].get("machine"), f"the catalog names its machine: {data['measured']}")
    p = run([a.build / "bin/fsi", "list"], timeout=60)
    check(p.returncode == 0 and all(n in p.stdout for n in shipped), "fsi list prints every scene")


def case_fluid_standalone(a, tmp):
    bindir = a.build / "bin"
    scene = a.source / "configs/dfg_2d1.yaml"
    coarse = ["--set", "fluid.mesh.size=0.04", "--set", "fluid.mesh.parameters.hc=0.005"]
    out = tmp / "dfg"
    p = run([bindir / "fsi", "run", scene, "--out", out, *coarse], timeout=240)
    check(p.returncode == 0, f"fsi run dfg_2d1 (coarse): exit {p.returncode} {p.stderr.strip()[-600:]}")
    if p.returncode != 0:
        return
    table = rows(out / "probes.csv")
    header = table[0]
    check({"time", "fluid.cd", "fluid.cl", "fluid.dp", "fluid.drag", "fluid.lift"} <= set(header)
          and not any(c in header for c in ("cd", "cl", "dp")), f"probes.csv columns {header}")
    check(len(table) == 2 and table[1][0] == "1", f"one steady step, time written as '1' ({table[1][:1]})")
    values = dict(zip(header, table[1]))
    cd = float(values["fluid.cd"])
    check(abs(cd / 5.57953523384 - 1) < 0.01, f"C_D {cd:.5f} within 1 % of 5.57954")
    s = json.load(open(out / "summary.json"))
    check(s["status"] == "completed" and s["steps"] == 1, f"summary: {s['status']}, steps {s['steps']}")
    check(isinstance(s.get("dofs"), int) and s["dofs"] > 1000 and isinstance(s.get("nodes"), int)
          and isinstance(s.get("triangles"), int), f"summary sizes: dofs {s.get('dofs')}, nodes {s.get('nodes')}, "
          f"triangles {s.get('triangles')}")
    check(s.get("final", {}).get("fluid.cd") == float(values["fluid.cd"]), "summary final.fluid.cd = the last row")
    solves = int(float(values["fluid.nonlinear_iterations"]))
    check(s.get("solver_iterations") == solves and solves > 1,
          f"summary solver_iterations {s.get('solver_iterations')} = the step's Picard solves {solves}")
    log = out / "fluid_server.log"
    text = log.read_text() if log.exists() else ""
    progress = [ln for ln in text.splitlines() if "step 1/1 t=" in ln]
    check(len(progress) == 1 and re.search(r"\[fluid_server\] \[info\] step 1/1 t=1 iterations \d+ elapsed [\d.]+ s, "
                                           r"ETA 0\.0 s$", progress[0]) is not None,
          f"fluid_server.log: one progress line {progress}")
    check("completed 1 steps" in text and "fluid: " in text, "fluid_server.log holds the solver's and the runner's lines")
    check(not re.search(r"\] step \d+ t=[\d.]+/", text + p.stderr), "no second progress format (step t=T/END ...)")
    # Inside the step: a line per nonlinear iteration once the step has run for the interval
    # (2 s; 0 here), so a long steady solve is not silent.
    out3 = tmp / "dfg_progress"
    q = run([bindir / "fsi", "run", scene, "--out", out3, *coarse], timeout=240,
            env=dict(os.environ, FSI_PROGRESS_INTERVAL="0"))
    inside = re.findall(r"step 1/1 nonlinear iteration (\d+) change [\d.e+-]+ \(this step: [\d.]+ s so far\)",
                        (out3 / "fluid_server.log").read_text() if (out3 / "fluid_server.log").exists() else "")
    check(q.returncode == 0 and [int(i) for i in inside] == list(range(1, solves + 1)),
          f"progress inside the step: one line per nonlinear iteration 1..{solves} ({inside})")
    # The deprecated alias: a deprecation line, the same run.
    alias = bindir / "fluid_run"
    if alias.exists():
        out2 = tmp / "dfg_alias"
        q = run([alias, scene, "--out", out2, *coarse], timeout=240)
        check(q.returncode == 0 and "fluid_run is deprecated" in q.stderr and "fsi run" in q.stderr,
              f"fluid_run: exit {q.returncode}, deprecation line")
        check(q.returncode == 0 and (out2 / "probes.csv").read_bytes() == (out / "probes.csv").read_bytes(),
              "fluid_run writes the same probes.csv as fsi run")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--case", required=True, choices=["version", "install", "fluid_standalone", "list"])
    ap.add_argument("--build", type=Path, required=True)
    ap.add_argument("--source", type=Path, required=True)
    ap.add_argument("--version", required=True)
    ap.add_argument("--build-type", default="")
    ap.add_argument("--cmake", default="cmake")
    a = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix=f"fsi_cli_{a.case}_"))
    try:
        globals()["case_" + a.case](a, tmp)
    except subprocess.TimeoutExpired as e:
        check(False, f"timed out: {e.cmd}")
    print(f"{len(failures)} failure(s)" if failures else "all checks passed")
    if failures:
        print(f"kept {tmp}")
        sys.exit(1)
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
