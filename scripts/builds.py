"""The NAME=BUILD_DIR arguments of the scripts that compare builds, and the
machine they ran on."""
import os
import sys


def named_builds(items, program):
    """[(name, build dir)] from NAME=BUILD_DIR items, each with `program` (a path inside a build) built in it."""
    builds = []
    for item in items:
        name, sep, folder = item.partition("=")
        if not sep or not os.path.isfile(os.path.join(folder, program)):
            sys.exit(f"{item}: expected NAME=BUILD_DIR with {program} built in it")
        builds.append((name, folder))
    return builds


def host():
    """The processor a comparison ran on: its model, its widest vector
    extension and the cores this process may use. A build's ratio to
    another depends on it (README.md, "The same builds on another
    processor"): kernels vectorised over particles gain more from 512-bit
    vectors than from 128-bit ones."""
    model, flags = "unknown processor", set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() == "model name":
                    model = value.strip()
                elif key.strip() == "flags":
                    flags = set(value.split())
                if model != "unknown processor" and flags:
                    break
    except OSError:
        pass
    vectors = next((name for flag, name in [("avx512f", "AVX-512"), ("avx2", "AVX2"), ("avx", "AVX")]
                    if flag in flags), "SSE")
    return f"{model}, {vectors}, {len(os.sched_getaffinity(0))} cores"
