"""Run-out of the axisymmetric granular collapse (granular_collapse_3d.toml)
against Lube, Huppert, Sparks & Hallworth (2004), J. Fluid Mech. 508,
175-199: (R_inf - R0) / R0 = 1.24 a for a = H0 / R0 below 1.7, 1.6 a^(1/2)
above (the two meet near a = 1.7). The column's radius and height are the
run's own (its scene's bodies: R0 from their footprint's area, a quarter
disc's), the deposit's from the particles at the last output. For
runout.py and the test.

usage: python3 -m cases.granular_collapse_3d.measure RUN_DIR
"""
import csv
import math
import os
import sys

import h5py
import numpy as np

from ..run_output import last_snapshot, scene
from ..units import value


def lube(a):
    """(R_inf - R0) / R0 of Lube et al.'s axisymmetric columns at aspect ratio a."""
    return 1.24 * a if a < 1.7 else 1.6 * math.sqrt(a)


def column(s):
    """R0 and H0 [m] of the scene's quarter column: the radius of the quarter
    disc of its bodies' footprint on the floor (x, z), and their height."""
    area, height = 0.0, 0.0
    for body in s["mpm"]["bodies"]:
        lo = [value(x, "m") for x in body["box_min"]]
        hi = [value(x, "m") for x in body["box_max"]]
        area += (hi[0] - lo[0]) * (hi[2] - lo[2])
        height = max(height, hi[1])
    return math.sqrt(4 * area / math.pi), height


def deposit(run_dir):
    """The particles' initial and last positions [m] and last speeds [m/s], and the last output's time [s]."""
    with h5py.File(last_snapshot(run_dir, "particles")) as f:
        x = f["particles/points"][:]
        u = f["particles/displacement"][:]
        speed = np.linalg.norm(f["particles/velocity"][:], axis=1)
        time = float(f.attrs["time"])
    return x - u, x, speed, time


def run_out(run_dir):
    """The deposit's run-out and height against the column's, and Lube's run-out.
    A particle stands for a cube of the particle spacing s: the deposit's edge
    is the farthest particle's centre plus s / 2 (the column's, R0, is its
    footprint's), its top the highest centre plus s / 2. The run-out along the
    two walls (within 10 deg of x or z) and along the diagonal (40-50 deg)
    shows how round the deposit is on a square grid."""
    r0, h0 = column(scene(run_dir))
    x0, x, speed, time = deposit(run_dir)
    spacing = float(np.diff(np.unique(x0[:, 0])).min())
    radius = np.hypot(x[:, 0], x[:, 2])
    angle = np.degrees(np.arctan2(x[:, 2], x[:, 0]))
    edge = lambda inside: float(radius[inside].max()) + spacing / 2
    with open(os.path.join(run_dir, "mpm_history.csv")) as f:
        removed = int(float(list(csv.DictReader(f))[-1]["removed_total"]))
    a = h0 / r0
    r_inf = edge(np.ones(len(x), dtype=bool))
    return {"aspect_ratio": a, "R0_m": r0, "H0_m": h0, "spacing_m": spacing, "particles": len(x),
            "time_s": time, "R_inf_m": r_inf, "spread": (r_inf - r0) / r0, "lube_spread": lube(a),
            "spread_along_walls": (edge((angle < 10) | (angle > 80)) - r0) / r0,
            "spread_along_diagonal": (edge((angle > 40) & (angle < 50)) - r0) / r0,
            "H_inf_m": float(x[:, 1].max()) + spacing / 2, "fastest_m_per_s": float(speed.max()),
            "removed": removed}


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__.strip().splitlines()[-1])
    for key, number in run_out(sys.argv[1]).items():
        print(f"{key}: {number:.6g}")
