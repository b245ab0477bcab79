"""What a run folder holds, as the tests check it: the times each XDMF index
lists, the HDF5 files it names, whether each of them opens, and whether two
folders hold the same results bit for bit."""
import csv
import os
import re

import h5py
import numpy as np

WALL_CLOCK = {"seepage_s", "solid_s", "coupler_s"}  # coupling.csv: seconds each part took
WALL_CLOCK_FILES = {"wall_times.csv"}  # a coupled run's seconds by part, nothing else
# Checkpoint datasets that hold wall-clock seconds, or the length of a CSV
# with such columns.
WALL_CLOCK_STATE = re.compile(r"(first|second|coupler)_seconds$|coupling_log/bytes$")


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


def value(dataset):
    """A dataset's shape, type and bytes (text as text)."""
    data = dataset[()]
    if isinstance(data, (bytes, str)):
        return data
    data = np.asarray(data)
    return data.shape, data.dtype.str, data.tobytes()


def datasets(path, skip=None):
    """{name: value} of every dataset in an HDF5 file whose name `skip` does not match."""
    found = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and not (skip and skip.search(name)):
                found[name] = value(obj)
        f.visititems(visit)
        found["stage attribute"] = f.attrs.get("stage")
    return found


def differences(a, b):
    if a.keys() != b.keys():
        return [f"datasets {sorted(set(a) ^ set(b))} in one only"]
    return [f"{key} differs" for key in sorted(a) if a[key] != b[key]]


def compare_listed(reference, other, index):
    """Differences between the snapshots two folders list in `index`: the
    times, the files and every dataset of each."""
    times_a, files_a = listed(reference, index)
    times_b, files_b = listed(other, index)
    if times_a != times_b or files_a != files_b:
        return [f"{index}: lists {len(times_b)} times {times_b[-3:]}, expected {len(times_a)} {times_a[-3:]}"]
    failures = []
    for name in files_a:
        a, b = datasets(os.path.join(reference, name)), datasets(os.path.join(other, name))
        failures += [f"{name}:{d}" for d in differences(a, b)]
    return failures


def compare_checkpoints(reference, other):
    """The whole state at the last checkpoint, but for wall-clock seconds."""
    a = datasets(os.path.join(reference, "checkpoint.h5"), WALL_CLOCK_STATE)
    b = datasets(os.path.join(other, "checkpoint.h5"), WALL_CLOCK_STATE)
    return [f"checkpoint.h5: {d}" for d in differences(a, b)]


def rows(path):
    with open(path) as f:
        return [{k: v for k, v in row.items() if k not in WALL_CLOCK} for row in csv.DictReader(f)]


def compare_histories(reference, other, history):
    """The first row where two CSV histories differ, but for wall-clock columns."""
    a, b = rows(os.path.join(reference, history)), rows(os.path.join(other, history))
    if len(a) != len(b):
        return [f"{history}: {len(b)} rows, expected {len(a)}"]
    for k, (ra, rb) in enumerate(zip(a, b)):
        if ra != rb:
            column = next(c for c in ra if ra[c] != rb.get(c))
            return [f"{history}: row {k + 1} differs in {column}: {rb.get(column)} instead of {ra[column]}"]
    return []
