"""Scene files: reading, validation and conversion to kernel inputs.

A scene describes one planar two-vehicle impact in the format of
``conventions.md`` (JSON or TOML, same structure).  Frame: x, y in the scene
plane, angles counter-clockwise from +x.  ``impact.normal_angle`` is Γ in
degrees; the normal ``n = (cos Γ, sin Γ)`` points from vehicle 1 toward
vehicle 2 (given in the other sense, it is turned round: see
:func:`impactsym.casefile.used_normal_angle`).  ``impact_point`` is the vector
from a vehicle's centre of gravity to the impact centre, in the scene frame
(or ``{forward, left}`` in the vehicle frame).

Units are consistent sets: ``"SI"`` (kg, m, kg·m², m/s, rad/s) or ``"US"``
(slug, ft, slug·ft², ft/s, rad/s).  Any number may instead be a unit string
or a distribution (:mod:`impactsym.casefile`, docs/casefile.md); a
:class:`Scene` holds everything in its system's units.

Validation is strict about values and keys: a bad value or an unknown key
raises :class:`SceneError` with one line naming the field path
(``vehicles[1].mass: must be a positive finite number, got -5``,
``impact.restitusion: unknown key; did you mean "restitution"?``); a known key
the command does not use is reported in :attr:`Scene.warnings`.
"""

from __future__ import annotations

import json
import math
import numbers
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

from ._kernels import COEFFICIENT_INPUTS, PRESETS
from .casefile import (
    COEFFICIENT_KEYS,
    CRUSH_LEAVES,
    IMPACT_KEYS,
    TOP_KEYS,
    VEHICLE_KEYS,
    Leaf,
    LeafReader,
    check_keys,
    domain_reasons,
    parse_correlations,
    unknown_key,
    used_normal_angle,
    vehicle_state,
)
from .errors import SceneError, show_value

__all__ = [
    "KINDS",
    "MODELS",
    "UNITS",
    "Impact",
    "Scene",
    "SceneColumns",
    "SceneError",
    "Vehicle",
    "load_scene",
    "scene_columns",
    "scene_data",
    "show_value",
    "uses_yaw",
]

# Model names a scene may give (generated.presets.PRESETS): the general model
# ("rigid" or "brach"), "particle", and the seed's named models as presets.
MODELS = tuple(PRESETS)
UNITS = ("SI", "US")
CRITICAL = "critical"
KINDS = ("forward", "inverse", "reconstruct", "crash3")
#: Vehicle entries Scene.to_dict leaves out for a kind that does not read them.
_TO_DICT_LEFT_OUT = {"inverse": ("velocity", "yaw_rate"), "reconstruct": ("velocity",)}
#: The command that reads each kind of scene (for "not used" warnings).
COMMAND = {"forward": "solve", "inverse": "invert", "reconstruct": "reconstruct", "crash3": "crash3"}


@dataclass(frozen=True)
class Vehicle:
    """One vehicle at first contact, in the scene's units and frame.

    ``mass`` [kg | slug] and ``yaw_inertia`` [kg·m² | slug·ft²] are ``None``
    when not given (a fixed vehicle, or ``yaw_inertia`` in the particle model).
    ``velocity`` [m/s | ft/s] and ``yaw_rate`` [rad/s] are the initial motion
    (zero by default for a fixed vehicle); ``impact_point`` [m | ft] is the
    vector from the centre of gravity to the impact centre in the scene frame,
    (0, 0) when not needed.  ``fixed`` marks an immovable object (infinite
    mass and inertia).  ``extra`` holds the other keys of the vehicle entry,
    normalised: ``heading`` [deg], ``final_velocity`` (x, y), ``final_yaw_rate``,
    ``length``, ``width``, ``crush`` (its numbers in CRASH3's units).
    """

    name: str
    mass: float | None
    yaw_inertia: float | None
    velocity: tuple[float, float]
    yaw_rate: float = 0.0
    impact_point: tuple[float, float] = (0.0, 0.0)
    fixed: bool = False
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The vehicle entry in plain scene-file form (``None`` entries left out)."""
        entry = {
            "name": self.name,
            "mass": self.mass,
            "yaw_inertia": self.yaw_inertia,
            "velocity": list(self.velocity),
            "yaw_rate": self.yaw_rate,
            "impact_point": list(self.impact_point),
            "fixed": self.fixed,
        }
        entry.update(
            {key: list(value) if isinstance(value, tuple) else value for key, value in self.extra.items()}
        )
        return {key: value for key, value in entry.items() if value is not None}


@dataclass(frozen=True)
class Impact:
    """Impact coefficients.

    ``normal_angle``: Γ in degrees, in the sense used (from vehicle 1 toward
    vehicle 2; :attr:`Scene.warnings` says when the scene gave the other).
    ``restitution``: e.  ``impulse_ratio``: signed μ = Pt/Pn, or ``"critical"``
    for μ = μ_c (no sliding at separation).  ``moment_restitution``: e_m (1
    gives no moment impulse).  ``slip``: IMPAC's sideswipe constraint, the
    fraction of the initial tangential relative velocity at the impact centre
    left at separation.  A coefficient the scene's model fixes holds the fixed
    value (``limpert``: e = 0, ``"critical"``, e_m = 1); one the model does not
    use is ``None``.
    """

    normal_angle: float
    restitution: float | None
    impulse_ratio: float | str | None
    moment_restitution: float | None = 1.0
    slip: float | None = None

    @property
    def critical(self) -> bool:
        """True when the impulse ratio is the critical one."""
        return self.impulse_ratio == CRITICAL

    def to_dict(self) -> dict[str, Any]:
        """The ``impact`` table in scene-file form (unused coefficients left out)."""
        entry = {
            "normal_angle": self.normal_angle,
            "restitution": self.restitution,
            "impulse_ratio": self.impulse_ratio,
            "moment_restitution": self.moment_restitution,
            "slip": self.slip,
        }
        return {
            key: value
            for key, value in entry.items()
            if value is not None and not (isinstance(value, float) and math.isnan(value))
        }


@dataclass(frozen=True)
class Scene:
    """A validated scene: model, units, impact coefficients and two vehicles,
    in the scene's units and frame, at the nominal values of uncertain leaves.

    ``source`` is the file it was read from (``None`` for a dict).  ``extra``
    holds the top-level keys other than the four of the format (``title``,
    ``crash3``, ...; not ``correlations``); ``warnings`` lists what the reader
    should know: keys given but not used by the command, a normal angle turned
    round.  ``kind`` is what the scene was read for (:data:`KINDS`).
    ``leaves`` maps each numeric leaf the command uses to its
    :class:`~impactsym.casefile.Leaf` (scene units, angles in degrees);
    ``correlations`` are ``(path_a, path_b, rho)``; ``data`` is the mapping as
    read (units, alternative forms and distributions included).
    """

    model: str
    units: str
    impact: Impact
    vehicles: tuple[Vehicle, Vehicle]
    source: Path | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    kind: str = "forward"
    leaves: dict[str, Leaf] = field(default_factory=dict, repr=False)
    correlations: tuple[tuple[str, str, float], ...] = ()
    data: Mapping | None = field(default=None, repr=False, compare=False)

    @property
    def uncertain(self) -> tuple[tuple[str, str, tuple[float, ...]], ...]:
        """The uncertain leaves as ``(path, kind, params)``, params in scene
        units (normal: mean, sd; uniform: low, high; triangular: low, mode,
        high; angles in degrees)."""
        return tuple(
            (leaf.path, leaf.kind, leaf.params) for leaf in self.leaves.values() if leaf.kind is not None
        )

    def to_dict(self) -> dict[str, Any]:
        """The scene in plain scene-file form (what :func:`load_scene` reads back):
        numbers in the scene's units, vectors in the scene frame, nominal values."""
        vehicles = [vehicle.to_dict() for vehicle in self.vehicles]
        for entry in vehicles:  # the initial motion is what these kinds compute
            for key in _TO_DICT_LEFT_OUT.get(self.kind, ()):
                entry.pop(key, None)
        data = {
            "model": self.model,
            "units": self.units,
            "impact": self.impact.to_dict(),
            "vehicles": vehicles,
        }
        data.update(self.extra)
        return data

    @property
    def family(self) -> str:
        """The kernel family that solves the scene's model: ``"rigid"``,
        ``"particle"`` or ``"impac_sideswipe"`` (generated.presets.PRESETS)."""
        return PRESETS[self.model]["kernel"]

    @property
    def uses_yaw(self) -> bool:
        """True when the model has yaw rates and lever arms (all but particles)."""
        return uses_yaw(self.model)

    def to_inputs(self) -> tuple[str, bool, dict[str, float]]:
        """Kernel inputs ``(family, critical, values)``.

        ``family`` is the kernel family of the scene's model (a preset such as
        ``limpert`` is the ``rigid`` family with its coefficients fixed).
        ``values`` uses the batch names of ``conventions.md``: ``gamma`` is Γ in
        radians, a fixed vehicle has ``m = I = inf``.  The particle model gets
        only ``m1 m2 v1x v1y v2x v2y gamma e mu``, IMPAC's sideswipe ``slip``
        in place of ``e mu e_m``.  With a critical impulse ratio ``mu`` is a
        placeholder 0.0, which the kernel ignores.
        """
        impact = self.impact
        values = {"gamma": math.radians(impact.normal_angle)}
        if self.family == "impac_sideswipe":
            values["slip"] = impact.slip
        else:
            values["e"] = impact.restitution
            values["mu"] = 0.0 if impact.critical else float(impact.impulse_ratio)
        if self.family == "rigid":
            values["e_m"] = impact.moment_restitution
        for number, vehicle in enumerate(self.vehicles, start=1):
            values.update(_vehicle_inputs(vehicle, number, self.uses_yaw))
        return self.family, impact.critical, values


def load_scene(source: Scene | Mapping | str | Path, kind: str = "forward") -> Scene:
    """Read and validate a scene.

    ``source`` is a :class:`Scene` (its data read again), a mapping in
    scene-file form, or the path of a ``.json`` or ``.toml`` file.  ``kind``
    says what the scene is for: ``"forward"`` (initial motion given),
    ``"inverse"`` (final motion given instead: ``final_velocity``,
    ``final_yaw_rate``), ``"reconstruct"`` (final motion and pre-impact
    ``heading``; the impact needs only ``normal_angle``) or ``"crash3"`` (each
    moving vehicle carries ``crush``; the motion, yaw inertia and impact point
    are optional, the impact needs only ``normal_angle``).  Raises
    :class:`SceneError` for a bad scene and :class:`OSError` for a file that
    cannot be read.
    """
    if kind not in KINDS:
        raise ValueError(f"kind: unknown scene kind {kind!r} (use one of {', '.join(KINDS)})")
    if isinstance(source, Scene):
        return _parse_scene(scene_data(source), source.source, kind)
    if isinstance(source, Mapping):
        return _parse_scene(source, None, kind)
    if isinstance(source, (str, Path)):
        path = Path(source)
        return _parse_scene(_read_file(path), path, kind)
    raise TypeError(f"load_scene: expected a Scene, a mapping or a path, got {type(source).__name__}")


def scene_data(source: Scene | Mapping | str | Path) -> Mapping:
    """The scene-file mapping of ``source`` (a :class:`Scene`, a mapping or a
    ``.json``/``.toml`` path), not validated: what a scene gives, before its
    model's defaults and fixed coefficients are applied."""
    if isinstance(source, Scene):
        return source.data if source.data is not None else source.to_dict()
    if isinstance(source, Mapping):
        return source
    return _read_file(Path(source))


def _read_file(path: Path) -> Any:
    """The parsed content of a JSON or TOML scene file."""
    suffix = path.suffix.lower()
    if suffix not in (".json", ".toml"):
        raise SceneError(f"{path}: unknown scene file type {suffix or '(none)'!r} (use .json or .toml)")
    raw = path.read_bytes()
    try:
        # utf-8-sig: a byte-order mark (as some Windows editors write) is dropped.
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    try:
        if suffix == ".json":
            return json.loads(text, object_pairs_hook=_unique_keys)
        return tomllib.loads(text)
    except json.JSONDecodeError as exc:
        raise SceneError(f"{path}: invalid JSON: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: invalid TOML: {exc}") from None
    except _DuplicateKey as exc:
        raise SceneError(
            f'{path}: invalid JSON: the key "{exc.args[0]}" is given twice in one '
            "object (the second would silently replace the first)"
        ) from None
    except RecursionError:
        kind = "JSON" if suffix == ".json" else "TOML"
        raise SceneError(f"{path}: invalid {kind}: nested too deeply") from None


class _DuplicateKey(Exception):
    """A JSON object that names one key twice (``args[0]`` is the key)."""


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """``json.loads``'s object hook: the object as a dict, refusing a key given
    twice (json keeps the last one silently; a second ``"units"`` would relabel
    every number of the scene)."""
    data: dict[str, Any] = {}
    for key, value in pairs:
        if key in data:
            raise _DuplicateKey(key)
        data[key] = value
    return data


class _Reading:
    """The state of reading one scene: its kind, model and units, the leaf
    reader, and the warnings so far (keys not used, a normal turned round)."""

    def __init__(self, kind: str, model: str, units: str):
        self.kind, self.model, self.units = kind, model, units
        self.leaves = LeafReader(units)
        self.warnings: list[str] = []
        self.unused: list[str] = []  # leaf path prefixes read only to be checked

    def not_used(self, path: str, why: str) -> None:
        """Report a known key the command does not use; its leaves are not kept."""
        self.warnings.append(f"{path} is given but not used: {why}")
        self.unused.append(path)

    def used_leaves(self) -> dict[str, Leaf]:
        """The leaves of the keys the command uses."""
        return {
            path: leaf
            for path, leaf in self.leaves.leaves.items()
            if not any(path == p or path.startswith((p + ".", p + "[")) for p in self.unused)
        }


def _parse_scene(data: Any, source: Path | None, kind: str) -> Scene:
    """Validate a whole scene in scene-file form and normalise it."""
    if not isinstance(data, Mapping):
        where = f"{source}: " if source else ""
        raise SceneError(f"{where}a scene must be an object (a table of keys), got {show_value(data)}")
    check_keys(data, TOP_KEYS, "")
    model = _choice(data.get("model", "rigid"), "model", MODELS, "model")
    units = _units(_require(data, "units", ""))
    # CRASH3 uses the impact geometry only for delta-V directions and moment arms.
    no_impact = kind == "crash3" and "impact" not in data
    impact_data = {} if no_impact else _mapping(_require(data, "impact", ""), "impact")
    check_keys(impact_data, IMPACT_KEYS, "impact")
    if kind == "inverse" and PRESETS[model]["kernel"] not in ("rigid", "particle"):
        raise SceneError(f"the {model} model has no inverse solution", "model")
    reading = _Reading(kind, model, units)
    if "crash3" in data and kind != "crash3":
        reading.not_used("crash3", "the CRASH3 options are read by crash3 and compare")
    raw_vehicles = _vehicle_list(_require(data, "vehicles", ""))
    fixed = tuple(_fixed(entry, index) for index, entry in enumerate(raw_vehicles))
    if all(fixed):
        raise SceneError("both vehicles are fixed; at most one may be", "vehicles")
    coefficients = _parse_coefficients(impact_data, reading)
    if not no_impact:
        reading.leaves.number(_require(impact_data, "normal_angle", "impact"), "impact.normal_angle", "angle")
    extras = [
        _read_vehicle(entry, index, is_fixed, reading)
        for index, (entry, is_fixed) in enumerate(zip(raw_vehicles, fixed))
    ]
    leaves = reading.used_leaves()
    correlations = parse_correlations(data["correlations"], leaves) if "correlations" in data else ()
    values = {path: leaf.nominal for path, leaf in reading.leaves.leaves.items()}
    states = [vehicle_state(values, index, units) for index in range(2)]
    given = values.get("impact.normal_angle", math.nan)
    used = {path: leaf.nominal for path, leaf in leaves.items()}
    points = [vehicle_state(used, index, units)["r"] for index in range(2)]
    angle, flipped = used_normal_angle(given, *points)
    if flipped:
        reading.warnings.append(
            f"impact.normal_angle = {given:g} deg points from vehicle 2 toward vehicle 1; "
            f"the opposite sense, {float(angle):g} deg, is used (n·(r1 - r2) > 0)"
        )
    impact = Impact(normal_angle=float(angle), **coefficients)
    vehicles = tuple(
        _vehicle(raw, index, is_fixed, state, extra)
        for index, (raw, is_fixed, state, extra) in enumerate(zip(raw_vehicles, fixed, states, extras))
    )
    extra = {
        key: data[key] for key in data if key not in ("model", "units", "impact", "vehicles", "correlations")
    }
    warnings = reading.warnings
    if kind in ("forward", "inverse"):
        warnings += _unused_coefficients(impact_data, model)
    return Scene(
        model, units, impact, vehicles, source, extra, tuple(warnings), kind, leaves, correlations, data
    )


def _vehicle_list(raw: Any) -> list:
    """The list of exactly two vehicle entries."""
    if not isinstance(raw, list):
        raise SceneError(f"must be a list of exactly 2 vehicles, got {show_value(raw)}", "vehicles")
    if len(raw) != 2:
        raise SceneError(f"must be a list of exactly 2 vehicles, got {len(raw)}", "vehicles")
    for index, entry in enumerate(raw):
        _mapping(entry, f"vehicles[{index}]")
        check_keys(entry, VEHICLE_KEYS, f"vehicles[{index}]")
    return raw


def _fixed(entry: Mapping, index: int) -> bool:
    return _flag(entry.get("fixed", False), f"vehicles[{index}].fixed")


def _parse_coefficients(data: Mapping, reading: _Reading) -> dict[str, Any]:
    """The impact coefficients of a forward or inverse scene (the model's
    preset says which the scene gives and which it fixes). A reconstruction
    infers them and CRASH3 uses none: there they are reported as not used."""
    if reading.kind in ("reconstruct", "crash3"):
        why = (
            "a reconstruction infers them from the motion"
            if reading.kind == "reconstruct"
            else "CRASH3 takes its restitution from the crash3 options"
        )
        for key in COEFFICIENT_KEYS:
            if key in data:
                reading.not_used(f"impact.{key}", why)
        return {"restitution": math.nan, "impulse_ratio": math.nan, "moment_restitution": math.nan}
    preset = PRESETS[reading.model]
    coefficients = {key: _coefficient(data, key, preset, reading) for key in COEFFICIENT_KEYS}
    if reading.kind == "inverse" and coefficients["impulse_ratio"] == CRITICAL:
        raise SceneError(
            'must be a number for an inverse solution: with "critical" the final '
            "velocities do not determine the tangential slip",
            "impact.impulse_ratio",
        )
    return coefficients


def _coefficient(data: Mapping, key: str, preset: Mapping, reading: _Reading) -> Any:
    """One impact coefficient of a model: its fixed value, the scene's (required
    or optional with a default), or ``None`` when the model does not use it."""
    if key in preset["fixed"]:
        return preset["fixed"][key]
    path = f"impact.{key}"
    if key not in data:
        if key in preset["required"]:
            raise SceneError("missing", path)
        return preset["optional"].get(key)
    if key not in (*preset["required"], *preset["optional"]):
        return None
    if key == "impulse_ratio":
        return _impulse_ratio(data[key], reading)
    return reading.leaves.number(data[key], path, "number")


def _impulse_ratio(value: Any, reading: _Reading) -> float | str:
    """A signed impulse ratio μ, or the string ``"critical"``."""
    if isinstance(value, str) and value == CRITICAL:
        return CRITICAL
    try:
        return reading.leaves.number(value, "impact.impulse_ratio", "number")
    except SceneError as exc:
        if isinstance(value, Mapping) or (isinstance(value, str) and any(c.isdigit() for c in value)):
            raise
        raise SceneError(
            f'must be a finite number or "critical", got {show_value(value)}', "impact.impulse_ratio"
        ) from exc


def _unused_coefficients(data: Mapping, model: str) -> list[str]:
    """Warnings for coefficients the scene gives but its model fixes or does not use."""
    preset = PRESETS[model]
    warnings = []
    for key in COEFFICIENT_KEYS:
        if key not in data:
            continue
        if key in preset["fixed"] and data[key] != preset["fixed"][key]:
            warnings.append(
                f"impact.{key} = {show_value(data[key])} is not used: the {model} model "
                f"fixes it at {show_value(preset['fixed'][key])}"
            )
        elif key not in preset["fixed"] and key not in (*preset["required"], *preset["optional"]):
            warnings.append(f"impact.{key} is not used by the {model} model")
    return warnings


def uses_yaw(model: str) -> bool:
    """True for a model with yaw rates and lever arms (every kernel family but
    the particle one)."""
    return PRESETS[model]["kernel"] != "particle"


#: Per scene kind: vehicle keys required of a moving vehicle, and keys the
#: command does not use (with the reason shown).
_REQUIRED = {
    "forward": ("velocity",),
    "inverse": ("final_velocity",),
    "reconstruct": ("final_velocity", "heading"),
    "crash3": ("crush",),
}
_NOT_USED = {
    "forward": {
        "final_velocity": "solve starts from the initial motion",
        "final_yaw_rate": "solve starts from the initial motion",
        "crush": "crush tables are read by crash3 and compare",
    },
    "inverse": {
        "velocity": "invert computes the initial motion",
        "yaw_rate": "invert computes the initial motion",
        "crush": "crush tables are read by crash3 and compare",
    },
    "reconstruct": {
        "velocity": "reconstruct computes the pre-impact velocity from the heading",
        "crush": "crush tables are read by crash3 and compare",
    },
    "crash3": {"final_velocity": "CRASH3 works from crush", "final_yaw_rate": "CRASH3 works from crush"},
}
_NOT_USED_BY_PARTICLES = ("yaw_inertia", "radius_of_gyration", "yaw_rate", "final_yaw_rate", "impact_point")
_NOT_USED_BY_FIXED = (
    "mass",
    "weight",
    "yaw_inertia",
    "radius_of_gyration",
    "crush",
    "final_velocity",
    "final_yaw_rate",
)


def _read_vehicle(data: Mapping, index: int, fixed: bool, reading: _Reading) -> dict[str, Any]:
    """Check vehicle ``index``'s entry and read its leaves; return its extras
    (``crush`` normalised, ``length``, ``width``). A moving vehicle needs its
    kind's keys (:data:`_REQUIRED`), a mass and, in a rigid model (not for
    CRASH3), a yaw inertia and an impact point. A key the command does not use
    is still checked and reported."""
    path = f"vehicles[{index}]"
    kind, rigid_model = reading.kind, uses_yaw(reading.model)
    _name(data.get("name", f"vehicle {index + 1}"), f"{path}.name")
    for first, second in (("mass", "weight"), ("yaw_inertia", "radius_of_gyration")):
        if first in data and second in data:
            raise SceneError(f"give {first} or {second}, not both", f"{path}.{second}")
    unused = dict(_NOT_USED[kind])
    if not rigid_model and kind in ("forward", "inverse"):
        unused.update(dict.fromkeys(_NOT_USED_BY_PARTICLES, "the particle model has no yaw"))
    if fixed:
        unused.update(dict.fromkeys(_NOT_USED_BY_FIXED, "the vehicle is fixed (immovable)"))
    for key in data:
        if key in unused:
            reading.not_used(f"{path}.{key}", unused[key])
    if not fixed:
        needed = list(_REQUIRED[kind]) + ["mass"]
        if rigid_model and kind != "crash3":
            needed += ["yaw_inertia", "impact_point"]
        for key in needed:
            if key not in data and not (key in _ALTERNATIVE and _ALTERNATIVE[key] in data):
                raise SceneError("missing", f"{path}.{key}")
    leaves = reading.leaves
    for key, dimension in (
        ("mass", "mass"),
        ("weight", "force"),
        ("yaw_inertia", "inertia"),
        ("radius_of_gyration", "length"),
    ):
        if key in data:
            leaves.number(data[key], f"{path}.{key}", dimension, "positive")
    for key in ("velocity", "final_velocity"):
        if key in data:
            leaves.vector(data[key], f"{path}.{key}", "speed", "velocity")
    for key, dimension in (("yaw_rate", "rate"), ("final_yaw_rate", "rate"), ("heading", "angle")):
        if key in data:
            leaves.number(data[key], f"{path}.{key}", dimension)
    if "impact_point" in data:
        leaves.vector(data["impact_point"], f"{path}.impact_point", "length", "impact_point")
        if isinstance(data["impact_point"], Mapping) and "heading" not in data:
            raise SceneError(
                "in the vehicle frame ({forward, left} or {distance, angle}) it needs "
                f"the vehicle's heading ({path}.heading)",
                f"{path}.impact_point",
            )
    extra = {
        key: leaves.number(data[key], f"{path}.{key}", "length", "positive")
        for key in ("length", "width")
        if key in data
    }
    if "crush" in data:
        extra["crush"] = _crush(data["crush"], f"{path}.crush", leaves)
    return extra


#: A required key and the alternative form that may stand for it.
_ALTERNATIVE = {"mass": "weight", "yaw_inertia": "radius_of_gyration"}


def _crush(raw: Any, path: str, leaves: LeafReader) -> dict[str, Any]:
    """A ``crush`` table with its numeric entries (:data:`CRUSH_LEAVES`,
    ``depths``) read as leaves in CRASH3's units; its other entries are kept
    as given, and ranges checked, by impactsym.crash3 (its kernels give a
    status for out-of-range values)."""
    data = _mapping(raw, path)
    crush = dict(data)
    for key, dimension in CRUSH_LEAVES.items():
        if key in data:
            crush[key] = leaves.number(data[key], f"{path}.{key}", dimension)
    depths = data.get("depths")
    if isinstance(depths, list):
        crush["depths"] = [
            leaves.number(value, f"{path}.depths[{i}]", "crush_length") for i, value in enumerate(depths)
        ]
    return crush


def _vehicle(raw: Mapping, index: int, fixed: bool, state: Mapping, extra: dict) -> Vehicle:
    """The normalised Vehicle from its leaves' nominal state."""
    if state["heading"] is not None:
        extra["heading"] = float(state["heading"])
    if state["V"] is not None:
        extra["final_velocity"] = _pair(state["V"])
    if "final_yaw_rate" in raw:
        extra["final_yaw_rate"] = float(state["W"])
    return Vehicle(
        name=raw.get("name", f"vehicle {index + 1}"),
        mass=None if state["m"] is None else float(state["m"]),
        yaw_inertia=None if state["I"] is None else float(state["I"]),
        velocity=_pair(state["v"]) if state["v"] is not None else (0.0, 0.0),
        yaw_rate=float(state["w"]),
        impact_point=_pair(state["r"]),
        fixed=fixed,
        extra={key: extra[key] for key in sorted(extra, key=_EXTRA_ORDER.index)},
    )


_EXTRA_ORDER = ["heading", "final_velocity", "final_yaw_rate", "length", "width", "crush"]


def _pair(vector) -> tuple[float, float]:
    return float(vector[0]), float(vector[1])


def _vehicle_inputs(vehicle: Vehicle, number: int, yaw: bool) -> dict[str, float]:
    """Batch-named inputs of vehicle ``number`` (1 or 2); ``yaw``: with yaw
    inertia, yaw rate and impact point (every model but particles)."""
    values = {
        f"m{number}": math.inf if vehicle.fixed else vehicle.mass,
        f"v{number}x": vehicle.velocity[0],
        f"v{number}y": vehicle.velocity[1],
    }
    if yaw:
        values[f"I{number}"] = math.inf if vehicle.fixed else vehicle.yaw_inertia
        values[f"w{number}"] = vehicle.yaw_rate
        values[f"r{number}x"] = vehicle.impact_point[0]
        values[f"r{number}y"] = vehicle.impact_point[1]
    return values


def _require(data: Mapping, key: str, path: str) -> Any:
    """``data[key]``, or a ``missing`` error naming ``path.key``."""
    if key not in data:
        raise SceneError("missing", f"{path}.{key}" if path else key)
    return data[key]


def _mapping(value: Any, path: str) -> Mapping:
    """``value`` if it is an object/table."""
    if not isinstance(value, Mapping):
        raise SceneError(f"must be an object (a table of keys), got {show_value(value)}", path)
    return value


def _choice(value: Any, path: str, allowed: tuple[str, ...], what: str) -> str:
    """``value`` if it is one of the ``allowed`` strings (exact spelling)."""
    if not isinstance(value, str) or value not in allowed:
        options = " or ".join(f'"{option}"' for option in allowed)
        raise SceneError(f"unknown {what} {show_value(value)} (use {options})", path)
    return value


def _units(value: Any) -> str:
    """The unit system, ``"SI"`` or ``"US"``, in any letter case (``"si"``)."""
    if isinstance(value, str) and value.upper() in UNITS:
        return value.upper()
    return _choice(value, "units", UNITS, "units")


def _flag(value: Any, path: str) -> bool:
    """``value`` if it is a bool."""
    if not isinstance(value, bool):
        raise SceneError(f"must be true or false, got {show_value(value)}", path)
    return value


def _name(value: Any, path: str) -> str:
    """``value`` if it is a non-empty string."""
    if not isinstance(value, str) or not value.strip():
        raise SceneError(f"must be a non-empty string, got {show_value(value)}", path)
    return value


def _number(value: Any, path: str) -> float:
    """``value`` as a finite float (a bare number; for tables other modules read)."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        try:
            number = float(value)
        except OverflowError:
            number = math.inf
        if math.isfinite(number):
            return number
    raise SceneError(f"must be a finite number, got {show_value(value)}", path)


def _positive(value: Any, path: str) -> float:
    """``value`` as a positive finite float (masses, inertias, sizes)."""
    try:
        number = _number(value, path)
    except SceneError:
        number = math.nan
    if number > 0.0:
        return number
    raise SceneError(f"must be a positive finite number, got {show_value(value)}", path)


# --------------------------------------------------------------------------- columns of draws


@dataclass(frozen=True)
class SceneColumns:
    """Kernel input columns of a scene with some leaves replaced by arrays.

    ``columns`` maps kernel input names (conventions.md batch names, angles in
    radians, a fixed vehicle ``m = I = inf``) to floats (the same for every
    row) or 1-D float64 arrays of ``rows`` values; ``mu`` is ``"critical"``
    for a critical scene. Forward columns leave out the coefficients the
    scene's model fixes, so they go straight to ``solve_batch(columns,
    model=model)``; ``invert_batch`` and ``reconstruct_batch`` take theirs as
    they are. CRASH3 columns are ``m1 m2 I1 I2 r1x r1y r2x r2y gamma`` plus
    ``crush``: per vehicle ``None`` (fixed) or the inputs of its crush-energy
    kernel (``A B width alpha C1..Cn``, CRASH3 units, alpha in radians) with
    ``moment_arm`` and ``radius_of_gyration`` when given.

    ``reason`` holds per row ``""`` or why the row's leaves are out of their
    domain (``"vehicles[0].weight is not positive"``, ``"impact.restitution
    is outside [0, 1]"``): such rows must be rejected, not solved. ``flipped``
    is per row True where the normal was turned round (n·(r1 - r2) < 0).
    """

    kind: str
    model: str
    rows: int
    columns: dict[str, Any]
    reason: np.ndarray
    flipped: Any

    @property
    def valid(self) -> np.ndarray:
        """True for the rows whose leaves are all in their domains."""
        return self.reason == ""


#: Physical ranges of coefficients, checked on drawn values.
_COEFFICIENT_RANGES = {
    "impact.restitution": (0.0, 1.0),
    "impact.moment_restitution": (-1.0, 1.0),
    "impact.slip": (0.0, 1.0),
}


def scene_columns(scene: Scene, overrides: Mapping[str, Any] | None = None) -> SceneColumns:
    """The kernel input columns of ``scene`` for its kind (forward, inverse,
    reconstruct, crash3), with the leaves named in ``overrides`` (paths as in
    :attr:`Scene.leaves`, ``vehicles[0].velocity.speed``) set to NumPy arrays
    of values in scene units (angles in degrees, as in the file), one element
    per row. Every alternative form (weight, radius of gyration, speed and
    direction, vehicle-frame impact points, the normal's sense) is computed
    row by row from the leaves. Raises ValueError for an unknown path or
    arrays of different lengths."""
    arrays, rows = _override_arrays(scene, overrides or {})
    values = {path: leaf.nominal for path, leaf in scene.leaves.items()}
    values.update(arrays)
    reason = domain_reasons(scene.leaves, arrays, rows)
    for path, (low, high) in _COEFFICIENT_RANGES.items():
        if path in arrays:
            outside = ~((arrays[path] >= low) & (arrays[path] <= high))
            reason[outside & (reason == "")] = f"{path} is outside [{low:g}, {high:g}]"
    states = [_row_state(scene, values, index) for index in range(2)]
    angle, flipped = used_normal_angle(
        values.get("impact.normal_angle", math.nan), states[0]["r"], states[1]["r"]
    )
    gamma = np.deg2rad(angle) if np.ndim(angle) else math.radians(float(angle))
    columns = _KIND_COLUMNS[scene.kind](scene, values, states, gamma)
    return SceneColumns(scene.kind, scene.model, rows, columns, reason, flipped)


def _override_arrays(scene: Scene, overrides: Mapping[str, Any]) -> tuple[dict, int]:
    """The overrides as float64 1-D arrays of one common length (and that length)."""
    arrays, lengths = {}, set()
    for path, value in overrides.items():
        if path not in scene.leaves:
            raise ValueError(f"{path}: not a leaf of the scene{_nearest(path, tuple(scene.leaves))}")
        array = np.asarray(value, dtype=np.float64)
        if array.ndim != 1:
            raise ValueError(f"{path}: must be a 1-D array, got shape {array.shape}")
        arrays[path] = array
        lengths.add(array.shape[0])
    if len(lengths) > 1:
        raise ValueError(f"overrides: arrays of different lengths {sorted(lengths)}")
    return arrays, lengths.pop() if lengths else 1


def _nearest(path: str, known: tuple[str, ...]) -> str:
    return "; " + unknown_key(path, known).split("; ", 1)[-1] if known else ""


def _row_state(scene: Scene, values: Mapping, index: int) -> dict[str, Any]:
    """vehicle_state with a fixed vehicle's infinite mass and inertia and the
    defaults of absent motion."""
    state = vehicle_state(values, index, scene.units)
    if scene.vehicles[index].fixed:
        state["m"] = state["I"] = math.inf
    for key in ("v", "V"):
        if state[key] is None:
            state[key] = (0.0, 0.0)
    return state


def _motion_columns(states, yaw: bool, initial: bool) -> dict[str, Any]:
    """m, v (or final V), and with yaw I, w (or W), r, by batch name."""
    columns = {}
    for number, state in enumerate(states, start=1):
        v, w = ("v", "w") if initial else ("V", "W")
        columns[f"m{number}"] = state["m"]
        columns[f"{v}{number}x"], columns[f"{v}{number}y"] = state[v]
        if yaw:
            columns[f"I{number}"] = state["I"]
            columns[f"{w}{number}"] = state[w]
            columns[f"r{number}x"], columns[f"r{number}y"] = state["r"]
    return columns


def _coefficient_columns(scene: Scene, values: Mapping) -> dict[str, Any]:
    """e, mu ("critical" for a critical scene), e_m, slip as the model takes them,
    without those its preset fixes."""
    impact, columns = scene.impact, {}
    for key in COEFFICIENT_KEYS:
        given = getattr(impact, key)
        if given is None or key in PRESETS[scene.model]["fixed"]:
            continue
        columns[COEFFICIENT_INPUTS[key]] = values.get(f"impact.{key}", given)
    if scene.family == "particle":
        columns.pop("e_m", None)
    return columns


def _forward_columns(scene: Scene, values, states, gamma) -> dict[str, Any]:
    columns = {"gamma": gamma, **_coefficient_columns(scene, values)}
    columns.update(_motion_columns(states, scene.uses_yaw, initial=True))
    return columns


def _inverse_columns(scene: Scene, values, states, gamma) -> dict[str, Any]:
    columns = {"gamma": gamma, **_coefficient_columns(scene, values)}
    columns.update(_motion_columns(states, scene.uses_yaw, initial=False))
    return columns


def _reconstruct_columns(scene: Scene, values, states, gamma) -> dict[str, Any]:
    columns = {"gamma": gamma, **_motion_columns(states, True, initial=False)}
    for number, state in enumerate(states, start=1):
        columns[f"w{number}"] = state["w"]
        columns[f"theta{number}"] = np.deg2rad(state["heading"])
    return columns


def _crash3_columns(scene: Scene, values, states, gamma) -> dict[str, Any]:
    columns = {"gamma": gamma}
    for number, state in enumerate(states, start=1):
        columns[f"m{number}"] = state["m"]
        columns[f"I{number}"] = math.inf if state["I"] is None else state["I"]
        columns[f"r{number}x"], columns[f"r{number}y"] = state["r"]
    columns["crush"] = [
        None if vehicle.fixed else _crush_columns(values, index)
        for index, vehicle in enumerate(scene.vehicles)
    ]
    return columns


def _crush_columns(values: Mapping, index: int) -> dict[str, Any]:
    """The crush-energy kernel inputs of vehicle ``index`` from its crush leaves."""
    prefix = f"vehicles[{index}].crush"
    columns = {
        key: values[f"{prefix}.{key}"]
        for key in ("A", "B", "width", "moment_arm", "radius_of_gyration")
        if f"{prefix}.{key}" in values
    }
    if f"{prefix}.pdof" in values:
        columns["alpha"] = np.deg2rad(values[f"{prefix}.pdof"])
    depth = 0
    while f"{prefix}.depths[{depth}]" in values:
        columns[f"C{depth + 1}"] = values[f"{prefix}.depths[{depth}]"]
        depth += 1
    return columns


_KIND_COLUMNS = {
    "forward": _forward_columns,
    "inverse": _inverse_columns,
    "reconstruct": _reconstruct_columns,
    "crash3": _crash3_columns,
}
