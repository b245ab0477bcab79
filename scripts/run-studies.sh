#!/bin/sh
# Regenerates the shipped studies: every cases/<case>/study.toml (accuracy
# against time) and schemes.toml (coupling schemes and windows), each run with
# cases.study into results/<case>_<spec>/, its table, plot and CSVs copied
# to cases/<case>/<spec>/, which the manual shows (docs/verification/). About 6 minutes on 2 cores.
# Needs a build (scripts/run-main.sh makes one).
set -eu
cd "$(dirname "$0")/.."
for spec in cases/*/study.toml cases/*/schemes.toml; do
  case_dir=$(dirname "$spec")
  name=$(basename "$spec" .toml)
  out=results/$(basename "$case_dir")_$name
  /usr/bin/python3 -m cases.study "$spec" --out "$out"
  mkdir -p "$case_dir/$name"
  cp "$out/study.md" "$out/study.png" "$out/study.csv" "$out/study_orders.csv" "$case_dir/$name/"
done
