#!/usr/bin/python3
"""Whether two run folders of the same scene hold the same results, bit for
bit: every snapshot each XDMF index lists (dataset by dataset), every CSV
history row by row, and the last checkpoint's whole state; wall-clock seconds
(columns, and wall_times.csv whole) and the program's version and build
(attributes) are left out, so that two builds can be compared. For checking
that a change moved no result: build both sides with
-DOUTBURST_NO_FP_CONTRACTION=ON (where GCC places fused multiply-adds moves
with inlining), run the scene with each on the same thread count, then

    scripts/same-results.py REFERENCE_RUN OTHER_RUN

Exit 0 when equal, 1 listing the first differences, 2 for a folder that is
not a run."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from run_folder import WALL_CLOCK_FILES, compare_checkpoints, compare_histories, compare_listed  # noqa: E402


def files(folder, suffix):
    return sorted(n for n in os.listdir(folder) if n.endswith(suffix) and n not in WALL_CLOCK_FILES)


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    reference, other = argv[1], argv[2]
    for folder in (reference, other):
        if not os.path.isdir(folder) or not files(folder, ".xdmf") + files(folder, ".csv"):
            print(f"{folder}: expected a run folder (XDMF indexes, CSV histories)", file=sys.stderr)
            return 2
    found = []
    for kind, compare in ((".xdmf", compare_listed), (".csv", compare_histories)):
        names = files(reference, kind)
        if names != files(other, kind):
            found.append(f"the folders hold different {kind} files: {names} and {files(other, kind)}")
        found += [d for name in names if os.path.exists(os.path.join(other, name))
                  for d in compare(reference, other, name)]
    checkpoints = [os.path.exists(os.path.join(folder, "checkpoint.h5")) for folder in (reference, other)]
    if checkpoints[0] != checkpoints[1]:
        found.append(f"checkpoint.h5 in {(reference, other)[checkpoints[1]]} only")
    elif checkpoints[0]:
        found += compare_checkpoints(reference, other)
    if found:
        print(f"{other} differs from {reference}:")
        for d in found[:20]:
            print("  " + d)
        return 1
    print(f"{other} equals {reference} bit for bit ({', '.join(files(reference, '.xdmf') + files(reference, '.csv'))}"
          f"{', checkpoint.h5' if os.path.exists(os.path.join(reference, 'checkpoint.h5')) else ''})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
