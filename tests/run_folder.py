"""What a run folder holds, as the tests check it: the times each XDMF index
lists, the HDF5 files it names, and whether each of them opens."""
import os
import re

import h5py


def listed(directory, index):
    """(times, files) the index lists; ([], []) when the index does not exist."""
    path = os.path.join(directory, index)
    if not os.path.exists(path):
        return [], []
    with open(path) as f:
        text = f.read()
    times = [float(t) for t in re.findall(r'<Time Value="([^"]+)"', text)]
    files = sorted(set(re.findall(r'>([^<>:]+\.h5):/', text)))
    return times, files


def unreadable(directory, files):
    """The files of `files` that h5py cannot open and read."""
    bad = []
    for name in files:
        try:
            with h5py.File(os.path.join(directory, name), "r") as f:
                f.visititems(lambda _, obj: obj[()] if isinstance(obj, h5py.Dataset) else None)
        except OSError as e:
            bad.append(f"{name}: {e}")
    return bad


def leftovers(directory):
    """Temporary files a run left behind."""
    return [n for n in os.listdir(directory) if ".partial-" in n]
