#!/usr/bin/env python3
"""Nothing a user produced is changed by a command that then fails; a run can be extended.

Each refused command leaves every file of the run folder byte-identical (or creates nothing).
The runs are the SDOF model problem (configs/sdof_model.yaml: 500 steps, well under a second).

    test_data_safety.py --bin BUILD/bin --source SRC --case NAME
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile

ARGS = None
SCENE = "configs/sdof_model.yaml"


def fsi(*args):
    p = subprocess.run([os.path.join(ARGS.bin, "fsi"), *args], capture_output=True, text=True, timeout=120,
                       cwd=ARGS.source)
    return p.returncode, p.stdout + p.stderr


def snapshot(folder):
    """{relative path: sha256} of every file under `folder`."""
    out = {}
    for root, _, files in os.walk(folder):
        for name in files:
            path = os.path.join(root, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, folder)] = hashlib.sha256(f.read()).hexdigest()
    return out


def run_ok(*args):
    code, text = fsi("run", *args)
    assert code == 0, f"fsi run {' '.join(args)} exited {code}:\n{text}"
    return text


def refused_unchanged(out, args, expected_text, expected_code=1):
    before = snapshot(out)
    code, text = fsi("run", *args)
    assert code == expected_code, f"expected exit {expected_code}, got {code}:\n{text}"
    assert expected_text in text, f"expected {expected_text!r} in:\n{text}"
    after = snapshot(out)
    assert before == after, f"the folder changed: {sorted(set(before.items()) ^ set(after.items()))}"
    print(f"refused ({expected_text!r}); {len(before)} files byte-identical")
    return text


def resume_without_checkpoints(tmp):
    """The one cause, read from the run: checkpoints were off (not "or it stopped before its first")."""
    out = os.path.join(tmp, "run")
    run_ok(SCENE, "--out", out)
    text = refused_unchanged(out, [SCENE, "--out", out, "--resume"],
                             "wrote no checkpoints: it was started with time.checkpoint_every: 0")
    assert "before its first" not in text, text


def damaged_tables(tmp):
    """A resume or an extension whose probes.csv (or iterations.csv) lacks rows up to the checkpoint, or
    has a damaged row, is refused before anything is written: exit 1, the file named, every file of the
    folder byte-identical (summary.json, the logs, commands.json included)."""
    out = os.path.join(tmp, "run")
    run_ok(SCENE, "--out", out, "--set", "time.checkpoint_every=50", "--set", "time.end=4")  # 200 steps
    probes = os.path.join(out, "probes.csv")
    with open(probes) as f:
        lines = f.readlines()
    assert len(lines) == 201, len(lines)
    with open(probes, "w") as f:  # cut back to 120 rows: the checkpoint of step 200 needs 200
        f.writelines(lines[:121])
    extend = [SCENE, "--out", out, "--resume", "--set", "time.end=6"]
    refused_unchanged(out, extend, "probes.csv has 120 complete rows, the checkpoint needs 200")
    with open(probes, "w") as f:  # every row, one of them cut short
        f.writelines(lines[:60] + [lines[60].split(",")[0] + "\n"] + lines[61:])
    refused_unchanged(out, extend, "probes.csv line 61 has 1 fields")
    with open(probes, "w") as f:
        f.writelines(lines)
    iterations = os.path.join(out, "iterations.csv")
    with open(iterations) as f:
        kept = f.readlines()
    with open(iterations, "w") as f:
        f.writelines(kept[:10])
    refused_unchanged(out, extend, "iterations.csv has 9 complete rows")
    with open(iterations, "w") as f:
        f.writelines(kept)
    run_ok(*extend)  # the repaired folder extends


def resume_mismatched_scene(tmp):
    out = os.path.join(tmp, "run")
    run_ok(SCENE, "--out", out, "--set", "time.checkpoint_every=50", "--set", "time.end=4")
    refused_unchanged(out, [SCENE, "--out", out, "--resume", "--set", "solid.mass=2"],
                      "the scene differs from the one checkpoint")
    # Another scene file altogether: named first, not a list of every key that differs.
    refused_unchanged(out, ["configs/added_mass.yaml", "--out", out, "--resume"],
                      f"this folder was run with {SCENE} (scene 'sdof_model'), not configs/added_mass.yaml")
    # A completed run without a longer time.end: nothing to do (exit 0), nothing touched.
    refused_unchanged(out, [SCENE, "--out", out, "--resume"], "the run is complete", expected_code=0)


def invalid_scene(tmp):
    bad = os.path.join(tmp, "bad.yaml")
    with open(os.path.join(ARGS.source, SCENE)) as f:
        text = f.read()
    with open(bad, "w") as f:
        f.write(text.replace("  mass:", "  mas:", 1))
    fresh = os.path.join(tmp, "fresh")
    code, out = fsi("run", bad, "--out", fresh)
    assert code == 1 and "unknown key 'solid.mas'" in out, out
    assert not os.path.exists(fresh) or not os.listdir(fresh), f"a refused scene wrote {os.listdir(fresh)}"
    # The corrected scene then runs into the same folder without --force.
    run_ok(SCENE, "--out", fresh)
    # An invalid scene pointed at an existing run changes nothing in it.
    refused_unchanged(fresh, [bad, "--out", fresh, "--force"], "unknown key 'solid.mas'")
    print("a refused scene wrote nothing; the corrected one ran into the same --out")


def configure_error(tmp):
    """A run that stops while configuring (here a missing fluid.initial_state) computed nothing:
    the corrected run goes into the same --out without --force, a user's own file stays."""
    out = os.path.join(tmp, "beam")
    scene = "configs/thick_beam.yaml"
    code, text = fsi("run", scene, "--out", out, "--set", "time.end=0.04",
                     "--set", f"fluid.initial_state={tmp}/no_such.state")
    assert code == 1 and "'fluid.initial_state' file" in text and "does not exist" in text, f"exit {code}:\n{text}"
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    assert summary["status"] == "failed" and summary["steps"] == 0, summary
    with open(os.path.join(out, "notes.txt"), "w") as f:
        f.write("mine\n")
    run_ok(scene, "--out", out, "--set", "time.end=0.04")
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    assert summary["status"] == "completed" and summary["steps"] == 2, summary
    assert open(os.path.join(out, "notes.txt")).read() == "mine\n", "a user's file in --out was touched"
    # A run that computed steps is still protected.
    refused_unchanged(out, [scene, "--out", out, "--set", "time.end=0.04"], "is not empty")
    print("a run failed while configuring is replaced by the corrected one without --force; a completed one is not")


def extend(tmp):
    """--resume --set time.end=T2 continues a completed run (its --set overrides from the
    checkpoint); the tables equal those of one run to T2."""
    short, whole = os.path.join(tmp, "short"), os.path.join(tmp, "whole")
    sets = ["--set", "time.checkpoint_every=50", "--set", "coupling.relaxation=0.7", "--set", "coupling.iterations.max=3"]
    # t = 4.5: 225 steps, the last not on the checkpoint schedule (every 50): the final step's
    # checkpoint lets the extension continue from step 225 without computing a step again.
    run_ok(SCENE, "--out", short, *sets, "--set", "time.end=4.5")
    assert os.path.isdir(os.path.join(short, "checkpoints", "step_00000225")), os.listdir(os.path.join(short, "checkpoints"))
    run_ok(SCENE, "--out", short, "--resume", "--set", "time.end=6")
    with open(os.path.join(short, "summary.json")) as f:
        resumed = json.load(f)["resumed_from_step"]
    assert resumed == 225, f"the extension resumed from step {resumed}, not from the final step 225"
    run_ok(SCENE, "--out", whole, *sets, "--set", "time.end=6")
    for name in ("probes.csv", "iterations.csv"):
        with open(os.path.join(short, name), "rb") as a, open(os.path.join(whole, name), "rb") as b:
            assert a.read() == b.read(), f"{name}: the extended run differs from the run to t = 6"
    print("extended 4.5 -> 6 from the final step's checkpoint (step 225, none recomputed): probes.csv and "
          "iterations.csv byte-identical to one run to 6")


def study_invalid_case(tmp):
    """A study with one invalid value stops before running any case."""
    study = os.path.join(tmp, "study.yaml")
    with open(study, "w") as f:
        f.write(f"study: bad_value\nscene: {os.path.join(ARGS.source, SCENE)}\n"
                "vary:\n  coupling.relaxation: [0.5, -1.0]\n")
    out = os.path.join(tmp, "study")
    code, text = fsi("study", study, "--out", out)
    assert code != 0, f"a study with an invalid case exited 0:\n{text}"
    assert "nothing was run" in text and "relaxation" in text, text
    assert not os.path.exists(os.path.join(out, "runs")), "a case of the invalid study ran"
    print(f"refused before running (exit {code})")


CASES = {"damaged_tables": damaged_tables, "study_invalid_case": study_invalid_case, "resume_without_checkpoints": resume_without_checkpoints, "resume_mismatched_scene": resume_mismatched_scene,
         "invalid_scene": invalid_scene, "extend": extend, "configure_error": configure_error}


def main():
    global ARGS
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--source", required=True)
    parser.add_argument("--case", required=True, choices=sorted(CASES))
    ARGS = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        CASES[ARGS.case](tmp)


if __name__ == "__main__":
    main()
