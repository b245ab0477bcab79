#!/bin/sh
# Does an effect a scene does not name cost nothing? Builds the MPM a second
# time without gravity, loads and pore pressure (OUTBURST_MPM_LEAN, in
# build-lean/), then runs mpm-benchmark --unloaded (an elastic block spinning
# free of gravity and loads, 1 thread) from both builds in turn, 6 times each,
# and prints the full build's best throughput over the lean one's (single
# runs on a shared machine land in a fast or a slow mode, 20 % apart; the
# best of six is the fast one). Needs a build (scripts/build.sh); about 2
# minutes.
set -eu
cd "$(dirname "$0")/.."
cmake -S . -B build-lean -DCMAKE_BUILD_TYPE=Release -DOUTBURST_MPM_LEAN=ON > /dev/null
cmake --build build-lean --target mpm-benchmark -j "$(nproc)" > /dev/null
cmake --build build --target mpm-benchmark -j "$(nproc)" > /dev/null
best_full=0
best_lean=0
for i in 1 2 3 4 5 6; do
  full=$(build/mpm_solid/mpm-benchmark --unloaded)
  lean=$(build-lean/mpm_solid/mpm-benchmark --unloaded)
  echo "run $i: full build $full, lean build $lean particle-steps/s"
  best_full=$(awk -v a="$full" -v b="$best_full" 'BEGIN { print (a > b ? a : b) }')
  best_lean=$(awk -v a="$lean" -v b="$best_lean" 'BEGIN { print (a > b ? a : b) }')
done
awk -v a="$best_full" -v b="$best_lean" \
  'BEGIN { printf "best: full build %.4g, lean build %.4g particle-steps/s; full / lean = %.3f\n", a, b, a / b }'
