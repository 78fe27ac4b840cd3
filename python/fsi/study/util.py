"""Constants, numbers, JSON files: shared by every module of fsi.study."""
import json
import math
import os
import re
from pathlib import Path

import numpy as np



def _repo():
    env = os.environ.get("FSI_SOURCE_DIR")
    if env:
        return Path(env).resolve()
    here = Path(__file__).resolve().parents[3]  # <repo>/python/fsi/study/util.py
    return here if (here / "configs").is_dir() else Path.cwd()


REPO = _repo()

STUDY_KEYS = {"extends", "study", "description", "scene", "from", "fixed", "vary", "zip", "derived", "where",
              "time_limit", "probes", "reference", "metrics", "stability", "plots"}
FINISHED = ("completed", "diverged", "failed")
ABBREV = {"coupling.algorithm": "alg", "coupling.gamma_n1": "g", "coupling.relaxation": "beta",
          "coupling.iterations.max": "kmax", "coupling.iterations.tolerance": "tol", "time.dt": "dt",
          "fluid.mesh.size": "h", "solid.mass": "m", "solid.stiffness": "k", "solid.damping": "c",
          "fluid.added_mass": "ma", "coupling.predictor": "pred",
          "coupling.acceleration": "acc"}


class StudyError(Exception):
    pass


# ----------------------------------------------------------------------------------------------
# Numbers
# ----------------------------------------------------------------------------------------------

def finite(x):
    """x as a float if finite, else None."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def fmt_num(x):
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    v = finite(x)
    if v is None:
        return ""
    return "%.10g" % v


def clean_value(v):
    """Stable representation of a parameter value (floats rounded to 12 significant digits)."""
    if isinstance(v, str) and re.fullmatch(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?", v.strip()):
        v = float(v)  # YAML 1.1 reads 1.0e9 (no exponent sign) as a string
    if isinstance(v, bool) or isinstance(v, int) or isinstance(v, str):
        return v
    if isinstance(v, (float, np.floating)):
        return float("%.12g" % float(v))
    if isinstance(v, np.integer):
        return int(v)
    return v


def set_value(v):
    """A value as text for `--set key=value`."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    return str(v)



def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def write_json(path, data):
    tmp = Path(str(path) + ".tmp")
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1, sort_keys=True, allow_nan=False)
        f.write("\n")
    os.replace(tmp, path)

