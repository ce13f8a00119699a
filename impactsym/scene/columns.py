"""Columns of draws: the kernel inputs of a scene with some of its leaves
replaced by arrays (uncertainty propagation, sweeps)."""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

if sys.version_info >= (3, 11):
    pass
else:
    pass

from .._kernels import COEFFICIENT_INPUTS, PRESETS
from .casefile import COEFFICIENT_KEYS, domain_reasons, unknown_key, used_normal_angle, vehicle_state
from .model import Scene


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
