"""Plausibility warnings: values a scene may give but no road collision has,
each named with the slip that most likely made it (never an error: the scene
is solved as given). The one table of ranges is :data:`RANGES` (SI units),
documented in docs/careless-use.md.

Each check reads the scene's numeric leaves (:attr:`Scene.leaves`, scene
units) by their dimension, so every alternative form (``weight``, ``{speed,
direction}``, unit strings) is covered; values are converted to SI to compare.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from .units import FOOT

__all__ = ["RANGES", "angle_warnings", "crush_energy_warning", "implausible"]

INCH = FOOT / 12.0
SLUG = 14.593902937206364  # kg (1 lbf·s²/ft)
#: Scene unit -> SI factor per leaf dimension (angles and yaw rates are the same in both).
_TO_SI = {
    "SI": {"mass": 1.0, "length": 1.0, "speed": 1.0, "crush_length": 1.0, "rate": 1.0},
    "US": {"mass": SLUG, "length": FOOT, "speed": FOOT, "crush_length": INCH, "rate": 1.0},
}

#: dimension -> (largest plausible magnitude in SI, its unit, the likely slip).
#: Lengths (impact points, crush depths) are bounded by the vehicle's ``length``
#: when the scene gives it, else by the value here.
RANGES: dict[str, tuple[float, str, str]] = {
    # the road limits (EU 40 t, US 80,000 lb = 36 t): 2,900 slug (42 t) is a
    # 2,900 lb car's weight given as its mass
    "mass": (
        40_000.0,
        "kg",
        "a weight given as a mass (in US units lb is a weight; mass is lb/32.174 slug)?",
    ),
    # a spinning car reaches about 5 rad/s (300 deg/s)
    "rate": (10.0, "rad/s", "a yaw rate in deg/s given as rad/s?"),
    # 100 m/s = 360 km/h = 224 mph: faster than any vehicle in road traffic
    "speed": (100.0, "m/s", "a speed in mph or km/h given as ft/s or m/s?"),
    # the impact centre lies on the vehicle: within its length of the centre of gravity
    "length": (12.0, "m", "a length in inches or cm given as ft or m, or a scene-frame position?"),
    # a crush deeper than a car is long (CRASH3 is for cars)
    "crush_length": (6.0, "m", "a crush depth in cm or mm given as m, or in in given as ft?"),
}
#: Smallest plausible mass [kg]: below it, a mass in tonnes (1.5 for 1500 kg).
SMALLEST_MASS = 50.0

_SHOWN = {
    "SI": {"mass": "kg", "length": "m", "speed": "m/s", "crush_length": "m", "rate": "rad/s"},
    "US": {"mass": "slug", "length": "ft", "speed": "ft/s", "crush_length": "in", "rate": "rad/s"},
}


def implausible(leaves: Mapping[str, Any], vehicles: Sequence[Any], units: str) -> list[str]:
    """The plausibility warnings of a scene: its leaves (path -> Leaf, scene
    units) and vehicles (for a given ``length``)."""
    warnings = _range_warnings(leaves, vehicles, units) + angle_warnings(leaves)
    return warnings + _crush_zero_warnings(leaves)


def _range_warnings(leaves, vehicles, units) -> list[str]:
    """Masses, yaw rates and crush depths (leaves); speeds and impact points
    (the vehicles' vectors, whatever form gave them)."""
    shown, to_si = _SHOWN[units], _TO_SI[units]
    values = [(p, leaf.dimension, leaf.nominal) for p, leaf in leaves.items() if leaf.dimension != "length"]
    values = [(p, d, v) for p, d, v in values if d in RANGES and d != "speed"]
    for index, vehicle in enumerate(vehicles):
        where = f"vehicles[{index}]"
        for key, vector in (
            ("velocity", vehicle.velocity),
            ("final_velocity", vehicle.extra.get("final_velocity")),
        ):
            if vector is not None:
                values.append((f"{where}.{key}", "speed", math.hypot(*vector)))
        values.append((f"{where}.impact_point", "length", math.hypot(*vehicle.impact_point)))
    warnings = []
    for path, dimension, value in values:
        if not math.isfinite(value):
            continue
        limit, unit, slip = RANGES[dimension]
        si = abs(value) * to_si[dimension]
        length = _vehicle_length(path, vehicles) if dimension == "length" else None
        if length is not None:
            limit, unit = length * to_si["length"], "m (its length)"
        text = f"{path}: {value:g} {shown[dimension]}"
        if dimension == "mass" and 0.0 < si < SMALLEST_MASS:
            warnings.append(f"{text} is lighter than any vehicle ({SMALLEST_MASS:g} kg): a mass in tonnes?")
        elif si > limit:
            warnings.append(f"{text} is beyond {limit:g} {unit}, the most a road vehicle has: {slip}")
    return warnings


def _vehicle_length(path: str, vehicles) -> float | None:
    """The ``length`` [scene units] the scene gives for the vehicle of ``path``, or None."""
    index = int(path[len("vehicles[") :].split("]")[0])
    length = vehicles[index].extra.get("length") if index < len(vehicles) else None
    return float(length) if isinstance(length, (int, float)) and length > 0 else None


def angle_warnings(leaves: Mapping[str, Any]) -> list[str]:
    """All angles of a scene within ±2π, one of them not a whole number of
    degrees: radians given as degrees (the file's angles are degrees)."""
    angles = {p: leaf.nominal for p, leaf in leaves.items() if leaf.dimension == "angle"}
    values = [v for v in angles.values() if math.isfinite(v)]
    if not any(v != 0.0 for v in values) or any(abs(v) > 2.0 * math.pi for v in values):
        return []
    if all(v == round(v) for v in values):
        return []
    return [
        "every angle of the scene is within ±2π ("
        + ", ".join(f"{p} = {v:g}" for p, v in angles.items())
        + "): angles are in degrees; radians given as degrees?"
    ]


def _crush_zero_warnings(leaves) -> list[str]:
    depths: dict[str, list[float]] = {}
    for path, leaf in leaves.items():
        if ".crush.depths[" in path:
            depths.setdefault(path.split(".crush.depths[")[0], []).append(leaf.nominal)
    return [
        f"{vehicle}.crush.depths: every depth is 0: no crush, so no crush energy (depths not filled in?)"
        for vehicle, values in depths.items()
        if values and all(v == 0.0 for v in values)
    ]


def crush_energy_warning(crush_energy: float, scene: Any) -> list[str]:
    """The total crush energy [scene units] above the moving vehicles' initial
    kinetic energy (when the scene gives their motion; a crush-only scene has
    none): the crush stiffness (A, B) or depths are too large, or the speeds
    too small."""
    kinetic = sum(
        0.5 * v.mass * (v.velocity[0] ** 2 + v.velocity[1] ** 2)
        + 0.5 * (v.yaw_inertia or 0.0) * v.yaw_rate**2
        for v in scene.vehicles
        if not v.fixed
    )
    if not (math.isfinite(crush_energy) and math.isfinite(kinetic)) or not 0.0 < kinetic < crush_energy:
        return []
    unit = "J" if scene.units == "SI" else "ft·lb"
    return [
        f"the total crush energy {crush_energy:.4g} {unit} is more than the vehicles' initial kinetic "
        f"energy {kinetic:.4g} {unit}: check the crush stiffness (A, B), the depths and the speeds"
    ]
