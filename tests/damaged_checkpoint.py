#!/usr/bin/python3
"""--restart refuses a damaged checkpoint with exit code 2, naming the file and
the dataset: a byte flipped in a dataset's data (its CRC-32 no longer
matches) or in the file's structure (HDF5's metadata checksums), a checksum
missing, and values no run holds written with a matching checksum (as an
edit would): a NaN velocity or an infinite pressure, a negative particle id
or one given twice, a particle mass or a cell's conductivity of 0, a
coupling slice past the end of its vector. An intact copy
of each checkpoint restarts (exit code 0). Before (issue 57): every one of
these restarted with exit code 0, or failed later, blamed on the time step.

usage: damaged_checkpoint.py BUILD_DIR SOURCE_DIR WORK_DIR"""
import os
import shutil
import subprocess
import sys
import zlib

import h5py
import numpy as np

# (program, scene, overrides): short runs that write a checkpoint.
RUNS = {
    "mpm": ("mpm_solid/mpm-solid", "granular_collapse/granular_collapse.toml",
            ['scene.end_time="0.02 s"', 'output.checkpoint_interval="0.01 s"']),
    "seepage": ("seepage_fe/seepage-fe", "drainage/drainage.toml",
                ['scene.end_time="1 d"', 'output.checkpoint_interval="12 h"']),
    "coupled": ("coupler/outburst", "gas_face/gas_face.toml",
                ['scene.end_time="0.004 s"', 'output.checkpoint_interval="0.002 s"']),
}


def command(build, source, run, out):
    program, scene, overrides = RUNS[run]
    line = [os.path.join(build, program), os.path.join(source, "cases", scene), "-q", "-o", out]
    for o in overrides:
        line += ["--set", o]
    return line


def flip_data(dataset, byte):
    """Flips a bit of byte `byte` of the dataset's data, in the file itself."""
    def damage(path):
        with h5py.File(path, "r") as f:
            offset = f[dataset].id.get_offset()
        with open(path, "r+b") as f:
            f.seek(offset + byte)
            value = f.read(1)[0]
            f.seek(offset + byte)
            f.write(bytes([value ^ 0x10]))
    return damage


def flip_header(dataset):
    """Flips a bit inside the dataset's object header (its shape, type, layout)."""
    def damage(path):
        with h5py.File(path, "r") as f:
            offset = h5py.h5o.get_info(f[dataset].id).addr
        with open(path, "r+b") as f:
            f.seek(offset + 12)
            value = f.read(1)[0]
            f.seek(offset + 12)
            f.write(bytes([value ^ 0x01]))
    return damage


def edit(dataset, change):
    """Changes the dataset's values and writes the checksum that matches them."""
    def damage(path):
        with h5py.File(path, "a") as f:
            d = f[dataset]
            values = d[...]
            change(values)
            d[...] = values
            d.attrs["crc32"] = np.int64(zlib.crc32(np.ascontiguousarray(values).tobytes()))
    return damage


def unchecked(dataset):
    def damage(path):
        with h5py.File(path, "a") as f:
            del f[dataset].attrs["crc32"]
    return damage


def setitem(index, value):
    return lambda values: values.__setitem__(index, value)


# (name, run, damage, words the message must hold)
CASES = [
    ("a bit flipped in the particles' positions", "mpm", flip_data("mpm/particles/x", 8 * 1001 + 3),
     ["checkpoint.h5", "dataset /mpm/particles/x", "do not match the checksum written with them"]),
    ("a bit flipped in the positions' object header", "mpm", flip_header("mpm/particles/x"), ["checkpoint.h5"]),
    ("a checksum missing", "mpm", unchecked("mpm/particles/v"),
     ["checkpoint.h5", "dataset /mpm/particles/v", "has no checksum"]),
    ("a NaN velocity", "mpm", edit("mpm/particles/v", setitem((7, 0), np.nan)),
     ["checkpoint.h5", "dataset /mpm/particles/v", "holds nan in row 7"]),
    ("a particle id of -1", "mpm", edit("mpm/particles/id", setitem(5, -1)),
     ["checkpoint.h5", "dataset /mpm/particles/id", "has a negative id"]),
    ("a particle id given twice", "mpm", edit("mpm/particles/id", lambda v: v.__setitem__(5, v[6])),
     ["checkpoint.h5", "dataset /mpm/particles/id", "has the id of row 5 too"]),
    ("a particle mass of 0", "mpm", edit("mpm/particles/mass", setitem(3, 0.0)),
     ["checkpoint.h5", "dataset /mpm/particles/mass", "(row 3) has the mass 0"]),
    ("a negative step count", "mpm", edit("mpm/steps", setitem(0, -3)),
     ["checkpoint.h5", "dataset /mpm/steps", "-3 steps"]),
    ("a negative count of particles removed", "mpm", edit("mpm/removed", setitem(0, -1)),
     ["checkpoint.h5", "dataset /mpm/removed", "-1 particles removed"]),
    ("a bit flipped in the pressures", "seepage", flip_data("seepage/u", 8 * 10 + 6),
     ["checkpoint.h5", "dataset /seepage/u", "do not match the checksum"]),
    ("an infinite pressure", "seepage", edit("seepage/u", setitem(10, np.inf)),
     ["checkpoint.h5", "dataset /seepage/u", "holds inf in row 10"]),
    ("a conductivity of 0", "seepage", edit("seepage/conductivity", setitem(4, 0.0)),
     ["checkpoint.h5", "dataset /seepage/conductivity", "cell 4 has the conductivity 0"]),
    ("a bit flipped in the coupled run's positions", "coupled", flip_data("model/mpm/particles/x", 8 * 11 + 7),
     ["checkpoint.h5", "dataset /model/mpm/particles/x", "do not match the checksum"]),
    ("a coupling slice past the end of its vector", "coupled",
     edit("model/coupling/slice_extents", lambda v: v.__setitem__(1, v[1] + 1)),
     ["checkpoint.h5", "dataset /model/coupling/slice_extents", "of a y of"]),
]


def main():
    build, source, work = sys.argv[1:4]
    shutil.rmtree(work, ignore_errors=True)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    failures = []
    for run in RUNS:
        done = subprocess.run(command(build, source, run, os.path.join(work, run)), capture_output=True, text=True,
                              env=env)
        if done.returncode != 0:
            sys.exit(f"the {run} run failed: {done.stderr.strip()[-300:]}")
    for name, run, damage, words in [("intact", run, None, []) for run in RUNS] + CASES:
        out = os.path.join(work, f"{run}_{name}".replace(" ", "_").replace("'", ""))
        shutil.copytree(os.path.join(work, run), out)
        if damage:
            damage(os.path.join(out, "checkpoint.h5"))
        done = subprocess.run(command(build, source, run, out) + ["--restart"], capture_output=True, text=True,
                              env=env)
        lines = done.stderr.strip().splitlines()
        message = lines[-1] if lines else ""
        expected = 0 if damage is None else 2
        missing = [w for w in words if w not in message]
        ok = done.returncode == expected and not missing
        print(f"{'ok  ' if ok else 'FAIL'} {run:8} {name}: exit {done.returncode}: {message[:400]}")
        if not ok:
            failures.append(f"{name}: exit {done.returncode} (expected {expected}), missing {missing}")
    if failures:
        sys.exit("\n".join(failures))


if __name__ == "__main__":
    main()
