#!/usr/bin/env bash
# Configures (Release, optimised for this machine's CPU) and builds everything
# into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p build
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DOUTBURST_NATIVE=ON > build/build.log 2>&1 || { cat build/build.log; exit 1; }
cmake --build build -j "$(nproc)" >> build/build.log 2>&1 || { tail -50 build/build.log; exit 1; }
echo "build: ok (log in build/build.log)"
