"""Reading a fit scene: the vehicles, the optional impact block and the evidence.

A fit scene (conventions.md, "Reconstruction from evidence") is a scene whose
vehicles carry ``mass``, ``yaw_inertia``, ``impact_point`` and ``heading``
(pre-impact direction of travel and orientation, degrees) and whose
``evidence`` list holds the observations, each with its standard deviation.
Numbers take units as in any scene (impactsym.casefile); the result is in the
scene's system (SI: m/s, rad/s, J; US: ft/s, rad/s, ft·lb). Angles are kept
in radians here.

Unknowns (the state is z = (v1x, v1y, w1, v2x, v2y, w2, Px, Py, M)):
- a vehicle that gives ``velocity`` has a known pre-impact velocity; otherwise
  its speed along its heading is unknown (``vehicles[i].speed``);
- its pre-impact yaw rate is its ``yaw_rate`` (default 0), unknown only when it
  gives none and the evidence lists a ``yaw_rate`` of it;
- the impulse (Px, Py) is always unknown; the moment impulse M only when
  ``impact.moment_restitution`` is given (then moment restitution is an exact
  constraint); otherwise M = 0 (a point impulse).
A fixed vehicle (a barrier) has no unknowns.

Bad input is a :class:`SceneError` naming the field (one line).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SceneError, show_value
from ..scene import scene_data
from ..scene.casefile import (
    IMPACT_KEYS,
    TOP_KEYS,
    VEHICLE_KEYS,
    LeafReader,
    check_keys,
    used_normal_angle,
    vehicle_state,
)
from ..scene.reader import read_body
from .crush_item import as_energy_lost, crash3_restitution, unused_crush, with_profile_energy
from .edr_item import edr_observations
from .items import EVIDENCE_KEYS, Observation, crush_energies, read_item
from .rest_item import RUNOUT_VEHICLE_KEYS, RestEvidence, frictions, read_rest, rest_evidence

STATE = ("v1x", "v1y", "w1", "v2x", "v2y", "w2", "Px", "Py", "M")
#: Impact laws a fit can read its answer in, besides Brach's (e, mu): impactsym.laws.
FIT_LAWS = ("kudlich_slibar",)


@dataclass
class FitCase:
    """A fit scene read: kernel parameters, the affine map z = z0 + T x from
    the unknowns x to the state, the unknowns' output paths, observations."""

    units: str
    names: tuple[str, str]
    params: dict
    z0: np.ndarray
    T: np.ndarray
    unknowns: list[str]
    observations: list[Observation]
    has_normal: bool
    moment: bool
    fixed: tuple[bool, bool]
    headings: tuple[float, float]
    warnings: list[str] = field(default_factory=list)
    normal: tuple | None = None  # the normal angle's distribution: (kind, params [deg], offset [deg])
    law: str | None = None  # "model": "kudlich_slibar": the fit is also read as that law (FIT_LAWS)
    rest: RestEvidence | None = None  # the rest items, whitened together (rest_item.py)
    crush_restitution: float | None = None  # crash3.restitution of crush energies read as "absorbed"


def read_case(source: Mapping | str | Path) -> FitCase:
    """Read and check a fit scene (a mapping or a .json/.toml path)."""
    data = scene_data(source)
    if not isinstance(data, Mapping):
        raise SceneError(f"a scene must be an object, got {show_value(data)}")
    check_keys(data, (*TOP_KEYS, "evidence", "runout"), "")
    units = data.get("units")
    if units not in ("SI", "US"):
        raise SceneError(f'must be "SI" or "US", got {show_value(units)}', "units")
    model = data.get("model", "rigid")
    if model not in ("rigid", "brach", *FIT_LAWS):
        raise SceneError(
            "fit uses the rigid model (point impulse at the impact centre), or reads it as the "
            f"alternative law {' or '.join(FIT_LAWS)}; got {show_value(model)}",
            "model",
        )
    leaves = LeafReader(units)
    vehicles = data.get("vehicles")
    if not isinstance(vehicles, list) or len(vehicles) != 2:
        raise SceneError(f"must be a list of exactly 2 vehicles, got {show_value(vehicles)}", "vehicles")
    fixed = tuple(_read_vehicle(v, i, leaves) for i, v in enumerate(vehicles))
    if all(fixed):
        raise SceneError("both vehicles are fixed; at most one may be", "vehicles")
    impact = data.get("impact", {})
    if not isinstance(impact, Mapping):
        raise SceneError(f"must be an object, got {show_value(impact)}", "impact")
    check_keys(impact, IMPACT_KEYS, "impact")
    warnings = [
        f"impact.{k} is given but not used: a fit infers it"
        for k in ("restitution", "impulse_ratio")
        if k in impact
    ]
    if "normal_angle" in impact:
        leaves.number(impact["normal_angle"], "impact.normal_angle", "angle")
    if "moment_restitution" in impact:
        leaves.number(impact["moment_restitution"], "impact.moment_restitution", "number")
    values = {path: leaf.nominal for path, leaf in leaves.leaves.items()}
    for path, leaf in leaves.leaves.items():
        if leaf.kind is not None and path != "impact.normal_angle":
            raise SceneError(
                "fit takes plain numbers here (the evidence carries the sd; only impact.normal_angle "
                "may be a distribution)",
                path,
            )
    states = [vehicle_state(values, i, units) for i in range(2)]
    params, z0, columns, unknowns = _state_map(states, fixed, values)
    has_normal = "impact.normal_angle" in values
    normal = None  # (kind, params [deg], offset [deg]) of a normal angle given as a distribution
    if has_normal:
        angle, flipped = used_normal_angle(values["impact.normal_angle"], states[0]["r"], states[1]["r"])
        params["gamma"] = math.radians(float(angle))
        leaf = leaves.leaves["impact.normal_angle"]
        if leaf.kind is not None:
            normal = (leaf.kind, leaf.params, float(angle) - values["impact.normal_angle"])
        if flipped:
            warnings.append(f"impact.normal_angle is turned round to {float(angle):g} deg (n·(r1 - r2) > 0)")
    else:
        params["gamma"] = 0.0
    moment = "impact.moment_restitution" in values
    params["e_m"] = values.get("impact.moment_restitution", 1.0)
    if moment:
        columns.append(_unit(8))
        unknowns.append("impulse.moment")
    names = tuple(str(v.get("name", f"vehicle {i + 1}")) for i, v in enumerate(vehicles))
    raw = data.get("evidence")
    if not isinstance(raw, list) or not raw:
        raise SceneError(f"must be a non-empty list of evidence items, got {show_value(raw)}", "evidence")
    observations, rests = [], []  # rests: (position in observations, RestFit)
    for k, item in enumerate(raw):
        if isinstance(item, Mapping) and "edr" in item:
            check_keys(item, EVIDENCE_KEYS, f"evidence[{k}]")
            observations += edr_observations(item, k, units, names, fixed, source, warnings)
        elif isinstance(item, Mapping) and item.get("quantity") == "rest":
            check_keys(item, EVIDENCE_KEYS, f"evidence[{k}]")
            rests.append(
                (len(observations), read_rest(item, k, data, (units, names, fixed, params), warnings))
            )
        else:
            item = with_profile_energy(item, k, data, names, fixed, warnings)
            observations += read_item(item, k, units, names, fixed)
    rest = _insert_rest(observations, rests, data)
    absorbed = crash3_restitution(data)
    if not any(o.label.endswith(".crush_energy") for o in observations):
        absorbed = None  # no crush energy read with it
    observations = crush_energies(as_energy_lost(observations, absorbed), fixed, absorbed)
    if rest is not None:
        rest.rows = [j for j, o in enumerate(observations) if o.how[0] == "combination"]
    warnings += unused_crush(data, names)
    yaw_observed = {o.how[1] for o in observations if o.how[0] == "state"}
    for i in range(2):
        if f"w{i + 1}" in yaw_observed and f"vehicles[{i}].yaw_rate" not in values and not fixed[i]:
            columns.append(_unit(3 * i + 2))
            unknowns.append(f"vehicles[{i}].yaw_rate")
    T = np.array(columns, dtype=float).T if columns else np.zeros((9, 0))
    headings = tuple(math.radians(s["heading"] or 0.0) for s in states)
    return FitCase(
        units,
        names,
        params,
        z0,
        T,
        unknowns,
        observations,
        has_normal,
        moment,
        fixed,
        headings,
        warnings,
        normal,
        model if model in FIT_LAWS else None,
        rest,
        absorbed,
    )


def _insert_rest(observations: list, rests: list, data) -> RestEvidence | None:
    """Put the rest items' joint observations (rest_item.rest_evidence) where
    each item stands in the evidence list; the record of them, or None."""
    if not rests:
        return None
    items = [r for _, r in rests]
    rows, evidence = rest_evidence(items, frictions(data, items))
    for j, (position, _) in reversed(list(enumerate(rests))):
        observations[position:position] = rows[3 * j : 3 * j + 3]
    return evidence


def _unit(index: int) -> np.ndarray:
    column = np.zeros(9)
    column[index] = 1.0
    return column


def _read_vehicle(entry: Any, index: int, leaves: LeafReader) -> bool:
    """Check vehicle `index` and record its leaves; True when it is fixed."""
    path = f"vehicles[{index}]"
    if not isinstance(entry, Mapping):
        raise SceneError(f"must be an object, got {show_value(entry)}", path)
    check_keys(entry, (*VEHICLE_KEYS, *RUNOUT_VEHICLE_KEYS, "rest"), path)
    fixed = entry.get("fixed", False)
    if not isinstance(fixed, bool):
        raise SceneError(f"must be true or false, got {show_value(fixed)}", f"{path}.fixed")
    if not fixed:
        for key, alt in (("mass", "weight"), ("yaw_inertia", "radius_of_gyration"), ("impact_point", None)):
            if key not in entry and (alt is None or alt not in entry):
                raise SceneError("missing", f"{path}.{key}")
        if "heading" not in entry:
            raise SceneError(
                "missing (the pre-impact direction of travel and orientation)", f"{path}.heading"
            )
    read_body(leaves, entry, path)
    for key, dimension in (("yaw_rate", "rate"), ("heading", "angle")):
        if key in entry:
            leaves.number(entry[key], f"{path}.{key}", dimension)
    if "velocity" in entry:
        leaves.vector(entry["velocity"], f"{path}.velocity", "speed", "velocity")
    if "impact_point" in entry:
        leaves.vector(entry["impact_point"], f"{path}.impact_point", "length", "impact_point")
    for key in ("final_velocity", "final_yaw_rate", "length", "width", "rest"):
        if key in entry:
            raise SceneError("not read by fit: give it as an evidence item with its sd", f"{path}.{key}")
    return fixed


def _state_map(states, fixed, values):
    """Kernel parameters, the known state z0 and the unknowns' columns of T."""
    params, z0, columns, unknowns = {}, np.zeros(9), [], []
    for i, (state, is_fixed) in enumerate(zip(states, fixed)):
        n = i + 1
        params[f"m{n}"] = math.inf if is_fixed else float(state["m"])
        params[f"I{n}"] = math.inf if is_fixed else float(state["I"])
        params[f"r{n}x"], params[f"r{n}y"] = (float(c) for c in state["r"])
        params[f"theta{n}"] = math.radians(state["heading"] or 0.0)
        if is_fixed:
            continue
        z0[3 * i + 2] = float(state["w"])
        if state["v"] is not None:
            z0[3 * i], z0[3 * i + 1] = (float(c) for c in state["v"])
        else:
            column = np.zeros(9)
            # exact 0 for a heading along an axis (cos 90° is 6e-17 in floating point)
            column[3 * i], column[3 * i + 1] = (
                0.0 if abs(c) < 1e-15 else c
                for c in (math.cos(params[f"theta{n}"]), math.sin(params[f"theta{n}"]))
            )
            columns.append(column)
            unknowns.append(f"vehicles[{i}].speed")
    columns += [_unit(6), _unit(7)]
    unknowns += ["impulse.x", "impulse.y"]
    return params, z0, columns, unknowns
