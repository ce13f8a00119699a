"""The run-out's leaves of a reconstruct-from-rest scene with distributions
(``reconstruct --uncertainty`` through the run-out, uncertain.py): which leaves
it reads and their domains (conventions.md, "Uncertainty"), the nominal scene
the plain chained ``reconstruct`` solves, and why a drawn row lies outside a
leaf's domain.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping

import numpy as np

from ..scene import load_scene, scene_data
from ..scene.casefile import Leaf, LeafReader, domain_reasons, vehicle_state
from ..uncertainty.inputs import CHOICE, Input
from .chain import _check, _impact_part, reconstruct_from_rest
from .scene import STATES, load_runout, locked_probability

RUNOUT_LEAVES = {
    "friction": ("number", "positive"),
    "slip_angle_max": ("angle", "positive"),
    "rolling_resistance": ("number", "nonnegative"),
}
WHEEL_LEAVES = {"brake": ("number", "nonnegative"), "steer": ("angle", "any")}
WHEEL_KEYS = {"front_left": "fl", "front_right": "fr", "rear_left": "rl", "rear_right": "rr"}


def nominal_leaves(data: dict, units: str) -> dict:
    """Read the run-out's leaves of `data` (changed in place: each becomes its
    nominal number in scene units) and return them, path -> Leaf. Entries of
    the wrong type are left for load_runout to name."""
    reader = LeafReader(units)

    def number(block: dict, key: str, path: str, dimension: str, domain: str = "any") -> None:
        if key in block:
            block[key] = reader.number(block[key], path, dimension, domain)

    def pair(block: dict, key: str, path: str) -> None:
        if isinstance(block.get(key), (list, tuple)):
            reader.vector(block[key], path, "length")
            block[key] = [reader.leaves[f"{path}[{i}]"].nominal for i in (0, 1)]

    if isinstance(data.get("runout"), dict):
        for key, (dimension, domain) in RUNOUT_LEAVES.items():
            number(data["runout"], key, f"runout.{key}", dimension, domain)
    if isinstance(data.get("impact"), dict):
        pair(data["impact"], "position", "impact.position")
    for i, v in enumerate(data.get("vehicles") or []):
        if not isinstance(v, dict):
            continue
        p = f"vehicles[{i}]"
        number(v, "friction", f"{p}.friction", "number", "positive")
        number(v, "cg_height", f"{p}.cg_height", "length", "nonnegative")
        for block in ("rest", "separation"):
            if isinstance(v.get(block), dict):
                pair(v[block], "position", f"{p}.{block}.position")
                number(v[block], "heading", f"{p}.{block}.heading", "angle")
        marks = v["separation"].get("mark_directions") if isinstance(v.get("separation"), dict) else None
        if isinstance(marks, dict):
            for name in WHEEL_KEYS:
                number(marks, name, f"{p}.separation.mark_directions.{name}", "angle")
        poses = v.get("intermediate")
        for j, pose in enumerate(poses if isinstance(poses, list) else []):
            if isinstance(pose, dict):
                pair(pose, "position", f"{p}.intermediate[{j}].position")
                number(pose, "heading", f"{p}.intermediate[{j}].heading", "angle")
        if isinstance(v.get("wheels"), dict):
            for name, wheel in v["wheels"].items():
                if isinstance(wheel, dict):
                    for key, (dimension, domain) in WHEEL_LEAVES.items():
                        number(wheel, key, f"{p}.wheels.{name}.{key}", dimension, domain)
                    if isinstance(wheel.get("state"), Mapping):
                        _state_leaf(wheel, f"{p}.wheels.{name}.state", reader.leaves)
    return reader.leaves


def _state_leaf(wheel: dict, path: str, leaves: dict) -> None:
    """A wheel state given as probabilities (`locked_probability`): a CHOICE leaf
    (1 locked, 0 rolling; certain probabilities a plain leaf), and in `wheel`
    the more probable state, the nominal scene's."""
    locked = locked_probability(wheel["state"], path)
    nominal = Input(path, CHOICE, (locked,)).nominal
    kind, params = (CHOICE, (locked,)) if 0.0 < locked < 1.0 else (None, ())
    leaves[path] = Leaf(path, "number", "any", nominal, kind, params)
    wheel["state"] = STATES[int(nominal)]


def with_final(impact: dict, finals) -> dict:
    """The impact part with each vehicle's final velocity and yaw rate set (scene units)."""
    out = copy.deepcopy(impact)
    for v, (vx, vy, w) in zip(out["vehicles"], finals):
        v["final_velocity"], v["final_yaw_rate"] = [vx, vy], w
    out.pop("correlations", None)  # read below with the run-out's leaves too
    return out


def runout_reasons(leaves: Mapping, arrays: Mapping, n: int) -> np.ndarray:
    """Per row, why drawn run-out leaves are out of their domain ("" if not)."""
    reason = domain_reasons(leaves, arrays, n)
    for path, a in arrays.items():
        if path.endswith(".brake"):
            bad, why = a > 1.0, "above 1"
        elif path.endswith(".steer") or path == "runout.slip_angle_max":
            bad, why = np.abs(a) >= 90.0, "90 degrees or more"
        else:
            continue
        reason[np.broadcast_to(bad, (n,)) & (reason == "")] = f"{path} is {why}"
    return reason


def nominal_data(scene) -> tuple[dict, dict, dict]:
    """(the scene with every leaf the run-out reads a plain number in scene
    units: its nominal value; the run-out's leaves; the impact part as given,
    distributions kept) of a reconstruct-from-rest scene. The plain chained
    ``reconstruct`` solves the first (conventions.md: the plain commands solve
    the nominal scene)."""
    data = copy.deepcopy(scene_data(scene))
    if not isinstance(data, dict) or data.get("units") not in ("SI", "US"):
        load_runout(data)  # names what is wrong
    leaves = nominal_leaves(data, data["units"])
    if len(_check(data)) != len(data["vehicles"]):
        reconstruct_from_rest(data)  # names the vehicle without run-out data
    impact = _impact_part(data)
    placeholder = load_scene(with_final(impact, [(0.0, 0.0, 0.0)] * 2), kind="reconstruct")
    nominal = {path: leaf.nominal for path, leaf in placeholder.leaves.items()}
    for i, v in enumerate(data["vehicles"]):
        state = vehicle_state(nominal, i, data["units"])
        for key in ("weight", "radius_of_gyration"):
            v.pop(key, None)
        v.update(
            mass=float(state["m"]), yaw_inertia=float(state["I"]), impact_point=[float(x) for x in state["r"]]
        )
        if state["heading"] is not None:
            v["heading"] = float(state["heading"])
    return data, leaves, impact
