"""Rounding residue of a zero, judged against the scene's own scale: the one
rule by which tables, ``--json`` outputs and pictures show it as 0.

A value is residue when its magnitude is below :data:`RESIDUE` times the scale
of its quantity in the same result: a yaw rate of -4.4e-16 rad/s of a car that
does not rotate, μ_c = -4.2e-17 of a head-on impact. The scale of a quantity is
the largest magnitude of that quantity in the result, and for the quantities a
zero of which is common (yaw rates, moments) at least what the result's speeds
and impulses give over one unit of length (1 m or 1 ft: a vehicle's size is a
few of them, and 1e-12 leaves a margin of 10⁴ over double rounding). Ratios
(μ, μ_c, e, e_m) have the scale 1. The API keeps the computed values.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from typing import Any

__all__ = ["RESIDUE", "drop_residue", "path_quantity", "quantity_scales", "without_json_residue"]

#: A value below this fraction of its quantity's scale is rounding residue.
RESIDUE = 1e-12

#: JSON keys (last named step of a path) -> the quantity they hold.
_QUANTITY = {
    "velocity": "speed",
    "final_velocity": "speed",
    "delta_v": "speed",
    "delta_v_magnitude": "speed",
    "speed": "speed",
    "yaw_rate": "yaw_rate",
    "final_yaw_rate": "yaw_rate",
    "normal": "impulse",
    "tangential": "impulse",
    "moment": "moment",
    "moment_residual": "moment",
    "impulse_ratio": "ratio",
    "critical_impulse_ratio": "ratio",
    "restitution": "ratio",
    "moment_restitution": "ratio",
}


def drop_residue(value: float, scale: float) -> float:
    """``value`` with rounding residue (below ``RESIDUE·scale``) and a negative
    zero shown as 0.0; NaN and infinities unchanged."""
    if not math.isfinite(value):
        return value
    return 0.0 if abs(value) < RESIDUE * scale else value + 0.0


def path_quantity(path: str) -> str | None:
    """The quantity of a JSON path (``vehicles[0].yaw_rate``,
    ``energy_loss.total``, ``impulse.moment``), or None when it is not one of
    a result's quantities (then nothing is dropped)."""
    steps = [s for s in re.split(r"[.\[\]]", path) if s and not s.isdigit()]
    if not steps:
        return None
    if steps[0] == "energy_loss":
        return "energy"
    if steps[-1] in ("normal", "tangential", "moment") and "impulse" not in steps:
        return None
    return _QUANTITY.get(steps[-1])


def quantity_scales(values: Iterable[tuple[str, float]]) -> dict[str, float]:
    """Scales per quantity from ``(quantity, value)`` pairs: the largest finite
    magnitude, yaw rates at least the largest speed per unit length, moments at
    least the largest impulse times a unit length, ratios 1."""
    scales = {"ratio": 1.0}
    for quantity, value in values:
        if quantity is not None and math.isfinite(value):
            scales[quantity] = max(scales.get(quantity, 0.0), abs(value))
    scales["yaw_rate"] = max(scales.get("yaw_rate", 0.0), scales.get("speed", 0.0))
    scales["moment"] = max(scales.get("moment", 0.0), scales.get("impulse", 0.0))
    return scales


def without_json_residue(data: Any) -> Any:
    """A result's ``--json`` object with the residue of each known quantity
    dropped against the scales of the whole object (:func:`quantity_scales`);
    the ``"uncertainty"`` block's ``outputs`` are judged by their paths."""
    leaves = list(_leaves(data, ""))
    scales = quantity_scales((q, v) for _, q, v in leaves)
    return _rebuild(data, "", scales)


def _quantity(path: str) -> str | None:
    head, marker, tail = path.partition(".uncertainty.outputs.")
    if marker:  # "<output path>.<statistic>": the statistic has the output's quantity
        output = tail.rpartition(".")[0]
        return None if ".budget" in tail or output == "" else path_quantity(output)
    return None if path.startswith(".uncertainty") else path_quantity(path)


def _leaves(data: Any, path: str):
    if isinstance(data, Mapping):
        for key, value in data.items():
            yield from _leaves(value, f"{path}.{key}")
    elif isinstance(data, (list, tuple)):
        for index, value in enumerate(data):
            yield from _leaves(value, f"{path}[{index}]")
    elif isinstance(data, float):
        yield path, _quantity(path), data


def _rebuild(data: Any, path: str, scales: Mapping[str, float]) -> Any:
    if isinstance(data, Mapping):
        return {key: _rebuild(value, f"{path}.{key}", scales) for key, value in data.items()}
    if isinstance(data, (list, tuple)):
        return [_rebuild(value, f"{path}[{index}]", scales) for index, value in enumerate(data)]
    if isinstance(data, float):
        quantity = _quantity(path)
        return drop_residue(data, scales[quantity]) if quantity in scales else data
    return data
