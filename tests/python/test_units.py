"""cases/units.py reads what the scenes write, with common/units.cpp's meaning."""
import math
import os
import re

import pytest

from cases import units


NAMED = {"length": (1, 0, 0, 0), "mass": (0, 1, 0, 0), "time": (0, 0, 1, 0), "angle": (0, 0, 0, 1),
         "pressure": (-1, 1, -2, 0)}


def cpp_units(repo):
    """(symbol, SI factor, (length, mass, time, angle) exponents) of every unit
    common/units.cpp knows, and the size its table declares."""
    with open(os.path.join(repo, "common", "units.cpp")) as f:
        source = f.read()
    declared = int(re.search(r"std::array<NamedUnit, (\d+)> known_units", source).group(1))
    start = source.index("known_units{{")
    table = source[start:source.index("}};", start)]
    rows = []
    for symbol, factor, dimension in re.findall(r'\{"(\w+)", ([^,]+), (\w+|\{[^}]*\})\}', table):
        exponents = NAMED[dimension] if dimension in NAMED else tuple(int(x) for x in dimension.strip("{}").split(","))
        rows.append((symbol, eval(factor, {"pi": math.pi}), exponents))
    return rows, declared


def test_every_cpp_unit_means_the_same(repo):
    known, declared = cpp_units(repo)
    assert len(known) == declared
    for symbol, factor, (length, mass, time, angle) in known:
        assert units.si(f"1 {symbol}") == pytest.approx(factor, rel=1e-12), symbol
        # Pint counts angles as dimensionless; the rest must match exponent by exponent.
        dims = units.registry(f"1 {symbol}").dimensionality
        assert (dims.get("[length]", 0), dims.get("[mass]", 0), dims.get("[time]", 0)) == (length, mass, time), symbol


@pytest.mark.parametrize("text, si", [
    ("0.1 MPa", 1e5),
    ("1 m2/(MPa2 d)", 1 / (1e12 * 86400)),
    ("30 deg", math.pi / 6),
    ("2 d", 172800.0),
    ("1 h", 3600.0),
    ("2 MPa^-0.5", 2e-3),
    ("1600 kg/m3", 1600.0),
    ("-9.81 m/s2", -9.81),
    ("1e-3 Pa s", 1e-3),
    ("1e-7 Pa^-1", 1e-7),
    ("400 1/s", 400.0),
    ("-10 kN/m", -1e4),
    ("2 N.m", 2.0),
    ("1 a", 365.25 * 86400),
    ("0.5", 0.5),
])
def test_scene_quantities(text, si):
    assert units.si(text) == pytest.approx(si, rel=1e-12)


def test_value_in_a_unit_checks_its_kind():
    assert units.value("0.1 m2/(MPa2 d)", "m2/(Pa2 s)") == pytest.approx(0.1 / (1e12 * 86400), rel=1e-12)
    with pytest.raises(ValueError, match="not in units of m"):
        units.value("3 MPa", "m")


@pytest.mark.parametrize("text", ["linear", "bar", '"10 MPa"', "3 foo", "3 m/"])
def test_what_is_no_quantity(text):
    with pytest.raises(ValueError):
        units.si(text)


def test_split():
    assert units.split("0.3333333333333333 m") == (0.3333333333333333, "m")
    assert units.split("1e-4") == (1e-4, "")
    assert units.split("gimp") is None
