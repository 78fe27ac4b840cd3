#!/usr/bin/env python3
"""`fsi check`: every key of every section against the scene schema, without meshing or
starting a process; `fsi run` checks first; docs/scene-reference.md is current.

    test_check.py --bin BUILD/bin --source SRC --case NAME
"""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

ARGS = None


def fsi(*args, env=None, cwd=None):
    """Runs build/bin/fsi; returns (exit code, stdout, stderr, seconds)."""
    t0 = time.monotonic()
    p = subprocess.run([os.path.join(ARGS.bin, "fsi"), *args], capture_output=True, text=True, timeout=60,
                       env=env, cwd=cwd or ARGS.source)
    return p.returncode, p.stdout, p.stderr, time.monotonic() - t0


def place(path, text):
    """'path:line:col' of the first occurrence of `text` in the file."""
    with open(path) as f:
        for i, line in enumerate(f, 1):
            col = line.find(text)
            if col >= 0:
                return f"{path}:{i}:{col + 1}"
    raise AssertionError(f"{text!r} not in {path}")


def edited(tmp, scene, replacements, name=None):
    """A copy of configs/SCENE in tmp with (old, new) replacements (each must match once)."""
    with open(os.path.join(ARGS.source, "configs", scene)) as f:
        text = f.read()
    for old, new in replacements:
        assert text.count(old) == 1, (scene, old, text.count(old))
        text = text.replace(old, new)
    path = os.path.join(tmp, name or scene)
    with open(path, "w") as f:
        f.write(text)
    return path


def expect(args, code, stdout="", stderr="", **kw):
    got = fsi(*args, **kw)
    assert (got[0], got[1], got[2]) == (code, stdout, stderr), \
        f"fsi {' '.join(args)}:\n  expected exit {code}\n{stdout}{stderr}\n  got exit {got[0]}\n{got[1]}{got[2]}"
    return got


def shipped():
    """Every scene in configs/ and every study in studies/ passes (how fast: bench/fsi/check_speed.py,
    not here: a test does not depend on the machine's speed)."""
    files = sorted(glob.glob("configs/*.yaml", root_dir=ARGS.source)) + \
        sorted(glob.glob("studies/*.yaml", root_dir=ARGS.source))
    assert len(files) > 20, files
    slowest = 0.0
    for f in files:
        code, out, err, seconds = fsi("check", f)
        assert code == 0 and err == "" and out.startswith(f"OK: {f} (") and out.endswith(" keys checked)\n"), \
            (f, code, out, err)
        slowest = max(slowest, seconds)
    print(f"{len(files)} files OK, slowest {slowest:.3f} s")


def solver_typos():
    """A typo in a solver key is found at once, with file:line:col and the suggestion, without meshing."""
    with tempfile.TemporaryDirectory() as tmp:
        cache = os.path.join(tmp, "cache")
        os.mkdir(cache)
        env = dict(os.environ, FSI_MESH_CACHE=cache, XDG_CACHE_HOME=cache, HOME=cache)
        scene = edited(tmp, "fsi3.yaml", [("nonlinear: {max_iterations: 1,", "nonlinear: {max_iteratons: 1,"),
                                          ("  stabilisation: {supg: true,", "  stabilisation: {supg: 1.5,")])
        _, _, _, seconds = expect(["check", scene], 1, "",
                                  f"{place(scene, 'max_iteratons')}: unknown key 'fluid.nonlinear.max_iteratons' "
                                  "(did you mean 'max_iterations'?)\n"
                                  f"{place(scene, 'supg: 1.5')}: 'fluid.stabilisation.supg' must be a boolean "
                                  "(true/false), got '1.5'\n", env=env)
        assert os.listdir(cache) == [], os.listdir(cache)  # nothing meshed (the speed: bench/fsi/check_speed.py)
        # A key of the other model, and of the other element.
        expect(["check", "configs/fsi3.yaml", "--set", "solid.mass=1", "--set", "fluid.stabilisation.grad_div=1"], 1,
               "", "configs/fsi3.yaml (--set solid.mass=1): unknown key 'solid.mass' for solid.model 'fem' (it is a "
               "key of solid.model 'sdof')\n"
               "configs/fsi3.yaml (--set fluid.stabilisation.grad_div=1): 'fluid.stabilisation.grad_div' is only "
               "used when 'fluid.element' is p2p1\n", env=env)
        # fsi run refuses it before starting anything (no server, no mesh); the summary says why.
        out = os.path.join(tmp, "run")
        _, _, _, seconds = expect(["run", scene, "--out", out], 1, "",
                                  f"{place(scene, 'max_iteratons')}: unknown key 'fluid.nonlinear.max_iteratons' "
                                  "(did you mean 'max_iterations'?)\n"
                                  f"{place(scene, 'supg: 1.5')}: 'fluid.stabilisation.supg' must be a boolean "
                                  "(true/false), got '1.5'\n", env=env)
        assert os.listdir(cache) == [], (seconds, os.listdir(cache))
        # A refused scene writes nothing: the corrected one runs into the same --out.
        assert not os.path.exists(out), os.listdir(out)
        print(f"typos reported in {seconds:.3f} s, mesh cache empty, nothing written to --out")


def misspelt_required():
    """A misspelt required key is unknown AND the required one is missing, at the misspelt key's line."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = edited(tmp, "fsi3.yaml", [("  material: {law", "  materal: {law")])
        expect(["check", scene], 1, "", f"{place(scene, 'materal')}: unknown key 'solid.materal' (did you mean "
               "'material'?); the required key 'solid.material' is missing\n")
        scene = edited(tmp, "sdof_model.yaml", [("  mass: 1.0", "  mas: 1.0"), ("  model: sdof ", "  modle: sdof ")])
        expect(["check", scene], 1, "", f"{place(scene, 'modle')}: unknown key 'solid.modle' (did you mean 'model'?); "
               "the required key 'solid.model' is missing (one of sdof, fem)\n")
        scene = edited(tmp, "sdof_model.yaml", [("  mass: 1.0", "  mas: 1.0")])
        expect(["check", scene], 1, "", f"{place(scene, 'mas: 1.0')}: unknown key 'solid.mas' (did you mean 'mass'?); "
               "the required key 'solid.mass' is missing\n")
        # Missing without a look-alike: at the section's line.
        scene = edited(tmp, "sdof_model.yaml", [("  mass: 1.0", "  # no mass")])
        expect(["check", scene], 1, "", f"{place(scene, 'solid:')}: 'solid.mass' is required but missing\n")


def wrong_type():
    with tempfile.TemporaryDirectory() as tmp:
        scene = edited(tmp, "thick_beam.yaml", [("  dt: ", "  dt: fast #")])
        expect(["check", scene], 1, "", f"{place(scene, 'dt: fast')}: 'time.dt' must be a number, got 'fast'\n")
    expect(["check", "configs/csm1.yaml", "--set", "solid.mesh.elements=[320]", "--set", "solid.clamp={a: 1}"], 1, "",
           "configs/csm1.yaml (--set solid.mesh.elements=[320]): 'solid.mesh.elements' must be a list of 2 "
           "integers, got a list\n"
           "configs/csm1.yaml (--set solid.clamp={a: 1}): 'solid.clamp' must be a name or a list of names, got a "
           "section\n")
    expect(["check", "configs/dfg_2d1.yaml", "--set", "fluid.scheme=stedy"], 1, "",
           "configs/dfg_2d1.yaml (--set fluid.scheme=stedy): 'fluid.scheme' must be one of bdf1, bdf2, steady, got "
           "'stedy' (did you mean 'steady'?)\n")


def out_of_range():
    with tempfile.TemporaryDirectory() as tmp:
        scene = edited(tmp, "csm1.yaml", [("poisson_ratio: 0.4", "poisson_ratio: 0.5")])
        expect(["check", scene], 1, "",
               f"{place(scene, 'poisson_ratio')}: 'solid.material.poisson_ratio' must be in (-1, 0.5), got '0.5'\n")
    expect(["check", "configs/sdof_model.yaml", "--set", "coupling.algorithm=1", "--set", "coupling.relaxation=2.5"],
           1, "", "configs/sdof_model.yaml:19:3: 'coupling.relaxation' (beta) must be in (0, 2) with Algorithm 1 "
           "(its stability limit 2 m_eff / (m_eff + m_a) is below 2)\n")
    expect(["check", "configs/sdof_model.yaml", "--set", "time.end=10.01"], 1, "",
           "configs/sdof_model.yaml:12:3: 'time.end' (10.01) must be a whole number of time steps dt = 0.02: "
           "end / dt = 500.5; use 10 (500 steps) or 10.02 (501 steps)\n")
    expect(["check", "configs/sdof_model.yaml", "--set", "units=furlongs"], 1, "",
           "configs/sdof_model.yaml (--set units=furlongs): 'units' must be one of SI, CGS, got 'furlongs'\n")
    expect(["check", "configs/fsi3.yaml", "--set", "fluid.umfpack_irstep=3", "--set", "time.checkpoint_keep=0"], 1,
           "", "configs/fsi3.yaml (--set time.checkpoint_keep=0): 'time.checkpoint_keep' must be >= 1, got '0'\n"
           "configs/fsi3.yaml (--set fluid.umfpack_irstep=3): 'fluid.umfpack_irstep' must be in [0, 2], got '3'\n")


def obstacles():
    """solid.obstacles: a negative contact gap or stiffness is refused at its line; the sdof solid has no
    contact and names the model that has."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = edited(tmp, "thin_beam.yaml", [("contact_gap: 0.008", "contact_gap: -0.008, stiffness: -1")])
        expect(["check", scene], 1, "",
               f"{place(scene, 'contact_gap')}: 'solid.obstacles[0].contact_gap' must be positive, got '-0.008'\n"
               f"{place(scene, 'stiffness')}: 'solid.obstacles[0].stiffness' must be positive, got '-1'\n")
        scene = edited(tmp, "sdof_model.yaml", [("  mass: 1.0 ", "  obstacles: [{point: [0, 0], normal: [0, 1], "
                                                 "contact_gap: 0.01}]\n  mass: 1.0 ")])
        expect(["check", scene], 1, "", f"{place(scene, 'obstacles')}: unknown key 'solid.obstacles' for solid.model "
               "'sdof' (it is a key of solid.model 'fem')\n")
    expect(["check", "configs/sdof_model.yaml", "--set",
            "solid.obstacles=[{point: [0, 0], normal: [0, 1], contact_gap: 0.01}]"], 1, "",
           "configs/sdof_model.yaml (--set solid.obstacles=[{point: [0, 0], normal: [0, 1], contact_gap: 0.01}]): "
           "unknown key 'solid.obstacles' for solid.model 'sdof' (it is a key of solid.model 'fem')\n")


def override_typo():
    """A --set with a misspelt key names the override."""
    expect(["check", "configs/sdof_model.yaml", "--set", "coupling.relaxtion=0.5"], 1, "",
           "configs/sdof_model.yaml (--set coupling.relaxtion=0.5): unknown key 'coupling.relaxtion' (did you "
           "mean 'relaxation'?)\n")
    expect(["check", "configs/sdof_model.yaml", "--set", "couplng.algorithm=1"], 1, "",
           "configs/sdof_model.yaml (--set couplng.algorithm=1): unknown section 'couplng' (did you mean "
           "'coupling'?)\n")
    expect(["check", "configs/sdof_model.yaml", "--set", "coupling.gamma_n1=100"], 0,
           "OK: configs/sdof_model.yaml (29 keys checked)\n")


def external_solver():
    """A scene whose solid section belongs to an external solid (its own keys): refused by a plain
    check, accepted with --solid-command (as fsi run --solid-command skips it), the rest still checked."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = edited(tmp, "sdof_model.yaml", [("solid:\n", "solid:\n  my_own_key: 3\n")])
        code, out, err, _ = fsi("check", scene)
        assert code == 1 and "unknown key 'solid.my_own_key'" in err, (code, out, err)
        code, out, err, _ = fsi("check", scene, "--solid-command", "python3 my_solid.py")
        assert code == 0 and err == "" and out.endswith("; solid left to the external solver)\n"), (code, out, err)
        code, out, err, _ = fsi("check", scene, "--solid-command", "python3 my_solid.py", "--set", "coupling.relaxtion=1")
        assert code == 1 and "unknown key 'coupling.relaxtion'" in err, (code, out, err)
    print("an external solid's section is its own; the other sections are still checked")


def study():
    """A study: its scene with `fixed` as overrides, every value of `vary` / `zip` and the names of `derived`,
    reported at the study's lines."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "s.yaml")
        with open(path, "w") as f:
            f.write(f"study: s\nscene: {ARGS.source}/configs/fsi3.yaml\nfixed:\n  fluid.mesh.sise: 0.04\n"
                    "  fluid.mesh.parameters: {hc: 0.006}\nvary:\n  coupling.algorithm: [1, 3]\n  beta: [1, 2]\n"
                    "zip:\n  - coupling.iterations.maxx: [3, 30]\nderived:\n  time.ned: \"10 * time_dt\"\n")
        expect(["check", path], 1, "",
               f"{path}:4:3: unknown key 'fluid.mesh.sise' (did you mean 'size'?)\n"
               f"{path}:7:27: 'coupling.algorithm' must be 1 or 2, got '3'\n"
               f"{path}:10:5: unknown key 'coupling.iterations.maxx' (did you mean 'max'?)\n"
               f"{path}:12:3: unknown key 'time.ned' (did you mean 'end'?)\n")
    code, out, err, _ = fsi("check", "studies/fsi3.yaml", "--set", "time.dt=0.005")
    assert (code, err) == (0, "") and out.startswith("OK: studies/fsi3.yaml (scene configs/fsi3.yaml, "), (out, err)


def reference_current():
    """docs/scene-reference.md is what `fsi check --reference` prints today."""
    code, out, err, _ = fsi("check", "--reference")
    assert code == 0 and err == "", err
    path = os.path.join(ARGS.source, "docs", "scene-reference.md")
    with open(path, "rb") as f:
        current = f.read()
    if current != out.encode():
        sys.exit("docs/scene-reference.md is not current with the scene-key declarations (the *_keys.cpp files); "
                 "regenerate it: build/bin/fsi check --reference > docs/scene-reference.md")
    print(f"docs/scene-reference.md current ({len(current)} bytes)")


CASES = {f.__name__: f for f in (shipped, solver_typos, misspelt_required, wrong_type, out_of_range, obstacles,
                                 override_typo, external_solver, study, reference_current)}

if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--source", required=True)
    parser.add_argument("--case", required=True, choices=sorted(CASES))
    ARGS = parser.parse_args()
    ARGS.bin = os.path.abspath(ARGS.bin)
    CASES[ARGS.case]()
