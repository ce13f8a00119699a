"""The run-out chained with the impact, in both directions.

* `solve_to_rest(scene)`: pre-impact -> impact (`impactsym.solve`) -> rest: each
  moving vehicle that carries run-out data (``wheelbase`` ...) runs out from its
  final velocity; its ``solve`` entry gains ``"rest"`` and ``"runout"``.
* `reconstruct_from_rest(scene)`: rest -> separation (fit to rest) -> pre-impact
  (`impactsym.reconstruct` with the fitted velocities as ``final_velocity`` and
  ``final_yaw_rate``); each vehicle entry gains ``"runout"``.

A chained scene is an impact scene (``impact`` with ``normal_angle`` and the
coefficients, vehicles with ``mass``, ``yaw_inertia``, ``impact_point`` ...)
plus the top-level ``runout`` object and the run-out keys of each vehicle. The
vehicle's ``heading`` is its orientation at separation for the run-out (unless
``separation.heading`` is given) and, for ``reconstruct``, its pre-impact
direction of travel: the same angle for a vehicle that was not yawing.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping

from ..errors import SceneError
from ..reconstruct import reconstruct
from ..scene import scene_data
from ..single import solve
from .api import runout
from .scene import RUNOUT_VEHICLE_KEYS


def _impact_part(data: Mapping) -> dict:
    """The scene without the run-out keys (what the impact commands read)."""
    out = {key: copy.deepcopy(value) for key, value in data.items() if key != "runout"}
    out["vehicles"] = [
        {key: value for key, value in v.items() if key not in RUNOUT_VEHICLE_KEYS} for v in data["vehicles"]
    ]
    return out


def _moving_with_runout(data: Mapping) -> list[int]:
    return [
        i
        for i, v in enumerate(data["vehicles"])
        if isinstance(v, Mapping) and "wheelbase" in v and not v.get("fixed")
    ]


def _check(data: Mapping) -> list[int]:
    if "runout" not in data:
        raise SceneError("missing (a chained scene needs the run-out's tyre data)", "runout")
    if not isinstance(data.get("vehicles"), list):
        raise SceneError("must be a list of vehicles", "vehicles")
    chosen = _moving_with_runout(data)
    if not chosen:
        raise SceneError(
            "no vehicle carries run-out data (wheelbase, cg_to_front_axle, track, wheels)", "vehicles"
        )
    return chosen


def solve_to_rest(scene, path: bool = False) -> dict:
    """``solve --json`` of the scene, each run-out vehicle's entry with its
    ``rest`` and ``runout`` (the `runout` entry) added."""
    data = scene_data(scene)
    chosen = _check(data)
    result = solve(_impact_part(data))
    out = result.to_json_dict()
    ro = {key: copy.deepcopy(value) for key, value in data.items() if key != "vehicles"}
    ro["vehicles"] = []
    for i in chosen:
        v = copy.deepcopy(data["vehicles"][i])
        v.pop("rest", None)
        sep = v.setdefault("separation", {})
        sep["velocity"] = list(result.vehicles[i].velocity)
        sep["yaw_rate"] = result.vehicles[i].yaw_rate
        ro["vehicles"].append(v)
    runs = runout(ro, path=path)
    for i, entry in zip(chosen, runs["vehicles"]):
        out["vehicles"][i]["rest"] = entry["rest"]
        out["vehicles"][i]["runout"] = entry
    out["warnings"] = list(out.get("warnings", [])) + runs["warnings"]
    return out


def reconstruct_from_rest(scene, path: bool = False, **search) -> dict:
    """``reconstruct --json`` of the scene with each vehicle's final motion
    fitted to its ``rest`` pose; each entry gains ``runout`` (fit included).
    `search`: `runout`'s grid-search keywords (exhaustive, speed_max,
    yaw_rate_max). Where another separation state reaches a vehicle's rest
    pose (its ``runout.fit.alternatives``), the impact is also reconstructed
    with it (the other vehicles as reported): ``"alternatives"`` lists each
    such state with the pre-impact speeds it gives, and a warning says so."""
    data = scene_data(scene)
    chosen = _check(data)
    if len(chosen) != len(data["vehicles"]):
        raise SceneError(
            "every vehicle needs run-out data and a rest pose to reconstruct from rest", "vehicles"
        )
    for i in chosen:
        if "rest" not in data["vehicles"][i]:
            raise SceneError(
                "missing (reconstructing from rest needs each vehicle's rest pose)", f"vehicles[{i}].rest"
            )
    ro = copy.deepcopy(dict(data))
    for v in ro["vehicles"]:
        sep = v.get("separation", {})
        sep.pop("velocity", None)
        sep.pop("yaw_rate", None)
    runs = runout(ro, path=path, **search)
    impact = _impact_part(data)
    for v, entry in zip(impact["vehicles"], runs["vehicles"]):
        v["final_velocity"] = entry["separation"]["velocity"]
        v["final_yaw_rate"] = entry["separation"]["yaw_rate"]
    out = reconstruct(impact).to_json_dict()
    for i, entry in enumerate(runs["vehicles"]):
        out["vehicles"][i]["runout"] = entry
    out["warnings"] = list(out.get("warnings", [])) + runs["warnings"]
    others = _alternatives(impact, runs["vehicles"], out)
    if others:
        out["alternatives"] = others
    return out


def _alternatives(impact: dict, entries: list, out: dict) -> list[dict]:
    """Each other separation state that reaches a vehicle's rest pose, with the
    pre-impact speeds the impact then gives (scene units; or why it cannot be
    reconstructed); a warning per state in ``out``."""
    found = []
    for i, entry in enumerate(entries):
        for alt in entry.get("fit", {}).get("alternatives", []):
            scene = copy.deepcopy(impact)
            scene["vehicles"][i]["final_velocity"] = alt["velocity"]
            scene["vehicles"][i]["final_yaw_rate"] = alt["yaw_rate"]
            item = {"vehicle": i, "separation": {"velocity": alt["velocity"], "yaw_rate": alt["yaw_rate"]}}
            try:
                item["speed"] = [v.speed for v in reconstruct(scene).vehicles]
                then = "pre-impact speeds " + ", ".join(f"{s:.3f}" for s in item["speed"])
            except SceneError as exc:
                item["error"] = str(exc)
                then = f"no reconstruction ({exc})"
            found.append(item)
            reported = ", ".join(f"{v['speed']:.3f}" for v in out["vehicles"])
            out["warnings"].append(
                f"vehicles[{i}]: another separation state reaching its rest pose (velocity "
                f"[{alt['velocity'][0]:.3f}, {alt['velocity'][1]:.3f}], yaw rate {alt['yaw_rate']:.3f} rad/s) "
                f"gives {then} (reported: {reported})"
            )
    return found
