#!/usr/bin/python3
"""Run one coupled scene under every coupling scheme and window, and print what
each costs and how far its answer is from a reference.

usage: scheme_study.py SCENE [--windows "10 ms" "5 ms" "2.5 ms"] [--out DIR]
                       [--outburst build/coupler/outburst] [--set KEY=VALUE ...]

The reference is the implicit IQN-ILS run at half the smallest window. The
error is the RMS difference of the final gas pressure field from the
reference's, over the reference's largest |p|. Writes DIR/scheme_study.md and
DIR/scheme_study.csv; runs one at a time (each uses every core).
"""
import argparse
import csv
import glob
import os
import re
import subprocess
import time

import h5py
import numpy as np

# The fixed-stress row applies to scenes with Biot storage only; elsewhere its
# note says why it did not run.
SCHEMES = [
    ("explicit", ['coupling.scheme="explicit"']),
    ("explicit, fixed stress", ['coupling.scheme="explicit"', "coupling.fixed_stress=true"]),
    ("implicit, constant", ['coupling.scheme="implicit"', 'coupling.acceleration="constant"']),
    ("implicit, Aitken", ['coupling.scheme="implicit"', 'coupling.acceleration="aitken"']),
    ("implicit, IQN-ILS", ['coupling.scheme="implicit"', 'coupling.acceleration="iqn_ils"']),
]


def seconds(window):
    value, unit = re.fullmatch(r"\s*([0-9.eE+-]+)\s*(ms|s)\s*", window).groups()
    return float(value) * (1e-3 if unit == "ms" else 1.0)


def run(args, directory, overrides):
    command = [args.outburst, args.scene, "-q", "-o", directory]
    for o in list(args.set) + overrides:
        command += ["--set", o]
    start = time.monotonic()
    done = subprocess.run(command, capture_output=True, text=True)
    wall = time.monotonic() - start
    if done.returncode != 0:
        return None, wall, done.stderr.strip().splitlines()[-1] if done.stderr.strip() else "failed"
    last = sorted(glob.glob(os.path.join(directory, "seepage_0*.h5")))[-1]
    with h5py.File(last) as f:
        pressure = f["mesh/p"][:]
    log = np.atleast_1d(np.genfromtxt(os.path.join(directory, "coupling.csv"), delimiter=",", names=True))
    return (pressure, log["iterations"].mean()), wall, ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--windows", nargs="+", default=["10 ms", "5 ms", "2.5 ms"])
    ap.add_argument("--out", default="results/scheme_study")
    ap.add_argument("--outburst", default="build/coupler/outburst")
    ap.add_argument("--set", action="append", default=[], help="an override for every run")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    finest = min(args.windows, key=seconds)
    reference_window = f"{seconds(finest) / 2 * 1e3:g} ms"
    result, wall, error = run(args, os.path.join(args.out, "reference"),
                              SCHEMES[-1][1] + [f'coupling.window="{reference_window}"'])
    if result is None:
        raise SystemExit(f"the reference run failed: {error}")
    reference = result[0]
    scale = np.abs(reference).max()
    print(f"reference: implicit IQN-ILS, window {reference_window}, {wall:.1f} s", flush=True)

    rows = []
    for label, overrides in SCHEMES:
        for window in args.windows:
            tag = re.sub(r"[^a-z0-9]+", "_", f"{label} {window}".lower())
            result, wall, error = run(args, os.path.join(args.out, tag), overrides + [f'coupling.window="{window}"'])
            row = {"scheme": label, "window": window, "wall_s": wall}
            if result is None:
                row.update(error_rel=float("nan"), iterations=float("nan"), note=error)
            else:
                pressure, iterations = result
                row.update(error_rel=float(np.sqrt(np.mean((pressure - reference) ** 2)) / scale),
                           iterations=float(iterations), note="")
            rows.append(row)
            print(row, flush=True)

    with open(os.path.join(args.out, "scheme_study.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    lines = [f"# Scheme study: `{args.scene}`", "",
             f"Error: RMS of the final pressure minus the reference's (implicit IQN-ILS, window "
             f"{reference_window}), over its largest |p|.", "",
             "| scheme | window | error | sub-iterations / window | wall [s] | note |", "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['scheme']} | {r['window']} | {r['error_rel']:.2e} | {r['iterations']:.2f} | "
                     f"{r['wall_s']:.1f} | {r['note'][:80]} |")
    with open(os.path.join(args.out, "scheme_study.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
