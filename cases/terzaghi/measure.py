"""Errors of a Terzaghi run (terzaghi.toml) against the analytic series, at the
run's last output: pore pressure (RMS over the seepage nodes, over p0) and the
settlement of the top particles (relative). For cases/study.py."""
import glob
import os

import h5py
import numpy as np

# The scene's values (terzaghi.toml's header).
E, NU, Q, S, MOBILITY, ALPHA, H = 1e7, 0.25, 1e4, 1e-7, 1.833e-10 / 1e-3, 1.0, 1.0
M = E * (1 - NU) / ((1 + NU) * (1 - 2 * NU))
P0 = ALPHA * Q / (ALPHA ** 2 + S * M)
CV = MOBILITY / (S + ALPHA ** 2 / M)


def pressure(z, t):
    """p at depth z below the drained top."""
    m = np.pi * (2 * np.arange(400) + 1) / 2
    z = np.atleast_1d(z)[:, None]
    return (2 * P0 / m * np.sin(m * z / H) * np.exp(-m * m * CV * t / H ** 2)).sum(axis=1)


def settlement(y, t):
    """Downward displacement at height y: the strain (q - alpha p) / M integrated from the bottom."""
    at = (np.arange(200) + 0.5) * y / 200
    return float(((Q - ALPHA * pressure(H - at, t)) / M).sum() * y / 200)


def last(run_dir, prefix):
    return sorted(glob.glob(os.path.join(run_dir, f"{prefix}_0*.h5")))[-1]


def errors(run_dir):
    with h5py.File(os.path.join(run_dir, "seepage_mesh.h5")) as f:
        nodes = f["nodes"][:]
    with h5py.File(last(run_dir, "seepage")) as f:
        t = float(f.attrs["time"])
        p = f["mesh/p"][:]
    rms = float(np.sqrt(np.mean((p - pressure(H - nodes[:, 1], t)) ** 2)) / P0)
    with h5py.File(last(run_dir, "particles")) as f:
        x = f["particles/points"][:, :2]
        u = f["particles/displacement"][:, :2]
    x0 = x - u
    top = x0[:, 1] > x0[:, 1].max() - 1e-9
    measured = -u[top, 1].sum()
    expected = sum(settlement(y, t) for y in x0[top, 1])
    return {"pressure": rms, "settlement": abs(measured / expected - 1)}
