"""fsi_study: parameter studies over `fsi run`.

  fsi_study.py run STUDY.yaml --out DIR [--jobs N] [--fsi PATH]   run (or resume) a sweep
               [--set K=V ...] [--dry-run] [--executor local|dask] [--scheduler tcp://H:P] [--shared-dir D]
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
import subprocess
import sys
import time
from pathlib import Path

import yaml

from .analysis import analyse, print_counts
from .plots import cmd_plot
from .runner import Runner
from .spec import GridSource, Study, build_sources, reference_spec
from .check import check_overrides, check_study, fsi_has_check
from .util import REPO, StudyError, clean_value, read_json


def apply_sets(study, sets):
    """`--set key=value` (repeatable): an override of every run, like the study's `fixed`."""
    out = {}
    for s in sets or []:
        if "=" not in s:
            raise StudyError(f"--set {s}: expected key=value")
        k, v = (x.strip() for x in s.split("=", 1))
        if not k:
            raise StudyError(f"--set {s}: empty key")
        if k in study.vary or any(k in g for g in study.zip) or k in study.derived:
            raise StudyError(f"--set {k}: the study varies or derives '{k}'; --set applies to every run")
        try:
            val = yaml.safe_load(v) if v != "" else ""
        except yaml.YAMLError:
            val = v
        out[k] = clean_value(val)
    study.fixed.update(out)
    return out


def first_specs(study):
    """The specs that carry every override key of the study: the first run (the first of each
    source) and the reference run."""
    sources, _ = build_sources(study)
    specs = []
    for src in sources:
        s = src.next()
        if s is not None:
            specs.append(s)
            break
    ref = reference_spec(study)
    if ref and not ref.get("shared"):
        specs.append(ref)
    return specs


def dry_run(study, out, sources, n, check_how, jobs):
    from .. import catalog
    measured = catalog.load_catalog()
    scene = Path(study.scene).stem
    bis = (study.stability or {}).get("bisection")
    print(f"study '{study.name}' (dry run, nothing is run): {n} {'bisection groups' if bis else 'runs'} of "
          f"{study.scene}; keys checked ({check_how})")
    i = 0
    for src in sources:
        while True:
            s = src.next()
            if s is None:
                break
            i += 1
            overrides = {k: yaml.safe_load(v) for k, v in (x.split("=", 1) for x in s["sets"])}
            e = catalog.estimate(scene, study.scene_values, overrides, measured, catalog.fork_time(study.fork))
            print(f"{i:4d}  {out / 'runs' / s['name']}")
            print("      " + " ".join(f"--set {x}" for x in s["sets"]))
            print(f"      about {catalog.duration(min(e, study.time_limit))}" if e is not None else
                  "      (no estimate: the scene has no measured wall time)")
            if bis:  # only the first value of each bisection is known before running
                print(f"      (bisection of {study.stability['parameter']}: further values follow the outcomes)")
                break
            src.done(s, {"outcome": "completed"})
    runs, total, unknown, how = catalog.study_estimate(study, measured)
    if total is None:
        print(f"estimate: none ({scene} has no measured wall time in {catalog.CATALOG}; bench/catalog.py measure {scene})")
    else:
        print(f"estimate: {catalog.duration(total)} for {runs} run(s) one after the other"
              f"{' (bisection: worst case)' if bis else ''}, about {catalog.duration(total / jobs)} with --jobs {jobs}"
              f" (each run capped at the time limit {study.time_limit:g} s; scaled from the scene's measured "
              f"time per step{'; ' + str(unknown) + ' run(s) not counted' if unknown else ''})")
    return 0


def check_every_case(study, fsi, sets):
    """Every value of every varied key on top of the fixed ones (`fsi check STUDY`): a study with
    any invalid case stops here, before anything runs."""
    if not fsi_has_check(fsi):
        return
    scene_sets = [s for s in (sets or []) if "." in s.split("=", 1)[0]]
    problems, _, _ = check_study(study.path, fsi, scene_sets)
    if problems:
        raise StudyError("the study has invalid cases; nothing was run:\n" + "\n".join(problems))


def cmd_check(args):
    """`fsi check STUDY`: "OK: ..." on stdout and 0, or the problems at the study's lines on stderr and 1."""
    fsi = args.fsi or os.environ.get("FSI_BIN") or str(REPO / "build" / "bin" / "fsi")
    problems, keys, scene = check_study(args.study, fsi, args.set)
    if problems:
        print("\n".join(problems), file=sys.stderr)
        return 1
    print(f"OK: {args.study} (scene {scene}, {keys} keys checked)")
    return 0


def make_runner(args, study, out, fsi, jobs):
    if args.executor == "local":
        if args.scheduler or args.shared_dir:
            raise StudyError("--scheduler and --shared-dir need --executor dask")
        return Runner(study, out, fsi, jobs, quiet=args.quiet)
    from .executors import DaskRunner
    return DaskRunner(study, out, fsi, jobs, quiet=args.quiet, scheduler=args.scheduler,
                      shared_dir=args.shared_dir, retries=args.retries)


def cmd_run(args):
    study = Study(args.study, fork=args.fork or None)
    study.require_fork()
    if not args.out:
        args.out = os.path.join("runs", "study_" + Path(args.study).stem)
        print(f"fsi_study: results in {args.out} (choose the folder with --out)", flush=True)
    out = Path(args.out).resolve()
    cli_sets = apply_sets(study, args.set)
    fsi = args.fsi or os.environ.get("FSI_BIN") or str(REPO / "build" / "bin" / "fsi")
    if not os.access(fsi, os.X_OK):
        raise StudyError(f"fsi executable not found: {fsi} (build it, or pass --fsi)")
    fsi = os.path.abspath(fsi)
    check_how = check_overrides(study, first_specs(study), fsi, cli_sets)
    check_every_case(study, fsi, args.set)
    jobs = max(1, args.jobs or os.cpu_count() or 1)
    sources, n = build_sources(study)
    ref = reference_spec(study)
    if ref and not ref.get("shared"):
        sources.insert(0, GridSource([ref]))
        n += 1
    if args.dry_run:
        return dry_run(study, out, sources, n, check_how, jobs)
    out.mkdir(parents=True, exist_ok=True)
    copy = dict(study.raw)
    copy["scene"] = str(study.scene)  # the copy works from DIR (plot, analyse)
    if study.fork:
        copy["from"] = str(study.fork)
    if cli_sets:  # the copy names the runs as they were run (analyse)
        copy["fixed"] = dict(study.fixed)
    (out / "study.yaml").write_text(f"# copy of {study.path}\n" + yaml.safe_dump(copy, sort_keys=False))
    runner = make_runner(args, study, out, fsi, jobs)
    runner.total_hint = n if not (study.stability or {}).get("bisection") else 0
    where = f"{jobs} at a time" if args.executor == "local" else runner.describe()
    print(f"study '{study.name}': {n} {'groups' if runner.total_hint == 0 else 'runs'} of {study.scene}, "
          f"{where}, time limit {study.time_limit:g} s, results in {out}", file=sys.stderr)
    t0 = runner.t0 = time.monotonic()
    interrupted = False

    def on_term(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGTERM, on_term)
    try:
        try:
            runner.execute(sources)
        except KeyboardInterrupt:
            interrupted = True
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            print(f"interrupted: stopping {len(runner.running)} running run(s)", file=sys.stderr)
            runner.kill_all("interrupted")
        finally:
            signal.signal(signal.SIGTERM, old)
        counts, stab = analyse(study, out, runner.ordered_results(), ref)
        print(f"{runner.started} run(s) started, {runner.resumed} done before, {time.monotonic() - t0:.1f} s",
              file=sys.stderr)
        print_counts(counts, stab, out)
        if hasattr(runner, "report"):
            runner.report(out)
    finally:
        if hasattr(runner, "close"):
            runner.close()
    if interrupted:
        return 130
    if args.plot:
        from .plots import cmd_plot
        cmd_plot(argparse.Namespace(dir=str(out)))
    # Every case failed: none could run (a configuration error, a dead peer, a crash, a lost
    # worker). Divergence and time limits are answers of a study, not failures of it.
    no_run = counts["failed"] + counts["crashes"]
    if counts["cases"] and no_run == counts["cases"]:
        print(f"fsi_study: every case failed ({counts['failed']} failed, {counts['crashes']} crashed): "
              f"see the reason column of {out}/results.csv", file=sys.stderr)
        return 1
    return 0


def cmd_analyse(args):
    out = Path(args.dir).resolve()
    study = Study(out / "study.yaml" if not args.study else args.study)
    runner = Runner(study, out, "", 1, quiet=True)
    sources, _ = build_sources(study)
    ref = reference_spec(study)
    for s in ([ref] if ref and not ref.get("shared") else []):  # first, as `run` hands it out first
        m = read_json(out / "runs" / s["name"] / "study_run.json")
        if m:
            runner.record(s, m)
    for src in sources:  # grids: every spec; bisection: replay from the markers
        while not src.finished():
            s = src.next()
            if s is None:
                break
            m = read_json(out / "runs" / s["name"] / "study_run.json")
            if not m:
                break
            src.done(s, runner.record(s, m))
    counts, stab = analyse(study, out, runner.results, ref)
    print_counts(counts, stab, out)
    return 0


def cmd_list(args):
    from .. import catalog
    return catalog.main((["--json"] if args.json else []) + (["--catalog", args.catalog] if args.catalog else []))


def main(argv=None):
    ap = argparse.ArgumentParser(prog="fsi_study.py", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run (or resume) a study")
    r.add_argument("study")
    r.add_argument("--out", default="", help="study folder (default: runs/study_<study file name without .yaml>); "
                   "a folder of the same study is resumed")
    r.add_argument("--jobs", type=int, default=0, help="parallel runs (default: number of cores); with --executor dask and no --scheduler: the LocalCluster's workers")
    r.add_argument("--fsi", default="", help="the fsi executable (default: build/bin/fsi or $FSI_BIN)")
    r.add_argument("--quiet", action="store_true", help="no line per run")
    r.add_argument("--plot", action="store_true", help="at the end, the study's PNGs into --out (as `plot DIR`)")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="an override of every run, like the study's `fixed` (repeatable)")
    r.add_argument("--from", dest="fork", default="", metavar="RUN_OR_CHECKPOINT",
                   help="every run forks from this run's newest checkpoint (replaces the study's `from`)")
    r.add_argument("--dry-run", action="store_true",
                   help="check the keys, list the runs (folder and overrides) and run nothing")
    r.add_argument("--executor", choices=("local", "dask"), default="local",
                   help="local: process trees here (default); dask: one Dask task per run")
    r.add_argument("--scheduler", default="", metavar="tcp://HOST:PORT",
                   help="with --executor dask: a running Dask scheduler (default: a LocalCluster of --jobs "
                        "single-threaded workers on 127.0.0.1)")
    r.add_argument("--shared-dir", default="", metavar="DIR",
                   help="with --executor dask: the study folder as the workers see it (they write the run "
                        "folders there; default: they send them back)")
    r.add_argument("--retries", type=int, default=2,
                   help="with --executor dask: submissions of a run again after Dask gave up on it "
                        "(KilledWorker: its workers died); default 2")
    p = sub.add_parser("plot", help="PNGs from DIR/results.csv")
    p.add_argument("dir")
    c = sub.add_parser("check", help="every case of a study against the scene schema (fsi check STUDY)")
    c.add_argument("study")
    c.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    c.add_argument("--fsi", default="")
    ls = sub.add_parser("list", help="the scenes and studies of this checkout with their measured wall times")
    ls.add_argument("--json", action="store_true")
    ls.add_argument("--catalog", default="")
    a = sub.add_parser("analyse", help="recompute DIR/results.* from the runs on disk, running nothing")
    a.add_argument("dir")
    a.add_argument("--study", default="")
    args = ap.parse_args(argv)
    try:
        return {"run": cmd_run, "plot": cmd_plot, "analyse": cmd_analyse, "list": cmd_list, "check": cmd_check}[args.cmd](args)
    except StudyError as e:
        print(f"fsi_study: {e}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output piped into `head`: stop quietly, as other tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


if __name__ == "__main__":
    sys.exit(main())
