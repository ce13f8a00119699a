"""Quantities with units in scene files, converted to the scene's unit system.

A scene's bare numbers are in its ``units`` system (``"SI"`` or ``"US"``,
conventions.md); any numeric field may instead be a string with a unit that
pint understands (``"35.1 mph"``, ``"3451 lb"``, ``"2152 lbf*ft*s**2"``).
:func:`to_scene_units` converts such a string to a number in the scene's
system, after checking that it has the dimension the field needs.

pint is imported only when a scene uses a unit string (its registry takes
about 0.4 s to build), so plain scenes keep their start-up time; one registry
serves the process (:func:`registry`).

Conventions: ``lb`` is the pound-mass and ``lbf`` the pound-force (pint's
definitions; 1 lbf = 1 lb × standard gravity). A slug is lbf·s²/ft. Scene
angles are in degrees, yaw rates in rad/s. ``weight`` is a force;
:data:`STANDARD_GRAVITY` turns it into a mass. A mass field given a force, or
a weight field given a mass, is converted with standard gravity too: with
g_n a pound of mass weighs exactly a pound-force, so ``"weight": "3451 lb"``
and ``"mass": "3451 lb"`` mean the same vehicle (only bare numbers depend on
the field: a bare ``weight`` is lbf or N, a bare ``mass`` slug or kg).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from .._util import require

__all__ = [
    "DIMENSIONS",
    "GRAVITY",
    "SCENE_UNITS",
    "STANDARD_GRAVITY",
    "Dimension",
    "registry",
    "to_scene_units",
]

#: Standard gravity g_n [m/s²] (exact, CGPM 1901): mass = weight / g_n.
STANDARD_GRAVITY = 9.80665
FOOT = 0.3048  # m, exact
#: g_n in each system's acceleration unit (m/s², ft/s²).
GRAVITY = {"SI": STANDARD_GRAVITY, "US": STANDARD_GRAVITY / FOOT}


@dataclass(frozen=True)
class Dimension:
    """What a field measures: its name in messages (``"a mass"``), example
    units, and pint's dimensionality (``None`` for angles, yaw rates and plain
    numbers, which pint treats as dimensionless and are told apart by their
    root units)."""

    what: str
    examples: str
    pint: str | None


DIMENSIONS = {
    "mass": Dimension("a mass", "kg, lb, slug", "[mass]"),
    "force": Dimension("a force (a weight)", "N, lbf, kN", "[force]"),
    "inertia": Dimension(
        "a yaw inertia (mass × length²)", "kg*m**2, slug*ft**2, lbf*ft*s**2", "[mass]*[length]**2"
    ),
    "length": Dimension("a length", "m, ft, in", "[length]"),
    "speed": Dimension("a speed", "m/s, ft/s, mph, km/h", "[length]/[time]"),
    "angle": Dimension("an angle", "deg, rad", None),
    "rate": Dimension("a yaw rate", "rad/s, deg/s", None),
    "number": Dimension("a plain number", "no unit, or %", None),
    "stiffness_A": Dimension("a force per unit width (CRASH3 A)", "lbf/in, N/m, N/cm", "[force]/[length]"),
    "stiffness_B": Dimension(
        "a force per unit area (CRASH3 B)", "lbf/in**2, N/m**2, N/cm**2", "[force]/[length]**2"
    ),
    "crush_length": Dimension("a length", "in, cm, m", "[length]"),
}

#: The unit of each dimension in each system: what a bare number means.
#: CRASH3 crush inputs keep CRASH3's own units (lb/in, lb/in², in) in US scenes.
SCENE_UNITS = {
    "SI": {
        "mass": "kg",
        "force": "N",
        "inertia": "kg*m**2",
        "length": "m",
        "speed": "m/s",
        "angle": "deg",
        "rate": "rad/s",
        "number": "",
        "stiffness_A": "N/m",
        "stiffness_B": "N/m**2",
        "crush_length": "m",
    },
    "US": {
        "mass": "slug",
        "force": "lbf",
        "inertia": "slug*ft**2",
        "length": "ft",
        "speed": "ft/s",
        "angle": "deg",
        "rate": "rad/s",
        "number": "",
        "stiffness_A": "lbf/in",
        "stiffness_B": "lbf/in**2",
        "crush_length": "in",
    },
}


@functools.cache
def registry():
    """The process's one pint UnitRegistry, built on first use (ImportError
    with the extra to install when pint is missing)."""
    pint = require("pint", extra="units", what="a unit string in a scene")
    return pint.UnitRegistry()


def to_scene_units(text: str, path: str, dimension: str, system: str) -> float:
    """``text`` (a number with a unit, ``"35 mph"``) as a float in the unit of
    ``dimension`` in ``system``. A string without a unit is a plain number
    (right only for plain-number fields such as ``restitution``). Raises :class:`ValueError` with a one-line reason (the caller
    adds the field path) when pint cannot read it or its dimension is wrong."""
    quantity = _parse(text)
    found = _kind(quantity)
    if {found, dimension} == {"mass", "force"}:
        # standard gravity: a pound of mass weighs a pound-force, so "3451 lb"
        # as a weight and "3451 lbf" as a mass both give the same mass
        gravity = registry().Quantity(STANDARD_GRAVITY, "m/s**2")
        quantity = quantity * gravity if found == "mass" else quantity / gravity
        found = dimension
    if found != dimension and not _same_length(found, dimension):
        need = DIMENSIONS[dimension]
        got = DIMENSIONS[found].what if found else f"dimension {quantity.dimensionality}"
        raise ValueError(f"needs {need.what} ({need.examples}), got {text!r} ({got})")
    unit = SCENE_UNITS[system][dimension]
    return _finite(quantity.to(unit).magnitude if unit else quantity.to("").magnitude, text)


def _same_length(found: str | None, dimension: str) -> bool:
    """Crush lengths are lengths (they only have another default unit)."""
    return found == "length" and dimension == "crush_length"


def _parse(text: str):
    """pint's reading of ``text``: a Quantity, or a plain number when it has no unit."""
    ureg = registry()
    try:
        return ureg.Quantity(ureg(text))
    except Exception as exc:  # noqa: BLE001 - pint raises many types (UndefinedUnitError, SyntaxError, ...)
        raise ValueError(
            f"must be a finite number or a number with a unit pint understands, got {text!r} ({_reason(exc)})"
        ) from None


def _reason(exc: Exception) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 60 else text[:57] + "..."


def _kind(quantity) -> str | None:
    """The dimension (a key of :data:`DIMENSIONS`) of a pint Quantity, or None."""
    ureg = registry()
    if quantity.dimensionless:
        _, root = ureg.get_root_units(quantity.units)
        return "angle" if "radian" in str(root) else "number"
    if quantity.dimensionality == ureg.get_dimensionality("1/[time]"):
        return "rate"
    for name, dimension in DIMENSIONS.items():
        if dimension.pint and quantity.dimensionality == ureg.get_dimensionality(dimension.pint):
            return "length" if name == "crush_length" else name
    return None


def _finite(value, text: str) -> float:
    """``value`` as a finite float."""
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        number = math.nan
    if not math.isfinite(number):
        raise ValueError(f"must be a finite number, got {text!r}")
    return number
