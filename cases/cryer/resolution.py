"""Cryer's sphere at three resolutions: the centre's pressure against the
series, and what each cost.

usage: python3 -m cases.cryer.resolution [--program build/coupler/outburst]
                                         [--out results/cryer_resolution] [--jobs 1] [--measure-only]
runs cryer.toml with the seepage's and the MPM's cells both a / 8, a / 12 and
a / 16 (one thread each, `jobs` side by side) and writes OUT/resolution.csv:
a row per run with the errors of measure.py (over the outputs, every 0.02 s)
and its wall time. The shipped copy is resolution/resolution.csv beside this
file; cases.readme_tables writes docs/verification/cryer.md's table from it. --measure-only
runs nothing and measures the runs OUT holds (their rows without wall_s).
"""
import argparse
import os

from ..runs import run_side_by_side, write_rows
from .measure import errors

SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cryer.toml")
SIDE = 1.25  # [m], the mesh's and the grid's (cryer.toml)
CELLS_ACROSS_RADIUS = [8, 12, 16]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--program", default="build/coupler/outburst")
    ap.add_argument("--out", default="results/cryer_resolution")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--measure-only", action="store_true")
    args = ap.parse_args()
    runs = []
    for n in CELLS_ACROSS_RADIUS:
        cells = round(SIDE * n)
        overrides = [f"seepage.mesh.cells=[{cells}, {cells}, {cells}]", f'mpm.grid.cell_size="{SIDE / cells!r} m"']
        runs.append((n, overrides, os.path.join(args.out, f"a_over_{n}")))
    walls = {}
    if not args.measure_only:
        os.makedirs(args.out, exist_ok=True)
        walls = run_side_by_side(args.program, SCENE, [(o, d) for _, o, d in runs], args.jobs)
    rows = []
    for n, _, directory in runs:
        row = {"cells_across_radius": n, **errors(directory)}
        if directory in walls:
            row["wall_s"] = round(walls[directory], 1)
        rows.append(row)
        print(f"cells of a / {n}: centre pressure RMS error {row['centre_rms']:.4f} of p0, worst {row['centre_worst']:.4f}; "
              f"peak {row['peak']:.4f} against {row['exact_peak']:.4f}")
    write_rows(os.path.join(args.out, "resolution.csv"), rows)


if __name__ == "__main__":
    main()
