#!/usr/bin/env bash
# Runs a libFuzzer target (fuzz/README.md) with its corpus for a given time, one process.
#   bench/fuzz/run.sh TARGET SECONDS     TARGET = fuzz_solid_request | fuzz_fluid_request |
#   bench/fuzz/run.sh all SECONDS                 fuzz_scene | fuzz_gmsh (the fuzz_ prefix is optional)
#   bench/fuzz/run.sh merge TARGET       minimise: fuzz/corpus/TARGET + new inputs -> a fresh
#                                        folder (-merge=1), which then replaces fuzz/corpus/TARGET
# Configures/builds the `fuzz` preset (build-fuzz/) when needed. New inputs go to
# build-fuzz/fuzz-work/TARGET/new (the repository corpus is only read); crashes, timeouts and
# leaks to build-fuzz/fuzz-work/TARGET/artifacts/. Environment: FSI_FUZZ_RUNS (max executions,
# default 10000000), FSI_FUZZ_TIMEOUT (s per input, default 2), FSI_FUZZ_BUILD_JOBS (default 1).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BUILD=$ROOT/build-fuzz
ALL=(fuzz_solid_request fuzz_fluid_request fuzz_scene fuzz_gmsh)

usage() { sed -n '2,10p' "$0" >&2; exit 1; }
[[ $# -eq 2 ]] || usage
norm() { local t=$1; [[ $t == fuzz_* ]] || t=fuzz_$t; for a in "${ALL[@]}"; do [[ $a == "$t" ]] && { echo "$t"; return; }; done; echo "unknown target '$1'" >&2; exit 1; }

build() {
  if [[ ! -f $BUILD/build.ninja ]]; then (cd "$ROOT" && cmake --preset fuzz >/dev/null); fi
  cmake --build "$BUILD" -j"${FSI_FUZZ_BUILD_JOBS:-1}" --target "$@" | tail -1
}

max_len() { case $1 in fuzz_gmsh) echo 12000;; fuzz_scene) echo 4096;; *) echo 6000;; esac; }

run_one() {
  local t=$1 secs=$2 work=$BUILD/fuzz-work/$1
  mkdir -p "$work/new" "$work/artifacts"
  local dict=() ; [[ -f $ROOT/fuzz/dict/$t.dict ]] && dict=(-dict="$ROOT/fuzz/dict/$t.dict")
  echo "== $t: ${secs} s (at most ${FSI_FUZZ_RUNS:-10000000} executions)"
  local before; before=$(ls "$work/artifacts" | wc -l)
  set +e
  "$BUILD/bin/$t" "$work/new" "$ROOT/fuzz/corpus/$t" "${dict[@]}" -max_total_time="$secs" \
    -runs="${FSI_FUZZ_RUNS:-10000000}" -timeout="${FSI_FUZZ_TIMEOUT:-2}" -rss_limit_mb=2048 \
    -max_len="$(max_len "$t")" -print_final_stats=1 -artifact_prefix="$work/artifacts/" \
    >"$work/log" 2>&1
  local rc=$?
  set -e
  local last; last=$(grep -E '^#[0-9]+' "$work/log" | tail -1 || true)
  echo "   exit code $rc; last status: $last"
  grep -E 'stat::number_of_executed_units|stat::peak_rss_mb' "$work/log" | sed 's/^/   /' || true
  echo "   corpus: $(ls "$ROOT/fuzz/corpus/$t" | wc -l) repository files + $(ls "$work/new" | wc -l) new in $work/new"
  echo "   artifacts (crash-/timeout-/leak-/oom-): $(( $(ls "$work/artifacts" | wc -l) - before )) new, in $work/artifacts"
  grep -E '^==[0-9]+==ERROR|runtime error|^fuzz|SUMMARY' "$work/log" | head -5 | sed 's/^/   /' || true
  echo "   log: $work/log"
}

merge_one() {
  local t=$1 work=$BUILD/fuzz-work/$1 fresh
  fresh=$(mktemp -d "$BUILD/fuzz-work/$t.merge.XXXX")
  mkdir -p "$work/new"
  "$BUILD/bin/$t" -merge=1 -max_len="$(max_len "$t")" -timeout="${FSI_FUZZ_TIMEOUT:-2}" "$fresh" \
    "$ROOT/fuzz/corpus/$t" "$work/new" >"$work/merge.log" 2>&1
  grep -E 'MERGE-OUTER: [0-9]+ new files' "$work/merge.log" || tail -3 "$work/merge.log"
  # libFuzzer names the kept files by the sha1 of their content: give kept repository files
  # back their names, and keep every regression input (regress_*) even if it adds no coverage.
  local f sum
  for f in "$ROOT/fuzz/corpus/$t"/*; do
    sum=$(sha1sum "$f" | cut -d' ' -f1)
    if [[ -f $fresh/$sum ]]; then mv "$fresh/$sum" "$fresh/$(basename "$f")";
    elif [[ $(basename "$f") == regress_* ]]; then cp "$f" "$fresh/"; fi
  done
  rm -rf "$ROOT/fuzz/corpus/$t" && mv "$fresh" "$ROOT/fuzz/corpus/$t" && chmod 755 "$ROOT/fuzz/corpus/$t"
  rm -rf "$work/new" && mkdir -p "$work/new"
  echo "$t: $(ls "$ROOT/fuzz/corpus/$t" | wc -l) files, $(du -sb "$ROOT/fuzz/corpus/$t" | cut -f1) bytes"
}

case $1 in
  merge) t=$(norm "$2"); build "$t"; merge_one "$t";;
  all) build "${ALL[@]}"; for t in "${ALL[@]}"; do run_one "$t" "$2"; done;;
  *) t=$(norm "$1"); build "$t"; run_one "$t" "$2";;
esac
