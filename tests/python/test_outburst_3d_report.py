"""The 3D outburst's report (cases.outburst_3d.report): its cavity measure on
seams of known shape, the hexahedra's faces it draws the pressure on, the wall
time it reads from the log, then the whole report on a run of the shipped
heading a few milliseconds long (cells of 1 m, a few seconds) beside a plane
run as short: every number it writes finite, every figure there.

The cavity row is what says whether the paper's "large cavity with a small
opening" formed in 3D; these cases pin down that a carved one is measured at
its size and a void sealed off from the face is not one.
"""
import csv
import math
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from cases.outburst.report import bin_counts
from cases.outburst_3d.headline import cavity, wall_time
from cases.outburst_3d.report import faces_on_plane

FACE, RIGHT, TOP, FAR = 25.0, 45.0, 9.0, 6.0
SPACING = 0.25  # 2 x 2 x 2 particles in cells of 1/2 m, as shipped
BIN = 0.5
FIGURES = ["fig3_pressure", "fig4_pressure_profile", "fig5_damage", "fig6_min_principal_stress", "fig7_velocity",
           "fig8_tracer_velocity", "fig9_tracer_displacement", "fig10_pile_and_seam", "fig11_heap_plan",
           "fig12_damage_mid_height", "fig13_seam_fill_plan"]


@pytest.fixture(scope="module")
def seam():
    axes = [np.arange(lo + SPACING / 2, hi, SPACING) for lo, hi in ((FACE, RIGHT), (0.0, TOP), (0.0, FAR))]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def measure(x0, gone):
    """The cavity once the coal in `gone` is thrown into the heading."""
    x = x0.copy()
    x[gone, 0] = FACE - 5.0
    edges = [np.arange(lo, hi + 1e-9, BIN) for lo, hi in ((FACE, RIGHT), (0.0, TOP), (0.0, FAR))]
    return cavity(*bin_counts(x0, x, edges), BIN)


def test_untouched_seam_has_no_cavity(seam):
    assert measure(seam, np.zeros(len(seam), bool)) == {"volume": 0, "depth": 0, "mouth": 0, "width": 0, "height": 0}


def test_carved_cavity_is_measured_at_its_size(seam):
    # A mouth 2 m high and 1 m from the axis, 2 m long, opening into half a
    # ball of radius 2.5 m on the plane of symmetry.
    x, y, z = seam.T
    mouth = (x < FACE + 2.0) & (np.abs(y - 4.5) < 1.0) & (z < 1.0)
    ball = np.sqrt((x - 29.0) ** 2 + (y - 4.5) ** 2 + z ** 2) < 2.5
    hole = measure(seam, mouth | ball)
    carved = (mouth | ball).sum() * SPACING ** 3
    print(f"carved {carved:.2f} m3, measured {hole}")
    assert hole["volume"] / carved == pytest.approx(1, abs=0.15)
    assert hole["depth"] == pytest.approx(6.5, abs=0.5)
    assert hole["width"] == pytest.approx(2.5, abs=0.5)
    assert hole["height"] == pytest.approx(5.0, abs=0.5)
    assert hole["mouth"] == pytest.approx(2.0, abs=0.25)


def test_sealed_void_is_no_cavity(seam):
    x, y, z = seam.T
    assert measure(seam, np.sqrt((x - 36.0) ** 2 + (y - 4.5) ** 2 + (z - 3.0) ** 2) < 2.5)["volume"] == 0


def test_faces_on_the_plane_go_round_their_corners():
    # Two unit cubes stacked along z, corners in VTK's order: only the lower
    # one has a face on z = 0.
    nodes = np.array([(x, y, z) for z in (0, 1, 2) for y in (0, 1) for x in (0, 1)], float)
    at = {tuple(p): i for i, p in enumerate(nodes)}
    cube = lambda z: [at[(x, y, z + dz)] for dz in (0, 1) for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))]
    quads = faces_on_plane(nodes, np.array([cube(1), cube(0)]))
    assert quads.shape == (1, 4)
    xy = nodes[quads[0], :2]
    assert np.all(nodes[quads[0], 2] == 0)
    # The shoelace area of a quadrilateral whose corners go round it is its area.
    assert abs(np.dot(xy[:, 0], np.roll(xy[:, 1], -1)) - np.dot(xy[:, 1], np.roll(xy[:, 0], -1))) / 2 == 1


def test_wall_time_is_the_runs_own(tmp_path):
    log = tmp_path / "run.log"
    log.write_text("[01:00:00] [outburst] [info] done: 2 windows, 2 sub-iterations, 38 MPM steps, 0.5 s wall; x\n"
                   f"[01:00:00] [outburst] [info] results: {tmp_path / 'other'}\n"
                   "[01:00:09] [outburst] [info] done: 500 windows, 500 sub-iterations, 9 MPM steps, 812 s wall; y\n"
                   f"[01:00:09] [outburst] [info] results: {tmp_path / 'mine'}\n")
    assert wall_time(log, str(tmp_path / "mine")) == 812.0
    with pytest.raises(ValueError):
        wall_time(log, str(tmp_path / "elsewhere"))


def run(program, scene, folder, *settings):
    """Runs a scene on one thread into folder; its log beside it."""
    log = f"{folder}.log"
    with open(log, "w") as f:
        subprocess.run([program, scene, "-o", folder, "--overwrite"] + [a for s in settings for a in ("--set", s)],
                       check=True, stdout=f, stderr=subprocess.STDOUT, env=os.environ | {"OMP_NUM_THREADS": "1"})
    return log


def numbers(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 1
    return {k: float(v) for k, v in rows[0].items() if k not in ("version", "run")}


def test_report_of_a_short_run_has_every_row_and_figure(repo, build, tmp_path):
    program = os.path.join(build, "coupler", "outburst")
    short = ['scene.end_time="0.004 s"', 'mpm.settle.time="0.002 s"', 'output.interval="0.002 s"']
    heading, plane = str(tmp_path / "heading"), str(tmp_path / "plane")
    log = run(program, os.path.join(repo, "cases/outburst_3d/outburst_3d.toml"), heading, *short,
              'mpm.grid.cell_size="1 m"')
    run(program, os.path.join(repo, "cases/outburst/outburst.toml"), plane, *short)
    subprocess.run([sys.executable, "-m", "cases.outburst_3d.report", heading, "--plane", plane, "--log", log],
                   check=True, cwd=repo)
    with open(os.path.join(heading, "report.md")) as f:
        text = f.read()
    for row in ("peak speed, face centre / top / bottom", "farthest coal from the face", "coal in front of the face",
                "gas released", "cavity", "loosened seam", "particles that left the grid", "energy books",
                "Energy budget", "3D over plane"):
        assert row in text, row
    assert not re.search(r"\b(nan|inf)\b", text, re.IGNORECASE)
    h, p = numbers(os.path.join(heading, "headline.csv")), numbers(os.path.join(heading, "headline_plane.csv"))
    print({k: f"{v:.4g}" for k, v in h.items()})
    assert all(math.isfinite(v) for v in [*h.values(), *p.values()])
    # The half model's gas over the half-width: the whole heading's per metre of its width.
    released = np.genfromtxt(os.path.join(heading, "coupling.csv"), delimiter=",", names=True)["gas_released"][-1]
    assert h["gas_released_m3"] == pytest.approx(released, rel=1e-12)
    assert h["gas_released_m3_per_m"] == pytest.approx(released / 2.0, rel=1e-12)
    assert (h["particles"], h["simulated_s"], h["heading_half_width_m"]) == (8640, pytest.approx(0.004), 2.0)
    assert h["wall_s"] > 0 and h["centre_m_per_s"] > 0
    assert p["particles"] == 6480
    for name in FIGURES:
        with open(os.path.join(heading, f"{name}.png"), "rb") as f:
            assert f.read(8) == b"\x89PNG\r\n\x1a\n", name
