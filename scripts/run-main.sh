#!/usr/bin/env bash
# The main job: install what is missing, build, run the paper's outburst case,
# draw its figures, write its report and film it (results/outburst/), then run
# it on to rest in a longer tunnel (results/outburst_to_rest/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
rm -rf results/outburst
build/coupler/outburst cases/outburst/outburst.toml --output results/outburst
/usr/bin/python3 -m cases.outburst.report results/outburst
/usr/bin/python3 -m cases.outburst.animate results/outburst
cases/outburst/run-to-rest.sh results/outburst_to_rest
echo "main job: results in results/outburst (the paper's first second) and results/outburst_to_rest (to rest):"
echo "report.md, fig*.png, outburst.mp4 (the film); open particles.xdmf and seepage.xdmf in ParaView"
