#!/usr/bin/env bash
# The 3D outburst (outburst_3d.toml) from one command: the run, then its
# report and figures beside the plane case's numbers (docs/cases/outburst-3d.md). Usage:
#   cases/outburst_3d/run.sh [--fine] [RESULTS_DIR]
# default RESULTS_DIR results/outburst_3d (results/outburst_3d_fine with
# --fine: the plane case's cells of 1/3 m, 233,280 particles). On all cores;
# the plane case's run in results/outburst is compared if it is there. The
# run's log is written beside its folder (RESULTS_DIR.log).
set -euo pipefail
cd "$(dirname "$0")/../.."
fine=()
default=results/outburst_3d
if [ "${1:-}" = "--fine" ]; then
  fine=(--set 'mpm.grid.cell_size="0.3333333333333333 m"')
  default=results/outburst_3d_fine
  shift
fi
out=${1:-$default}
# The log beside the folder (the report reads the run's wall time from it).
mkdir -p "$(dirname "$out")"
build/coupler/outburst cases/outburst_3d/outburst_3d.toml --output "$out" --overwrite "${fine[@]}" 2>&1 |
  tee "$out.log"
plane=()
[ -f results/outburst/coupling.csv ] && plane=(--plane results/outburst)
/usr/bin/python3 -m cases.outburst_3d.report "$out" --log "$out.log" "${plane[@]}"
