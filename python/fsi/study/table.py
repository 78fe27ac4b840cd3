"""load_study(folder): one table of a study folder (fsi.load_study)."""
import csv
import json
from pathlib import Path

import numpy as np

# Columns that are always numbers (empty cells: NaN); every other column is converted when all
# of its non-empty cells are numbers (parameters, metrics).
_TEXT = {"name", "outcome", "status", "reason_kind", "reason"}


def _column(values, name):
    if name not in _TEXT:
        try:
            return np.array([float(v) if v not in ("", None) else np.nan for v in values], float)
        except (TypeError, ValueError):
            pass
    return np.array(["" if v is None else v for v in values], object)


def load_study(folder, frame=None):
    """One row per run of the study folder `folder` (written by `fsi study`): `name`, the varied
    parameters, `outcome`, `status`, `reason_kind`, `wall_time` (the run's own), `elapsed`
    (process, incl. start-up), `cpu_time` (user + system of the run's whole process tree),
    `steps`, `coupling_iterations`, every metric column, `is_reference` and `reason`.

    A pandas DataFrame when pandas is importable (or frame=True), else (or frame=False) a dict
    of numpy arrays (numbers as float with NaN for empty cells, text as object arrays)."""
    d = Path(folder)
    with open(d / "results.csv", newline="") as f:
        rows = list(csv.DictReader(f))
        cols = list(rows[0].keys()) if rows else []
    if not cols:
        with open(d / "results.csv", newline="") as f:
            cols = next(csv.reader(f), [])
    try:
        meta = json.loads((d / "results.json").read_text())
    except (OSError, ValueError):
        meta = {}
    runs = {r.get("name"): r for r in meta.get("runs", [])}
    cpu = []
    for r in rows:
        v = (runs.get(r["name"]) or {}).get("cpu_time")
        if v is None:  # older folders: the marker of the run
            try:
                v = json.loads((d / "runs" / r["name"] / "study_run.json").read_text()).get("cpu_time")
            except (OSError, ValueError):
                v = None
        cpu.append(v)
    table = {}
    for c in cols:
        if c == "reason":
            continue
        table[c] = _column([r[c] for r in rows], c)
        if c == "elapsed":
            table["cpu_time"] = _column(cpu, "cpu_time")
    if "cpu_time" not in table:
        table["cpu_time"] = _column(cpu, "cpu_time")
    ref = meta.get("reference_run")
    table["is_reference"] = np.array([bool(r["name"].startswith("reference-") or (ref and r["name"] == ref))
                                      for r in rows], bool)
    if "reason" in cols:
        table["reason"] = _column([r["reason"] for r in rows], "reason")
    if frame is None:
        try:
            import pandas  # noqa: F401
            frame = True
        except ImportError:
            frame = False
    if frame:
        import pandas as pd
        return pd.DataFrame(table)
    return table
