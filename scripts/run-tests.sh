#!/usr/bin/env bash
# Every test: install what is missing, build, run the Catch2 suite, the
# ParaView check and the Python tests (pytest) through CTest on all cores.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
cd build
ctest --output-on-failure --timeout 600 -j "$(nproc)"
