#!/usr/bin/python3
"""What the outburst costs, build against build: the shipped case's first
second and its run to rest (cases/outburst/run-to-rest.sh's scene), each
build in turn, with the wall time, the solid's share of it and its MPM
throughput (particle-steps per second of solid time, from coupling.csv and
mpm_history.csv), beside mpm-benchmark's standalone throughput at the same
particle count, shape and material (B-splines, elastic_damage) and threads,
and the parts of the wall time by the program's own clocks (wall_times.csv).

usage: scripts/outburst-benchmark.py [--threads 2] [--only first_second|to_rest] [--set KEY=VALUE ...] [--csv FILE] [--out DIR] NAME=BUILD_DIR ...
  e.g. scripts/outburst-benchmark.py --csv results/outburst-benchmark.csv before=../old/build after=build
--set adds a scene override (as the outburst program's --set) to every run, after the case's own: a
longer step, say, costed against the shipped one's rows of another run.
Run it on an idle machine: two threads that share their cores with other
work wait on each other at every barrier. The processor is printed first
and written as the CSV's last column, host: the wall times depend on it
(docs/performance/index.md, "Hosts").
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
from cases.effect_cost import particle_steps  # noqa: E402
from builds import host, named_builds  # noqa: E402 (scripts/builds.py)

SCENE = os.path.join(ROOT, "cases", "outburst", "outburst.toml")
# The run to rest: cases/outburst/run-to-rest.sh's overrides.
TO_REST = ['scene.end_time="10 s"', 'output.interval="0.1 s"', 'seepage.mesh.file="seam_long.msh"',
           'mpm.grid.origin=["-75 m", "0 m"]', 'mpm.grid.size=["120 m", "9 m"]',
           'mpm.obstacles[0].box_min=["-75 m", "0 m"]', 'mpm.obstacles[1].box_min=["-75 m", "6 m"]']
CASES = {"first_second": [], "to_rest": TO_REST}
# The parts of a run's wall time the outburst program writes to wall_times.csv (builds from this one on; older
# ones leave these columns empty), which add up to its run loop's wall time (run_loop_wall_s: the process's
# wall_s less its start, settling and end).
PARTS = ["mpm_particles_to_grid", "mpm_grid", "mpm_stresses_and_forces", "mpm_grid_to_particles", "gas_force",
         "solid_bookkeeping", "seepage", "exchanges_and_acceleration", "output_and_rest"]
ROW = re.compile(r"^\s*(\d+)\s+bspline\s+elastic_damage\s+([0-9.e+]+)")


def standalone(build, particles, threads):
    """mpm-benchmark's B-spline elastic_damage throughput at this particle count and thread count. Builds from
    before its row filters (cd51f91 and older) take the particle count alone and print every row, with
    columns for 1 and 2 threads."""
    program = os.path.join(build, "mpm_solid", "mpm-benchmark")
    filtered = subprocess.run([program, str(particles), "--shape", "bspline", "--material", "elastic_damage",
                               "--threads", str(threads)], capture_output=True, text=True)
    old = filtered.returncode == 2
    if old:
        if threads not in (1, 2):
            sys.exit(f"{build}: its mpm-benchmark measures 1 and 2 threads only")
        filtered = subprocess.run([program, str(particles)], capture_output=True, text=True, check=True)
    for line in filtered.stdout.splitlines():
        m = ROW.match(line)
        if m:
            return float(line.split()[3 + (threads - 1 if old else 0)])
    sys.exit(f"{build}: mpm-benchmark printed no bspline elastic_damage row:\n{filtered.stdout}{filtered.stderr}")


def run(build, case, threads, folder, overrides):
    command = [os.path.join(build, "coupler", "outburst"), SCENE, "-q", "-o", folder, "--overwrite",
               "-j", str(threads)]
    for o in CASES[case] + overrides:
        command += ["--set", o]
    times = os.path.join(folder, "wall_times.csv")
    if os.path.exists(times):
        os.remove(times)  # an older build's run, which writes none, is not to read a newer one's
    start = time.monotonic()
    subprocess.run(command, check=True, capture_output=True)
    wall = time.monotonic() - start
    with open(os.path.join(folder, "coupling.csv")) as f:
        windows = list(csv.DictReader(f))
    solid = sum(float(w["solid_s"]) for w in windows)
    steps = particle_steps(folder)
    with open(os.path.join(folder, "mpm_history.csv")) as f:
        mpm_steps = int(list(csv.DictReader(f))[-1]["step"])
    parts = {}
    if os.path.exists(times):
        with open(times) as f:
            parts = {r["part"]: r["seconds"] for r in csv.DictReader(f)}
    return {"overrides": "; ".join(overrides), "wall_s": wall, "solid_s": solid,
            "simulated_s": float(windows[-1]["time"]), "particles": int(windows[0]["particles"]),
            "mpm_steps": mpm_steps, "coupled_particle_steps_per_s": steps / solid,
            "run_loop_wall_s": parts.get("wall", "")} | {f"{p}_s": parts.get(p, "") for p in PARTS}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("builds", nargs="+", help="NAME=BUILD_DIR, the first the reference")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--only", choices=sorted(CASES))
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="a scene override for every run (repeatable)")
    parser.add_argument("--csv", help="also write the rows here")
    parser.add_argument("--out", help="keep the runs here, one folder per case and build (for their reports: "
                                      "python3 -m cases.outburst.report DIR/NAME_CASE)")
    args = parser.parse_args()
    builds = named_builds(args.builds, os.path.join("coupler", "outburst"))
    rows = []
    machine = host()
    print(f"on {machine}", flush=True)
    with tempfile.TemporaryDirectory() as temporary:
        scratch = args.out or temporary
        for case in [args.only] if args.only else list(CASES):
            for name, build in builds:
                r = run(build, case, args.threads, os.path.join(scratch, f"{name}_{case}"), args.overrides)
                r["standalone_particle_steps_per_s"] = standalone(build, r["particles"], args.threads)
                rows.append({"case": case, "build": name, "threads": args.threads} | r | {"host": machine})
                print(f"{case} {name}: {r['wall_s']:.1f} s wall for {r['simulated_s']:.3g} s, solid "
                      f"{r['solid_s']:.1f} s at {r['coupled_particle_steps_per_s']:.3g} particle-steps/s "
                      f"(standalone {r['standalone_particle_steps_per_s']:.3g}: "
                      f"{r['coupled_particle_steps_per_s'] / r['standalone_particle_steps_per_s']:.2f})", flush=True)
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)


if __name__ == "__main__":
    main()
