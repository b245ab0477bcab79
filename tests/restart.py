#!/usr/bin/python3
"""--restart continues a run bit for bit. Each case runs a scene to the end,
then again, stopped by SIGKILL or SIGTERM at a random point (seeded) of the
stage it names (the solid's settling stage, or the run after it) once a
checkpoint exists, and continued with --restart: every snapshot the two runs
list must be equal dataset by dataset, bit for bit, the history CSVs row for
row (but for wall-clock columns), and the last checkpoints, the whole state,
dataset by dataset. A restart from a checkpoint with one position changed by
one ulp must differ: the comparison sees that much. Then the refusals (exit code
2): no folder, a folder without a checkpoint, another scene text, mesh, set of
overrides, version or build, and a fresh run into a folder that holds one.

usage (from the top folder): python3 -m tests.restart BUILD_DIR SOURCE_DIR WORK_DIR [SEED]"""
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
import zlib
from collections import namedtuple

import h5py
import numpy as np

from tests.run_folder import compare_checkpoints, compare_histories, compare_listed, leftovers, listed


# stops: (signal, stage) pairs; the stage is "settling" or "run".
Case = namedtuple("Case", "name program scene overrides threads stops indexes histories")
CASES = [
    Case("drainage", "seepage_fe/seepage-fe", "drainage/drainage.toml",
         ['seepage.max_time_step="30 min"', 'output.checkpoint_interval="1 d"'], 1,
         [(signal.SIGKILL, "run"), (signal.SIGTERM, "run")], ["seepage.xdmf"], ["seepage_history.csv"]),
    # In 3D: hexahedra, and a supernodal CHOLMOD factor set up afresh on restart.
    Case("drainage in 3D", "seepage_fe/seepage-fe", "drainage_3d/drainage_3d.toml",
         ['scene.end_time="6 d"', 'output.interval="2 d"', 'output.checkpoint_interval="12 h"'], 1,
         [(signal.SIGKILL, "run"), (signal.SIGTERM, "run")], ["seepage.xdmf"], ["seepage_history.csv"]),
    Case("granular collapse", "mpm_solid/mpm-solid", "granular_collapse/granular_collapse.toml",
         ['scene.end_time="0.2 s"', 'output.interval="0.05 s"', 'output.checkpoint_interval="0.01 s"'], 1,
         [(signal.SIGKILL, "run"), (signal.SIGTERM, "run")], ["particles.xdmf"], ["mpm_history.csv"]),
    # Two threads: per-thread scatter buffers, summed in a fixed order.
    Case("elastic block, 2 threads", "mpm_solid/mpm-solid", "elastic_block/elastic_block.toml",
         ['scene.end_time="0.04 s"', 'output.checkpoint_interval="0.001 s"'], 2,
         [(signal.SIGKILL, "run")], ["particles.xdmf"], ["mpm_history.csv", "tracers.csv"]),
    # 3D, two threads: the threads' scatter buffers over blocks of 4 x 4 x 4 nodes.
    Case("3D heading, 2 threads", "mpm_solid/mpm-solid", "elastic_block_3d/elastic_block_3d.toml",
         ['scene.end_time="0.01 s"', 'mpm.grid.cell_size="1 m"', 'output.interval="0.002 s"',
          'output.checkpoint_interval="0.0005 s"'], 2,
         [(signal.SIGKILL, "run")], ["particles.xdmf"], ["mpm_history.csv", "tracers.csv"]),
    # A settling stage of mpm-solid's own.
    Case("elastic block, settling", "mpm_solid/mpm-solid", "elastic_block/elastic_block.toml",
         ['mpm.settle.time="0.02 s"', 'output.checkpoint_interval="1 ms"'], 1,
         [(signal.SIGTERM, "settling"), (signal.SIGKILL, "settling"), (signal.SIGKILL, "run")], ["particles.xdmf"],
         ["mpm_history.csv", "tracers.csv"]),
    # Implicit with IQN-ILS and Biot storage: the reused columns of past
    # windows, the solid's dilatation over the last window and the pressure it
    # felt carry over.
    Case("Terzaghi, implicit IQN-ILS", "coupler/outburst", "terzaghi/terzaghi.toml",
         ['output.checkpoint_interval="0.01 s"'], 1,
         [(signal.SIGKILL, "run"), (signal.SIGTERM, "run")], ["seepage.xdmf", "particles.xdmf"],
         ["coupling.csv", "mpm_history.csv", "seepage_history.csv"]),
    # The same in 3D: hexahedra, six stress components, the 3D solid's state.
    Case("Terzaghi 3D, implicit IQN-ILS", "coupler/outburst", "terzaghi_3d/terzaghi_3d.toml",
         ['output.checkpoint_interval="0.01 s"'], 1,
         [(signal.SIGKILL, "run")], ["seepage.xdmf", "particles.xdmf"],
         ["coupling.csv", "mpm_history.csv", "seepage_history.csv", "tracers.csv"]),
    # Damage, open cells and the gas force of the outburst, implicit ...
    Case("gas face, implicit IQN-ILS", "coupler/outburst", "gas_face/gas_face.toml",
         ['output.checkpoint_interval="1 ms"'], 1,
         [(signal.SIGKILL, "run")], ["seepage.xdmf", "particles.xdmf"],
         ["coupling.csv", "mpm_history.csv", "seepage_history.csv", "tracers.csv"]),
    # ... and explicit: the data the solid sent last window goes to the seepage first.
    Case("gas face, explicit", "coupler/outburst", "gas_face/gas_face.toml",
         ['scene.end_time="0.06 s"', 'coupling.scheme="explicit"', 'output.checkpoint_interval="3 ms"'], 1,
         [(signal.SIGKILL, "run")], ["seepage.xdmf", "particles.xdmf"],
         ["coupling.csv", "mpm_history.csv", "tracers.csv"]),
    # The main case as shipped but for its length (and its settling stage's):
    # the settling stage (the face supported, damped) is stopped and continued
    # too.
    Case("outburst", "coupler/outburst", "outburst/outburst.toml",
         ['mpm.settle.time="0.025 s"', 'scene.end_time="0.02 s"', 'output.interval="0.01 s"',
          'output.checkpoint_interval="4 ms"'], 1,
         [(signal.SIGKILL, "settling"), (signal.SIGTERM, "settling"), (signal.SIGKILL, "run")],
         ["seepage.xdmf", "particles.xdmf"],
         ["coupling.csv", "mpm_history.csv", "seepage_history.csv", "tracers.csv"]),
]


def command(build, source, program, scene, overrides, threads, out, *extra):
    scene = scene if os.path.isabs(scene) else os.path.join(source, "cases", scene)
    line = [os.path.join(build, program), scene, "-q", "-o", out, "-j", str(threads)]
    for o in overrides:
        line += ["--set", o]
    return line + list(extra)


class Run:
    """A program running in the background; notes when each log line came."""

    def __init__(self, line):
        self.start = time.monotonic()
        self.process = subprocess.Popen(line, stderr=subprocess.PIPE, text=True)
        self.lines = []  # (seconds since the start, line)
        self.reader = threading.Thread(target=self._read)
        self.reader.start()

    def _read(self):
        for line in self.process.stderr:
            self.lines.append((time.monotonic() - self.start, line))

    def wait(self, timeout=120):
        try:
            self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.reader.join()
        return self.process.returncode

    def stderr(self):
        return "".join(line for _, line in self.lines)

    def when(self, words):
        """Seconds from the start to the first log line holding `words`, or None."""
        return next((t for t, line in self.lines if words in line), None)


def run(line):
    r = Run(line)
    code = r.wait()
    return code, r.stderr(), time.monotonic() - r.start, r


def checkpoint_stage(out):
    try:
        with h5py.File(os.path.join(out, "checkpoint.h5"), "r") as f:
            return f.attrs["stage"]
    except (OSError, KeyError):
        return None


def stop_and_restart(line, out, sig, stage, delay):
    """Runs `line` into `out`, sends `sig` `delay` s after its first
    checkpoint of `stage` and restarts it. Returns a list of failures, or None
    when the signal came too late (the run had ended, or left the stage)."""
    shutil.rmtree(out, ignore_errors=True)
    r = Run(line)
    deadline = time.monotonic() + 60
    while checkpoint_stage(out) != stage and r.process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    time.sleep(delay)
    if r.process.poll() is not None:
        r.wait()
        return None
    r.process.send_signal(sig)
    code = r.wait(60)
    expected = 3 if sig == signal.SIGTERM else -signal.SIGKILL
    if code != expected:
        return [f"exit code {code} after {sig.name}, expected {expected}: {r.stderr().strip()[-300:]}"]
    found = checkpoint_stage(out)
    if found != stage:
        return None
    stopped = re.search(r"stopped by SIGTERM (?:at t = |while settling, at )(\S+) s", r.stderr())
    code, stderr, _, _ = run(line + ["--restart"])
    restarted = re.search(r"restarted from \S+ (?:at t = |while settling, at )(\S+) s", stderr)
    print(f"    {sig.name} in the {stage} stage{f' (stopped at {stopped.group(1)} s)' if stopped else ''}; "
          f"restarted at {restarted.group(1) if restarted else '?'} s, exit code {code}")
    if code != 0 or not restarted:
        return [f"--restart after {sig.name}: exit code {code}: {stderr.strip()[-300:]}"]
    return []


def stop_in_time(line, out, sig, stage, delay):
    """stop_and_restart, with shorter delays when the signal came too late:
    a run faster than the uninterrupted one on a machine whose load fell."""
    for _ in range(4):
        found = stop_and_restart(line, out, sig, stage, delay)
        if found is not None:
            return found
        print(f"    {sig.name} {delay:.2f} s after the first checkpoint missed the {stage} stage: again sooner")
        delay /= 4
    return [f"{sig.name} missed the {stage} stage four times: lengthen it"]


def compare_snapshots(reference, other, index):
    """Differences between the snapshots two folders list in `index`, and
    snapshot files the restarted run left beyond them."""
    failures = compare_listed(reference, other, index)
    # The killed run's snapshots after its checkpoint are gone or rewritten.
    _, files = listed(reference, index)
    written = sorted(n for n in os.listdir(other) if re.fullmatch(index[:-5] + r"_\d{6}\.h5", n))
    if written != [n for n in files if re.fullmatch(r".*_\d{6}\.h5", n)]:
        failures.append(f"{index}: the folder holds snapshot files {written[-3:]} beyond those listed")
    return failures


def compare(reference, other, case):
    found = []
    for index in case.indexes:
        found += compare_snapshots(reference, other, index)
    for history in case.histories:
        found += compare_histories(reference, other, history)
    found += compare_checkpoints(reference, other)
    if leftovers(other):
        found.append(f"temporary files left: {leftovers(other)}")
    return found


def one_ulp_off(build, source, work, case, reference):
    """A restart from a checkpoint with one particle's position one ulp off
    must end elsewhere: the comparison can fail."""
    out = os.path.join(work, "one_ulp_off")
    shutil.rmtree(out, ignore_errors=True)
    line = command(build, source, case.program, case.scene, case.overrides, case.threads, out)
    r = Run(line)
    deadline = time.monotonic() + 60
    while checkpoint_stage(out) != "run" and r.process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    r.process.send_signal(signal.SIGTERM)  # at once: most of the run follows
    if r.wait(60) != 3:
        return [f"one ulp off: exit code {r.process.returncode} after SIGTERM, expected 3"]
    with h5py.File(os.path.join(out, "checkpoint.h5"), "a") as f:
        x = f["mpm/particles/x"]
        middle = len(x) // 2
        position = x[middle]
        position[0] = np.nextafter(position[0], np.inf)
        x[middle] = position
        # An edit, not damage: its checksum follows (a damaged checkpoint is
        # refused, tests/damaged_checkpoint.py).
        x.attrs["crc32"] = np.int64(zlib.crc32(x[...].astype("<f8").tobytes()))
    code, stderr, _, _ = run(line + ["--restart"])
    if code != 0:
        return [f"one ulp off: --restart: exit code {code}: {stderr.strip()[-200:]}"]
    differ = compare(reference, out, case)
    print(f"  one particle's position one ulp off in the checkpoint: {len(differ)} differences, e.g. {differ[:2]}")
    return [] if differ else ["a checkpoint one ulp off restarts to the same end: the comparison sees nothing"]


def perturb_mesh(path):
    """Moves the first node inside a surface of a Gmsh 4.1 file by 1e-10 m
    (so little that no cell gets too narrow for the particles)."""
    with open(path) as f:
        lines = f.read().split("\n")
    at = lines.index("$Nodes") + 2
    while True:
        dim, _, _, count = (int(x) for x in lines[at].split())
        if dim == 2 and count > 0:
            coordinates = lines[at + 1 + count].split()
            coordinates[0] = repr(float(coordinates[0]) + 1e-10)
            lines[at + 1 + count] = " ".join(coordinates)
            break
        at += 1 + 2 * count
    with open(path, "w") as f:
        f.write("\n".join(lines))


def refusals(build, source, work):
    """--restart refuses what it cannot continue bit for bit, with exit code 2."""
    base = ("mpm_solid/mpm-solid", "elastic_block/elastic_block.toml")
    out = os.path.join(work, "refusals")
    shutil.rmtree(out, ignore_errors=True)
    failures = []

    def expect(what, line, words):
        code, stderr, _, _ = run(line)
        ok = code == 2 and re.search(words, stderr)
        print(f"  {what}: exit code {code}{'' if ok else ': ' + stderr.strip()[-200:]}")
        if not ok:
            failures.append(f"{what}: exit code {code}, expected 2 and '{words}'")

    expect("no folder", command(build, source, *base, [], 1, out, "--restart"), r"no such folder")
    os.makedirs(out)
    expect("no checkpoint", command(build, source, *base, [], 1, out, "--restart"), r"no checkpoint there")
    code, stderr, _, _ = run(command(build, source, *base, [], 1, out))
    if code != 0:
        return failures + [f"the run for the refusals failed: {stderr.strip()[-200:]}"]
    expect("a fresh run into it", command(build, source, *base, [], 1, out), r"--restart to continue it from its checkpoint")
    expect("other overrides", command(build, source, *base, ['scene.end_time="0.04 s"'], 1, out, "--restart"),
           r"other --set overrides")
    expect("--restart with --overwrite", command(build, source, *base, [], 1, out, "--restart", "--overwrite"),
           r"excludes")
    changed = os.path.join(work, "changed_elastic_block.toml")
    with open(os.path.join(source, "cases", base[1])) as f, open(changed, "w") as g:
        g.write(f.read() + "# one more comment\n")
    expect("another scene text", command(build, source, base[0], changed, [], 1, out, "--restart"),
           r"another scene text")
    for attribute, words in [("version", r"written by version 0\.0\.0"), ("build", r"another build")]:
        with h5py.File(os.path.join(out, "checkpoint.h5"), "a") as f:
            kept = f.attrs[attribute]
            f.attrs[attribute] = "0.0.0 (elsewhere)"
        expect(f"another {attribute}", command(build, source, *base, [], 1, out, "--restart"), words)
        with h5py.File(os.path.join(out, "checkpoint.h5"), "a") as f:
            f.attrs[attribute] = kept

    # The scene names a mesh file, which may change under the same scene text.
    copy = os.path.join(work, "mesh_changed")
    shutil.rmtree(copy, ignore_errors=True)
    os.makedirs(copy)
    for name in ("outburst.toml", "seam.msh"):
        shutil.copy(os.path.join(source, "cases", "outburst", name), copy)
    scene, mesh_out = os.path.join(copy, "outburst.toml"), os.path.join(copy, "out")
    short = ['mpm.settle.time="1 ms"', 'scene.end_time="2 ms"', 'output.interval="1 ms"']
    code, stderr, _, _ = run(command(build, source, "coupler/outburst", scene, short, 1, mesh_out))
    if code != 0:
        return failures + [f"the outburst run for the mesh refusal failed: {stderr.strip()[-200:]}"]
    perturb_mesh(os.path.join(copy, "seam.msh"))
    expect("another mesh", command(build, source, "coupler/outburst", scene, short, 1, mesh_out, "--restart"),
           r"another seepage mesh")
    return failures


def main():
    build, source, work = sys.argv[1:4]
    # Threads that sleep while they wait: on a machine busier than its cores,
    # spinning ones take 20 times longer (the results are the same).
    os.environ["OMP_WAIT_POLICY"] = "passive"
    rng = random.Random(int(sys.argv[4]) if len(sys.argv) > 4 else 1)
    failures = []
    started = time.monotonic()
    for case in CASES:
        case_started = time.monotonic()
        reference = os.path.join(work, re.sub(r"\W+", "_", case.name), "uninterrupted")
        shutil.rmtree(reference, ignore_errors=True)
        code, stderr, wall, r = run(command(build, source, case.program, case.scene, case.overrides, case.threads,
                                            reference))
        settled = r.when("settled for")
        print(f"{case.name}: uninterrupted run {wall:.2f} s"
              f"{f' (settled after {settled:.2f} s)' if settled else ''}, exit code {code}")
        if code != 0:
            failures.append(f"{case.name}: the uninterrupted run failed: {stderr.strip()[-300:]}")
            continue
        for sig, stage in case.stops:
            other = os.path.join(os.path.dirname(reference), f"{sig.name}_{stage}")
            line = command(build, source, case.program, case.scene, case.overrides, case.threads, other)
            # Early enough in the stage that a run somewhat faster than the
            # uninterrupted one is still in it.
            delay = (rng.uniform(0.0, 0.4) * settled if stage == "settling"
                     else rng.uniform(0.05, 0.6) * (wall - (settled or 0)))
            found = stop_in_time(line, other, sig, stage, delay)
            if not found:
                found = compare(reference, other, case)
            print(f"    {'bit for bit' if not found else 'DIFFERS: ' + '; '.join(found[:4])}")
            failures += [f"{case.name}, {sig.name} in the {stage} stage: {f}" for f in found]
        if case.name == "granular collapse":
            failures += [f"{case.name}: {f}" for f in one_ulp_off(build, source, work, case, reference)]
        if case.threads > 1:
            # What the README claims: runs at different thread counts differ
            # (round-off), so only a restart at the same count is bit for bit.
            single = os.path.join(os.path.dirname(reference), "one_thread")
            shutil.rmtree(single, ignore_errors=True)
            run(command(build, source, case.program, case.scene, case.overrides, 1, single))
            found = [d for index in case.indexes for d in compare_snapshots(reference, single, index)]
            print(f"    1 thread against {case.threads}: {'; '.join(found[:2]) if found else 'bit for bit'}")
            if not found:
                failures.append(f"{case.name}: 1 and {case.threads} threads agree bit for bit: the README's claim "
                                "that they differ is out of date")
        print(f"  ({time.monotonic() - case_started:.1f} s)")
    failures += refusals(build, source, work)
    print(f"all: {time.monotonic() - started:.1f} s")
    if failures:
        sys.exit("\n".join(failures))


if __name__ == "__main__":
    main()
