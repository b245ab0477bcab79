"""Figures of the drainage case against the self-similar half-space solution.

usage: python3 -m cases.drainage.plot RESULTS_DIR SCENE   (writes RESULTS_DIR/drainage_*.png)

The similarity solution P = P0 f(x / sqrt(D0 t)) of model-notes section 1 is
computed here by ODE shooting, independently of the C++ code.
"""
import sys
import glob
import os
import tomllib

import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ..units import value

MPA = 1e6
DAY = 86400.0


def similarity(face_ratio, z_max=10.0, dz=1e-3):
    """f(z) with f'' = -(z/2) f^(-3/4) f', f(0) = face_ratio, f(inf) = 1."""
    z = np.arange(0.0, z_max + dz, dz)

    def shoot(slope, keep=False):
        y, v = face_ratio, slope
        out = [y]
        for zi in z[:-1]:
            def rhs(zz, yy, vv):
                return -0.5 * zz * yy ** -0.75 * vv
            k1y, k1v = v, rhs(zi, y, v)
            k2y, k2v = v + 0.5 * dz * k1v, rhs(zi + 0.5 * dz, y + 0.5 * dz * k1y, v + 0.5 * dz * k1v)
            k3y, k3v = v + 0.5 * dz * k2v, rhs(zi + 0.5 * dz, y + 0.5 * dz * k2y, v + 0.5 * dz * k2v)
            k4y, k4v = v + dz * k3v, rhs(zi + dz, y + dz * k3y, v + dz * k3v)
            y += dz / 6 * (k1y + 2 * k2y + 2 * k3y + k4y)
            v += dz / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
            if keep:
                out.append(y)
            elif y > 1:
                return y
        return np.array(out) if keep else y

    lo, hi = 0.0, 1.0
    while shoot(hi) < 1:
        hi *= 2
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if shoot(mid) < 1 else (lo, mid)
    slope = 0.5 * (lo + hi)
    return z, shoot(slope, keep=True), slope


def main(results, scene_file):
    with open(scene_file, "rb") as f:
        scene = tomllib.load(f)
    region = scene["seepage"]["regions"][0]
    lam = value(region["lambda"], "m2/(Pa2 s)")
    a = value(region["gas_content_coefficient"], "Pa^-0.5")
    p0 = value(region["initial_pressure"], "Pa")
    pf = value(scene["seepage"]["boundaries"][0]["value"], "Pa")
    height = value(scene["seepage"]["mesh"]["size"][1], "m")
    P0 = p0 ** 2
    d0 = 4 * lam * P0 ** 0.75 / a
    z, f, slope = similarity((pf / p0) ** 2)

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
        exact = p0 * np.sqrt(np.interp(x / np.sqrt(d0 * t), z, f, right=1.0))
        ax.plot(x, exact / MPA, "k--", lw=1)
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
    released = -hist["inflow_left_m3_per_m"] / height  # per unit face area
    t = hist["time_s"]
    analytic = 2 * lam * P0 * slope * np.sqrt(t / d0)
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
    main(sys.argv[1], sys.argv[2])
