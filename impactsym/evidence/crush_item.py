"""A ``crush_energy`` evidence item given as a crush profile: its energy
through CRASH3 (impactsym.crash3, the generated CRASH3 kernels).

The profile is the item's ``crush`` object or, when the item has neither
``crush`` nor ``value``, the vehicle's own ``crush`` block (as in a crash3
scene). The energy is CRASH3's crush energy with its oblique correction
(``crash3.correction`` of the scene's top-level ``"crash3"`` options), in the
scene's energy unit; the item's ``sd`` is that energy's standard deviation.
Only CRASH3's energy "dissipated" is an observation of the fit (the energy
lost over the impact, :func:`.items.crush_energies`); "absorbed" would need
the energy loss as a function of the absorbed energy and the restitution,
which derive/ does not emit for the fit, so it is refused.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..crash3 import crash3, crash3_options
from ..errors import SceneError
from .items import vehicle_index


def crash3_mode(data: Mapping) -> str:
    """The scene's CRASH3 energy mode, checked (``crash3`` options as crash3 reads them)."""
    return crash3_options(data).energy


def profile_energy(item: Mapping, i: int, k: int, data: Mapping, warnings: list) -> float:
    """Crush energy [J | ft·lb] of vehicle `i`'s profile for evidence item `k`.

    A bad profile is a one-line :class:`SceneError` naming the item's field
    (``evidence[k].crush.width``) or the vehicle's (``vehicles[i].crush.width``).
    """
    own = "crush" not in item
    raw = data["vehicles"][i].get("crush") if own else item["crush"]
    where = f"vehicles[{i}].crush" if own else f"evidence[{k}].crush"
    if raw is None:
        raise SceneError(
            f"missing: give value, or crush (a CRASH3 profile), or vehicles[{i}].crush",
            f"evidence[{k}].value",
        )
    vehicles: list[dict[str, Any]] = [{"fixed": True}, {"fixed": True}]
    vehicles[i] = {"name": "crushed", "mass": 1.0, "crush": raw}  # the energy needs no mass
    scene = {"units": data.get("units"), "vehicles": vehicles}
    if "crash3" in data:
        scene["crash3"] = data["crash3"]
    try:
        result = crash3(scene)
    except SceneError as exc:
        field = exc.field or ""
        prefix = f"vehicles[{i}].crush"
        if field.startswith(prefix):
            raise SceneError(str(exc)[len(field) + 2 :], where + field[len(prefix) :]) from None
        raise
    warnings += [
        f"evidence[{k}]: {w.replace(f'vehicles[{i}].crush', where)}"
        for w in result.warnings
        if w.startswith(f"vehicles[{i}].crush.pdof")
    ]
    return result.vehicles[i].crush_energy


def with_profile_energy(item: Mapping, k: int, data: Mapping, names, fixed, warnings: list) -> Mapping:
    """Evidence item `k` with a profile (``crush``, or neither ``crush`` nor
    ``value``) as the same item with its CRASH3 energy as ``value``; any other
    item unchanged."""
    if (
        not isinstance(item, Mapping)
        or item.get("quantity") != "crush_energy"
        or ("value" in item and "crush" not in item)
    ):
        return item
    if "value" in item:
        raise SceneError("give value or crush, not both", f"evidence[{k}].crush")
    i = vehicle_index(item.get("vehicle"), names, f"evidence[{k}].vehicle")
    if fixed[i]:
        raise SceneError("vehicle is fixed: it has no motion to observe", f"evidence[{k}].vehicle")
    energy = profile_energy(item, i, k, data, warnings)
    return {**{key: v for key, v in item.items() if key != "crush"}, "value": energy}


def unused_crush(data: Mapping, names) -> list[str]:
    """A warning per vehicle ``crush`` block no evidence item reads (it is
    evidence only through a ``crush_energy`` item with neither value nor crush)."""
    used = {
        vehicle_index(item.get("vehicle"), names, f"evidence[{k}].vehicle")
        for k, item in enumerate(data["evidence"])
        if isinstance(item, Mapping)
        and item.get("quantity") == "crush_energy"
        and "value" not in item
        and "crush" not in item
    }
    return [
        f'vehicles[{i}].crush is not used: add {{"vehicle": {i}, "quantity": "crush_energy", "sd": …}} '
        "to the evidence to observe its crush energy"
        for i, v in enumerate(data["vehicles"])
        if isinstance(v, Mapping) and "crush" in v and i not in used
    ]
