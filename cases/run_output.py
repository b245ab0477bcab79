"""Reading a run's output, for the measures and reports: its last snapshot,
and the scene it ran, which every HDF5 output carries as provenance."""
import glob
import os
import tomllib

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


def _text(attribute):
    return attribute.decode() if isinstance(attribute, bytes) else str(attribute)


def apply_override(root, assignment):
    """One --set "dotted.key=<TOML value>" on a scene's tables, as common/scene.cpp
    applies it ("regions[1]" steps into an array of tables)."""
    path, text = assignment.split("=", 1)
    *tables, key = path.split(".")
    node = root
    for part in tables:
        name, _, index = part.partition("[")
        node = node.setdefault(name, {})
        if index:
            node = node[int(index.rstrip("]"))]
    node[key] = tomllib.loads("v = " + text)["v"]


def scene(run_dir):
    """The scene a run ran, as its program read it: the scene file's text and the
    run's --set overrides, both stored in each of its HDF5 outputs
    (common/field_output.cpp), so a measure reads the run's own values."""
    for path in sorted(glob.glob(os.path.join(run_dir, "*.h5"))):
        with h5py.File(path) as f:
            if "scene_text" not in f.attrs:
                continue
            root = tomllib.loads(_text(f.attrs["scene_text"]))
            for assignment in _text(f.attrs["scene_overrides"]).splitlines():
                apply_override(root, assignment)
            return root
    raise FileNotFoundError(f"{run_dir}: no HDF5 output holding the run's scene")
