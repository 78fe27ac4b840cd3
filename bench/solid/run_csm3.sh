#!/bin/sh
# Turek-Hron CSM3 with the second-order scheme (Newmark trapezoidal) and with BDF1 at the
# same dt, on the mesh of configs/csm3.yaml; prints mean/amplitude/frequency of A.
# Usage: bench/solid/run_csm3.sh [BUILD_DIR] [extra key=value overrides]
set -e
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=${1:-$ROOT/build}
[ $# -gt 0 ] && shift
BIN="$BUILD/bin/solid_bench"
echo "reference: A_x -14.305 +/- 14.305 [1.0995], A_y -63.607 +/- 65.160 [1.0995] (1e-3 m, Hz)"
for scheme in newmark bdf1; do
  echo "== time_scheme $scheme"
  SOLID_BENCH_CSV="csm3_$scheme.csv" FSI_LOG_LEVEL=warn "$BIN" run "$ROOT/configs/csm3.yaml" solid.time_scheme=$scheme "$@"
done
