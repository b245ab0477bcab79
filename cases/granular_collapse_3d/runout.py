"""The axisymmetric collapse's run-out at two resolutions, under the shipped
cone and the other one.

usage: python3 -m cases.granular_collapse_3d.runout [--program build/mpm_solid/mpm-solid]
                                                    [--out results/granular_collapse_3d_runout] [--jobs 2] [--measure-only]
runs granular_collapse_3d.toml with cells of R0 / 8 and R0 / 16 (3 thousand
and 26 thousand particles), under the inner Drucker-Prager cone it ships with
and the outer one, one thread each, `jobs` side by side (the R0 / 16 runs take
most of the time: the CSV's wall_s), and writes OUT/runout.csv: a row per run
with the deposit's run-out against Lube et al.'s (measure.py). The shipped
copy is runout/runout.csv beside this file. --measure-only runs nothing and
measures the runs OUT holds (their rows without wall_s).
"""
import argparse
import os

from ..runs import run_side_by_side, write_rows
from .measure import run_out

SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "granular_collapse_3d.toml")
FITS = ["inner", "outer"]
# R0 / 8 and R0 / 16 (R0 = 0.5 m): strip edges fall between particles.
CELLS = {8: "0.0625 m", 16: "0.03125 m"}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--program", default="build/mpm_solid/mpm-solid")
    ap.add_argument("--out", default="results/granular_collapse_3d_runout")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--measure-only", action="store_true")
    args = ap.parse_args()
    runs = []
    for fit in FITS:
        for across, cell in CELLS.items():
            overrides = [f'mpm.grid.cell_size="{cell}"', f'mpm.materials[0].fit="{fit}"']
            runs.append((fit, across, overrides, os.path.join(args.out, f"{fit}_{across}")))
    walls = {}
    if not args.measure_only:
        os.makedirs(args.out, exist_ok=True)
        walls = run_side_by_side(args.program, SCENE, [(o, d) for _, _, o, d in runs], args.jobs)
    rows = []
    for fit, across, _, directory in runs:
        row = {"fit": fit, "cells_across_R0": across, **run_out(directory)}
        if directory in walls:
            row["wall_s"] = walls[directory]
        rows.append(row)
        print(f"{fit} cone, cells of R0 / {across} ({row['particles']} particles): (R_inf - R0) / R0 = "
              f"{row['spread']:.3f} against Lube's {row['lube_spread']:.3f} (ratio {row['spread'] / row['lube_spread']:.2f}); "
              f"along the walls {row['spread_along_walls']:.3f}, the diagonal {row['spread_along_diagonal']:.3f}; "
              f"H_inf / H0 = {row['H_inf_m'] / row['H0_m']:.3f}; fastest particle at t = {row['time_s']:g} s "
              f"{row['fastest_m_per_s']:.3g} m/s; {row['removed']} removed")
    write_rows(os.path.join(args.out, "runout.csv"), rows)


if __name__ == "__main__":
    main()
