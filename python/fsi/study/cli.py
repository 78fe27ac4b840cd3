"""fsi_study: parameter studies over `fsi run`.

  fsi_study.py run STUDY.yaml --out DIR [--jobs N] [--fsi PATH]   run (or resume) a sweep
  fsi_study.py plot DIR                                           PNGs from DIR/results.csv
  fsi_study.py analyse DIR                                        recompute tables without running

A study file names a scene, fixed overrides, the parameters to vary (cartesian product of
lists, `zip` groups, derived expressions, a `where` filter), a per-run time limit, the probes
and a reference (a designated fine run, a closed form, or published values). Each run is one
`fsi run` process tree in DIR/runs/<name>; finished runs are not run again; a run past its
time limit is killed (its whole process tree) and classified "timeout". Results:
DIR/results.csv (one row per run), DIR/results.json, DIR/outcomes.json, DIR/stability.csv
when the study has a `stability` section. Every number written is finite or empty.
See docs/studies.md for every key.

Only the standard library, numpy, yaml, (for `plot`) matplotlib and (for `--executor dask`)
Dask distributed.
"""
import argparse
import os
import signal
import sys
import time
from pathlib import Path

import yaml

from .analysis import analyse, print_counts
from .plots import cmd_plot
from .runner import Runner
from .spec import GridSource, Study, build_sources, reference_spec
from .util import REPO, StudyError, read_json


def cmd_run(args):
    study = Study(args.study)
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    copy = dict(study.raw)
    copy["scene"] = str(study.scene)  # the copy works from DIR (plot, analyse)
    (out / "study.yaml").write_text(f"# copy of {study.path}\n" + yaml.safe_dump(copy, sort_keys=False))
    fsi = args.fsi or os.environ.get("FSI_BIN") or str(REPO / "build" / "bin" / "fsi")
    if not os.access(fsi, os.X_OK):
        raise StudyError(f"fsi executable not found: {fsi} (build it, or pass --fsi)")
    jobs = max(1, args.jobs or os.cpu_count() or 1)
    runner = Runner(study, out, os.path.abspath(fsi), jobs, quiet=args.quiet)
    sources, n = build_sources(study)
    ref = reference_spec(study)
    if ref and not ref.get("shared"):
        sources.insert(0, GridSource([ref]))
        n += 1
    runner.total_hint = n if not (study.stability or {}).get("bisection") else 0
    print(f"study '{study.name}': {n} {'groups' if runner.total_hint == 0 else 'runs'} of {study.scene}, "
          f"{jobs} at a time, time limit {study.time_limit:g} s, results in {out}", file=sys.stderr)
    t0 = time.monotonic()
    interrupted = False

    def on_term(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGTERM, on_term)
    try:
        runner.execute(sources)
    except KeyboardInterrupt:
        interrupted = True
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        print(f"interrupted: stopping {len(runner.running)} running run(s)", file=sys.stderr)
        runner.kill_all("interrupted")
    finally:
        signal.signal(signal.SIGTERM, old)
    counts, stab = analyse(study, out, runner.results, ref)
    print(f"{runner.started} run(s) started, {runner.resumed} done before, {time.monotonic() - t0:.1f} s",
          file=sys.stderr)
    print_counts(counts, stab, out)
    return 130 if interrupted else 0


def cmd_analyse(args):
    out = Path(args.dir).resolve()
    study = Study(out / "study.yaml" if not args.study else args.study)
    runner = Runner(study, out, "", 1, quiet=True)
    sources, _ = build_sources(study)
    ref = reference_spec(study)
    specs = ([ref] if ref and not ref.get("shared") else [])
    for src in sources:  # grids: every spec; bisection: replay from the markers
        while not src.finished():
            s = src.next()
            if s is None:
                break
            m = read_json(out / "runs" / s["name"] / "study_run.json")
            if not m:
                break
            src.done(s, runner.record(s, m))
    for s in specs:
        m = read_json(out / "runs" / s["name"] / "study_run.json")
        if m:
            runner.record(s, m)
    counts, stab = analyse(study, out, runner.results, ref)
    print_counts(counts, stab, out)
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(prog="fsi_study.py", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run (or resume) a study")
    r.add_argument("study")
    r.add_argument("--out", default="runs/study", help="study folder (default: runs/study)")
    r.add_argument("--jobs", type=int, default=0, help="parallel runs (default: number of cores)")
    r.add_argument("--fsi", default="", help="the fsi executable (default: build/bin/fsi or $FSI_BIN)")
    r.add_argument("--quiet", action="store_true", help="no line per run")
    p = sub.add_parser("plot", help="PNGs from DIR/results.csv")
    p.add_argument("dir")
    a = sub.add_parser("analyse", help="recompute DIR/results.* from the runs on disk, running nothing")
    a.add_argument("dir")
    a.add_argument("--study", default="")
    args = ap.parse_args(argv)
    try:
        return {"run": cmd_run, "plot": cmd_plot, "analyse": cmd_analyse}[args.cmd](args)
    except StudyError as e:
        print(f"fsi_study: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
