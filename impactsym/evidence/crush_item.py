"""A ``crush_energy`` evidence item given as a crush profile: its energy
through CRASH3 (impactsym.crash3, the generated CRASH3 kernels).

The profile is the item's ``crush`` object or, when the item has neither
``crush`` nor ``value``, the vehicle's own ``crush`` block (as in a crash3
scene). The energy is CRASH3's crush energy with its oblique correction
(``crash3.correction`` of the scene's top-level ``"crash3"`` options), in the
scene's energy unit; the item's ``sd`` is that energy's standard deviation.

What the energy observes follows the scene's ``crash3.energy`` option, as in
``impactsym crash3``: "dissipated" (default) is the energy lost over the
impact; "absorbed" is the energy absorbed up to maximum crush, and the energy
lost is then (1 - e)(1 + e) times it (kernel ``evidence_crush_absorbed``,
derived and proved in derive/evidence.py; its sd scales by the same factor),
e the scene's ``crash3.restitution``: the restitution of CRASH3's 1-D impact
along the PDOF that the energy was read with, not the fit's e (docs/conventions.md,
"Reconstruction from evidence"). Either way the crush energies are then summed
into an observation of T_L (:func:`.items.crush_energies`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..codes import describe_status
from ..crash3 import crash3, crash3_options
from ..errors import SceneError
from ._door import evaluate
from .items import Observation, vehicle_index


def crash3_restitution(data: Mapping) -> float | None:
    """The scene's CRASH3 restitution when its crush energies are "absorbed"
    (``crash3`` options as crash3 reads them, checked); None when "dissipated"."""
    options = crash3_options(data)
    return options.restitution if options.energy == "absorbed" else None


def as_energy_lost(observations: list[Observation], restitution: float | None) -> list[Observation]:
    """Crush energies absorbed up to maximum crush as the energies lost over
    the impact, (1 - e^2) E with sd (1 - e^2) sd (module docstring); the list
    unchanged when `restitution` is None (energies dissipated)."""
    if restitution is None:
        return observations
    out = []
    for obs in observations:
        if obs.label.endswith(".crush_energy"):
            lost = evaluate("evidence_crush_absorbed", {"E_absorbed": obs.value, "e": restitution})
            if lost["status"] != 0:
                raise SceneError(
                    f"the crush energy absorbed does not give an energy loss: {describe_status(lost['status'])}",
                    f"evidence[{obs.evidence}].value",
                )
            sd = lost["d_E_lost__d_E_absorbed"] * obs.sd
            if not sd > 0:
                raise SceneError(
                    "with the crush energy absorbed and restitution 1 the energy loss is 0 whatever the crush: "
                    "the crush energy observes nothing (give a restitution below 1)",
                    "crash3.restitution",
                )
            obs = Observation(obs.evidence, obs.label, lost["E_lost"], sd, obs.how)
        out.append(obs)
    return out


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
