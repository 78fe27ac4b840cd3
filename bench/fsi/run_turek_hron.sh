#!/usr/bin/env bash
# Turek-Hron FSI1-3 with the real fluid and solid servers under the coupler.
#   bench/fsi/run_turek_hron.sh CASE [OUT] [extra fsi run args, e.g. --set time.end=4]
#     CASE: fsi1 | fsi2 | fsi3, or a variant scene such as fsi1_p2p1 (configs/CASE.yaml,
#     compared with the reference of the part before the first '_');  OUT default: runs/CASE
# Runs `fsi run configs/CASE.yaml`, then bench/fsi/th_stats.py (table vs the reference,
# iterations per step, wall-time split) and writes OUT/stats.json and OUT/CASE.png. A run with
# fewer than 3 whole periods of u_y (FSI2/FSI3) is said to be too short (exit 3), no table.
# FSI_BIN (default build/bin) selects the executables. Single-threaded BLAS/OpenMP waits
# (shared 2-core machine): see docs/fluid.md.
set -euo pipefail
cd "$(dirname "$0")/../.."
case_name=${1:?usage: $0 fsi1|fsi2|fsi3 [OUT] [fsi run args...]}
out=${2:-runs/$case_name}
shift $(( $# >= 2 ? 2 : 1 ))
bin=${FSI_BIN:-build/bin}
export OPENBLAS_NUM_THREADS=1 OMP_WAIT_POLICY=passive
status=0
"$bin/fsi" run "configs/$case_name.yaml" --out "$out" "$@" || status=$?
stats=0
/usr/bin/python3 bench/fsi/th_stats.py "${case_name%%_*}" "$out" --json "$out/stats.json" --plot "$out/$case_name.png" \
  || stats=$?
if [ "$stats" = 3 ]; then
  # th_stats refuses fewer than 3 whole periods of u_y: no table, rather than errors that mean nothing
  echo "run_turek_hron: the run in $out is too short for the periodic statistics (fewer than 3 whole periods" \
       "of u_y; FSI2 and FSI3 reach their periodic state after several seconds: --set time.end=...);" \
       "$out/$case_name.png shows the histories against the reference" >&2
fi
exit $(( status != 0 ? status : stats ))
