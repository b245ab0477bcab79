"""The measure cases.study uses when a study names none: quantities any run
has, compared with the reference run's. Seepage: the mean and largest gas
pressure at the last output; MPM: the particles' mean and largest
displacement at the last output."""
import glob
import os

import numpy as np

from .run_output import particle_state, seepage_state


def quantities(run_dir):
    q = {}
    if glob.glob(os.path.join(run_dir, "seepage_0*.h5")):
        _, _, p = seepage_state(run_dir)
        q.update(mean_pressure=float(np.mean(p)), largest_pressure=float(np.max(np.abs(p))))
    if glob.glob(os.path.join(run_dir, "particles_0*.h5")):
        _, u = particle_state(run_dir)
        d = np.linalg.norm(u, axis=1)
        q.update(mean_displacement=float(np.mean(d)), largest_displacement=float(np.max(d)))
    if not q:
        raise RuntimeError(f"{run_dir}: no seepage or particle output to measure")
    return q
