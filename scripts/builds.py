"""The NAME=BUILD_DIR arguments of the scripts that compare builds, and the
machine they ran on."""
import os
import platform
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
    """The processor a comparison ran on: its model (with family and model
    numbers, since a virtual machine may report no more than a brand name),
    its widest vector extension and the logical CPUs this process may use. A
    build's ratio to another depends on it (docs/performance/index.md,
    "Hosts"): kernels vectorised over particles gain more from
    256-bit vectors than from 128-bit ones."""
    fields = {}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, sep, value = line.partition(":")
                if not sep and fields:
                    break  # the first processor's entry is enough
                fields.setdefault(key.strip(), value.strip())
    except OSError:
        pass
    model = fields.get("model name") or platform.processor() or platform.machine() or "unknown processor"
    if "cpu family" in fields and "model" in fields:
        model += f" (family {fields['cpu family']}, model {fields['model']})"
    flags = set(fields.get("flags", fields.get("Features", "")).split())
    vectors = next((name for flag, name in [("avx512f", "AVX-512"), ("avx2", "AVX2"), ("avx", "AVX"),
                                             ("sse2", "SSE2"), ("sve", "SVE"), ("asimd", "NEON")]
                    if flag in flags), "vector extensions unknown")
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return f"{model}, {vectors}, {cpus} CPUs"
