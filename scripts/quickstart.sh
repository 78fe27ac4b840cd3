#!/usr/bin/env bash
# Installs what is missing, builds (Release) and runs the default scene (the seed paper's
# appendix model problem, three processes on loopback). Results in runs/sdof_model/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release -j "$(nproc)"
build/bin/fsi run configs/sdof_model.yaml --out runs/sdof_model --force "$@"   # --force: the quickstart may run again
echo "results: runs/sdof_model/{summary.json,probes.csv,iterations.csv}"
