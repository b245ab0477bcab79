"""The Python measures' analytic series (cases.terzaghi.measure.Column,
cases.mandel.measure.Specimen) equal the C++ tests' (tests/poroelastic_solutions.hpp,
printed by build/tests/analytic-samples) at points across space and time, for
the shipped scenes' parameters: two implementations of each solution, checked
against each other so that neither drifts."""
import os
import subprocess
import tomllib

import pytest

from cases.mandel.measure import Specimen
from cases.terzaghi.measure import Column
from cases.units import value

# Dimensionless times c t / L^2: early (steep front), middle, late.
TIMES = (1e-3, 0.05, 0.4)


def shipped(repo, name):
    with open(os.path.join(repo, "cases", name, f"{name}.toml"), "rb") as f:
        return tomllib.load(f)


def cpp(build, *args):
    program = os.path.join(build, "tests", "analytic-samples")
    out = subprocess.run([program] + [repr(float(a)) if not isinstance(a, str) else a for a in args],
                         check=True, capture_output=True, text=True).stdout
    return [float(x) for x in out.split()]


def moduli(s):
    """The scene's E, nu, storage, alpha and mobility, as the C++ side takes them."""
    material, region = s["mpm"]["materials"][0], s["seepage"]["regions"][0]
    return [value(material["youngs_modulus"], "Pa"), material["poisson_ratio"],
            value(region["storage_coefficient"], "1/Pa"), s["coupling"]["biot_coefficient"],
            value(region["permeability"], "m2") / value(region["viscosity"], "Pa s")]


def test_terzaghi_pressure(repo, build):
    s = shipped(repo, "terzaghi")
    column = Column(s)
    h = column.height
    for fraction in (0.02, 0.3, 0.7, 0.99):
        for time in TIMES:
            z, t = fraction * h, time * h * h / column.cv
            (expected,) = cpp(build, "terzaghi", h, column.load, *moduli(s), z, t)
            assert column.pressure(z, t)[0] == pytest.approx(expected, rel=1e-9, abs=1e-12 * column.p0)


def test_mandel_pressure_and_settlement(repo, build):
    s = shipped(repo, "mandel")
    specimen = Specimen(s)
    a = specimen.a
    for fraction in (0.0, 0.5, 0.95):
        for time in TIMES:
            x, t = fraction * a, time * a * a / specimen.c
            pressure, settlement = cpp(build, "mandel", a, specimen.b, specimen.force, *moduli(s), x, t)
            assert specimen.pressure(x, t)[0] == pytest.approx(pressure, rel=1e-9, abs=1e-12 * specimen.p0)
            assert specimen.settlement(t) == pytest.approx(settlement, rel=1e-9)
