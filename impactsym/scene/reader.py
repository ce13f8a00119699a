"""Reading a scene: a JSON or TOML file or a mapping, checked field by field
(one-line :class:`SceneError` naming the path), into a :class:`Scene`; keys a
command does not use become warnings."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

from .._kernels import PRESETS
from ..errors import SceneError, show_value
from .casefile import (
    COEFFICIENT_KEYS,
    CRUSH_LEAVES,
    IMPACT_KEYS,
    TOP_KEYS,
    VEHICLE_KEYS,
    Leaf,
    LeafReader,
    check_keys,
    parse_correlations,
    used_normal_angle,
    vehicle_state,
)
from .fields import as_choice, as_flag, as_mapping, as_name, require_key
from .model import CRITICAL, KINDS, MODELS, UNITS, Impact, Scene, Vehicle, pair, uses_yaw
from .plausibility import implausible


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
        return _parse_scene(read_file(path), path, kind)
    raise TypeError(f"load_scene: expected a Scene, a mapping or a path, got {type(source).__name__}")


def scene_data(source: Scene | Mapping | str | Path) -> Mapping:
    """The scene-file mapping of ``source`` (a :class:`Scene`, a mapping or a
    ``.json``/``.toml`` path), not validated: what a scene gives, before its
    model's defaults and fixed coefficients are applied."""
    if isinstance(source, Scene):
        return source.data if source.data is not None else source.to_dict()
    if isinstance(source, Mapping):
        return source
    return read_file(Path(source))


def read_file(path: Path) -> Any:
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
    model = as_choice(data.get("model", "rigid"), "model", MODELS, "model")
    units = _units(require_key(data, "units", ""))
    # CRASH3 uses the impact geometry only for delta-V directions and moment arms.
    no_impact = kind == "crash3" and "impact" not in data
    impact_data = {} if no_impact else as_mapping(require_key(data, "impact", ""), "impact")
    check_keys(impact_data, IMPACT_KEYS, "impact")
    if kind == "inverse" and PRESETS[model]["kernel"] not in ("rigid", "particle"):
        raise SceneError(f"the {model} model has no inverse solution", "model")
    reading = _Reading(kind, model, units)
    if "crash3" in data and kind != "crash3":
        reading.not_used("crash3", "the CRASH3 options are read by crash3 and compare")
    raw_vehicles = _vehicle_list(require_key(data, "vehicles", ""))
    fixed = tuple(_fixed(entry, index) for index, entry in enumerate(raw_vehicles))
    if all(fixed):
        raise SceneError("both vehicles are fixed; at most one may be", "vehicles")
    coefficients = _parse_coefficients(impact_data, reading)
    if not no_impact:
        reading.leaves.number(
            require_key(impact_data, "normal_angle", "impact"), "impact.normal_angle", "angle"
        )
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
    warnings += implausible(leaves, vehicles, units)
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
        as_mapping(entry, f"vehicles[{index}]")
        check_keys(entry, VEHICLE_KEYS, f"vehicles[{index}]")
    return raw


def _fixed(entry: Mapping, index: int) -> bool:
    return as_flag(entry.get("fixed", False), f"vehicles[{index}].fixed")


def _not_used_why(kind: str, key: str) -> str:
    """Why a reconstruction or CRASH3 does not read the coefficient ``key``."""
    if kind == "reconstruct":
        return "a reconstruction infers it from the motion"
    if key == "restitution":
        return "CRASH3 takes its restitution from the crash3 options"
    return "CRASH3 has no tangential or moment impulse law (it works from crush energy)"


def _parse_coefficients(data: Mapping, reading: _Reading) -> dict[str, Any]:
    """The impact coefficients of a forward or inverse scene (the model's
    preset says which the scene gives and which it fixes). A reconstruction
    infers them and CRASH3 uses none: there they are reported as not used."""
    if reading.kind in ("reconstruct", "crash3"):
        for key in COEFFICIENT_KEYS:
            if key in data:
                reading.not_used(f"impact.{key}", _not_used_why(reading.kind, key))
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
    as_name(data.get("name", f"vehicle {index + 1}"), f"{path}.name")
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
    read_body(leaves, data, path)
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
    data = as_mapping(raw, path)
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
        extra["final_velocity"] = pair(state["V"])
    if "final_yaw_rate" in raw:
        extra["final_yaw_rate"] = float(state["W"])
    return Vehicle(
        name=raw.get("name", f"vehicle {index + 1}"),
        mass=None if state["m"] is None else float(state["m"]),
        yaw_inertia=None if state["I"] is None else float(state["I"]),
        velocity=pair(state["v"]) if state["v"] is not None else (0.0, 0.0),
        yaw_rate=float(state["w"]),
        impact_point=pair(state["r"]),
        fixed=fixed,
        extra={key: extra[key] for key in sorted(extra, key=_EXTRA_ORDER.index)},
    )


_EXTRA_ORDER = ["heading", "final_velocity", "final_yaw_rate", "length", "width", "crush"]


def _units(value: Any) -> str:
    """The unit system, ``"SI"`` or ``"US"``, in any letter case (``"si"``)."""
    if isinstance(value, str) and value.upper() in UNITS:
        return value.upper()
    return as_choice(value, "units", UNITS, "units")


#: A vehicle's body quantities (each with its alternative form) and their dimensions.
BODY_FIELDS = (
    ("mass", "mass"),
    ("weight", "force"),
    ("yaw_inertia", "inertia"),
    ("radius_of_gyration", "length"),
)


def read_body(leaves, data, path: str) -> None:
    """Read the body quantities ``data`` gives (mass or weight, yaw inertia or
    radius of gyration) as positive leaves at ``path``; SceneError naming the field."""
    for key, dimension in BODY_FIELDS:
        if key in data:
            leaves.number(data[key], f"{path}.{key}", dimension, "positive")
