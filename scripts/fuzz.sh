#!/bin/sh
# A longer fuzz run than CI's (tests/fuzz_scenes.py): mutated shipped scenes
# checked and some run, scenes nested deep, corrupted meshes and damaged
# checkpoints, with statistics (exit codes, signal deaths, hangs, the messages
# of failed runs). Needs a build (scripts/build.sh).
#   scripts/fuzz.sh [SEED] [COUNT] [RUNS] [SHAPES]
#   (default 1, 5000 mutants, 500 runs, 500 of each other shape)
set -eu
cd "$(dirname "$0")/.."
shapes="${4:-500}"
exec /usr/bin/python3 tests/fuzz_scenes.py build . results/fuzz --seed "${1:-1}" --count "${2:-5000}" --runs "${3:-500}" \
  --nesting "$shapes" --meshes "$shapes" --checkpoints "$shapes"
