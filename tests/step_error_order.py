#!/usr/bin/python3
"""Check that the MPM time step's own energy error (integration_J_per_m in
mpm_history.csv, integration_J in 3D) falls at the order expected when the step is halved.

usage: step_error_order.py COARSE_DIR FINE_DIR [--order 1] [--slack 0.2] [--at-least ORDER]

Both runs cover the same time with the fine run's step half the coarse one's.
The measure is the largest |integration| over each run; the order observed is
log2 of their ratio and must lie within slack of the order expected, or with
--at-least be no lower than that (a step's error still falling faster than
first order, as over a short run whose release transient dominates, shows the
books as well: a wrong book does not fall).
"""
import argparse
import csv
import math
import os
import sys


def largest_step_error(directory):
    """The largest |integration|, the end time and the median step of a run."""
    with open(os.path.join(directory, "mpm_history.csv")) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{directory}: no rows")
    steps = sorted(float(r["dt_s"]) for r in rows)
    column = "integration_J_per_m" if "integration_J_per_m" in rows[0] else "integration_J"
    return (max(abs(float(r[column])) for r in rows), float(rows[-1]["time_s"]),
            steps[len(steps) // 2])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("coarse")
    ap.add_argument("fine")
    ap.add_argument("--order", type=float, default=1.0)
    ap.add_argument("--slack", type=float, default=0.2)
    ap.add_argument("--at-least", type=float)
    args = ap.parse_args()
    (coarse, t_coarse, dt_coarse), (fine, t_fine, dt_fine) = largest_step_error(args.coarse), largest_step_error(args.fine)
    if not math.isclose(t_coarse, t_fine, rel_tol=1e-6):
        sys.exit(f"the runs end at different times: {t_coarse:g} s and {t_fine:g} s")
    if not math.isclose(dt_coarse / dt_fine, 2, rel_tol=0.1):
        sys.exit(f"the fine run's step is not half the coarse one's: median steps {dt_coarse:.4g} s and "
                 f"{dt_fine:.4g} s")
    if fine <= 0 or coarse <= 0:
        sys.exit("a run shows no time step error at all: the books cannot be measuring it")
    order = math.log2(coarse / fine)
    expected = f"at least {args.at_least:g}" if args.at_least is not None else f"{args.order:g} +- {args.slack:g}"
    print(f"largest time step error {coarse:.4g}, with half the step {fine:.4g} (J/m, or J in 3D): order {order:.2f} "
          f"(expected {expected})")
    if order < args.at_least if args.at_least is not None else abs(order - args.order) > args.slack:
        sys.exit(f"observed order {order:.2f} is not {expected}")


if __name__ == "__main__":
    main()
