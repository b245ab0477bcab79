"""Reading a run's last output, for the studies' measure modules."""
import glob
import os

import h5py


def last_snapshot(run_dir, prefix):
    return sorted(glob.glob(os.path.join(run_dir, f"{prefix}_0*.h5")))[-1]


def seepage_state(run_dir):
    """Time [s], node coordinates and nodal pressure [Pa] of the last output."""
    with h5py.File(os.path.join(run_dir, "seepage_mesh.h5")) as f:
        nodes = f["nodes"][:]
    with h5py.File(last_snapshot(run_dir, "seepage")) as f:
        return float(f.attrs["time"]), nodes, f["mesh/p"][:]


def particle_state(run_dir):
    """Initial positions and displacements [m] of the particles at the last output."""
    with h5py.File(last_snapshot(run_dir, "particles")) as f:
        x = f["particles/points"][:, :2]
        u = f["particles/displacement"][:, :2]
    return x - u, u
