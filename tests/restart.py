#!/usr/bin/python3
"""--restart continues a run bit for bit. Each case runs a scene to the end,
then again, stopped at a random point (seeded) after its first checkpoint,
by SIGKILL or SIGTERM, and continued with --restart: every snapshot the two
runs list, dataset by dataset, must be equal bit for bit, and the history
CSVs row for row (but for wall-clock columns). Then the refusals: a folder
without a checkpoint, another scene or overrides, another build.

usage: restart.py BUILD_DIR SOURCE_DIR WORK_DIR [SEED]"""
import csv
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_folder import leftovers, listed  # noqa: E402

WALL_CLOCK = {"seepage_s", "solid_s", "coupler_s"}  # coupling.csv: seconds each part took

# name, program, scene, overrides, threads, how to stop (signals), indexes, histories
CASES = [
    ("drainage", "seepage_fe/seepage-fe", "drainage/drainage.toml",
     ['seepage.max_time_step="30 min"', 'output.checkpoint_interval="1 d"'], 1,
     [signal.SIGKILL, signal.SIGTERM], ["seepage.xdmf"], ["seepage_history.csv"]),
    ("granular collapse", "mpm_solid/mpm-solid", "granular_collapse/granular_collapse.toml",
     ['scene.end_time="0.3 s"', 'output.interval="0.05 s"', 'output.checkpoint_interval="0.01 s"'], 1,
     [signal.SIGKILL, signal.SIGTERM], ["particles.xdmf"], ["mpm_history.csv"]),
    # Two threads: per-thread scatter buffers, summed in a fixed order.
    ("elastic block, 2 threads", "mpm_solid/mpm-solid", "elastic_block/elastic_block.toml",
     ['scene.end_time="0.04 s"', 'output.checkpoint_interval="0.001 s"'], 2,
     [signal.SIGKILL], ["particles.xdmf"], ["mpm_history.csv", "tracers.csv"]),
    # Implicit with IQN-ILS and Biot storage: the reused columns of past
    # windows, the solid's dilatation over the last window and the pressure it
    # felt carry over.
    ("Terzaghi, implicit IQN-ILS", "coupler/outburst", "terzaghi/terzaghi.toml",
     ['output.checkpoint_interval="0.01 s"'], 1,
     [signal.SIGKILL, signal.SIGTERM], ["seepage.xdmf", "particles.xdmf"],
     ["coupling.csv", "mpm_history.csv", "seepage_history.csv"]),
    # Damage, open cells and the gas force of the outburst, implicit ...
    ("gas face, implicit IQN-ILS", "coupler/outburst", "gas_face/gas_face.toml",
     ['output.checkpoint_interval="1 ms"'], 1,
     [signal.SIGKILL], ["seepage.xdmf", "particles.xdmf"],
     ["coupling.csv", "mpm_history.csv", "seepage_history.csv", "tracers.csv"]),
    # ... and explicit: the data the solid sent last window goes to the seepage first.
    ("gas face, explicit", "coupler/outburst", "gas_face/gas_face.toml",
     ['scene.end_time="0.06 s"', 'coupling.scheme="explicit"', 'output.checkpoint_interval="3 ms"'], 1,
     [signal.SIGKILL, signal.SIGTERM], ["seepage.xdmf", "particles.xdmf"],
     ["coupling.csv", "mpm_history.csv", "tracers.csv"]),
]


def command(build, source, program, scene, overrides, threads, out, *extra):
    line = [os.path.join(build, program), os.path.join(source, "cases", scene), "-q", "-o", out, "-j", str(threads)]
    for o in overrides:
        line += ["--set", o]
    return line + list(extra)


def run(line):
    start = time.monotonic()
    done = subprocess.run(line, stderr=subprocess.PIPE, text=True)
    return done.returncode, done.stderr, time.monotonic() - start


def stop_and_restart(line, out, sig, delay):
    """Runs `line` into `out`, sends `sig` `delay` s after its first checkpoint,
    restarts it; returns a list of failures."""
    shutil.rmtree(out, ignore_errors=True)
    process = subprocess.Popen(line, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    checkpoint = os.path.join(out, "checkpoint.h5")
    while not os.path.exists(checkpoint) and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    time.sleep(delay)
    if process.poll() is not None:
        return [f"the run ended (exit code {process.returncode}) before {sig.name}: lengthen it"]
    process.send_signal(sig)
    _, stderr = process.communicate(timeout=60)
    expected = 3 if sig == signal.SIGTERM else -signal.SIGKILL
    if process.returncode != expected:
        return [f"exit code {process.returncode} after {sig.name}, expected {expected}: {stderr.strip()[-300:]}"]
    stopped = re.search(r"stopped by SIGTERM at t = (\S+) s", stderr)
    code, stderr, _ = run(line + ["--restart"])
    restarted = re.search(r"restarted from \S+ at t = (\S+) s", stderr)
    print(f"    {sig.name} {delay:.2f} s after the first checkpoint"
          f"{f' (stopped at t = {stopped.group(1)} s)' if stopped else ''}; "
          f"restarted at t = {restarted.group(1) if restarted else '?'} s, exit code {code}")
    if code != 0 or not restarted:
        return [f"--restart after {sig.name}: exit code {code}: {stderr.strip()[-300:]}"]
    return []


def datasets(path):
    found = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: found.__setitem__(name, np.asarray(obj[()]))
                     if isinstance(obj, h5py.Dataset) else None)
    return found


def compare_snapshots(reference, other, index):
    """Differences between the snapshots two folders list in `index`."""
    times_a, files_a = listed(reference, index)
    times_b, files_b = listed(other, index)
    if times_a != times_b or files_a != files_b:
        return [f"{index}: lists {len(times_b)} times {times_b[-3:]}, expected {len(times_a)} {times_a[-3:]}"]
    failures = []
    for name in files_a:
        a, b = datasets(os.path.join(reference, name)), datasets(os.path.join(other, name))
        if a.keys() != b.keys():
            failures.append(f"{name}: datasets {sorted(b)} instead of {sorted(a)}")
            continue
        for key in a:
            if a[key].shape != b[key].shape or a[key].tobytes() != b[key].tobytes():
                differ = a[key].shape != b[key].shape or np.count_nonzero(a[key] != b[key])
                failures.append(f"{name}:{key} differs ({differ} entries)")
    # The killed run's snapshots after its checkpoint are gone or rewritten.
    written = sorted(n for n in os.listdir(other) if re.fullmatch(index[:-5] + r"_\d{6}\.h5", n))
    if written != [n for n in files_a if re.fullmatch(r".*_\d{6}\.h5", n)]:
        failures.append(f"{index}: the folder holds snapshot files {written[-3:]} beyond those listed")
    return failures


def rows(path):
    with open(path) as f:
        return [{k: v for k, v in row.items() if k not in WALL_CLOCK} for row in csv.DictReader(f)]


def compare_histories(reference, other, history):
    a, b = rows(os.path.join(reference, history)), rows(os.path.join(other, history))
    if len(a) != len(b):
        return [f"{history}: {len(b)} rows, expected {len(a)}"]
    for k, (ra, rb) in enumerate(zip(a, b)):
        if ra != rb:
            column = next(c for c in ra if ra[c] != rb.get(c))
            return [f"{history}: row {k + 1} differs in {column}: {rb.get(column)} instead of {ra[column]}"]
    return []


def refusals(build, source, work):
    """--restart refuses what it cannot continue bit for bit, with exit code 2."""
    base = ("mpm_solid/mpm-solid", "elastic_block/elastic_block.toml")
    out = os.path.join(work, "refusals")
    shutil.rmtree(out, ignore_errors=True)
    failures = []

    def expect(what, line, words):
        code, stderr, _ = run(line)
        ok = code == 2 and re.search(words, stderr)
        print(f"  {what}: exit code {code}{'' if ok else ': ' + stderr.strip()[-200:]}")
        if not ok:
            failures.append(f"{what}: exit code {code}, expected 2 and '{words}'")

    expect("no checkpoint", command(build, source, *base, [], 1, out, "--restart"), r"no checkpoint there")
    code, stderr, _ = run(command(build, source, *base, [], 1, out))
    if code != 0:
        return failures + [f"the run for the refusals failed: {stderr.strip()[-200:]}"]
    expect("other overrides", command(build, source, *base, ['scene.end_time="0.04 s"'], 1, out, "--restart"),
           r"other --set overrides")
    expect("--restart with --overwrite", command(build, source, *base, [], 1, out, "--restart", "--overwrite"),
           r"excludes")
    with h5py.File(os.path.join(out, "checkpoint.h5"), "a") as f:
        f.attrs["version"] = "0.0.0 (elsewhere)"
    expect("another build", command(build, source, *base, [], 1, out, "--restart"), r"written by version 0\.0\.0")
    return failures


def main():
    build, source, work = sys.argv[1:4]
    # Threads that sleep while they wait: on a machine busier than its cores,
    # spinning ones take 20 times longer (the results are the same).
    os.environ["OMP_WAIT_POLICY"] = "passive"
    rng = random.Random(int(sys.argv[4]) if len(sys.argv) > 4 else 1)
    failures = []
    for name, program, scene, overrides, threads, signals, indexes, histories in CASES:
        reference = os.path.join(work, re.sub(r"\W+", "_", name), "uninterrupted")
        shutil.rmtree(reference, ignore_errors=True)
        code, stderr, wall = run(command(build, source, program, scene, overrides, threads, reference))
        print(f"{name}: uninterrupted run {wall:.2f} s, exit code {code}")
        if code != 0:
            failures.append(f"{name}: the uninterrupted run failed: {stderr.strip()[-300:]}")
            continue
        for sig in signals:
            other = os.path.join(os.path.dirname(reference), sig.name)
            line = command(build, source, program, scene, overrides, threads, other)
            found = stop_and_restart(line, other, sig, rng.uniform(0.05, 0.6) * wall)
            if not found:
                for index in indexes:
                    found += compare_snapshots(reference, other, index)
                for history in histories:
                    found += compare_histories(reference, other, history)
                if leftovers(other):
                    found.append(f"temporary files left: {leftovers(other)}")
            print(f"    {'bit for bit' if not found else 'DIFFERS: ' + '; '.join(found[:4])}")
            failures += [f"{name}, {sig.name}: {f}" for f in found]
        if threads > 1:
            # What the README claims: runs at different thread counts differ
            # (round-off), so only a restart at the same count is bit for bit.
            single = os.path.join(os.path.dirname(reference), "one_thread")
            shutil.rmtree(single, ignore_errors=True)
            run(command(build, source, program, scene, overrides, 1, single))
            found = [d for index in indexes for d in compare_snapshots(reference, single, index)]
            print(f"    1 thread against {threads}: {'; '.join(found[:2]) if found else 'bit for bit'}")
            if not found:
                failures.append(f"{name}: 1 and {threads} threads agree bit for bit: the README's claim that they "
                                "differ is out of date")
    failures += refusals(build, source, work)
    if failures:
        sys.exit("\n".join(failures))


if __name__ == "__main__":
    main()
