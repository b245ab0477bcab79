#!/usr/bin/python3
"""Check the outburst ensemble command (cases.outburst.ensemble) on a short
run: every member finishes and the statistics cover each headline number; the
heterogeneous coal of a seed is the same bit for bit on two thread counts
(two runs side by side with cores / 2 threads each, then seed 1 alone with all
the cores; skipped as a check on a machine of one core);
two seeds give two different coals and two different runs.

usage: ensemble_check.py OUTBURST_PROGRAM WORK_DIR
"""
import csv
import os
import subprocess
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(HERE)


def ensemble(program, out, seeds, jobs):
    subprocess.run([sys.executable, "-m", "cases.outburst.ensemble", "--outburst", program, "--out", out, "--seeds", str(seeds),
                    "--jobs", str(jobs), "--end-time", "0.02 s"], check=True, stdout=subprocess.DEVNULL, cwd=SOURCE)


def coal(run_dir):
    """The particles' strength factors followed by their modulus factors."""
    with h5py.File(os.path.join(run_dir, "particles_000000.h5")) as f:
        return np.concatenate([f["particles/strength_scale"][()], f["particles/modulus_scale"][()]])


def main():
    program, work = sys.argv[1], sys.argv[2]
    side_by_side, alone = os.path.join(work, "two_jobs"), os.path.join(work, "one_job")
    ensemble(program, side_by_side, 2, 2)
    ensemble(program, alone, 1, 1)
    with open(os.path.join(side_by_side, "ensemble.csv")) as f:
        rows = list(csv.DictReader(f))
    failures = []
    if len(rows) != 2 or any(r.get("failure") for r in rows):
        failures.append(f"expected two finished members, got {rows}")
    with open(os.path.join(side_by_side, "ensemble.md")) as f:
        table = f.read()
    for label in ["peak speed", "farthest coal", "coal ejected", "fully damaged", "gas released"]:
        if label not in table:
            failures.append(f"ensemble.md has no row for {label}")
    one_thread, two_threads = coal(os.path.join(side_by_side, "seed_001")), coal(os.path.join(alone, "seed_001"))
    other = coal(os.path.join(side_by_side, "seed_002"))
    print(f"seed 1: {len(one_thread) // 2} particles, factors {one_thread.min():.3f}-{one_thread.max():.3f}, "
          f"mean {one_thread.mean():.4f}; on two threads identical: {np.array_equal(one_thread, two_threads)}; "
          f"seed 2 differs in {np.count_nonzero(one_thread != other)} of the {len(other)} factors")
    if (os.cpu_count() or 1) > 1 and not np.array_equal(one_thread, two_threads):
        failures.append("seed 1 drew another coal on two threads than on one")
    if np.count_nonzero(one_thread != other) < 0.99 * len(other):
        failures.append("seeds 1 and 2 drew (nearly) the same coal")
    if rows and rows[0]["fully_damaged_fraction"] == rows[-1]["fully_damaged_fraction"] and \
            rows[0]["centre_m_per_s"] == rows[-1]["centre_m_per_s"]:
        failures.append("seeds 1 and 2 ran alike")
    if failures:
        sys.exit("\n".join(failures))


if __name__ == "__main__":
    main()
