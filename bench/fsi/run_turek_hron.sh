#!/usr/bin/env bash
# Turek-Hron FSI1-3 with the real fluid and solid servers under the coupler.
#   bench/fsi/run_turek_hron.sh CASE [OUT] [extra fsi run args, e.g. --set time.end=4]
#     CASE: fsi1 | fsi2 | fsi3, or a variant scene such as fsi1_p2p1 (configs/CASE.yaml,
#     compared with the reference of the part before the first '_');  OUT default: runs/CASE
# Runs `fsi run configs/CASE.yaml`, then bench/fsi/th_stats.py (table vs the reference,
# iterations per step, wall-time split) and writes OUT/stats.json and OUT/CASE.png.
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
/usr/bin/python3 bench/fsi/th_stats.py "${case_name%%_*}" "$out" --json "$out/stats.json" --plot "$out/$case_name.png"
exit $status
