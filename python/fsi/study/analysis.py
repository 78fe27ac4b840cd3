"""Metrics of the runs against the reference, the stability table, the outcome counts and the
tables written to the study folder (results.csv, results.json, outcomes.json, stability.csv)."""
import csv
import os
import sys
from pathlib import Path

import numpy as np

from .forms import SCALAR_FORMS, SERIES_FORMS, evaluate
from .metrics import compare, compare_values, signal_metrics
from .util import finite, fmt_num, write_json


def read_probes(path):
    try:
        with open(path) as f:
            rows = list(csv.reader(f))
    except OSError:
        return None
    if len(rows) < 2:
        return None
    head = rows[0]
    data = {}
    for j, h in enumerate(head):
        col = []
        for r in rows[1:]:
            try:
                col.append(float(r[j]))
            except (ValueError, IndexError):
                col.append(float("nan"))
        data[h] = np.array(col)
    return data


def reference_series(study, out, ref_spec):
    """probe -> (t, y) of a reference run, or None."""
    if ref_spec is None:
        return None
    data = read_probes(Path(out) / "runs" / ref_spec["name"] / "probes.csv")
    if data is None or "time" not in data:
        return None
    return {p: (data["time"], data[p]) for p in study.probes if p in data}


def run_metrics(study, out, rec, ref_series):
    m = {}
    if rec["outcome"] != "completed" or not study.probes:
        return m
    data = read_probes(Path(out) / "runs" / rec["name"] / "probes.csv")
    if data is None or "time" not in data:
        return m
    ref = study.reference
    for p in study.probes:
        if p not in data:
            continue
        t, y = data["time"], data[p]
        if "run" in ref:
            if not ref_series or p not in ref_series:
                vals = compare(t, y, t, y, study.window, study.steady_fraction)
                vals = {k: v for k, v in vals.items() if k in ("steady", "mean", "amplitude", "frequency")}
            else:
                vals = compare(t, y, *ref_series[p], study.window, study.steady_fraction)
        elif "closed_form" in ref:
            form = (ref["closed_form"] or {}).get(p)
            if form is None:
                vals = signal_metrics(t, y, study.window, study.steady_fraction)
            else:
                tr = np.concatenate([[0.0], t]) if t[0] > 0 else t
                if form in SERIES_FORMS:
                    yr = SERIES_FORMS[form](rec["params"], tr)
                else:
                    yr = np.broadcast_to(np.asarray(evaluate(form, rec["params"], tr, f"closed form for {p}"), float),
                                         tr.shape)
                vals = compare(t, y, tr, yr, study.window, study.steady_fraction)
        elif "values" in ref:
            vals = compare_values(t, y, (ref["values"] or {}).get(p, {}), study.window, study.steady_fraction)
        else:
            vals = signal_metrics(t, y, study.window, study.steady_fraction)
        for k, v in vals.items():
            m[f"{p}.{k}"] = finite(v)
    return m


def stability_table(study, records):
    """Per (series..., x): largest parameter value whose run completed, the smallest above it that
    did not, and the closed form when named."""
    st = study.stability
    if not st:
        return []
    key, x = st["parameter"], st["x"]
    series = list(st.get("series", []))
    groups = {}
    for r in records:
        if r.get("is_reference"):
            continue
        g = tuple(r["params"].get(k) for k in series) + (r["params"].get(x),)
        others = tuple(sorted((k, v) for k, v in r["combo"].items() if k not in series and k not in (x, key)))
        groups.setdefault(g + others, []).append(r)
    rows = []
    for g, rs in sorted(groups.items(), key=lambda kv: tuple(str(v) for v in kv[0])):
        vals = sorted(rs, key=lambda r: float(r["params"][key]))
        ok = [float(r["params"][key]) for r in vals if r["outcome"] == "completed"]
        best = max(ok) if ok else None
        above = [float(r["params"][key]) for r in vals if r["outcome"] != "completed" and (best is None or
                                                                                     float(r["params"][key]) > best)]
        bad_below = [float(r["params"][key]) for r in vals if r["outcome"] != "completed" and best is not None and
                     float(r["params"][key]) < best]
        row = {k: v for k, v in zip(series + [x], g)}
        row.update({"runs": len(rs), "stable_max": best, "unstable_min": min(above) if above else None,
                    "monotonic": not bad_below})
        form = st.get("closed_form")
        if form:
            p = dict(rs[0]["params"])
            p.pop(key, None)
            v = SCALAR_FORMS[form](p) if form in SCALAR_FORMS else evaluate(form, p, what="stability.closed_form")
            row["closed_form"] = finite(v)
            row["closed_form_capped"] = finite(min(v, float(st.get("cap", 1.0)))) if finite(v) is not None else None
            if best is not None and row["closed_form"] is not None:
                row["error"] = best - row["closed_form_capped"]
                row["rel_error"] = row["error"] / row["closed_form_capped"] if row["closed_form_capped"] else None
        rows.append(row)
    return rows


def outcome_counts(records):
    c = {"cases": 0, "completed": 0, "diverged": 0, "diverged_by_reason": {}, "mesh_tangled": 0,
         "solver_failed": 0, "failed": 0, "failed_by_reason": {}, "timeouts": 0, "crashes": 0, "nan_cells": 0}
    for r in records:
        if r.get("is_reference"):
            continue
        c["cases"] += 1
        o = r["outcome"]
        if o == "completed":
            c["completed"] += 1
        elif o == "diverged":
            c["diverged"] += 1
            k = r["reason_kind"] or "other"
            c["diverged_by_reason"][k] = c["diverged_by_reason"].get(k, 0) + 1
        elif o == "mesh tangled":
            c["mesh_tangled"] += 1
        elif o == "solver failed":
            c["solver_failed"] += 1
        elif o == "failed":
            c["failed"] += 1
            k = r["reason_kind"] or "other"
            c["failed_by_reason"][k] = c["failed_by_reason"].get(k, 0) + 1
        elif o == "timeout":
            c["timeouts"] += 1
        elif o == "interrupted":
            c["interrupted"] = c.get("interrupted", 0) + 1
        else:
            c["crashes"] += 1
    return c


BASE_COLUMNS = ["name", "outcome", "status", "reason_kind", "stop_step", "stop_iteration", "exit_code", "wall_time",
                "elapsed", "steps", "coupling_iterations", "iterations_per_step"]


def write_tables(study, out, records, ref_rec):
    out = Path(out)
    param_keys = []
    for r in records:
        for k in r["combo"]:
            if k not in param_keys:
                param_keys.append(k)
    metric_keys = []
    for r in records:
        for k in r.get("metrics", {}):
            if k not in metric_keys:
                metric_keys.append(k)
    cols = ["name"] + param_keys + BASE_COLUMNS[1:] + metric_keys + ["reason"]
    rows = sorted(records, key=lambda r: (not r.get("is_reference"), r["name"]))
    tmp = out / "results.csv.tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in rows:
            line = []
            for c in cols:
                if c in param_keys:
                    v = r["combo"].get(c, r["params"].get(c))
                elif c in metric_keys:
                    v = r.get("metrics", {}).get(c)
                else:
                    v = r.get(c)
                line.append("" if v is None else (v if isinstance(v, str) else fmt_num(v)))
            w.writerow(line)
    os.replace(tmp, out / "results.csv")
    counts = outcome_counts(records)
    with open(out / "results.csv") as f:  # the promise: no NaN / inf cell, ever
        counts["nan_cells"] = sum(c.strip().lower() in ("nan", "-nan", "inf", "-inf", "+inf", "infinity")
                                  for row in csv.reader(f) for c in row)
    stab = stability_table(study, records)
    if stab:
        keys = list(stab[0].keys())
        for r in stab:
            for k in r:
                if k not in keys:
                    keys.append(k)
        with open(out / "stability.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(keys)
            for r in stab:
                w.writerow(["" if r.get(k) is None else fmt_num(r[k]) if not isinstance(r.get(k), str) else r[k]
                            for k in keys])

    def jclean(x):
        if isinstance(x, dict):
            return {k: jclean(v) for k, v in x.items() if not k.startswith("_")}
        if isinstance(x, (list, tuple)):
            return [jclean(v) for v in x]
        if isinstance(x, (bool, str)) or x is None:
            return x
        if isinstance(x, (int, np.integer)):
            return int(x)
        return finite(x)

    base = {k: v for k, v in study.base_params().items() if isinstance(v, (int, float, str, bool))}
    write_json(out / "results.json", jclean({
        "study": study.name, "description": study.description, "study_file": str(study.path),
        "scene": str(study.scene), "probes": study.probes, "reference": study.reference,
        "reference_run": ref_rec["name"] if ref_rec else None, "base_params": base,
        "varied": param_keys, "stability": study.stability, "stability_table": stab, "outcomes": counts,
        "runs": [{k: v for k, v in r.items() if k != "params"} for r in rows]}))
    write_json(out / "outcomes.json", jclean(counts))
    return counts, stab


def analyse(study, out, runner_results, ref_spec):
    records = list(runner_results.values())
    ref_rec = runner_results.get(ref_spec["name"]) if ref_spec else None
    if ref_rec:
        # A run of its own is not one of the sweep's cases; a shared one is (results.json names it).
        ref_rec["is_reference"] = not ref_spec.get("shared")
    ref_series = reference_series(study, out, ref_spec) if ref_rec and ref_rec["outcome"] == "completed" else None
    for r in records:
        r["metrics"] = run_metrics(study, out, r, ref_series)
    return write_tables(study, out, records, ref_rec)


def print_counts(counts, stab, out):
    print(f"study results in {out}/results.csv ({counts['cases']} cases)", file=sys.stderr)
    parts = [f"completed {counts['completed']}", f"diverged {counts['diverged']}"]
    if counts["diverged_by_reason"]:
        parts[-1] += " (" + ", ".join(f"{k}: {v}" for k, v in sorted(counts["diverged_by_reason"].items())) + ")"
    parts += [f"mesh tangled {counts['mesh_tangled']}", f"solver failed {counts['solver_failed']}",
              f"failed {counts['failed']}", f"timeouts {counts['timeouts']}", f"crashes {counts['crashes']}"]
    print("outcomes: " + ", ".join(parts), file=sys.stderr)
    for r in stab:
        print("stability: " + ", ".join(f"{k}={fmt_num(v) if not isinstance(v, str) else v}" for k, v in r.items()),
              file=sys.stderr)

