"""Quantities as the scenes write them ("0.1 MPa", "1 m2/(MPa2 d)", "30 deg"),
read with Pint. Pint's own registry already holds every symbol of
common/units.cpp with the same meaning ("d" the day, "h" the hour, "a" the
Julian year, "t" the tonne, "us" the microsecond); what it lacks is the C++
parser's grammar, which the preprocessors below add."""
import re

import pint

# A bare exponent after a symbol or a bracket, "m2", "MPa2", "s-1", "(m/s)2",
# is a power to common/units.cpp; Pint wants it after '^'.
_BARE_EXPONENT = re.compile(r"(?<=[A-Za-z)])(-?\d+(?:\.\d+)?)")
# A '.' between factors multiplies ("N.m"), as in common/units.cpp.
_DOT = re.compile(r"(?<=[A-Za-z\d)])\.(?=[A-Za-z(])")

registry = pint.UnitRegistry(preprocessors=[lambda s: _DOT.sub("*", _BARE_EXPONENT.sub(r"^\1", s))])

# A quantity is a number and then, optionally, its unit: "3 MPa", "0.5", "1e-7 Pa^-1".
_QUANTITY = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*")


def split(text):
    """The number and the unit text of a quantity's text; None if it does not start with a number."""
    m = _QUANTITY.fullmatch(text)
    return (float(m.group(1)), m.group(2)) if m else None


def quantity(text):
    """A scene's quantity ("0.1 MPa") as a Pint quantity; ValueError if it is none."""
    parts = split(text)
    if parts is None:
        raise ValueError(f'"{text}" does not start with a number')
    number, unit = parts
    try:
        return registry.Quantity(number, registry.Unit(unit) if unit else registry.dimensionless)
    except (pint.errors.PintError, AttributeError, TypeError, SyntaxError) as e:
        raise ValueError(f'cannot read the unit of "{text}": {e}') from e


def value(text, unit):
    """A scene's quantity as a number in the given unit ("Pa", "m2/(Pa s)"); ValueError if it is not of that kind."""
    try:
        return quantity(text).m_as(registry.Unit(unit))
    except pint.errors.DimensionalityError as e:
        raise ValueError(f'"{text}" is not in units of {unit}: {e}') from e


def si(text):
    """A scene's quantity in SI base units (angles in radians), as the programs read it."""
    return quantity(text).to_base_units().magnitude
