"""Figures of the drainage case against the self-similar half-space solution
(solution.py), for the scene the run ran (read from its output).

usage: python3 -m cases.drainage.plot RESULTS_DIR   (writes RESULTS_DIR/drainage_*.png)
"""
import argparse
import glob
import os

import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ..run_output import scene
from .solution import Seam

MPA = 1e6
DAY = 86400.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", help="a drainage run's output folder")
    results = ap.parse_args().results
    seam = Seam(scene(results))

    with h5py.File(os.path.join(results, "seepage_mesh.h5")) as m:
        nodes = m["nodes"][:]
    mid = np.isclose(nodes[:, 1], np.median(np.unique(nodes[:, 1])))
    order = np.argsort(nodes[mid, 0])
    x = nodes[mid, 0][order]

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for path in sorted(glob.glob(os.path.join(results, "seepage_0*.h5")))[1::2]:
        with h5py.File(path) as s:
            t = float(s.attrs["time"])
            p = s["mesh/p"][:][mid][order]
        line, = ax.plot(x, p / MPA, lw=2, label=f"t = {t / DAY:.0f} d")
        ax.plot(x, seam.pressure(x, t) / MPA, "k--", lw=1)
    ax.plot([], [], "k--", lw=1, label="self-similar solution")
    ax.set_xlabel("distance from the face x [m]")
    ax.set_ylabel("gas pressure p [MPa]")
    ax.set_title("Drainage through the face: FE (colour) vs similarity solution")
    ax.set_xlim(0, 15)
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(results, "drainage_profiles.png"), dpi=120)

    hist = np.genfromtxt(os.path.join(results, "seepage_history.csv"), delimiter=",", names=True)
    released = -hist["inflow_left_m3_per_m"] / seam.height  # per unit face area
    t = hist["time_s"]
    analytic = seam.released(t)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(t / DAY, released, lw=2, label="FE (boundary reactions)")
    ax.plot(t / DAY, analytic, "k--", label=r"$2\lambda P_0 f'(0)\sqrt{t/D_0}$")
    ax.set_xlabel("time [d]")
    ax.set_ylabel("gas released per face area [m$^3$/m$^2$]")
    ax.set_title("Cumulative gas emission through the face")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(results, "drainage_emission.png"), dpi=120)
    error = abs(released[-1] - analytic[-1]) / analytic[-1]
    print(f"plot: released {released[-1]:.4g} m3/m2 by {t[-1] / DAY:.0f} d, "
          f"similarity solution {analytic[-1]:.4g} (relative difference {error:.2e})")
    print(f"plot: figures in {os.path.abspath(results)}/drainage_profiles.png, drainage_emission.png")


if __name__ == "__main__":
    main()
