#!/bin/sh
# Regenerates the shipped accuracy-against-time studies (cases/*/study.toml):
# runs each with cases/study.py into results/study_<case>/ and copies its
# table, plot and CSVs to cases/<case>/study/, which the README links.
# About 15 minutes on 2 cores. Needs a build (scripts/run-main.sh makes one).
set -eu
cd "$(dirname "$0")/.."
for case in bar drainage terzaghi mandel outburst; do
  out=results/study_$case
  /usr/bin/python3 cases/study.py cases/$case/study.toml --out "$out"
  mkdir -p cases/$case/study
  cp "$out/study.md" "$out/study.png" "$out/study.csv" "$out/study_orders.csv" cases/$case/study/
done
