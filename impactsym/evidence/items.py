"""Evidence items: reading one item of a fit scene's ``evidence`` list.

Each item becomes one or two scalar :class:`Observation` records (value and sd
in scene units, angles in radians) and says how the observation model computes
it. An ``edr`` item is read by :mod:`.edr_item`, a ``rest`` item by
:mod:`.rest_item` (both through :func:`.case.read_case`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..errors import SceneError, show_value
from ..scene.casefile import LeafReader, check_keys

EVIDENCE_KEYS = (
    "vehicle",
    "quantity",
    "value",
    "sd",
    "at",
    "edr",
    "lateral_positive",
    "module",
    "note",
    "crush",
)
#: quantity -> (dimension of its value, needs a vehicle)
QUANTITIES = {
    "speed": ("speed", True),
    "final_speed": ("speed", True),
    "final_direction": ("angle", True),
    "final_velocity": ("speed", True),
    "yaw_rate": ("rate", True),
    "final_yaw_rate": ("rate", True),
    "delta_v": ("speed", True),
    "delta_v_longitudinal": ("speed", True),
    "delta_v_lateral": ("speed", True),
    "energy_loss": ("energy", False),
    "crush_energy": ("energy", True),
    "rest": (None, True),
}
ENERGY_UNIT = {"SI": "J", "US": "ft*lbf"}


@dataclass(frozen=True)
class Observation:
    """One scalar observation: evidence item `evidence`, its `label`, the
    value and sd in scene units (angles in radians), and how the model
    computes it (`one_sided` ±1: the truth is at least `value` in that
    sense, a delta-V recorded before its pulse ended): ``("linear", output, (a, b))`` (an output of evidence_linear
    with that vehicle's module at (a, b)), ``("state", name)``,
    ``("norm" | "direction", (x_output, y_output))``, ``("energy",)``,
    ``("combination", ((c, output), ...))`` (the sum of c times each
    evidence_linear output: a whitened rest item, rest_item.py)."""

    evidence: int
    label: str
    value: float
    sd: float
    how: tuple
    angle: bool = False
    one_sided: int = 0  # +1/-1: the truth is at least `value` in this sense (a pulse still running)


def vehicle_index(raw: Any, names, path: str) -> int:
    if isinstance(raw, bool) or raw is None:
        raise SceneError(f"must be 0, 1 or a vehicle's name, got {show_value(raw)}", path)
    if isinstance(raw, int) and raw in (0, 1):
        return raw
    if isinstance(raw, str) and raw in names:
        return names.index(raw)
    raise SceneError(f"unknown vehicle {show_value(raw)} (use 0, 1 or one of {', '.join(names)})", path)


def _scalar(value: Any, path: str, dimension: str, units: str, domain: str = "any") -> float:
    """One number in scene units (angles in degrees, as given), or a one-line error."""
    if isinstance(value, Mapping):
        raise SceneError("an evidence value is a number (its uncertainty is the sd)", path)
    if dimension == "energy":
        return _energy(value, path, units, domain)
    return LeafReader(units).number(value, path, dimension, domain)


def _energy(value: Any, path: str, units: str, domain: str) -> float:
    from ..scene.units import registry

    if isinstance(value, str):
        try:
            number = float(registry().Quantity(value).to(ENERGY_UNIT[units]).magnitude)
        except Exception as exc:  # pint raises several kinds; the message is what matters
            raise SceneError(f"needs an energy (J, ft*lbf, kJ), got {value!r} ({exc})", path) from None
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        number = float(value)
    else:
        raise SceneError(f"must be a number (or a number with a unit), got {show_value(value)}", path)
    if not math.isfinite(number) or (domain == "positive" and number <= 0):
        raise SceneError(
            f"must be a {'positive ' if domain == 'positive' else ''}finite number, got {show_value(value)}",
            path,
        )
    return number


def sds(raw: Any, path: str, dimension: str, units: str, count: int) -> list[float]:
    if raw is None:
        raise SceneError("missing (every evidence item needs its standard deviation)", path)
    if count == 2 and isinstance(raw, list):
        if len(raw) != 2:
            raise SceneError(f"must be a number or a pair, got {show_value(raw)}", path)
        return [_scalar(x, f"{path}[{j}]", dimension, units, "positive") for j, x in enumerate(raw)]
    return [_scalar(raw, path, dimension, units, "positive")] * count


def read_item(item: Any, k: int, units: str, names, fixed) -> list[Observation]:
    """The scalar observations of evidence item `k` (not an ``edr`` item)."""
    path = f"evidence[{k}]"
    if not isinstance(item, Mapping):
        raise SceneError(f"must be an object, got {show_value(item)}", path)
    check_keys(item, EVIDENCE_KEYS, path)
    quantity = item.get("quantity")
    if quantity not in QUANTITIES:
        raise SceneError(
            f"unknown quantity {show_value(quantity)} (known: {', '.join(QUANTITIES)})", f"{path}.quantity"
        )
    dimension, per_vehicle = QUANTITIES[quantity]
    i = vehicle_index(item.get("vehicle"), names, f"{path}.vehicle") if per_vehicle else None
    if per_vehicle and fixed[i]:
        raise SceneError("vehicle is fixed: it has no motion to observe", f"{path}.vehicle")
    if "value" not in item:
        raise SceneError("missing", f"{path}.value")
    n = None if i is None else i + 1
    module = module_at(item, path, units) if quantity.startswith("delta_v_") else (0.0, 0.0)
    if "at" in item and not quantity.startswith("delta_v_"):
        raise SceneError("only delta_v_longitudinal and delta_v_lateral are read at a module", f"{path}.at")
    if quantity == "final_velocity":
        value = item["value"]
        if not isinstance(value, list) or len(value) != 2:
            raise SceneError(f"must be [x, y], got {show_value(value)}", f"{path}.value")
        vals = [_scalar(x, f"{path}.value[{j}]", dimension, units) for j, x in enumerate(value)]
        deviations = sds(item.get("sd"), f"{path}.sd", dimension, units, 2)
        return [
            Observation(
                k,
                f"vehicles[{i}].final_velocity[{j}]",
                vals[j],
                deviations[j],
                ("linear", f"V{n}{c}", (0.0, 0.0)),
            )
            for j, c in enumerate("xy")
        ]
    value = _scalar(item["value"], f"{path}.value", dimension, units)
    (sd,) = sds(item.get("sd"), f"{path}.sd", dimension, units, 1)
    if dimension == "angle":
        value, sd = math.radians(value), math.radians(sd)
    how = {
        "speed": ("linear", f"s{n}", (0.0, 0.0)),
        "final_speed": ("norm", (f"V{n}x", f"V{n}y")),
        "final_direction": ("direction", (f"V{n}x", f"V{n}y")),
        "yaw_rate": ("state", f"w{n}"),
        "final_yaw_rate": ("linear", f"W{n}", (0.0, 0.0)),
        "delta_v": ("norm", (f"dV{n}x", f"dV{n}y")),
        "delta_v_longitudinal": ("linear", f"dl{n}", module),
        "delta_v_lateral": ("linear", f"dt{n}", module),
        "energy_loss": ("energy",),
        "crush_energy": ("energy",),
    }[quantity]
    label = "energy_loss.total" if quantity == "energy_loss" else f"vehicles[{i}].{quantity}"
    return [Observation(k, label, value, sd, how, angle=dimension == "angle")]


def crush_energies(
    observations: list[Observation], fixed, absorbed: float | None = None
) -> list[Observation]:
    """The crush energies of the vehicles together are the energy loss (each
    already an energy lost over the impact: CRASH3's "dissipated", or its
    "absorbed" times (1 - e^2), crush_item.as_energy_lost). Given for every
    moving vehicle (one against a fixed barrier) their sum is an observation of
    T_L (the sds in quadrature); given for one of two moving vehicles it is a
    one-sided bound, T_L at least that energy (the other's crush energy is
    >= 0). `absorbed` is the restitution the energies were read with, for the
    label."""
    crush = [o for o in observations if o.label.endswith(".crush_energy")]
    if not crush:
        return observations
    moving = [i for i in (0, 1) if not fixed[i]]
    crushed = sorted(int(o.label[len("vehicles[")]) for o in crush)
    if len(set(crushed)) != len(crushed):
        raise SceneError(
            "one crush_energy per vehicle (a vehicle's crush energy is given twice)",
            f"evidence[{crush[-1].evidence}].vehicle",
        )
    both = crushed == moving
    label = (
        ("energy_loss.total" if len(moving) == 1 else "energy_loss.total (sum of the crush energies)")
        if both
        else f"energy_loss.total (at least vehicles[{crushed[0]}].crush_energy)"
    )
    if absorbed is not None:
        label += f" [absorbed energies x (1 - e^2), e = {absorbed:g}]"
    total = Observation(
        crush[0].evidence,
        label,
        sum(o.value for o in crush),
        math.sqrt(sum(o.sd**2 for o in crush)),
        ("energy",),
        one_sided=0 if both else 1,
    )
    return [o for o in observations if o not in crush] + [total]


def module_at(item: Mapping, path: str, units: str) -> tuple[float, float]:
    """The module position (forward, left) from the centre of gravity: ``at`` (or ``module``)."""
    raw = item.get("at", item.get("module"))
    if raw is None:
        return (0.0, 0.0)
    key = "at" if "at" in item else "module"
    if not isinstance(raw, Mapping):
        raise SceneError(f"must be {{forward, left}}, got {show_value(raw)}", f"{path}.{key}")
    check_keys(raw, ("forward", "left"), f"{path}.{key}")
    return tuple(_scalar(raw.get(c, 0.0), f"{path}.{key}.{c}", "length", units) for c in ("forward", "left"))
