"""Reconstruction: pre-impact speeds from post-impact motion and headings.

The generated `reconstruct` kernel does the physics (derive/reconstruct.py);
this module reads scenes, converts units of angle, and presents the result.
PDOF follows the CRASH3 habit: the direction the impulse on a vehicle comes
from, in degrees clockwise from straight ahead, and as a clock position
(12 = frontal, 3 = from the right side).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import _kernels
from .batch import run_columns
from .codes import describe_flags, describe_status
from .result import UNIT_LABELS, json_number, road_speed_rows, table_cell, without_residue
from .scene import Scene, SceneError, load_scene
from .single import overflow_error, turned_round_note

OUTPUTS = _kernels.FAMILY_OUTPUTS["reconstruct"]


def reconstruct_batch(columns):
    """Reconstruction for one scene per row.

    `columns`: ``m1 m2 I1 I2 V1x V1y W1 V2x V2y W2 theta1 theta2 w1 w2 r1x r1y
    r2x r2y gamma`` (headings θ and normal angle Γ in RADIANS: degrees given
    by mistake give wrong speeds and no flag; w = pre-impact yaw rates), as a
    dict or DataFrame; an unknown or non-numeric column is a one-line
    ValueError naming it, as in `solve_batch`. Returns ``s1 s2 v1x v1y v2x v2y Pn Pt M M_residual e mu e_m mu_c
    TL TLn TLt TLm pdof1 pdof2`` (PDOF in radians, counter-clockwise from the
    heading, of the direction the impulse comes from) plus status and flags.
    """
    return run_columns(_kernels.RECONSTRUCT, columns, OUTPUTS, "the reconstruction")


@dataclass(frozen=True)
class ReconstructedVehicle:
    """One vehicle before impact: speed along its heading, velocity, delta-V
    (final minus initial), PDOF in degrees clockwise from ahead and as a clock."""

    name: str
    speed: float
    velocity: tuple[float, float]
    delta_v: tuple[float, float]
    delta_v_magnitude: float
    pdof_deg: float
    pdof_clock: int

    def to_json_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "speed": json_number(self.speed),
            "velocity": [json_number(v) for v in self.velocity],
            "delta_v": [json_number(v) for v in self.delta_v],
            "delta_v_magnitude": json_number(self.delta_v_magnitude),
            "pdof_deg": json_number(self.pdof_deg),
            "pdof_clock": self.pdof_clock,
        }


@dataclass(frozen=True)
class Reconstruction:
    """The reconstructed impact, in the scene's units. `M` is the mean of the
    two angular-impulse estimates of the moment impulse and `M_residual` their
    difference (0 for perfectly consistent data)."""

    units: str
    vehicles: tuple[ReconstructedVehicle, ReconstructedVehicle]
    Pn: float
    Pt: float
    M: float
    M_residual: float
    e: float
    mu: float
    e_m: float
    mu_c: float
    TL: float
    TLn: float
    TLt: float
    TLm: float
    flags: int
    warnings: list[str] = field(default_factory=list)
    kind = "reconstruct"

    def to_json_dict(self) -> dict[str, Any]:
        """The object printed by ``impactsym reconstruct --json`` (conventions.md)."""
        return {
            "units": self.units,
            "vehicles": [v.to_json_dict() for v in self.vehicles],
            "impulse": {
                "normal": json_number(self.Pn),
                "tangential": json_number(self.Pt),
                "moment": json_number(self.M),
            },
            "moment_residual": json_number(self.M_residual),
            "restitution": json_number(self.e),
            "impulse_ratio": json_number(self.mu),
            "moment_restitution": json_number(self.e_m),
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
        """A plain-text table for people."""
        labels = UNIT_LABELS[self.units]
        speed, energy = f"[{labels['velocity']}]", f"[{labels['energy']}]"
        one, two = self.vehicles
        width = max(14, len(one.name) + 2, len(two.name) + 2)
        rows = [
            (f"pre-impact speed {speed}", one.speed, two.speed),
            (f"velocity x {speed}", one.velocity[0], two.velocity[0]),
            (f"velocity y {speed}", one.velocity[1], two.velocity[1]),
            (f"|delta-V| {speed}", one.delta_v_magnitude, two.delta_v_magnitude),
            *road_speed_rows(
                self.units,
                [
                    ("pre-impact speed", (one.speed, two.speed)),
                    ("|delta-V|", (one.delta_v_magnitude, two.delta_v_magnitude)),
                ],
            ),
            ("PDOF [deg, clockwise]", one.pdof_deg, two.pdof_deg),
            ("PDOF [o'clock]", one.pdof_clock, two.pdof_clock),
        ]
        lines = [f"reconstruction, {self.units} units", "", f"{'':<28}{one.name:>{width}}{two.name:>{width}}"]
        implied = [
            ("implied restitution e", self.e),
            ("implied impulse ratio mu", self.mu),
            ("critical impulse ratio mu_c", self.mu_c),
            ("implied moment restitution e_m", self.e_m),
            (f"moment impulse M [{labels['moment']}]", self.M),
            (f"  consistency residual [{labels['moment']}]", self.M_residual),
            (f"energy loss TL {energy}", self.TL),
            (f"  normal TLn {energy}", self.TLn),
            (f"  tangential TLt {energy}", self.TLt),
            (f"  moment TLm {energy}", self.TLm),
        ]
        clean = without_residue(rows + implied)  # rounding residue of a zero shown as 0
        rows, implied = clean[: len(rows)], clean[len(rows) :]
        lines += [f"{label:<28}{table_cell(a):>{width}}{table_cell(b):>{width}}" for label, a, b in rows]
        lines.append("")
        lines += [f"{label:<36}{table_cell(value):>14}" for label, value in implied]
        lines += (
            ["", "warnings:"] + [f"  - {w}" for w in self.warnings]
            if self.warnings
            else ["", "warnings: none"]
        )
        return "\n".join(lines)


def reconstruct(scene: Scene | Mapping | str | Path) -> Reconstruction:
    """Reconstruct the pre-impact speeds of a scene whose vehicles give
    ``final_velocity``, ``final_yaw_rate``, ``heading`` (degrees) and optionally
    ``yaw_rate`` (pre-impact, default 0); ``impact`` needs only ``normal_angle``.
    Raises SceneError when the speeds are not determined."""
    scene = load_scene(scene, kind="reconstruct")
    values = _inputs(scene)
    out = _kernels.run_one(_kernels.RECONSTRUCT, values, OUTPUTS)
    if out["status"] != 0:
        raise overflow_error(scene, out["status"]) or SceneError(
            f"cannot reconstruct the scene: {describe_status(out['status'])}"
            + turned_round_note(scene, out["status"])
        )
    vehicles = tuple(_vehicle(v, out, values, i) for i, v in enumerate(scene.vehicles, 1))
    scalars = {
        k: out[k]
        for k in ("Pn", "Pt", "M", "M_residual", "e", "mu", "e_m", "mu_c", "TL", "TLn", "TLt", "TLm")
    }
    return Reconstruction(
        units=scene.units,
        vehicles=vehicles,
        flags=out["flags"],
        warnings=describe_flags(out["flags"])
        + moment_warnings(out["e_m"])
        + residual_warnings(out, values, scene.units)
        + list(scene.warnings),
        **scalars,
    )


#: The physical range of the moment restitution: e_m is the ratio of the final
#: to the initial relative yaw rate at the impact, so TLm = (wr² - Wr²)/(2 Σj)
#: is a loss only when |e_m| <= 1 (the range scenes are warned about too).
MOMENT_RESTITUTION_RANGE = (-1.0, 1.0)


def moment_warnings(e_m: float) -> list[str]:
    """A warning when the implied moment restitution is outside its physical
    range (a runtime check of the kernel's output; the kernel has no flag bit
    for it)."""
    low, high = MOMENT_RESTITUTION_RANGE
    if not math.isfinite(e_m) or low <= e_m <= high:
        return []
    return [
        f"the implied moment restitution e_m = {e_m:.6g} is outside [{low:g}, {high:g}]: "
        "the final relative yaw rate exceeds the initial one, which creates rotational "
        "energy (TLm < 0); check the yaw rates, headings and impact centre"
    ]


#: The fraction of the yaw impulses I·|W - w| that the given yaw rates, read to
#: two or three digits, can explain: a moment residual below it is the data's
#: rounding, not an inconsistency.
RESIDUAL_READING = 0.01


def residual_warnings(out: Mapping, values: Mapping, units: str) -> list[str]:
    """A warning when the two angular-impulse equations disagree by more than
    the moment impulse itself, |M_residual| > |M| (and by more than
    :data:`RESIDUAL_READING` of the yaw impulses I·|W - w|): the mean M then
    has no meaning (a placeholder final yaw rate, a misplaced impact centre)."""
    M, residual = out["M"], out["M_residual"]
    reading = RESIDUAL_READING * max(
        abs(values[f"I{i}"] * (values[f"W{i}"] - values[f"w{i}"])) for i in (1, 2)
    )
    if not math.isfinite(residual) or abs(residual) <= max(abs(M), reading):
        return []
    unit = UNIT_LABELS[units]["moment"]
    return [
        f"the two angular-impulse equations disagree by moment_residual = {residual:.4g} {unit}, more "
        f"than the moment impulse M = {M:.4g} {unit} itself: the yaw rates and the impact centre are "
        "not consistent; check vehicles[].final_yaw_rate (a placeholder?) and vehicles[].impact_point"
    ]


def _inputs(scene: Scene) -> dict:
    """Kernel inputs: masses, finals, headings and geometry in batch names."""
    values = {"gamma": math.radians(scene.impact.normal_angle)}
    for number, vehicle in enumerate(scene.vehicles, start=1):
        if vehicle.fixed:
            raise SceneError("a reconstruction needs two moving vehicles", f"vehicles[{number - 1}].fixed")
        final = vehicle.extra["final_velocity"]
        values.update(
            {
                f"m{number}": vehicle.mass,
                f"I{number}": vehicle.yaw_inertia,
                f"V{number}x": final[0],
                f"V{number}y": final[1],
                f"W{number}": float(vehicle.extra.get("final_yaw_rate", 0.0)),
                f"theta{number}": math.radians(vehicle.extra["heading"]),
                f"w{number}": vehicle.yaw_rate,
                f"r{number}x": vehicle.impact_point[0],
                f"r{number}y": vehicle.impact_point[1],
            }
        )
    return values


def _vehicle(vehicle, out, values, number: int) -> ReconstructedVehicle:
    velocity = (out[f"v{number}x"], out[f"v{number}y"])
    delta = (values[f"V{number}x"] - velocity[0], values[f"V{number}y"] - velocity[1])
    clockwise = -math.degrees(out[f"pdof{number}"])
    pdof = (clockwise + 180.0) % 360.0 - 180.0
    return ReconstructedVehicle(
        name=vehicle.name,
        speed=out[f"s{number}"],
        velocity=velocity,
        delta_v=delta,
        delta_v_magnitude=math.hypot(*delta),
        pdof_deg=pdof,
        pdof_clock=(round(pdof / 30.0) - 1) % 12 + 1,
    )
