#!/usr/bin/python3
"""Is a change slower? Runs mpm-benchmark from two or more builds in turn,
ROUNDS times each on one thread, and prints each row's best throughput per
build and its ratio to the first build's. Single runs on a shared machine
land in a fast or a slow mode, so the best of the rounds is compared, the
builds interleaved so that a load on the machine falls on all of them.

usage: compare-mpm-benchmark.py [--particles N] [--rounds R] [--dimension 2|3] [--csv FILE] NAME=BUILD_DIR ...
  e.g. compare-mpm-benchmark.py before=/tmp/old/build after=build
"""
import argparse
import csv
import os
import re
import subprocess
import sys

from builds import named_builds  # scripts/builds.py

ROW = re.compile(r"^\s*(\d+)\s+(\S+)\s+(\S+)\s+([0-9.e+]+)")


def run(build, particles, dimension):
    program = os.path.join(build, "mpm_solid", "mpm-benchmark")
    plane = dimension == 2  # builds from before 3D take no --dimension
    out = subprocess.run([program, str(particles)] + ([] if plane else ["--dimension", "3"]), check=True, capture_output=True, text=True,
                         env=dict(os.environ, OMP_NUM_THREADS="1")).stdout
    rows = {}
    for line in out.splitlines():
        m = ROW.match(line)
        if m:
            rows[(m.group(2), m.group(3))] = float(m.group(4))
    if not rows:
        sys.exit(f"{program} printed no benchmark rows:\n{out}")
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("builds", nargs="+", help="NAME=BUILD_DIR, the first the reference")
    parser.add_argument("--particles", type=int, default=100000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--dimension", type=int, choices=(2, 3), default=2,
                        help="3: the 3D kernel (builds from 53491f2 on)")
    parser.add_argument("--csv", help="also write the table here")
    args = parser.parse_args()
    builds = named_builds(args.builds, os.path.join("mpm_solid", "mpm-benchmark"))
    best = {name: {} for name, _ in builds}
    for r in range(args.rounds):
        for name, folder in builds:
            for row, value in run(folder, args.particles, args.dimension).items():
                best[name][row] = max(best[name].get(row, 0.0), value)
        print(f"round {r + 1} of {args.rounds} done", file=sys.stderr)
    reference = builds[0][0]
    header = ["shape", "material"] + [f"{n} [particle-steps/s]" for n, _ in builds] + \
             [f"{n} / {reference}" for n, _ in builds[1:]]
    rows = []
    for row in best[reference]:
        values = [best[n].get(row, float("nan")) for n, _ in builds]
        rows.append(list(row) + [f"{v:.4g}" for v in values] + [f"{v / values[0]:.3f}" for v in values[1:]])
    print(f"best of {args.rounds} rounds, {args.particles} particles, 1 thread, {args.dimension}D")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        print("| " + " | ".join(r) + " |")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header)
            w.writerows(rows)


if __name__ == "__main__":
    main()
