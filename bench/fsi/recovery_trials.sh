#!/usr/bin/env bash
# Automatic recovery, acceptance trials: thick_beam (T = 2, a checkpoint every 5 steps);
# kill -9 of the fluid_server, then of the solid_server, at random steps, TRIALS times each;
# then the same with kill -STOP (the coupler's --timeout 3 notices the silent server).
# Every run must complete with probes.csv and iterations.csv identical to the uninterrupted
# run. Prints one line per trial (cause, step resumed from, seconds lost).
#   bench/fsi/recovery_trials.sh [TRIALS]      (default 10; about 15 minutes)
set -euo pipefail
cd "$(dirname "$0")/../.."
trials=${1:-10}
for case in recover_kill recover_stop; do
  FSI_RECOVERY_TRIALS=$trials /usr/bin/python3 tests/integration/test_resilience.py \
    --bin build/bin --proto build/python --source . --case "$case"
done
