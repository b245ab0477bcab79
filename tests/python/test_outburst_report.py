"""The outburst report's seam measures on seams of known shape, then the report
itself from a short run of the shipped case.

The cavity row is what says whether the paper's "large cavity with a small
opening" formed; these cases pin down that it finds a carved one of the right
size, and does not read a seam loosened throughout, or a void sealed off from
the face, as one.
"""
import os
import subprocess
import sys

import numpy as np
import pytest

from cases.outburst import report

FACE, RIGHT, TOP = 25.0, 45.0, 9.0
SPACING = 1.0 / 6.0  # 2 x 2 particles in cells of 1/3 m, as shipped


@pytest.fixture(scope="module")
def seam():
    xs = np.arange(FACE + SPACING / 2, RIGHT, SPACING)
    ys = np.arange(SPACING / 2, TOP, SPACING)
    return np.array([(x, y) for x in xs for y in ys])


def measures(x0, x):
    cav = report.cavity(*report.seam_bins(x0, x, FACE, RIGHT, TOP, 0.5)[2:], 0.5)
    loose = report.loosened(*report.seam_bins(x0, x, FACE, RIGHT, TOP, 1.0)[2:], 1.0)
    return cav, loose


def eject(x, gone):
    """The coal in `gone` thrown into the tunnel (out of the seam's bins)."""
    y = x.copy()
    y[gone, 0] = FACE - 5.0
    return y


def test_untouched_seam(seam):
    cav, loose = measures(seam, seam)
    assert cav["area"] == 0
    assert loose["area"] == 0


def test_pear_shaped_cavity(seam):
    # A 2 m mouth 2 m long opening into a disc of radius 2.5 m.
    mouth = (seam[:, 0] < FACE + 2.5) & (np.abs(seam[:, 1] - 4.5) < 1.0)
    disc = np.hypot(seam[:, 0] - 30.0, seam[:, 1] - 4.5) < 2.5
    cav, _ = measures(seam, eject(seam, mouth | disc))
    carved = (mouth | disc).sum() * SPACING ** 2
    assert cav["area"] / carved == pytest.approx(1, abs=0.15)
    assert cav["depth"] == pytest.approx(7.5, abs=0.5)
    assert cav["height"] == pytest.approx(5.0, abs=0.5)
    assert cav["mouth"] == pytest.approx(2.0, abs=0.5)


def test_sealed_void_is_no_cavity(seam):
    sealed = np.hypot(seam[:, 0] - 36.0, seam[:, 1] - 4.5) < 2.5
    cav, loose = measures(seam, eject(seam, sealed))
    assert cav["area"] == 0
    assert 16 <= loose["area"] <= 30


def test_seam_loosened_throughout_is_no_cavity(seam):
    # Every fifth particle gone: the whole seam loosened at 80 %.
    thinned = np.arange(len(seam)) % 5 == 0
    cav, loose = measures(seam, eject(seam, thinned))
    assert cav["area"] == 0
    assert loose["area"] == 180
    assert loose["fill"] == pytest.approx(0.8, abs=0.02)


def test_report_of_a_run_has_every_row_and_figure(repo, outburst_run):
    subprocess.run([sys.executable, "-m", "cases.outburst.report", outburst_run], check=True,
                   stdout=subprocess.DEVNULL, cwd=repo)
    with open(os.path.join(outburst_run, "report.md")) as f:
        text = f.read()
    for row in ("peak speed, face centre", "farthest coal from the face", "cavity", "loosened seam coal",
                "gas released into the tunnel", "steepest pressure drop", "Energy budget"):
        assert row in text
    for k in range(3, 11):
        assert any(f.startswith(f"fig{k}_") and f.endswith(".png") for f in os.listdir(outburst_run)), k
