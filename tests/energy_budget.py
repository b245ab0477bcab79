#!/usr/bin/python3
"""Check a run's MPM energy books (mpm_history.csv): every value finite, the
balance error and the time step's own error each never above a share of the
largest energy term.

usage: energy_budget.py DIR [--most-open 0.01] [--most-step 0.1]

The energies are per metre of depth (_J_per_m) in a plane run, in joules (_J)
in a 3D one. The largest term is the largest change any term of the account
shows over the run (kinetic, strain and gravitational energy from their first
values; the dissipated, transferred and external ones from zero), as
mpm::EnergyAudit measures it. The balance error (total energy now minus at
the start) above most_open of it at any output means energy the books do not
hold; the time step's own error (integration) above most_step, a step too
close to the stable one or a blow-up.
"""
import argparse
import csv
import math
import os
import sys

# The terms whose changes set the scale; the time step's own error is judged
# against them, not one of them.
TERMS = ["kinetic", "strain", "gravity", "plastic", "damage", "damping", "walls", "transfer", "left_grid",
         "external_work"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("directory")
    ap.add_argument("--most-open", type=float, default=0.01)
    ap.add_argument("--most-step", type=float, default=0.1)
    args = ap.parse_args()
    path = os.path.join(args.directory, "mpm_history.csv")
    with open(path) as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    if not rows:
        sys.exit(f"{path}: no rows")
    for r in rows:
        bad = [k for k, v in r.items() if not math.isfinite(v)]
        if bad:
            sys.exit(f"{path}: t = {r['time_s']:g} s: non-finite {', '.join(bad)}")
    first = rows[0]
    unit = "J_per_m" if "kinetic_J_per_m" in first else "J"
    shown = unit.replace("_per_", "/")
    e = lambda r, term: r[f"{term}_{unit}"]
    stored = {"kinetic", "strain", "gravity"}
    largest = max(abs(e(r, t) - (e(first, t) if t in stored else 0)) for r in rows for t in TERMS)
    worst = max(rows, key=lambda r: abs(e(r, "balance_error")))
    share = abs(e(worst, "balance_error")) / max(largest, 1e-300)
    step = max(abs(e(r, "integration") - e(first, "integration")) for r in rows) / max(largest, 1e-300)
    last = rows[-1]
    print(f"{path}: {len(rows)} outputs to t = {last['time_s']:g} s; largest term {largest:.4g} {shown}; balance "
          f"error at most {e(worst, 'balance_error'):+.4g} {shown} ({share:.2%} of it, t = {worst['time_s']:g} s); "
          f"time step's own error at most {step:.2%}; at the end transfer {e(last, 'transfer'):.4g} {shown}, "
          f"time step {e(last, 'integration'):.4g} {shown}, walls {e(last, 'walls'):.4g} {shown}")
    if share > args.most_open:
        sys.exit(f"energy books open by {share:.2%} of the largest term (at most {args.most_open:.2%})")
    if step > args.most_step:
        sys.exit(f"the time step's own energy error reached {step:.2%} of the largest term (at most "
                 f"{args.most_step:.2%})")


if __name__ == "__main__":
    main()
