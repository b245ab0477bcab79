#!/usr/bin/env bash
# The main job: install what is missing, build, run the paper's outburst case,
# draw its figures and write its report (results/outburst/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
rm -rf results/outburst
build/coupler/outburst cases/outburst/outburst.toml --output results/outburst
/usr/bin/python3 cases/outburst/report.py results/outburst
echo "main job: results in results/outburst: report.md, fig*.png; open particles.xdmf and seepage.xdmf in ParaView"
