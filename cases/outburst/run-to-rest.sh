#!/usr/bin/env bash
# The outburst run until the coal comes to rest: outburst.toml with the tunnel
# lengthened from 25 m to 100 m (seam_long.msh, seam.geo with tunnel = 100) so
# the ejected coal stays in the model, run until its kinetic energy is below
# rest_fraction of its peak (about 5.8 s simulated, a few minutes on 2 cores). Usage:
#   cases/outburst/run-to-rest.sh [RESULTS_DIR]      (default results/outburst_to_rest)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-results/outburst_to_rest}
rm -rf "$out"
build/coupler/outburst cases/outburst/outburst.toml --output "$out" \
  --set 'scene.end_time="10 s"' --set 'output.interval="0.1 s"' \
  --set 'seepage.mesh.file="seam_long.msh"' \
  --set 'mpm.grid.origin=["-75 m", "0 m"]' --set 'mpm.grid.size=["120 m", "9 m"]' \
  --set 'mpm.obstacles[0].box_min=["-75 m", "0 m"]' --set 'mpm.obstacles[1].box_min=["-75 m", "6 m"]'
/usr/bin/python3 -m cases.outburst.report "$out"
/usr/bin/python3 -m cases.outburst.animate "$out"
