#!/usr/bin/python3
"""tools/atlas.py on a reduced atlas study (2 mass ratios x 3 schemes): the page and its plot are
written, every run's numbers on the page are those of results.csv, and the numbers are the
closed forms' (converged schemes at the monolithic solution, Algorithm 1 loosely coupled stable
below m_a = m and diverged far above it)."""
import subprocess

from common import FSI, SRC, check, results, work_dir

w = work_dir("/tmp/study_test_atlas")
study = w / "atlas_small.yaml"
study.write_text(f"""
extends: {SRC}/studies/atlas_added_mass.yaml
vary:
  fluid.added_mass: [0.1, 100]
zip:
  - scheme: [A1 loose, constant, iqn-ils parallel]
    coupling.algorithm: [1, 1, 1]
    coupling.robin_auto: [none, none, none]
    coupling.scheme: [serial, serial, parallel]
    coupling.acceleration: [constant, constant, iqn-ils]
    coupling.iterations.max: [1, 3000, 3000]
    coupling.iterations.tolerance: [0, 1.0e-10, 1.0e-10]
    beta: [1, 0, 0.5]
fixed: {{coupling.gamma_n1: 1, coupling.force_limit: 1.0e6, time.end: 0.05}}
""")
page = w / "docs" / "choosing-a-scheme.md"
p = subprocess.run(["/usr/bin/python3", str(SRC / "tools" / "atlas.py"), "run", "--out", str(w / "out"), "--page",
                    str(page), "--study", str(study), "--jobs", "2", "--fsi", FSI],
                   capture_output=True, text=True, timeout=100)
check(p.returncode == 0, f"atlas.py exited {p.returncode}: {p.stderr[-2000:]}")
check((w / "docs" / "img" / "atlas_added_mass.png").stat().st_size > 10000, "the plot is written")
text = page.read_text()
rows = results(w / "out")
check(len(rows) == 6, f"6 runs ({len(rows)})")


def fmt(v):
    import importlib.util
    spec = importlib.util.spec_from_file_location("atlas", SRC / "tools" / "atlas.py")
    atlas = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(atlas)
    return atlas.fmt(float(v))


for r in rows:
    err = fmt(r["solid.d_x.l2_rel"]) if r["outcome"] == "completed" else "-"
    line = (f"| {r['scheme']} | " + (r["outcome"] if r["outcome"] == "completed" else f"{r['outcome']} (") )
    found = [l for l in text.splitlines() if l.startswith(line)]
    check(len(found) >= 1, f"{r['scheme']} m_a {r['fluid.added_mass']}: its row is on the page")
    check(any(f"| {fmt(r['iterations_per_step'])} | {fmt(r['wall_time'])} | {err} |" in l for l in found),
          f"{r['scheme']} m_a {r['fluid.added_mass']}: iterations, wall and error are results.csv's")
    ma = float(r["fluid.added_mass"])
    if r["scheme"] != "A1 loose":
        check(r["outcome"] == "completed" and float(r["solid.d_x.l2_rel"]) < 1e-9,
              f"{r['scheme']} m_a {ma}: converged to the monolithic solution ({r['solid.d_x.l2_rel']})")
    else:
        check(r["outcome"] == ("completed" if ma < 1 else "diverged"),
              f"A1 loose m_a {ma}: {r['outcome']} (stable iff m_a < m)")
check(text.count("Recommended: ") == 2, "one recommendation per mass ratio")
check(f"tools/atlas.py run --out {w / 'out'} --study {study}" in text, "the page names its command")
print("atlas page: every run's numbers are results.csv's")
