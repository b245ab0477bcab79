"""Errors of a drainage run (drainage.toml) against the self-similar
half-space solution (solution.py) at the run's last output: pressure (RMS
along the seam's middle over the first 15 m, over p0) and the gas released
through the face (relative). The seam's values are the run's own (its scene).
For cases.study."""
import os

import numpy as np

from ..run_output import scene, seepage_state
from .solution import Seam


def errors(run_dir):
    seam = Seam(scene(run_dir))
    t, nodes, p = seepage_state(run_dir)
    rows = np.unique(nodes[:, 1])
    middle = rows[np.argmin(np.abs(rows - seam.height / 2))]
    mid = np.isclose(nodes[:, 1], middle) & (nodes[:, 0] <= 15)
    rms = float(np.sqrt(np.mean((p[mid] - seam.pressure(nodes[mid, 0], t)) ** 2)) / seam.p0)
    history = np.genfromtxt(os.path.join(run_dir, "seepage_history.csv"), delimiter=",", names=True)
    released = -history["inflow_left_m3_per_m"][-1] / seam.height
    return {"pressure": rms, "gas_released": abs(released / seam.released(history["time_s"][-1]) - 1)}
