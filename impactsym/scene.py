"""Scene files: reading, validation and conversion to kernel inputs.

A scene describes one planar two-vehicle impact in the format of
``conventions.md`` (JSON or TOML, same structure).  Frame: x, y in the scene
plane, angles counter-clockwise from +x.  ``impact.normal_angle`` is Γ in
degrees; the normal ``n = (cos Γ, sin Γ)`` points from vehicle 1 toward
vehicle 2.  ``impact_point`` is the vector from a vehicle's centre of gravity to
the impact centre, in the scene frame.

Units are consistent sets: ``"SI"`` (kg, m, kg·m², m/s, rad/s) or ``"US"``
(slug, ft, slug·ft², ft/s, rad/s).  The kernels do not depend on the set; it
only labels the output.

Validation is strict about values and lenient about keys: a bad value raises
:class:`SceneError` with one line naming the field path
(``vehicles[1].mass: must be a positive finite number, got -5``); a key the
format does not know is kept and reported in :attr:`Scene.warnings`.
"""

from __future__ import annotations

import json
import math
import numbers
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

from ._kernels import PRESETS

__all__ = ["SceneError", "Vehicle", "Impact", "Scene", "load_scene", "scene_data", "uses_yaw",
           "MODELS", "UNITS"]

# Model names a scene may give (generated.presets.PRESETS): the general model
# ("rigid" or "brach"), "particle", and the seed's named models as presets.
MODELS = tuple(PRESETS)
UNITS = ("SI", "US")
CRITICAL = "critical"

_SCENE_KEYS = ("model", "units", "impact", "vehicles")
_SCENE_METADATA = ("title", "description", "notes", "comment")
_COEFFICIENT_KEYS = ("restitution", "impulse_ratio", "moment_restitution", "slip")
_IMPACT_KEYS = ("normal_angle",) + _COEFFICIENT_KEYS
_VEHICLE_KEYS = ("name", "mass", "yaw_inertia", "velocity", "yaw_rate", "impact_point", "fixed")


class SceneError(ValueError):
    """A scene that cannot be solved; the message is one line.

    ``field`` is the path of the offending entry (``"vehicles[1].mass"``) or
    ``None`` when the problem is not tied to one field (a malformed file, a
    scene the kernel rejects).
    """

    def __init__(self, message: str, field: str | None = None):
        self.field = field
        text = f"{field}: {message}" if field else message
        super().__init__(" ".join(text.split()))


@dataclass(frozen=True)
class Vehicle:
    """One vehicle at first contact.

    ``mass`` [kg | slug] and ``yaw_inertia`` [kg·m² | slug·ft²] are ``None``
    when not given (a fixed vehicle, or ``yaw_inertia`` in the particle model).
    ``velocity`` [m/s | ft/s] and ``yaw_rate`` [rad/s] are the initial motion
    (zero by default for a fixed vehicle); ``impact_point`` [m | ft] is the
    vector from the centre of gravity to the impact centre, (0, 0) when not
    needed.  ``fixed`` marks an immovable object (infinite mass and inertia).
    ``extra`` holds the other keys of the vehicle entry (``heading``,
    ``final_velocity``, ``crush``, …) as read.
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
        """The vehicle entry in scene-file form (``None`` entries left out)."""
        entry = {
            "name": self.name,
            "mass": self.mass,
            "yaw_inertia": self.yaw_inertia,
            "velocity": list(self.velocity),
            "yaw_rate": self.yaw_rate,
            "impact_point": list(self.impact_point),
            "fixed": self.fixed,
        }
        entry.update(self.extra)
        return {key: value for key, value in entry.items() if value is not None}


@dataclass(frozen=True)
class Impact:
    """Impact coefficients.

    ``normal_angle``: Γ in degrees, as written in the scene.  ``restitution``:
    e.  ``impulse_ratio``: signed μ = Pt/Pn, or ``"critical"`` for μ = μ_c (no
    sliding at separation).  ``moment_restitution``: e_m (1 gives no moment
    impulse).  ``slip``: IMPAC's sideswipe constraint, the fraction of the
    initial tangential relative velocity at the impact centre left at
    separation.  A coefficient the scene's model fixes holds the fixed value
    (``limpert``: e = 0, ``"critical"``, e_m = 1); one the model does not use is
    ``None``.
    """

    normal_angle: float
    restitution: float | None
    impulse_ratio: Union[float, str, None]
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
        return {key: value for key, value in entry.items() if value is not None}


@dataclass(frozen=True)
class Scene:
    """A validated scene: model, units, impact coefficients and two vehicles.

    ``source`` is the file it was read from (``None`` for a dict).  ``extra``
    holds top-level keys other than the four of the format; ``warnings`` lists
    the keys validation kept but does not know (likely typos).
    """

    model: str
    units: str
    impact: Impact
    vehicles: tuple[Vehicle, Vehicle]
    source: Path | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The scene in scene-file form (what :func:`load_scene` reads back)."""
        data = {
            "model": self.model,
            "units": self.units,
            "impact": self.impact.to_dict(),
            "vehicles": [vehicle.to_dict() for vehicle in self.vehicles],
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


KINDS = ("forward", "inverse", "reconstruct", "crash3")


def load_scene(source: Union[Scene, Mapping, str, Path], kind: str = "forward") -> Scene:
    """Read and validate a scene.

    ``source`` is a :class:`Scene` (validated again), a mapping in scene-file
    form, or the path of a ``.json`` or ``.toml`` file.  ``kind`` says what the
    scene is for: ``"forward"`` (initial motion given), ``"inverse"`` (final
    motion given instead: ``final_velocity``, ``final_yaw_rate``),
    ``"reconstruct"`` (final motion and pre-impact ``heading``; the impact needs
    only ``normal_angle``) or ``"crash3"`` (each moving vehicle carries ``crush``;
    the motion, yaw inertia and impact point are optional, the impact needs only
    ``normal_angle``).  Raises :class:`SceneError` for a bad scene and
    :class:`OSError` for a file that cannot be read.
    """
    if kind not in KINDS:
        raise ValueError(f"kind: unknown scene kind {kind!r} (use one of {', '.join(KINDS)})")
    if isinstance(source, Scene):
        return _parse_scene(source.to_dict(), source.source, kind)
    if isinstance(source, Mapping):
        return _parse_scene(source, None, kind)
    if isinstance(source, (str, Path)):
        path = Path(source)
        return _parse_scene(_read_file(path), path, kind)
    raise TypeError(f"load_scene: expected a Scene, a mapping or a path, got {type(source).__name__}")


def scene_data(source: Union[Scene, Mapping, str, Path]) -> Mapping:
    """The scene-file mapping of ``source`` (a :class:`Scene`, a mapping or a
    ``.json``/``.toml`` path), not validated: what a scene gives, before its
    model's defaults and fixed coefficients are applied."""
    if isinstance(source, Scene):
        return source.to_dict()
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
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    if suffix == ".json":
        try:
            return json.loads(text)
        except json.JSONDecodeError as exc:
            raise SceneError(f"{path}: invalid JSON: {exc}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: invalid TOML: {exc}") from None


def _parse_scene(data: Any, source: Path | None, kind: str) -> Scene:
    """Validate a whole scene in scene-file form."""
    if not isinstance(data, Mapping):
        where = f"{source}: " if source else ""
        raise SceneError(f"{where}a scene must be an object (a table of keys), got {show_value(data)}")
    model = _choice(data.get("model", "rigid"), "model", MODELS, "model")
    units = _choice(_require(data, "units", ""), "units", UNITS, "units")
    impact_data = _mapping(_require(data, "impact", ""), "impact")
    if kind == "inverse" and PRESETS[model]["kernel"] not in ("rigid", "particle"):
        raise SceneError(f"the {model} model has no inverse solution", "model")
    impact = _parse_impact(impact_data, kind, model)
    vehicles = _parse_vehicles(_require(data, "vehicles", ""), model, kind)
    extra = {key: data[key] for key in data if key not in _SCENE_KEYS}
    warnings = _ignored(extra, "", _SCENE_METADATA)
    warnings += _ignored(impact_data, "impact", _IMPACT_KEYS)
    if kind in ("forward", "inverse"):
        warnings += _unused_coefficients(impact_data, model)
    for index, vehicle in enumerate(vehicles):
        warnings += _ignored(vehicle.extra, f"vehicles[{index}]", _VEHICLE_EXTRAS)
    return Scene(model, units, impact, vehicles, source, extra, tuple(warnings))


def _parse_impact(data: Mapping, kind: str, model: str) -> Impact:
    """Validate the ``impact`` table. A reconstruction infers the coefficients
    and CRASH3 uses none, so they need only ``normal_angle``; an inverse needs
    a numeric impulse ratio. The model's preset says which coefficients the
    scene gives and which it fixes."""
    normal_angle = _number(_require(data, "normal_angle", "impact"), "impact.normal_angle")
    if kind in ("reconstruct", "crash3"):
        return Impact(normal_angle=normal_angle, restitution=math.nan, impulse_ratio=math.nan,
                      moment_restitution=math.nan)
    coefficients = {key: _coefficient(data, key, PRESETS[model]) for key in _COEFFICIENT_KEYS}
    if kind == "inverse" and coefficients["impulse_ratio"] == CRITICAL:
        raise SceneError('must be a number for an inverse solution: with "critical" the final '
                         "velocities do not determine the tangential slip", "impact.impulse_ratio")
    return Impact(normal_angle=normal_angle, **coefficients)


def _coefficient(data: Mapping, key: str, preset: Mapping) -> Any:
    """One impact coefficient of a model: its fixed value, the scene's (required
    or optional with a default), or ``None`` when the model does not use it."""
    if key in preset["fixed"]:
        return preset["fixed"][key]
    check = _impulse_ratio if key == "impulse_ratio" else (lambda v: _number(v, f"impact.{key}"))
    if key in preset["required"]:
        return check(_require(data, key, "impact"))
    if key in preset["optional"]:
        return check(data.get(key, preset["optional"][key]))
    return None


def _unused_coefficients(data: Mapping, model: str) -> list[str]:
    """Warnings for coefficients the scene gives but its model fixes or does not use."""
    preset = PRESETS[model]
    warnings = []
    for key in _COEFFICIENT_KEYS:
        if key not in data:
            continue
        if key in preset["fixed"] and data[key] != preset["fixed"][key]:
            warnings.append(f"impact.{key} = {show_value(data[key])} is not used: the {model} model "
                            f"fixes it at {show_value(preset['fixed'][key])}")
        elif key not in preset["fixed"] and key not in (*preset["required"], *preset["optional"]):
            warnings.append(f"impact.{key} is not used by the {model} model")
    return warnings


def uses_yaw(model: str) -> bool:
    """True for a model with yaw rates and lever arms (every kernel family but
    the particle one)."""
    return PRESETS[model]["kernel"] != "particle"


def _impulse_ratio(value: Any) -> Union[float, str]:
    """A signed impulse ratio μ, or the string ``"critical"``."""
    if isinstance(value, str) and value == CRITICAL:
        return CRITICAL
    try:
        return _number(value, "impact.impulse_ratio")
    except SceneError:
        raise SceneError(f'must be a finite number or "critical", got {show_value(value)}', "impact.impulse_ratio") from None


def _parse_vehicles(raw: Any, model: str, kind: str) -> tuple[Vehicle, Vehicle]:
    """Validate the list of exactly two vehicles; at most one may be fixed."""
    if not isinstance(raw, list):
        raise SceneError(f"must be a list of exactly 2 vehicles, got {show_value(raw)}", "vehicles")
    if len(raw) != 2:
        raise SceneError(f"must be a list of exactly 2 vehicles, got {len(raw)}", "vehicles")
    first, second = (_parse_vehicle(entry, index, model, kind) for index, entry in enumerate(raw))
    if first.fixed and second.fixed:
        raise SceneError("both vehicles are fixed; at most one may be", "vehicles")
    return first, second


def _parse_vehicle(raw: Any, index: int, model: str, kind: str) -> Vehicle:
    """Validate one vehicle entry of the given model and scene kind.

    A moving vehicle needs ``mass`` and ``velocity`` (an inverse or
    reconstruction scene: ``final_velocity`` instead, and a reconstruction also
    ``heading``), and in the rigid model also ``yaw_inertia`` and
    ``impact_point``.  A fixed vehicle needs none of them.  Keys given but not
    needed are still checked.
    """
    path = f"vehicles[{index}]"
    data = _mapping(raw, path)
    fixed = _flag(data.get("fixed", False), f"{path}.fixed")
    rigid = uses_yaw(model) and kind != "crash3"
    for key in _KIND_KEYS[kind]:
        if not fixed:
            _require(data, key, path)
    return Vehicle(
        name=_name(data.get("name", f"vehicle {index + 1}"), f"{path}.name"),
        mass=_optional(data, "mass", path, _positive, required=not fixed),
        yaw_inertia=_optional(data, "yaw_inertia", path, _positive, required=rigid and not fixed),
        velocity=_optional(data, "velocity", path, _vector, required=not fixed and kind == "forward",
                           default=(0.0, 0.0)),
        yaw_rate=_optional(data, "yaw_rate", path, _number, default=0.0),
        impact_point=_optional(
            data, "impact_point", path, _vector, required=rigid and not fixed, default=(0.0, 0.0)
        ),
        fixed=fixed,
        extra=_vehicle_extra(data, path),
    )


_KIND_KEYS = {
    "forward": (),
    "inverse": ("final_velocity",),
    "reconstruct": ("final_velocity", "heading"),
    "crash3": ("crush",),
}


def _vehicle_extra(data: Mapping, path: str) -> dict[str, Any]:
    """The vehicle's other keys; the documented ones have their values checked."""
    extra = {}
    for key, value in data.items():
        if key in _VEHICLE_KEYS:
            continue
        check = _VEHICLE_EXTRAS.get(key)
        extra[key] = check(value, f"{path}.{key}") if check else value
    return extra


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


def _ignored(extra: Mapping, path: str, known) -> list[str]:
    """Warnings for keys of ``extra`` that the format does not document."""
    prefix = f"{path}." if path else ""
    return [f"ignored unknown key {prefix}{key}" for key in extra if key not in known]


def _require(data: Mapping, key: str, path: str) -> Any:
    """``data[key]``, or a ``missing`` error naming ``path.key``."""
    if key not in data:
        raise SceneError("missing", f"{path}.{key}" if path else key)
    return data[key]


def _optional(data: Mapping, key: str, path: str, check, *, required: bool = False, default: Any = None) -> Any:
    """``check(data[key])`` when present, an error when required and absent, else ``default``."""
    if key in data:
        return check(data[key], f"{path}.{key}")
    if required:
        raise SceneError("missing", f"{path}.{key}")
    return default


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


def _is_number(value: Any) -> bool:
    """True for a real number that is not a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _number(value: Any, path: str) -> float:
    """``value`` as a finite float."""
    if _is_number(value):
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


def _vector(value: Any, path: str) -> tuple[float, float]:
    """``value`` as a pair of finite floats."""
    if isinstance(value, (list, tuple)) and len(value) == 2:
        try:
            return (_number(value[0], path), _number(value[1], path))
        except SceneError:
            pass
        raise SceneError(f"must be a list of 2 finite numbers, got {show_value(value)}", path)
    raise SceneError(f"must be a list of 2 numbers, got {show_value(value)}", path)


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


def _crush(value: Any, path: str) -> Mapping:
    """A ``crush`` table, kept as read (its entries are checked where used)."""
    return _mapping(value, path)


def show_value(value: Any) -> str:
    """A short, one-line rendering of a scene value for error messages."""
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape}"
    if isinstance(value, str):
        text = repr(value)
    else:
        try:
            text = json.dumps(value)
        except (TypeError, ValueError):
            text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


_VEHICLE_EXTRAS = {
    "length": _positive,
    "width": _positive,
    "heading": _number,
    "final_velocity": _vector,
    "final_yaw_rate": _number,
    "crush": _crush,
}
