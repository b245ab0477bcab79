"""The NAME=BUILD_DIR arguments of the scripts that compare builds."""
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
