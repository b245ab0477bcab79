"""Errors of a Mandel run (mandel.toml) against the analytic series
(Abousleiman et al. 1996) at the run's last output: pore pressure (RMS over the
seepage nodes, over p0) and the settlement of the top particles (relative,
against the plate's). For cases/study.py."""
import numpy as np

from ..run_output import particle_state, seepage_state

# The scene's values (mandel.toml's header): quarter a x b, force F per metre
# of depth on the quarter's plate.
A, B, F, E, NU, S, ALPHA, MOBILITY = 1.0, 1.0, 1e4, 1e7, 0.0, 1e-7, 1.0, 1.833e-10 / 1e-3
G = E / (2 * (1 + NU))
K = E / (3 * (1 - 2 * NU))
KU = K + ALPHA ** 2 / S
SKEMPTON = ALPHA / S / KU
NU_U = (3 * KU - 2 * G) / (2 * (3 * KU + G))
C = MOBILITY / S * (K + 4 * G / 3) / (KU + 4 * G / 3)
P0 = F * SKEMPTON * (1 + NU_U) / (3 * A)


def _roots(count):
    """tan(x) = k x: sin x - k x cos x changes sign once in (0, pi/2) and in each (n pi, n pi + pi/2)."""
    k = (1 - NU) / (NU_U - NU)
    n = np.arange(count)
    lo, hi = np.maximum(n * np.pi, 1e-9), n * np.pi + np.pi / 2
    f = lambda x: np.sin(x) - k * x * np.cos(x)
    rising = f(lo) < 0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        below = (f(mid) < 0) == rising
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


ROOTS = _roots(300)


def pressure(x, t):
    r = ROOTS[None, :]
    x = np.atleast_1d(x)[:, None]
    terms = np.sin(r) / (r - np.sin(r) * np.cos(r)) * (np.cos(r * x / A) - np.cos(r)) * np.exp(-r * r * C * t / A ** 2)
    return 2 * F * SKEMPTON * (1 + NU_U) / (3 * A) * terms.sum(axis=1)


def settlement(t):
    r = ROOTS
    terms = np.sin(r) * np.cos(r) / (r - np.sin(r) * np.cos(r)) * np.exp(-r * r * C * t / A ** 2)
    return -B * F / (G * A) * (-(1 - NU) / 2 + (1 - NU_U) * terms.sum())


def errors(run_dir):
    t, nodes, p = seepage_state(run_dir)
    rms = float(np.sqrt(np.mean((p - pressure(nodes[:, 0], t)) ** 2)) / P0)
    x0, u = particle_state(run_dir)
    top = x0[:, 1] > x0[:, 1].max() - 1e-9
    return {"pressure": rms, "settlement": abs(-u[top, 1].mean() / settlement(t) - 1)}
