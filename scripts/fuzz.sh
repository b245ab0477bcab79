#!/bin/sh
# A longer fuzz run than CI's (tests/fuzz_scenes.py): mutated shipped scenes
# checked and some run, with statistics (exit codes, signal deaths, hangs,
# the messages of failed runs). Needs a build (scripts/build.sh).
#   scripts/fuzz.sh [SEED] [COUNT] [RUNS]      (default 1, 5000 mutants, 500 runs: about 3 minutes)
set -eu
cd "$(dirname "$0")/.."
exec /usr/bin/python3 tests/fuzz_scenes.py build . results/fuzz --seed "${1:-1}" --count "${2:-5000}" --runs "${3:-500}"
