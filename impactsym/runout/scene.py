"""Reading a run-out scene: the top-level ``runout`` object and per vehicle its
chassis, ``wheels``, ``separation`` and ``rest`` (conventions.md, "Post-impact
run-out"). Every bad value raises a one-line SceneError naming its field.

Everything is converted to SI and radians for the kernel (US: slug, ft,
slug ft^2, ft/s; gravity default 32.174 ft/s^2); `to_scene` converts back.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import SceneError, show_value
from ..scene import scene_data
from ..scene.casefile import check_keys
from . import _door
from .batch import DEFAULTS

FT = 0.3048  # m
SLUG = 14.59390293720636  # kg
GRAVITY = {"SI": 9.80665, "US": 32.174}
TOP_KEYS = (
    "units",
    "impact",
    "runout",
    "vehicles",
    "title",
    "description",
    "notes",
    "comment",
    "model",
    "correlations",
    "impact_position",
)
RUNOUT_KEYS = ("friction", "slip_angle_max", "rolling_resistance", "gravity")
# Keys of the impact commands that a run-out scene may carry (read by them, not here).
IMPACT_VEHICLE_KEYS = (
    "fixed",
    "weight",
    "radius_of_gyration",
    "velocity",
    "yaw_rate",
    "final_velocity",
    "final_yaw_rate",
    "crush",
    "length",
    "width",
)
# A vehicle's run-out keys that the impact commands do not read (chain.py strips them).
RUNOUT_VEHICLE_KEYS = (
    "wheelbase",
    "cg_to_front_axle",
    "track",
    "cg_height",
    "wheels",
    "separation",
    "rest",
    "intermediate",
    "friction",
)
VEHICLE_KEYS = (
    "name",
    "mass",
    "yaw_inertia",
    "heading",
    *RUNOUT_VEHICLE_KEYS,
    "impact_point",
    *IMPACT_VEHICLE_KEYS,
)
WHEEL_NAMES = ("front_left", "front_right", "rear_left", "rear_right")
WHEEL_KEYS = ("state", "brake", "steer")
STATES = ("rolling", "locked")  # a wheel's state, as the batch column state_k: 0, 1
SEPARATION_KEYS = ("position", "heading", "velocity", "yaw_rate", "mark_directions")
REST_KEYS = ("position", "heading")
INTERMEDIATE_KEYS = ("position", "heading")


@dataclass
class RunoutVehicle:
    """One vehicle's run-out, in SI and radians. `row` holds the kernel COLUMNS
    values except the separation velocity (vx, vy, w), which is `velocity`/
    `yaw_rate` (None when it is to be fitted). `rest` is (x, y, psi) or None."""

    name: str
    row: dict
    position: tuple[float, float]
    heading: float
    velocity: tuple[float, float] | None
    yaw_rate: float | None
    rest: tuple[float, float, float] | None
    wheels: dict = field(default_factory=dict)
    marks: dict = field(
        default_factory=dict
    )  # wheel key (fl, fr, rl, rr) -> mark direction at separation [rad]
    via: tuple = ()  # intermediate poses passed through: (x, y [m], psi [rad] or None) each

    @property
    def fitted(self) -> bool:
        return self.velocity is None


@dataclass
class RunoutScene:
    units: str
    vehicles: list[RunoutVehicle]
    warnings: list[str]

    def length(self) -> float:
        """Metres per scene length unit."""
        return FT if self.units == "US" else 1.0


def _number(value: Any, path: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise SceneError(f"must be a finite number, got {show_value(value)}", path)
    return float(value)


def _positive(value: Any, path: str) -> float:
    x = _number(value, path)
    if x <= 0:
        raise SceneError(f"must be > 0, got {show_value(value)}", path)
    return x


def _pair(value: Any, path: str) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise SceneError(f"must be a list [x, y] of two numbers, got {show_value(value)}", path)
    return _number(value[0], f"{path}[0]"), _number(value[1], f"{path}[1]")


def _mapping(value: Any, path: str) -> Mapping:
    if not isinstance(value, Mapping):
        raise SceneError(f"must be an object (a table of keys), got {show_value(value)}", path)
    return value


def _require(data: Mapping, key: str, path: str) -> Any:
    if key not in data:
        raise SceneError("missing", f"{path}.{key}" if path else key)
    return data[key]


def _wheel(value: Any, path: str) -> tuple[float, float, float]:
    """(state, brake, steer [rad]) of one wheel entry."""
    if isinstance(value, str):
        if value not in ("rolling", "locked"):
            raise SceneError(f'unknown wheel state {show_value(value)} (use "rolling" or "locked")', path)
        return (1.0 if value == "locked" else 0.0), 0.0, 0.0
    entry = _mapping(value, path)
    check_keys(entry, WHEEL_KEYS, path)
    state = entry.get("state", "rolling")
    if state not in ("rolling", "locked"):
        raise SceneError(
            f'unknown wheel state {show_value(state)} (use "rolling" or "locked")', f"{path}.state"
        )
    brake = _number(entry.get("brake", 0.0), f"{path}.brake")
    if not 0.0 <= brake <= 1.0:
        raise SceneError(f"must be between 0 and 1 (a share of mu N), got {brake:g}", f"{path}.brake")
    steer = _number(entry.get("steer", 0.0), f"{path}.steer")
    if abs(steer) >= 90.0:
        raise SceneError(f"must be between -90 and 90 degrees, got {steer:g}", f"{path}.steer")
    return (1.0 if state == "locked" else 0.0), brake, math.radians(steer)


def locked_probability(value: Mapping, path: str) -> float:
    """The probability that a wheel was locked, from its state given as
    probabilities, ``{"locked": p, "rolling": 1 - p}`` (either key alone: the
    other takes the rest). ``reconstruct --uncertainty`` draws the state from it
    and the nominal scene takes the more probable one; equal probabilities
    leave none, a one-line SceneError naming the field."""
    check_keys(value, STATES, path)
    if not value:
        raise SceneError('give the probability of "locked" and/or "rolling"', path)
    probability = {}
    for key, raw in value.items():
        x = _number(raw, f"{path}.{key}")
        if not 0.0 <= x <= 1.0:
            raise SceneError(f"must be a probability between 0 and 1, got {show_value(raw)}", f"{path}.{key}")
        probability[key] = x
    if len(probability) == 2 and abs(probability["locked"] + probability["rolling"] - 1.0) > 1e-9:
        raise SceneError(f"the probabilities must sum to 1, got {show_value(dict(value))}", path)
    locked = probability.get("locked", 1.0 - probability.get("rolling", 0.0))
    if locked == 0.5:
        raise SceneError("equal probabilities leave no more probable state for the nominal scene", path)
    return locked


def _wheels(value: Any, path: str) -> dict[str, tuple[float, float, float]]:
    if isinstance(value, str):
        one = _wheel(value, path)
        return {name: one for name in WHEEL_NAMES}
    entry = _mapping(value, path)
    check_keys(entry, WHEEL_NAMES, path)
    return {name: _wheel(_require(entry, name, path), f"{path}.{name}") for name in WHEEL_NAMES}


def _tyre(data: Mapping, units: str) -> dict[str, float]:
    """The top-level runout object: friction, alpha_max [rad], f_r, g [SI]."""
    raw = _mapping(_require(data, "runout", ""), "runout")
    check_keys(raw, RUNOUT_KEYS, "runout")
    mu = _positive(_require(raw, "friction", "runout"), "runout.friction")
    amax = _positive(raw.get("slip_angle_max", 10.0), "runout.slip_angle_max")
    if amax >= 90.0:
        raise SceneError(f"must be below 90 degrees, got {amax:g}", "runout.slip_angle_max")
    f_r = _number(raw.get("rolling_resistance", 0.01), "runout.rolling_resistance")
    if f_r < 0:
        raise SceneError(f"must be >= 0, got {f_r:g}", "runout.rolling_resistance")
    g = _positive(raw.get("gravity", GRAVITY[units]), "runout.gravity")
    return {"mu": mu, "alpha_max": math.radians(amax), "f_r": f_r, "g": g * (FT if units == "US" else 1.0)}


def has_runout(scene) -> bool:
    """Whether `scene` (a path or a mapping) has a top-level ``runout`` object,
    so that its ``solve``/``reconstruct`` runs through the run-outs. A scene that
    cannot be read is False: the command's own reading reports it."""
    if not isinstance(scene, (str, Mapping)) and not hasattr(scene, "__fspath__"):
        return False
    try:
        data = scene_data(scene)
    except (OSError, ValueError):
        return False
    return isinstance(data, Mapping) and "runout" in data


def load_runout(source) -> RunoutScene:
    """The run-out scene of a file path, mapping or Scene."""
    data = _mapping(scene_data(source), "scene")
    check_keys(data, TOP_KEYS, "")
    units = _require(data, "units", "")
    if units not in ("SI", "US"):
        raise SceneError(f'unknown units {show_value(units)} (use "SI" or "US")', "units")
    tyre = _tyre(data, units)
    impact = _mapping(data.get("impact", {}), "impact")
    centre = _pair(impact["position"], "impact.position") if "position" in impact else (0.0, 0.0)
    raw = _require(data, "vehicles", "")
    if not isinstance(raw, list) or not raw:
        raise SceneError(f"must be a non-empty list of vehicles, got {show_value(raw)}", "vehicles")
    length = FT if units == "US" else 1.0
    vehicles = [
        _vehicle(_mapping(v, f"vehicles[{i}]"), i, tyre, centre, units, length) for i, v in enumerate(raw)
    ]
    return RunoutScene(units, vehicles, [])


def _vehicle(v: Mapping, index: int, tyre: dict, centre, units: str, length: float) -> RunoutVehicle:
    p = f"vehicles[{index}]"
    check_keys(v, VEHICLE_KEYS, p)
    mass_unit = SLUG if units == "US" else 1.0
    m = _positive(_require(v, "mass", p), f"{p}.mass") * mass_unit
    inertia = _positive(_require(v, "yaw_inertia", p), f"{p}.yaw_inertia") * mass_unit * length**2
    wb = _positive(_require(v, "wheelbase", p), f"{p}.wheelbase")
    a = _positive(_require(v, "cg_to_front_axle", p), f"{p}.cg_to_front_axle")
    if a >= wb:
        raise SceneError(f"must be less than the wheelbase {wb:g}, got {a:g}", f"{p}.cg_to_front_axle")
    track = _positive(_require(v, "track", p), f"{p}.track")
    wheels = _wheels(_require(v, "wheels", p), f"{p}.wheels")
    mu = _positive(v["friction"], f"{p}.friction") if "friction" in v else tyre["mu"]
    height = _cg_height(v, p, wb, a, track, mu, tyre["f_r"])
    sep = _mapping(v.get("separation", {}), f"{p}.separation")
    check_keys(sep, SEPARATION_KEYS, f"{p}.separation")
    if "heading" in sep:
        heading = _number(sep["heading"], f"{p}.separation.heading")
    else:
        heading = _number(_require(v, "heading", p), f"{p}.heading")
    if "position" in sep:
        pos = _pair(sep["position"], f"{p}.separation.position")
    elif "impact_point" in v:
        r = _pair(v["impact_point"], f"{p}.impact_point")
        pos = (centre[0] - r[0], centre[1] - r[1])
    else:
        raise SceneError("missing (or give the vehicle's impact_point)", f"{p}.separation.position")
    has_v, has_w = "velocity" in sep, "yaw_rate" in sep
    velocity = _pair(sep["velocity"], f"{p}.separation.velocity") if has_v else None
    yaw_rate = _number(sep["yaw_rate"], f"{p}.separation.yaw_rate") if has_w else None
    marks = _marks(sep.get("mark_directions", {}), f"{p}.separation.mark_directions")
    via = _intermediate(v.get("intermediate", []), f"{p}.intermediate", length)
    rest = None
    if "rest" in v:
        r = _mapping(v["rest"], f"{p}.rest")
        check_keys(r, REST_KEYS, f"{p}.rest")
        rp = _pair(_require(r, "position", f"{p}.rest"), f"{p}.rest.position")
        rest = (
            rp[0] * length,
            rp[1] * length,
            math.radians(_number(_require(r, "heading", f"{p}.rest"), f"{p}.rest.heading")),
        )
    if has_v != has_w:
        missing = "yaw_rate" if has_v else "velocity"
        raise SceneError(
            "give both velocity and yaw_rate, or neither (then they are fitted to rest)",
            f"{p}.separation.{missing}",
        )
    if not has_v and rest is None:
        raise SceneError(
            "missing: a vehicle needs a separation velocity and yaw_rate, or a rest pose",
            f"{p}.separation.velocity",
        )
    row = {
        "m": m,
        "I": inertia,
        "L": wb * length,
        "a": a * length,
        "track": track * length,
        "h": height * length,
        **tyre,
        "mu": mu,
        "x": pos[0] * length,
        "y": pos[1] * length,
        "psi": math.radians(heading),
    }
    for key, (state, brake, steer) in zip(("fl", "fr", "rl", "rr"), wheels.values()):
        row[f"state_{key}"], row[f"brake_{key}"], row[f"steer_{key}"] = state, brake, steer
    return RunoutVehicle(
        name=str(v.get("name", f"vehicle {index + 1}")),
        row=row,
        position=(pos[0] * length, pos[1] * length),
        heading=math.radians(heading),
        velocity=None if velocity is None else (velocity[0] * length, velocity[1] * length),
        yaw_rate=yaw_rate,
        rest=rest,
        wheels=wheels,
        marks=marks,
        via=via,
    )


def _cg_height(v: Mapping, p: str, wb: float, a: float, track: float, mu: float, f_r: float) -> float:
    """The optional ``cg_height`` [scene length]: 0 (absent) keeps the contract's
    static wheel loads; > 0 turns on quasi-static load transfer, refused at or
    above the height where it could lift a wheel (derive/load_transfer.py)."""
    if "cg_height" not in v:
        return 0.0
    height = _number(v["cg_height"], f"{p}.cg_height")
    if height < 0.0:
        raise SceneError(f"must be >= 0 (0: static wheel loads), got {height:g}", f"{p}.cg_height")
    limit = _door.plain().cg_height_limit(wb, a, track, mu, f_r)
    if height >= limit:
        raise SceneError(
            f"{height:g} is too high for friction {mu:g}: load transfer could lift a wheel "
            f"(this vehicle's limit is {limit:.3g})",
            f"{p}.cg_height",
        )
    return height


def _intermediate(value: Any, path: str, length: float) -> tuple:
    """``intermediate``: a list of poses the vehicle passed through between
    separation and rest, each ``{"position": [x, y], "heading": deg}`` (the
    heading optional; total heading, as ``rest.heading``), as (x, y [m], psi
    [rad] or None) tuples."""
    if not isinstance(value, list):
        raise SceneError(f"must be a list of poses {{position, heading}}, got {show_value(value)}", path)
    poses = []
    for i, raw in enumerate(value):
        entry = _mapping(raw, f"{path}[{i}]")
        check_keys(entry, INTERMEDIATE_KEYS, f"{path}[{i}]")
        x, y = _pair(_require(entry, "position", f"{path}[{i}]"), f"{path}[{i}].position")
        psi = math.radians(_number(entry["heading"], f"{path}[{i}].heading")) if "heading" in entry else None
        poses.append((x * length, y * length, psi))
    return tuple(poses)


def _marks(value: Any, path: str) -> dict[str, float]:
    """``mark_directions``: per wheel name, the direction [deg] in which the tyre
    mark of that wheel leaves the separation point (the direction of the wheel's
    contact-point velocity at separation), as wheel key -> radians."""
    entry = _mapping(value, path)
    check_keys(entry, WHEEL_NAMES, path)
    keys = dict(zip(WHEEL_NAMES, ("fl", "fr", "rl", "rr")))
    return {keys[name]: math.radians(_number(entry[name], f"{path}.{name}")) for name in entry}


def row_values(
    vehicle: RunoutVehicle, columns: tuple[str, ...], vx: float, vy: float, w: float
) -> np.ndarray:
    """The kernel row of `vehicle` with the separation velocity (vx, vy, w) [SI];
    a column its row leaves out takes the batch's documented default (batch.DEFAULTS)."""
    values = DEFAULTS | dict(vehicle.row, vx=vx, vy=vy, w=w)
    return np.array([values[c] for c in columns], dtype=np.float64)
