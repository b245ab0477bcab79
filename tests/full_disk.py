#!/usr/bin/python3
"""A coupled run whose disk fills while it writes a snapshot: exit code 1 with
a clear message (before: SIGSEGV), no temporary file left, and both indexes
list the same times, every listed file readable.

The disk "fills" through RLIMIT_FSIZE (no file may grow past 30 kB, and
SIGXFSZ is ignored so the write fails with EFBIG): the seepage snapshots
(16 kB) fit, the first particle snapshot (100 kB) does not.

usage (from the top folder): python3 -m tests.full_disk OUTBURST SCENE WORK_DIR"""
import os
import resource
import shutil
import signal
import subprocess
import sys

from tests.run_folder import leftovers, listed, unreadable


def fill_at_30_kb():
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (30000, resource.RLIM_INFINITY))


def main():
    program, scene, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    done = subprocess.run([program, scene, "-q", "-o", work, "--set", 'scene.end_time="0.002 s"'],
                          capture_output=True, text=True, preexec_fn=fill_at_30_kb)
    message = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else ""
    seepage_times, seepage_files = listed(work, "seepage.xdmf")
    particle_times, particle_files = listed(work, "particles.xdmf")
    print(f"exit code {done.returncode}: {message}")
    print(f"seepage.xdmf lists {seepage_times}, particles.xdmf {particle_times}")
    failures = []
    if done.returncode != 1:
        failures.append(f"exit code {done.returncode}, expected 1")
    if "cannot write " + os.path.join(work, "particles_000000.h5") + ": File too large" not in message:
        failures.append("the message must name the file and the full disk")
    if seepage_times != particle_times:
        failures.append("the indexes list different times")
    if leftovers(work):
        failures.append(f"temporary files left: {leftovers(work)}")
    failures += unreadable(work, seepage_files + particle_files)
    # A disk full before the run writes anything: a failed run too, exit code
    # 1 (before: 2, as for a bad command line).
    full = os.path.join(work, "full_at_start")
    done = subprocess.run([program, scene, "-q", "-o", full], capture_output=True, text=True,
                          preexec_fn=lambda: (signal.signal(signal.SIGXFSZ, signal.SIG_IGN),
                                              resource.setrlimit(resource.RLIMIT_FSIZE, (0, resource.RLIM_INFINITY))))
    message = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else ""
    print(f"full at the start: exit code {done.returncode}: {message}")
    if done.returncode != 1 or "File too large" not in message:
        failures.append(f"a disk full at the start: exit code {done.returncode}, expected 1 naming the full disk")
    if failures:
        sys.exit("; ".join(failures))


if __name__ == "__main__":
    main()
