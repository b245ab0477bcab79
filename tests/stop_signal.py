#!/usr/bin/python3
"""SIGINT and SIGTERM stop a run at the end of its current step or window:
exit code 3, a log line saying so, the state it reached as the last snapshot
listed in its index (readable), and histories complete up to it. Before,
the signal killed the run like kill -9, losing up to an output interval.

usage (from the top folder): python3 -m tests.stop_signal BUILD_DIR SOURCE_DIR WORK_DIR"""
import csv
import os
import re
import shutil
import signal
import subprocess
import sys
import time

from tests.run_folder import leftovers, listed, unreadable

# program, scene, overrides for a run far longer than the test, signal, the
# indexes and the histories whose last time must be the stop's.
RUNS = [
    ("seepage_fe/seepage-fe", "drainage/drainage.toml",
     ['seepage.time_step="10 s"', "seepage.time_step_growth=1"], signal.SIGINT,
     ["seepage.xdmf"], [("seepage_history.csv", "time_s")]),
    ("mpm_solid/mpm-solid", "elastic_block/elastic_block.toml", ['scene.end_time="100 s"'], signal.SIGTERM,
     ["particles.xdmf"], [("mpm_history.csv", "time_s")]),
    ("coupler/outburst", "gas_face/gas_face.toml", ['scene.end_time="100 s"', 'coupling.scheme="explicit"'],
     signal.SIGTERM,
     ["seepage.xdmf", "particles.xdmf"], [("coupling.csv", "time"), ("mpm_history.csv", "time_s")]),
]


def last_time(path, column):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return float(rows[-1][column]) if rows else None


def stop_one(build, source, work, program, scene, overrides, sig, indexes, histories):
    name = os.path.basename(program)
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    command = [os.path.join(build, program), os.path.join(source, "cases", scene), "-q", "-o", out]
    for o in overrides:
        command += ["--set", o]
    run = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    # Signal once the run loop has written its first snapshot and gone on.
    deadline = time.monotonic() + 60
    while not listed(out, indexes[0])[0] and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)
    run.send_signal(sig)
    try:
        _, stderr = run.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        run.kill()
        return [f"{name}: still running 60 s after {sig.name}"]
    failures = []
    stopped = re.search(rf"stopped by {sig.name} at t = (\S+) s", stderr)
    print(f"{name}: exit code {run.returncode}; {stopped.group(0) if stopped else stderr.strip()}")
    if run.returncode != 3:
        failures.append(f"{name}: exit code {run.returncode}, expected 3")
    if not stopped:
        return failures + [f"{name}: no log line 'stopped by {sig.name}'"]
    t = float(stopped.group(1))
    for index in indexes:
        times, files = listed(out, index)
        print(f"  {index}: {len(times)} times, the last {times[-1] if times else None}")
        if not times or abs(times[-1] - t) > 1e-8 * max(t, 1) or t <= 0:
            failures.append(f"{name}: {index} does not end with the stop's time {t}")
        failures += [f"{name}: {bad}" for bad in unreadable(out, files)]
    for history, column in histories:
        at = last_time(os.path.join(out, history), column)
        print(f"  {history}: last row at {at}")
        if at is None or abs(at - t) > 1e-8 * max(t, 1):
            failures.append(f"{name}: {history} ends at {at}, not at the stop's time {t}")
    if leftovers(out):
        failures.append(f"{name}: temporary files left: {leftovers(out)}")
    return failures


def main():
    build, source, work = sys.argv[1:4]
    failures = []
    for run in RUNS:
        failures += stop_one(build, source, work, *run)
    if failures:
        sys.exit("; ".join(failures))


if __name__ == "__main__":
    main()
