"""Errors of a Terzaghi run (terzaghi.toml) against the analytic series, at the
run's last output: pore pressure (RMS over the seepage nodes, over p0) and the
settlement of the top particles (relative). For cases/study.py."""
import numpy as np

from ..run_output import particle_state, seepage_state

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


def errors(run_dir):
    t, nodes, p = seepage_state(run_dir)
    rms = float(np.sqrt(np.mean((p - pressure(H - nodes[:, 1], t)) ** 2)) / P0)
    x0, u = particle_state(run_dir)
    top = x0[:, 1] > x0[:, 1].max() - 1e-9
    measured = -u[top, 1].sum()
    expected = sum(settlement(y, t) for y in x0[top, 1])
    return {"pressure": rms, "settlement": abs(measured / expected - 1)}
