"""Running the programs for the studies, sensitivity runs and ensembles, and
writing their rows."""
import concurrent.futures
import csv
import os
import subprocess
import time

# The programs' exit code for a valid scene refused because what it asks for
# cannot work in its regime (common/program.hpp).
REFUSED = 4


def run_one(program, scene, overrides, directory, threads):
    """Runs a program on a scene with overrides; its wall time and, if it failed, its last message."""
    # Studies rerun into their folders: the earlier run's files are replaced.
    command = [program, scene, "-q", "-o", directory, "--overwrite"]
    for o in overrides:
        command += ["--set", o]
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    start = time.monotonic()
    done = subprocess.run(command, capture_output=True, text=True, env=env)
    wall = time.monotonic() - start
    note = ""
    if done.returncode != 0:
        lines = (done.stderr or done.stdout).strip().splitlines()
        note = lines[-1] if lines else f"exit code {done.returncode}"
        if done.returncode == REFUSED:
            note = "refused: " + note.split("] ")[-1]
    return wall, note


def run_side_by_side(program, scene, runs, jobs):
    """Runs the scene with each (overrides, directory) of `runs`, one thread
    each, `jobs` side by side; returns their wall times by directory. A run
    that fails stops the study with its last message."""
    walls = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {pool.submit(run_one, program, scene, overrides, directory, 1): directory
                   for overrides, directory in runs}
        for done in concurrent.futures.as_completed(futures):
            wall, note = done.result()
            if note:
                raise SystemExit(f"{futures[done]}: {note}")
            walls[futures[done]] = wall
            print(f"  {futures[done]}: {wall:.0f} s", flush=True)
    return walls


def write_rows(path, rows):
    """Rows of dicts to a CSV whose columns are every key, in the order first met."""
    fields = []
    for r in rows:
        fields += [k for k in r if k not in fields]
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
