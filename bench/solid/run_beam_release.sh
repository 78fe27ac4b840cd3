#!/bin/sh
# Released thick beam under the coupler (fem solid + surrogate force): Algorithm 1 and
# Algorithm 2 with growing gamma_N1. Prints the 2% settling time of A_x for each run and
# plots A_x(t) into bench/solid/beam_release.svg.
# Usage: bench/solid/run_beam_release.sh [BUILD_DIR] [OUT_DIR]
set -e
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=${1:-$ROOT/build}
OUT=${2:-/tmp/beam_release}
RUNS="a1_g1:1:1.0 a2_g0.1:2:0.1 a2_g1:2:1.0 a2_g3:2:3.0 a2_g10:2:10.0"
for r in $RUNS; do
  name=${r%%:*}; rest=${r#*:}; alg=${rest%%:*}; gamma=${rest#*:}
  FSI_LOG_LEVEL=warn "$BUILD/bin/fsi" run "$ROOT/bench/solid/beam_release.yaml" --out "$OUT/$name" \
    --set coupling.algorithm=$alg --set coupling.gamma_n1=$gamma > /dev/null
done
python3 - "$OUT" "$ROOT/bench/solid/beam_release.svg" $RUNS <<'PY'
import csv, sys
out, png, runs = sys.argv[1], sys.argv[2], [r.split(':')[0] for r in sys.argv[3:]]
series = {}
for name in runs:
    rows = list(csv.DictReader(open(f"{out}/{name}/probes.csv")))
    t = [float(r['time']) for r in rows]; x = [float(r['solid.A_x']) for r in rows]
    series[name] = (t, x)
# Settling: last time |A_x - A_x(end)| > 2% of |A_x(end)|.
print("run        A_x(end)     2% settling time")
for name, (t, x) in series.items():
    final = x[-1]; ts = 0.0
    for ti, xi in zip(t, x):
        if abs(xi - final) > 0.02 * abs(final): ts = ti
    print(f"{name:10s} {final:.5e}  {ts:.2f} s")
# A dependency-free SVG plot.
W, H, pad = 800, 450, 50
tmax = max(max(t) for t, _ in series.values())
xs = [v for _, x in series.values() for v in x]; lo, hi = min(xs), max(xs)
colours = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b']
def px(t, x): return pad + (W - 2 * pad) * t / tmax, H - pad - (H - 2 * pad) * (x - lo) / (hi - lo)
svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
       f'<rect x="{pad}" y="{pad}" width="{W-2*pad}" height="{H-2*pad}" fill="none" stroke="black"/>',
       f'<text x="{W/2}" y="{H-15}" text-anchor="middle">t (0 .. {tmax:g})</text>',
       f'<text x="10" y="{pad-10}">A_x ({lo:.3g} .. {hi:.3g}); released thick beam, BDF1, dt = 0.01</text>']
for i, (name, (t, x)) in enumerate(series.items()):
    pts = ' '.join(f'{a:.1f},{b:.1f}' for a, b in (px(ti, xi) for ti, xi in zip(t, x)))
    c = colours[i % len(colours)]
    svg.append(f'<polyline fill="none" stroke="{c}" stroke-width="1.2" points="{pts}"/>')
    svg.append(f'<text x="{W-pad-110}" y="{pad+20+16*i}" fill="{c}">{name}</text>')
svg.append('</svg>')
open(png, 'w').write('\n'.join(svg)); print("plot:", png)
PY
