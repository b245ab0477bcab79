"""The outburst report's seam measures on seams of known shape, then the report
itself from a short run of the shipped case.

usage: test_outburst_report.py PROJECT_SOURCE_DIR RUN_DIR

The cavity row is what says whether the paper's "large cavity with a small
opening" formed; these cases pin down that it finds a carved one of the right
size, and does not read a seam loosened throughout, or a void sealed off from
the face, as one.
"""
import os
import subprocess
import sys

import numpy as np

FACE, RIGHT, TOP = 25.0, 45.0, 9.0
SPACING = 1.0 / 6.0  # 2 x 2 particles in cells of 1/3 m, as shipped


def seam():
    xs = np.arange(FACE + SPACING / 2, RIGHT, SPACING)
    ys = np.arange(SPACING / 2, TOP, SPACING)
    return np.array([(x, y) for x in xs for y in ys])


def measures(report, x0, x):
    cav = report.cavity(*report.seam_bins(x0, x, FACE, RIGHT, TOP, 0.5)[2:], 0.5)
    loose = report.loosened(*report.seam_bins(x0, x, FACE, RIGHT, TOP, 1.0)[2:], 1.0)
    return cav, loose


def eject(x, gone):
    """The coal in `gone` thrown into the tunnel (out of the seam's bins)."""
    y = x.copy()
    y[gone, 0] = FACE - 5.0
    return y


def check(failures, name, value, low, high):
    if not low <= value <= high:
        failures.append(f"{name}: {value:.4g}, expected {low:.4g}..{high:.4g}")


def main():
    source, run_dir = sys.argv[1], sys.argv[2]
    sys.path.insert(0, source)
    from cases.outburst import report
    failures = []
    x0 = seam()

    cav, loose = measures(report, x0, x0)
    check(failures, "untouched seam: cavity", cav["area"], 0, 0)
    check(failures, "untouched seam: loosened", loose["area"], 0, 0)

    # A pear: a 2 m mouth 2 m long opening into a disc of radius 2.5 m.
    mouth = (x0[:, 0] < FACE + 2.5) & (np.abs(x0[:, 1] - 4.5) < 1.0)
    disc = np.hypot(x0[:, 0] - 30.0, x0[:, 1] - 4.5) < 2.5
    cav, loose = measures(report, x0, eject(x0, mouth | disc))
    carved = (mouth | disc).sum() * SPACING ** 2
    check(failures, "pear: cavity area / carved area", cav["area"] / carved, 0.85, 1.15)
    check(failures, "pear: depth [m]", cav["depth"], 7.5 - 0.5, 7.5 + 0.5)
    check(failures, "pear: height [m]", cav["height"], 5.0 - 0.5, 5.0 + 0.5)
    check(failures, "pear: mouth [m]", cav["mouth"], 2.0 - 0.5, 2.0 + 0.5)

    # The same disc sealed off from the face by standing coal: no cavity.
    sealed = np.hypot(x0[:, 0] - 36.0, x0[:, 1] - 4.5) < 2.5
    cav, loose = measures(report, x0, eject(x0, sealed))
    check(failures, "sealed void: cavity", cav["area"], 0, 0)
    check(failures, "sealed void: loosened area [m2]", loose["area"], 16, 30)

    # The seam loosened throughout (every fifth particle gone): no cavity, the
    # whole seam loosened at 80 %.
    thinned = np.arange(len(x0)) % 5 == 0
    cav, loose = measures(report, x0, eject(x0, thinned))
    check(failures, "loosened seam: cavity", cav["area"], 0, 0)
    check(failures, "loosened seam: loosened area [m2]", loose["area"], 180, 180)
    check(failures, "loosened seam: fill", loose["fill"], 0.78, 0.82)

    # The report from a run: every row and figure written.
    subprocess.run([sys.executable, "-m", "cases.outburst.report", run_dir], check=True, stdout=subprocess.DEVNULL,
                   cwd=source)
    text = open(os.path.join(run_dir, "report.md")).read()
    for row in ("peak speed, face centre", "farthest coal from the face", "cavity", "loosened seam coal",
                "gas released into the tunnel", "steepest pressure drop", "Energy budget"):
        if row not in text:
            failures.append(f"report.md lacks the row '{row}'")
    for k in range(3, 11):
        if not any(f.startswith(f"fig{k}_") and f.endswith(".png") for f in os.listdir(run_dir)):
            failures.append(f"no fig{k}_*.png in {run_dir}")

    for f in failures:
        print("FAIL", f)
    print("outburst report measures:", "failed" if failures else "pass")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
