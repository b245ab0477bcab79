#!/usr/bin/python3
"""Is a change slower? Runs mpm-benchmark from two or more builds in turn,
ROUNDS times each on one thread, and prints each row's best throughput per
build and its ratio to the first build's. Single runs on a shared machine
land in a fast or a slow mode, so the best of the rounds is compared, the
builds interleaved so that a load on the machine falls on all of them.
Builds whose mpm-benchmark measures one row alone (it takes --shape and
--material) take turns row by row, one row's run apart (about a second at
1e5 particles): a slow spell of the machine then falls on all of them,
where whole runs, a minute apart, could catch it in one build's run alone.
Older builds (63e0ffd's, say) run whole once a round, before the others'
rows; the rows are found by one unbooked run of the first row-wise build.
--cpu pins every run to one core (on this kind of machine the two cores'
speeds differ at times). A build given twice, under two names, shows the
run's own noise.
Beside the ratio of the bests, each build's ratio to the first taken round
by round, and its median over the rounds: it does not rest on one fast
round per build. Between row-wise builds a row's two figures in a round
are a few seconds apart, so a slow spell falls on both; a whole-run
build's figure comes from the round's start, up to a minute before.
--shape and --material (either repeated for more) choose the rows of the
row-wise builds; whole-run builds measure their default rows.
--whole runs every build whole, the row-wise ones too: against an older
reference each round's figures then come from one program shape (a whole
run lasts about twenty seconds, a row-wise one a second or two), run back
to back, for the medians to pair.
The printout's first line and the CSV's last column name the processor:
the ratios depend on it (docs/performance/index.md, "Hosts").

usage: compare-mpm-benchmark.py [--particles N] [--rounds R] [--dimension 2|3] [--cpu C] [--shape S] [--material M] [--whole] [--csv FILE] NAME=BUILD_DIR ...
  e.g. compare-mpm-benchmark.py before=../old/build after=build
"""
import argparse
import csv
import os
import re
import statistics
import subprocess
import sys

from builds import host, named_builds  # scripts/builds.py

ROW = re.compile(r"^\s*(\d+)\s+(\S+)\s+(\S+)\s+([0-9.e+]+)")


def program(build):
    return os.path.join(build, "mpm_solid", "mpm-benchmark")


def by_rows(build):
    """Whether the build's mpm-benchmark measures a row alone."""
    shown = subprocess.run([program(build), "--help"], capture_output=True, text=True)
    return "--material" in shown.stdout


def run(build, particles, dimension, cpu, row=None, options=()):
    plane = dimension == 2  # builds from before 3D take no --dimension
    command = [program(build)] + ([] if plane else ["--dimension", "3"]) + list(options)
    if row:
        command += ["--shape", row[0], "--material", row[1], "--threads", "1"]
    if row or options:
        command += ["--"]
    out = subprocess.run(command + [str(particles)], check=True, capture_output=True, text=True,
                         env=dict(os.environ, OMP_NUM_THREADS="1"),
                         preexec_fn=None if cpu is None else lambda: os.sched_setaffinity(0, {cpu})).stdout
    rows = {}
    for line in out.splitlines():
        m = ROW.match(line)
        if m:
            rows[(m.group(2), m.group(3))] = float(m.group(4))
    if not rows:
        sys.exit(f"{program(build)} printed no benchmark rows:\n{out}")
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("builds", nargs="+", help="NAME=BUILD_DIR, the first the reference")
    parser.add_argument("--particles", type=int, default=100000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--dimension", type=int, choices=(2, 3), default=2,
                        help="3: the 3D kernel (builds from 53491f2 on)")
    parser.add_argument("--cpu", type=int, help="pin every run to this core")
    parser.add_argument("--shape", action="append",
                        help="the row-wise builds measure this shape (repeat for more; default: the benchmark's)")
    parser.add_argument("--material", action="append",
                        help="the row-wise builds measure this material (repeat for more; default: the benchmark's)")
    parser.add_argument("--whole", action="store_true",
                        help="run every build whole, once a round, as older builds are run")
    parser.add_argument("--csv", help="also write the table here")
    args = parser.parse_args()
    if args.cpu is not None and args.cpu not in os.sched_getaffinity(0):
        sys.exit(f"--cpu {args.cpu}: this process may run on cores {sorted(os.sched_getaffinity(0))} only")
    builds = named_builds(args.builds, os.path.join("mpm_solid", "mpm-benchmark"))
    names = [name for name, _ in builds]
    if len(set(names)) < len(names):
        sys.exit("each NAME once: the figures are kept by name (a build measured twice takes two names)")
    rowwise = [] if args.whole else [(name, folder) for name, folder in builds if by_rows(folder)]
    if (args.shape or args.material) and args.whole:
        sys.exit("--whole runs each build's default rows: --shape and --material choose none")
    if (args.shape or args.material) and not rowwise:
        sys.exit("--shape and --material choose the rows of builds whose mpm-benchmark takes them; none here does")
    whole = [(name, folder) for name, folder in builds if (name, folder) not in rowwise]
    best = {name: {} for name, _ in builds}
    each = {name: {} for name, _ in builds}  # each[name][row][round]

    def book(name, rows, r):
        for row, value in rows.items():
            best[name][row] = max(best[name].get(row, 0.0), value)
            each[name].setdefault(row, {})[r] = value

    measured = []  # the (shape, material) rows the row-wise builds run
    for r in range(args.rounds):
        for name, folder in whole:
            book(name, run(folder, args.particles, args.dimension, args.cpu), r)
        if rowwise:
            # The rows the first such build measures by default (found once,
            # not booked), each then by every such build in turn.
            measured = measured or list(
                run(rowwise[0][1], args.particles, args.dimension, args.cpu,
                    options=["--threads", "1"] + (["--shape", *args.shape] if args.shape else []) +
                    (["--material", *args.material] if args.material else [])))
            for row in measured:
                for name, folder in rowwise:
                    book(name, run(folder, args.particles, args.dimension, args.cpu, row), r)
        print(f"round {r + 1} of {args.rounds} done", file=sys.stderr)
    reference = builds[0][0]

    def paired(name, row, against):
        """The median over the rounds of name's figure over against's in the
        same round."""
        ours, theirs = each[name].get(row, {}), each[against].get(row, {})
        ratios = [ours[r] / theirs[r] for r in ours if r in theirs]
        return statistics.median(ratios) if ratios else float("nan")

    header = ["shape", "material"] + [f"{n} [particle-steps/s]" for n, _ in builds] + \
             [f"{n} / {reference}" for n, _ in builds[1:]] + \
             [f"{n} / {reference}, median of rounds" for n, _ in builds[1:]]
    machine = host()
    rows = []
    # The rows the row-wise builds measured (an older reference, run whole,
    # may lack some, whose ratios then read nan), else the reference's.
    for row in measured or best[reference]:
        values = [best[n].get(row, float("nan")) for n, _ in builds]
        rows.append(list(row) + [f"{v:.4g}" for v in values] + [f"{v / values[0]:.3f}" for v in values[1:]] +
                    [f"{paired(n, row, reference):.3f}" for n, _ in builds[1:]])
    pinned = "" if args.cpu is None else f", on core {args.cpu}"
    print(f"best of {args.rounds} rounds, {args.particles} particles, 1 thread{pinned}, {args.dimension}D, {machine}")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        print("| " + " | ".join(r) + " |")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header + ["host"])
            w.writerows(r + [machine] for r in rows)


if __name__ == "__main__":
    main()
