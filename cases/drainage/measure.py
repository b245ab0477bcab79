"""Errors of a drainage run (drainage.toml) against the self-similar
half-space solution (plot.py computes it) at the run's last output: pressure
(RMS along the seam's middle over the first 15 m, over p0) and the gas
released through the face (relative). For cases/study.py."""
import os

import numpy as np

from ..run_output import seepage_state
from .plot import DAY, MPA, similarity

# The scene's values (drainage.toml).
LAMBDA = 0.1 / (MPA ** 2 * DAY)
A = 2 * MPA ** -0.5
P0_PRESSURE, FACE_PRESSURE, HEIGHT = 3 * MPA, 0.1 * MPA, 3.0
P0 = P0_PRESSURE ** 2
D0 = 4 * LAMBDA * P0 ** 0.75 / A
_solution = None


def errors(run_dir):
    global _solution
    if _solution is None:
        _solution = similarity((FACE_PRESSURE / P0_PRESSURE) ** 2)
    z, f, slope = _solution
    t, nodes, p = seepage_state(run_dir)
    rows = np.unique(nodes[:, 1])
    middle = rows[np.argmin(np.abs(rows - HEIGHT / 2))]
    mid = np.isclose(nodes[:, 1], middle) & (nodes[:, 0] <= 15)
    exact = P0_PRESSURE * np.sqrt(np.interp(nodes[mid, 0] / np.sqrt(D0 * t), z, f, right=1.0))
    rms = float(np.sqrt(np.mean((p[mid] - exact) ** 2)) / P0_PRESSURE)
    history = np.genfromtxt(os.path.join(run_dir, "seepage_history.csv"), delimiter=",", names=True)
    released = -history["inflow_left_m3_per_m"][-1] / HEIGHT
    analytic = 2 * LAMBDA * P0 * slope * np.sqrt(history["time_s"][-1] / D0)
    return {"pressure": rms, "gas_released": abs(released / analytic - 1)}
