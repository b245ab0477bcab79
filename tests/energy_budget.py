#!/usr/bin/python3
"""Check a run's MPM energy books (mpm_history.csv): every value finite, the
method never creating energy (a blow-up does), and what it loses bounded.

usage: energy_budget.py DIR [--most-created 0.01] [--most-lost 0.5]

The balance error (total energy now minus at the start) is measured against the
work of the external forces (the gas) done so far: above +most_created of it at
any output means energy was created; below -most_lost at the end, more of the
gas work vanished into the grid than the scene's tests allow.
"""
import argparse
import csv
import math
import os
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("directory")
    ap.add_argument("--most-created", type=float, default=0.01)
    ap.add_argument("--most-lost", type=float, default=0.5)
    args = ap.parse_args()
    path = os.path.join(args.directory, "mpm_history.csv")
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: no rows")
    worst_created, at = -math.inf, 0.0
    for r in rows:
        values = {k: float(v) for k, v in r.items()}
        bad = [k for k, v in values.items() if not math.isfinite(v)]
        if bad:
            sys.exit(f"{path}: t = {values['time_s']:g} s: non-finite {', '.join(bad)}")
        # Below 1 J/m of work the ratio means nothing (the first steps).
        share = values["balance_error_J_per_m"] / max(values["external_work_J_per_m"], 1.0)
        if share > worst_created:
            worst_created, at = share, values["time_s"]
    last = {k: float(v) for k, v in rows[-1].items()}
    lost = -last["balance_error_J_per_m"] / max(last["external_work_J_per_m"], 1.0)
    print(f"{path}: {len(rows)} outputs to t = {last['time_s']:g} s; gas work {last['external_work_J_per_m']:.4g} J/m; "
          f"largest balance error {worst_created:+.2%} of it (t = {at:g} s); lost at the end {lost:.1%}")
    failed = []
    if worst_created > args.most_created:
        failed.append(f"energy created: {worst_created:.2%} of the work at t = {at:g} s (at most "
                      f"{args.most_created:.2%})")
    if lost > args.most_lost:
        failed.append(f"energy lost: {lost:.1%} of the work at the end (at most {args.most_lost:.0%})")
    if failed:
        sys.exit("; ".join(failed))


if __name__ == "__main__":
    main()
