"""The outcome of one solved scene, as data, JSON and a table for people.

All numbers are in the scene's units: SI (m/s, rad/s, N·s, N·m·s, J) or US
(ft/s, rad/s, lb·s, ft·lb·s, ft·lb).  Impulses are those on vehicle 1 in the
impact frame (``Pn`` along n, ``Pt`` along t, ``M`` the moment impulse);
vehicle 2 receives their opposites.  Energy losses are kinetic energy before
minus after, so a negative value means the coefficients created energy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from .codes import describe_flags
from .residue import RESIDUE, drop_residue
from .scene import Scene, uses_yaw

__all__ = [
    "Result",
    "VehicleResult",
    "UNIT_LABELS",
    "ROAD_SPEED",
    "json_number",
    "road_speed_rows",
    "scene_warnings",
    "table_cell",
    "without_residue",
    "TABLE_RESIDUE",
    "json_clean",
]

UNIT_LABELS = {
    "SI": {"velocity": "m/s", "yaw_rate": "rad/s", "impulse": "N·s", "moment": "N·m·s", "energy": "J"},
    "US": {
        "velocity": "ft/s",
        "yaw_rate": "rad/s",
        "impulse": "lb·s",
        "moment": "ft·lb·s",
        "energy": "ft·lb",
    },
}

#: The speed unit people read in each system, and its factor from the system's
#: speed unit (1 mph = 22/15 ft/s exactly, 1 km/h = 1/3.6 m/s).
ROAD_SPEED = {"SI": ("km/h", 3.6), "US": ("mph", 15.0 / 22.0)}

_KERNEL_SCALARS = ("Pn", "Pt", "M", "mu", "mu_c", "TL", "TLn", "TLt", "TLm")


@dataclass(frozen=True)
class VehicleResult:
    """One vehicle at separation.

    ``velocity`` and ``yaw_rate`` are the final motion; ``delta_v`` is final
    minus initial velocity and ``delta_v_magnitude`` its length.
    """

    name: str
    velocity: tuple[float, float]
    yaw_rate: float
    delta_v: tuple[float, float]
    delta_v_magnitude: float

    def to_json_dict(self) -> dict[str, Any]:
        """The vehicle entry of ``solve --json``."""
        return {
            "name": self.name,
            "velocity": [json_number(value) for value in self.velocity],
            "yaw_rate": json_number(self.yaw_rate),
            "delta_v": [json_number(value) for value in self.delta_v],
            "delta_v_magnitude": json_number(self.delta_v_magnitude),
        }


@dataclass(frozen=True)
class Result:
    """A solved scene.

    ``mu`` is the impulse ratio used (equal to ``mu_c`` for a critical
    scene), ``mu_c`` the critical one.  ``TL = TLn + TLt + TLm`` is the
    energy loss and its normal, tangential and moment parts.  ``flags`` is the
    kernel's bit field (see :mod:`impactsym.codes`); ``warnings`` explains it
    and lists unusual but accepted inputs.
    """

    model: str
    units: str
    critical: bool
    vehicles: tuple[VehicleResult, VehicleResult]
    Pn: float
    Pt: float
    M: float
    mu: float
    mu_c: float
    TL: float
    TLn: float
    TLt: float
    TLm: float
    flags: int
    warnings: list[str] = field(default_factory=list)
    direction: str = "forward"

    @property
    def kind(self) -> str:
        """The command that made it: ``"solve"`` or ``"invert"``."""
        return "solve" if self.direction == "forward" else "invert"

    @classmethod
    def from_kernel(cls, scene: Scene, out: Mapping[str, Any]) -> Result:
        """Combine a scene with the output of ``_kernels.solve_one`` (status 0)."""
        flags = int(out["flags"])
        return cls(
            model=scene.model,
            units=scene.units,
            critical=scene.impact.critical,
            vehicles=tuple(
                _vehicle_result(vehicle, out, number)
                for number, vehicle in enumerate(scene.vehicles, start=1)
            ),
            flags=flags,
            warnings=describe_flags(flags) + scene_warnings(scene),
            **{key: float(out[key]) for key in _KERNEL_SCALARS},
        )

    def to_json_dict(self) -> dict[str, Any]:
        """The object printed by ``impactsym solve --json`` (conventions.md).

        Non-finite numbers become ``null`` so the output is strict JSON.
        """
        return {
            "model": self.model,
            "units": self.units,
            "vehicles": [vehicle.to_json_dict() for vehicle in self.vehicles],
            "impulse": {
                "normal": json_number(self.Pn),
                "tangential": json_number(self.Pt),
                "moment": json_number(self.M),
            },
            "impulse_ratio": json_number(self.mu),
            "critical_impulse_ratio": json_number(self.mu_c),
            "energy_loss": {
                "total": json_number(self.TL),
                "normal": json_number(self.TLn),
                "tangential": json_number(self.TLt),
                "moment": json_number(self.TLm),
            },
            "flags": self.flags,
            "warnings": list(self.warnings),
        }

    def table(self) -> str:
        """A plain-text table for people, with unit labels and the warnings.

        The particle model has no yaw: its yaw-rate and moment rows are left out.
        Rounding residue of a zero is shown as 0 (:func:`without_residue`).
        """
        one, two = self.vehicles
        width = max(14, len(one.name) + 2, len(two.name) + 2)
        lines = [f"{self.model} model, {self.units} units (impulses on vehicle 1, impact frame)", ""]
        lines.append(f"{'':<28}{one.name:>{width}}{two.name:>{width}}")
        vehicle_rows, impact_rows = self._vehicle_rows(), self._impact_rows()
        clean = without_residue(vehicle_rows + impact_rows)
        vehicle_rows, impact_rows = clean[: len(vehicle_rows)], clean[len(vehicle_rows) :]
        lines += [
            f"{label:<28}{table_cell(a):>{width}}{table_cell(b):>{width}}" for label, a, b in vehicle_rows
        ]
        lines.append("")
        lines += [f"{label:<36}{table_cell(value):>14}" for label, value in impact_rows]
        lines.append("")
        if self.warnings:
            lines += ["warnings:"] + [f"  - {text}" for text in self.warnings]
        else:
            lines.append("warnings: none")
        return "\n".join(lines)

    def _vehicle_rows(self) -> list[tuple[str, float, float]]:
        """Per-vehicle table rows: (label with unit, vehicle 1, vehicle 2)."""
        labels = UNIT_LABELS[self.units]
        speed, rate = f"[{labels['velocity']}]", f"[{labels['yaw_rate']}]"
        one, two = self.vehicles
        when = "final" if self.direction == "forward" else "initial"
        rows = [
            (f"{when} velocity x {speed}", one.velocity[0], two.velocity[0]),
            (f"{when} velocity y {speed}", one.velocity[1], two.velocity[1]),
            (f"{when} yaw rate {rate}", one.yaw_rate, two.yaw_rate),
            (f"delta-V x {speed}", one.delta_v[0], two.delta_v[0]),
            (f"delta-V y {speed}", one.delta_v[1], two.delta_v[1]),
            (f"|delta-V| {speed}", one.delta_v_magnitude, two.delta_v_magnitude),
        ]
        rows += road_speed_rows(
            self.units,
            [
                (f"{when} speed", [math.hypot(*v.velocity) for v in self.vehicles]),
                ("|delta-V|", [v.delta_v_magnitude for v in self.vehicles]),
            ],
        )
        rows.append((f"{when} yaw rate [deg/s]", math.degrees(one.yaw_rate), math.degrees(two.yaw_rate)))
        return [row for row in rows if uses_yaw(self.model) or "yaw" not in row[0]]

    def _impact_rows(self) -> list[tuple[str, float]]:
        """Impulse, impulse ratio and energy rows: (label with unit, value)."""
        labels = UNIT_LABELS[self.units]
        impulse, moment, energy = (f"[{labels[key]}]" for key in ("impulse", "moment", "energy"))
        rows = [
            (f"normal impulse Pn {impulse}", self.Pn),
            (f"tangential impulse Pt {impulse}", self.Pt),
            (f"moment impulse M {moment}", self.M),
            ("impulse ratio mu (critical)" if self.critical else "impulse ratio mu", self.mu),
            ("critical impulse ratio mu_c", self.mu_c),
            (f"energy loss TL {energy}", self.TL),
            (f"  normal TLn {energy}", self.TLn),
            (f"  tangential TLt {energy}", self.TLt),
            (f"  moment TLm {energy}", self.TLm),
        ]
        return [row for row in rows if uses_yaw(self.model) or "moment" not in row[0]]


def scene_warnings(scene: Scene) -> list[str]:
    """Warnings about unusual but accepted scene inputs.

    Restitution outside [0, 1], moment restitution outside [-1, 1] (models
    with yaw), IMPAC's sideswipe slip outside [0, 1], a fixed vehicle given a
    motion, and the scene's own warnings (unknown keys, coefficients the model
    fixes or does not use).
    """
    impact = scene.impact
    warnings = []
    if not 0.0 <= impact.restitution <= 1.0:
        warnings.append(f"impact.restitution = {impact.restitution:g} is outside [0, 1]")
    if scene.uses_yaw and not -1.0 <= impact.moment_restitution <= 1.0:
        warnings.append(f"impact.moment_restitution = {impact.moment_restitution:g} is outside [-1, 1]")
    if impact.slip is not None and not 0.0 <= impact.slip <= 1.0:
        warnings.append(
            f"impact.slip = {impact.slip:g} is outside [0, 1]: the final tangential "
            "slip would reverse or exceed the initial one"
        )
    for index, vehicle in enumerate(scene.vehicles):
        if vehicle.fixed and (vehicle.velocity != (0.0, 0.0) or vehicle.yaw_rate != 0.0):
            warnings.append(
                f"vehicles[{index}] ({vehicle.name}) is fixed but given a non-zero velocity or yaw rate"
            )
    return warnings + list(scene.warnings)


def _vehicle_result(vehicle, out: Mapping[str, Any], number: int) -> VehicleResult:
    """Final motion and delta-V of vehicle ``number`` (1 or 2) from kernel output."""
    final = (float(out[f"V{number}x"]), float(out[f"V{number}y"]))
    delta = (final[0] - vehicle.velocity[0], final[1] - vehicle.velocity[1])
    return VehicleResult(
        name=vehicle.name,
        velocity=final,
        yaw_rate=float(out[f"W{number}"]),
        delta_v=delta,
        delta_v_magnitude=math.hypot(*delta),
    )


def road_speed_rows(units: str, speeds) -> list[tuple]:
    """Table rows of speeds (``(label, [per vehicle])`` in the system's speed
    unit, None where unknown) in the unit people read: mph (US) or km/h (SI)."""
    label, factor = ROAD_SPEED[units]
    return [
        (f"{name} [{label}]", *(None if value is None else factor * value for value in values))
        for name, values in speeds
    ]


def table_cell(value: float) -> str:
    """A table cell: six significant digits, negative zero shown as 0."""
    return f"{value + 0.0:.6g}"


#: In a table (and ``--json``: :mod:`impactsym.residue`; never the API), a value
#: smaller than this fraction of the largest magnitude printed in the same unit
#: (yaw rates: at least the speeds per unit length) is shown as 0: it is
#: rounding residue of a zero (7.3e-16 m/s beside 50 m/s), not a result.
TABLE_RESIDUE = RESIDUE


def without_residue(rows: list[tuple]) -> list[tuple]:
    """Table rows ``(label, *values)`` with rounding residue set to 0: a
    float below :data:`TABLE_RESIDUE` times the largest finite magnitude among
    the rows of the same unit (the ``[m/s]`` that ends the label; rows without
    one, such as ratios, form one group)."""
    scales: dict[str, float] = {"": 1.0}  # ratios: scale 1 (impactsym.residue)
    for label, *values in rows:
        unit = _unit_of(label)
        scales[unit] = max([scales.get(unit, 0.0)] + [abs(v) for v in values if _is_float(v)])
    # yaw rates and moments: at least the speeds (impulses) per unit length
    speed = max(scales.get(f"{u['velocity']}]", 0.0) for u in UNIT_LABELS.values())
    impulse = max(scales.get(f"{u['impulse']}]", 0.0) for u in UNIT_LABELS.values())
    floors = {"rad/s]": speed, "deg/s]": math.degrees(speed)}
    floors.update({f"{u['moment']}]": impulse for u in UNIT_LABELS.values()})
    return [
        (
            label,
            *(
                drop_residue(v, max(scales[_unit_of(label)], floors.get(_unit_of(label), 0.0)))
                if _is_float(v)
                else v
                for v in values
            ),
        )
        for label, *values in rows
    ]


def _unit_of(label: str) -> str:
    """The ``[unit]`` that ends a table label, or ``""``."""
    head, bracket, unit = label.rstrip().rpartition("[")
    return unit if bracket and unit.endswith("]") else ""


def _is_float(value: Any) -> bool:
    return isinstance(value, float) and math.isfinite(value)


def json_clean(data: Any) -> Any:
    """``data`` (dicts, lists, tuples, numbers, strings) with every float
    through :func:`json_number`: what the commands print with ``--json``
    (no ``-0.0``, no NaN), whichever result made it."""
    if isinstance(data, Mapping):
        return {key: json_clean(value) for key, value in data.items()}
    if isinstance(data, (list, tuple)):
        return [json_clean(value) for value in data]
    if isinstance(data, float):
        return json_number(data)
    return data


def json_number(value: float) -> float | None:
    """``value``, or ``None`` when it is NaN or infinite (JSON has no such
    numbers); a negative zero is written as 0.0 (``-0.0`` is rounding's sign,
    not a direction)."""
    if not math.isfinite(value):
        return None
    return value + 0.0 if value == 0 else value
