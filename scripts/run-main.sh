#!/usr/bin/env bash
# The main job: install what is missing, build, run the main case, draw its figures.
# Until the outburst case exists the main case is the seepage verification scene:
# gas drainage of a coal seam through a freshly opened face.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
build/seepage_fe/seepage-fe cases/drainage/drainage.toml --output results/drainage
/usr/bin/python3 cases/drainage/plot.py results/drainage cases/drainage/drainage.toml
echo "main job: results in results/drainage (open seepage.xdmf in ParaView)"
