"""A run's scene from its own output (cases/run_output.scene), and the scene
values the measures and reports read from it: those the shipped scenes'
headers state."""
import math
import os
import tomllib

import h5py
import pytest

from cases.bar.measure import bar
from cases.drainage.solution import Seam
from cases.mandel.measure import Specimen
from cases.outburst.report import tunnel
from cases.run_output import scene
from cases.terzaghi.measure import Column


def shipped(repo, path):
    with open(os.path.join(repo, "cases", path), "rb") as f:
        return tomllib.load(f)


def test_scene_applies_the_runs_overrides(tmp_path):
    text = '[scene]\nend_time = "1 s"\n[[mpm.materials]]\nname = "coal"\ndensity = "1600 kg/m3"\n'
    with h5py.File(tmp_path / "particles_000000.h5", "w") as f:
        f.attrs["scene_text"] = text
        f.attrs["scene_overrides"] = 'scene.end_time="0.1 s"\nmpm.materials[0].density="1 kg/m3"\nmpm.courant=0.3\n'
    s = scene(str(tmp_path))
    assert s["scene"]["end_time"] == "0.1 s"
    assert s["mpm"]["materials"][0] == {"name": "coal", "density": "1 kg/m3"}
    assert s["mpm"]["courant"] == 0.3


def test_no_output_no_scene(tmp_path):
    with pytest.raises(FileNotFoundError):
        scene(str(tmp_path))


def test_bar(repo):
    assert bar(shipped(repo, "bar/bar.toml")) == (1.0, 0.01, 10.0)


def test_terzaghi(repo):
    column = Column(shipped(repo, "terzaghi/terzaghi.toml"))
    # terzaghi.toml: M = 12 MPa, c_v = 1 m2/s, p0 = 4.545 kPa.
    assert (column.height, column.load, column.modulus) == (1.0, 1e4, 12e6)
    assert column.cv == pytest.approx(1.0, rel=1e-3)
    assert column.p0 == pytest.approx(4545.45, rel=1e-5)


def test_mandel(repo):
    specimen = Specimen(shipped(repo, "mandel/mandel.toml"))
    # mandel.toml: B = 0.75, nu_u = 1/3, p0 = 3333 Pa, c = 0.9165 m2/s.
    assert (specimen.a, specimen.b, specimen.force) == (1.0, 1.0, 1e4)
    assert specimen.skempton == pytest.approx(0.75)
    assert specimen.nu_u == pytest.approx(1 / 3)
    assert specimen.p0 == pytest.approx(3333.33, rel=1e-5)
    assert specimen.c == pytest.approx(0.9165, rel=1e-9)


def test_drainage(repo):
    seam = Seam(shipped(repo, "drainage/drainage.toml"))
    # drainage.toml: 3 MPa in a 3 m seam, 0.1 MPa at the face; diffusivity 1.2e-5 m2/s.
    assert (seam.p0, seam.pf, seam.height) == (3e6, 1e5, 3.0)
    assert seam.d0 == pytest.approx(1.2e-5, rel=0.01)
    assert math.isclose(seam.pressure(1e9, 1.0), seam.p0)


def test_outburst_tunnel(repo):
    # outburst.toml: the seam x = 25..45 m, y = 0..9 m; the tunnel y = 3..6 m.
    assert tunnel(shipped(repo, "outburst/outburst.toml")) == {"face": 25.0, "floor": 3.0, "roof": 6.0, "top": 9.0}
