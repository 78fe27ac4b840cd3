#!/usr/bin/python3
"""fsi.section: the SDK's strict reader of a scene section (external solvers, the FEniCS solid):
types and ranges checked with the key's scene path in the message, unknown keys named."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from fsi.section import SceneError, Section  # noqa: E402

from checks import check, failures  # noqa: E402


def error(fn):
    try:
        fn()
    except SceneError as e:
        return str(e)
    return None


s = Section({"mass": "0.5e6", "k": 4, "mode": "fast", "points": [1, 2], "material": {"E": 1.0, "nu": 0.7},
             "typo": 1}, "solid")
check(s.number("mass", positive=True) == 5e5, "a YAML 1.1 string such as 0.5e6 reads as a number")
check(s.integer("k", minimum=1) == 4, "integer")
check(s.vector("points", 2) == [1.0, 2.0], "vector [x, y]")
check(error(lambda: s.vector("points", 3)) == "'solid.points' must be [x, y, z] (three finite numbers), got [1, 2]",
      "a 2-vector where a 3-vector is needed names the key")
check(error(lambda: s.choice("mode", "slow", ("slow", "steady"))) ==
      "'solid.mode' must be one of slow, steady, got 'fast'", "choice")
m = s.child("material")
check(m.number("E", positive=True) == 1.0, "child section")
check(error(lambda: m.number("nu", positive=True, minimum=-1)) is None, "in range")
check(error(lambda: m.number("G", required=True)) == "'solid.material.G' is required but missing",
      "a missing required key names its path")
check(error(lambda: s.check_all_used()) == "unknown key(s) in 'solid': typo",
      "check_all_used names the key nobody read")
check(error(lambda: Section([1, 2], "solid")) == "'solid' must be a mapping, got [1, 2]", "not a mapping")
check(issubclass(SceneError, ValueError), "SceneError is a ValueError")
sys.exit(1 if failures else 0)
