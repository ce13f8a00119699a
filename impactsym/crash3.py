"""CRASH3: delta-V from crush energy, and its inconsistency with impulse-momentum.

The formulas are derive/crash3.py's (emitted to generated/crash3.py): crush energy
of each vehicle from its damage profile, the PDOF correction 1 + tan²α
(|α| ≤ 45°), the effective-mass factor γ = k²/(k² + h²), and delta-V from the
total energy with a common velocity (restitution e = 0 unless given).

A vehicle's ``crush`` table (scene file):

- ``A`` [N/m | lb/in], ``B`` [N/m² | lb/in²]: stiffness, F/w = A + B·C;
- ``width`` [m | in]: damage width L; ``depths`` [m | in]: 2, 4 or 6 equally
  spaced crush depths C1..CN across it (piecewise linear between them);
- ``pdof`` [deg]: the principal direction of force on the vehicle, measured
  from the inward normal of its damaged face, counter-clockwise positive; the
  damaged face is the crush surface of ``impact.normal_angle``, so the inward
  normal is -n for vehicle 1 and +n for vehicle 2, and the force on vehicle 1
  points along Γ + 180° + α (on vehicle 2 along Γ + α);
- optional ``moment_arm`` [m | ft] (h, the distance from the centre of gravity
  to the PDOF line) and ``radius_of_gyration`` [m | ft] (k).

Units: SI crush inputs give joules. US crush inputs are CRASH3's lb/in, lb/in²
and in (pounds of force; masses stay in slugs): their energy is in in·lb and is
divided by ``INCHES_PER_FOOT`` = 12 to give ft·lb. Moment arm and radius of
gyration are in the scene's length unit (m | ft).

Without ``moment_arm`` the arm is computed from ``impact_point`` (when given) and
the PDOF; without ``radius_of_gyration`` it comes from ``yaw_inertia`` and
``mass`` (when given). Missing either, γ = 1 (no effective-mass correction).

When the scene also has the motion of a forward scene (velocities, yaw
inertias, impact points), the common-velocity impulse-momentum solution of the
same scene (e_m = 1, the same restitution) gives the PDOF CRASH3's own |ΔV|
assumption implies, α = atan2(-Pt, -Pn) with tan α = μ_c: the seed's
criticism (CRASH takes |ΔV| from μ = μ_max but its direction from the user's
PDOF) is reported as the difference between the two.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

from ._kernels import STATUS_PDOF_BEYOND_LIMIT

from . import _kernels
from .codes import describe_status
from .result import UNIT_LABELS
from .scene import Scene, SceneError, Vehicle, _mapping, _number, _positive, load_scene, scene_data
from .single import solve

__all__ = ["crash3", "Crash3Result", "Crash3Vehicle", "Crush", "INCHES_PER_FOOT",
           "PDOF_MISMATCH_DEG"]

INCHES_PER_FOOT = 12.0
# Energy of crush inputs in the scene's energy unit: SI J per (N/m·m²), US ft·lb per in·lb.
ENERGY_FACTOR = {"SI": 1.0, "US": 1.0 / INCHES_PER_FOOT}
PROFILE_SIZES = tuple(_kernels.CRASH3_ENERGY)
# Entered and implied PDOFs further apart than this are reported as a warning [deg].
PDOF_MISMATCH_DEG = 5.0
PDOF_LIMIT_DEG = 45.0
CRUSH_KEYS = ("A", "B", "width", "depths", "pdof", "moment_arm", "radius_of_gyration")


@dataclass(frozen=True)
class Crush:
    """A validated ``crush`` table (units: see the module docstring)."""

    A: float
    B: float
    width: float
    depths: tuple[float, ...]
    pdof: float
    moment_arm: float | None = None
    radius_of_gyration: float | None = None


@dataclass(frozen=True)
class Crash3Vehicle:
    """CRASH3 outcome for one vehicle: energies [J | ft·lb], PDOF [deg],
    effective-mass factor γ, moment arm [m | ft], delta-V [m/s | ft/s] along
    the PDOF. ``pdof_implied`` [deg] and ``delta_v_magnitude_impulse_momentum``
    come from the common-velocity impulse-momentum solution (None without it)."""

    name: str
    crush_energy: float
    crush_energy_uncorrected: float
    pdof: float
    mass_factor: float
    moment_arm: float
    delta_v: tuple[float, float]
    delta_v_magnitude: float
    pdof_implied: float | None = None
    delta_v_magnitude_impulse_momentum: float | None = None

    def to_json_dict(self) -> dict[str, Any]:
        """The vehicle entry of ``impactsym crash3 --json``."""
        return {
            "name": self.name, "crush_energy": self.crush_energy,
            "crush_energy_uncorrected": self.crush_energy_uncorrected, "pdof": self.pdof,
            "effective_mass_factor": self.mass_factor, "moment_arm": self.moment_arm,
            "delta_v": list(self.delta_v), "delta_v_magnitude": self.delta_v_magnitude,
            "pdof_implied": self.pdof_implied,
            "delta_v_magnitude_impulse_momentum": self.delta_v_magnitude_impulse_momentum,
        }


@dataclass(frozen=True)
class Crash3Result:
    """CRASH3 for a scene: both vehicles, the total energy and the impulse
    magnitude |P| [N·s | lb·s], in the scene's units."""

    units: str
    restitution: float
    vehicles: tuple[Crash3Vehicle, Crash3Vehicle]
    energy_total: float
    impulse: float
    warnings: list[str] = field(default_factory=list)

    def to_json_dict(self) -> dict[str, Any]:
        """The object printed by ``impactsym crash3 --json`` (conventions.md)."""
        return {"units": self.units, "restitution": self.restitution,
                "vehicles": [v.to_json_dict() for v in self.vehicles],
                "energy_total": self.energy_total, "impulse": self.impulse,
                "warnings": list(self.warnings)}

    def table(self) -> str:
        """A plain-text table for people."""
        labels = UNIT_LABELS[self.units]
        energy, speed = labels["energy"], labels["velocity"]
        one, two = self.vehicles
        rows = [
            (f"crush energy [{energy}]", one.crush_energy_uncorrected, two.crush_energy_uncorrected),
            ("PDOF alpha [deg]", one.pdof, two.pdof),
            (f"  with 1 + tan^2(alpha) [{energy}]", one.crush_energy, two.crush_energy),
            ("effective-mass factor gamma", one.mass_factor, two.mass_factor),
            (f"|delta-V| [{speed}]", one.delta_v_magnitude, two.delta_v_magnitude),
            (f"delta-V x [{speed}]", one.delta_v[0], two.delta_v[0]),
            (f"delta-V y [{speed}]", one.delta_v[1], two.delta_v[1]),
            ("PDOF implied by impulse-momentum [deg]", one.pdof_implied, two.pdof_implied),
            (f"|delta-V| impulse-momentum [{speed}]", one.delta_v_magnitude_impulse_momentum,
             two.delta_v_magnitude_impulse_momentum),
        ]
        width = max(14, len(one.name) + 2, len(two.name) + 2)
        lines = [f"CRASH3, {self.units} units, restitution e = {self.restitution:g}", "",
                 f"{'':<40}{one.name:>{width}}{two.name:>{width}}"]
        lines += [f"{label:<40}{_cell(a):>{width}}{_cell(b):>{width}}" for label, a, b in rows]
        lines += ["", f"{'total energy [' + energy + ']':<40}{_cell(self.energy_total):>{width}}", ""]
        lines += (["warnings:"] + [f"  - {w}" for w in self.warnings]) if self.warnings \
            else ["warnings: none"]
        return "\n".join(lines)


def crash3(scene: Union[Scene, Mapping, str, Path], restitution: float = 0.0) -> Crash3Result:
    """CRASH3 delta-V of a scene whose moving vehicles carry ``crush`` tables.

    ``restitution`` e (0 ≤ e < 1; 0 is CRASH3's common velocity) relates the
    crush energy to the closing speed: E = m̄'·v_c²·(1 - e²)/2. A fixed vehicle
    (a barrier) needs no crush table and absorbs no energy. Raises
    :class:`SceneError` for a bad scene, crush table or restitution.
    """
    data = scene_data(scene)
    parsed = load_scene(data, kind="crash3")
    e = _restitution(restitution)
    gamma = math.radians(parsed.impact.normal_angle)
    crush = [None if v.fixed else _parse_crush(v.extra["crush"], f"vehicles[{i}].crush")
             for i, v in enumerate(parsed.vehicles)]
    energies = [_energy(c, parsed.units, f"vehicles[{i}].crush") if c else (0.0, 0.0)
                for i, c in enumerate(crush)]
    alphas = [math.radians(c.pdof) if c else 0.0 for c in crush]
    values = {"E": energies[0][1] + energies[1][1], "e": e, "gamma": gamma,
              "alpha1": alphas[0], "alpha2": alphas[1]}
    for number, (vehicle, c) in enumerate(zip(parsed.vehicles, crush), start=1):
        values[f"m{number}"] = math.inf if vehicle.fixed else vehicle.mass
        values[f"rg{number}"] = _radius_of_gyration(vehicle, c)
        values[f"h{number}"] = _moment_arm(vehicle, c, gamma)
    out = _run(_kernels.CRASH3_DELTA_V, values, "cannot compute the CRASH3 delta-V")
    implied = _implied(data, e)
    vehicles = tuple(_vehicle(v, c, energies[i], out, values, i + 1, implied)
                     for i, (v, c) in enumerate(zip(parsed.vehicles, crush)))
    warnings = _warnings(vehicles, crush, implied) + _unknown_crush_keys(parsed) \
        + list(parsed.warnings)
    return Crash3Result(parsed.units, e, vehicles, values["E"], out["P"], warnings)


def _restitution(value: Any) -> float:
    """CRASH3's restitution option, 0 ≤ e < 1."""
    e = _number(value, "restitution")
    if not 0.0 <= e < 1.0:
        raise SceneError(f"must be in [0, 1) for CRASH3, got {e:g}", "restitution")
    return e


def _parse_crush(raw: Any, path: str) -> Crush:
    """Validate a ``crush`` table (the kernels check ranges again)."""
    data = _mapping(raw, path)
    for key in ("A", "B", "width", "depths", "pdof"):
        if key not in data:
            raise SceneError("missing", f"{path}.{key}")
    depths = data["depths"]
    if not isinstance(depths, list) or len(depths) not in PROFILE_SIZES:
        raise SceneError(f"must be a list of 2, 4 or 6 crush depths, got {_short(depths)}",
                         f"{path}.depths")
    optional = {}
    if "moment_arm" in data:
        optional["moment_arm"] = _number(data["moment_arm"], f"{path}.moment_arm")
    if "radius_of_gyration" in data:
        optional["radius_of_gyration"] = _positive(data["radius_of_gyration"],
                                                   f"{path}.radius_of_gyration")
    return Crush(A=_number(data["A"], f"{path}.A"), B=_number(data["B"], f"{path}.B"),
                 width=_number(data["width"], f"{path}.width"),
                 depths=tuple(_number(c, f"{path}.depths") for c in depths),
                 pdof=_number(data["pdof"], f"{path}.pdof"), **optional)


def _energy(crush: Crush, units: str, path: str) -> tuple[float, float]:
    """(crush energy, PDOF-corrected energy) in the scene's energy unit."""
    values = {"A": crush.A, "B": crush.B, "width": crush.width, "alpha": math.radians(crush.pdof)}
    values.update({f"C{i}": c for i, c in enumerate(crush.depths, start=1)})
    ks = _kernels.CRASH3_ENERGY[len(crush.depths)]
    out = _kernels.run_one(ks, values, ks.outputs)
    if out["status"] == STATUS_PDOF_BEYOND_LIMIT:
        raise SceneError(f"|pdof| = {abs(crush.pdof):g} > {PDOF_LIMIT_DEG:g} degrees: "
                         f"{describe_status(out['status'])}", f"{path}.pdof")
    if out["status"]:
        raise SceneError(describe_status(out["status"]), path)
    factor = ENERGY_FACTOR[units]
    return out["E_crush"] * factor, out["E"] * factor


def _radius_of_gyration(vehicle: Vehicle, crush: Crush | None) -> float:
    """k [m | ft]: given, from the yaw inertia, or inf (no rotation: γ = 1)."""
    if crush is None:
        return math.inf
    if crush.radius_of_gyration is not None:
        return crush.radius_of_gyration
    if vehicle.yaw_inertia is None:
        return math.inf
    out = _run(_kernels.CRASH3_RADIUS_OF_GYRATION,
               {"mass": vehicle.mass, "inertia": vehicle.yaw_inertia}, "radius of gyration")
    return out["rg"]


def _moment_arm(vehicle: Vehicle, crush: Crush | None, gamma: float) -> float:
    """h [m | ft]: given, from the impact point and the PDOF, or 0."""
    if crush is None:
        return 0.0
    if crush.moment_arm is not None:
        return crush.moment_arm
    rx, ry = vehicle.impact_point
    out = _run(_kernels.CRASH3_MOMENT_ARM,
               {"rx": rx, "ry": ry, "theta": gamma + math.radians(crush.pdof)}, "moment arm")
    return out["h"]


def _run(ks: _kernels.KernelSet, values: dict, what: str) -> dict:
    """One row through a kernel; a non-zero status is a SceneError."""
    out = _kernels.run_one(ks, values, ks.outputs)
    if out["status"]:
        raise SceneError(f"{what}: {describe_status(out['status'])}")
    return out


def _implied(data: Mapping, e: float) -> dict | None:
    """The common-velocity impulse-momentum solution of the same scene (e_m = 1,
    CRASH3's restitution): its PDOF [deg] and |ΔV| per vehicle, or None when the
    scene lacks the motion or geometry for it."""
    variant = {**data, "model": "rigid",
               "impact": {"normal_angle": data["impact"]["normal_angle"], "restitution": e,
                          "impulse_ratio": "critical", "moment_restitution": 1.0}}
    try:
        result = solve(variant)
    except SceneError:
        return None
    out = _run(_kernels.CRASH3_IMPLIED_PDOF, {"Pn": result.Pn, "Pt": result.Pt}, "implied PDOF")
    return {"pdof": math.degrees(out["pdof"]), "mu_c": result.mu_c,
            "delta_v": [v.delta_v_magnitude for v in result.vehicles]}


def _vehicle(vehicle: Vehicle, crush: Crush | None, energy, out, values, number: int,
             implied: dict | None) -> Crash3Vehicle:
    """Vehicle ``number``'s result from its energies, the delta-V kernel's output and
    the implied impulse-momentum solution (a fixed vehicle: zero energy and delta-V)."""
    return Crash3Vehicle(
        name=vehicle.name, crush_energy=energy[1], crush_energy_uncorrected=energy[0],
        pdof=crush.pdof if crush else 0.0, mass_factor=out[f"mass_factor{number}"],
        moment_arm=values[f"h{number}"],
        delta_v=(out[f"dV{number}x"], out[f"dV{number}y"]),
        delta_v_magnitude=out[f"dV{number}"],
        pdof_implied=None if implied is None or vehicle.fixed else implied["pdof"],
        delta_v_magnitude_impulse_momentum=None if implied is None else implied["delta_v"][number - 1],
    )


def _warnings(vehicles, crush, implied: dict | None) -> list[str]:
    """The seed's CRASH3 criticisms, where the scene shows them."""
    warnings = []
    entered = [c.pdof for c in crush if c is not None]
    if len(entered) == 2 and abs(entered[0] - entered[1]) > 1e-9:
        warnings.append(f"the entered PDOFs differ ({entered[0]:g} and {entered[1]:g} degrees): "
                        "the impulses on the two vehicles are not equal and opposite, so "
                        "momentum is not conserved")
    if implied is None:
        return warnings
    if abs(implied["pdof"]) > PDOF_LIMIT_DEG:
        warnings.append(f"the impulse-momentum solution's PDOF ({implied['pdof']:.1f} degrees) "
                        "is beyond CRASH3's 45-degree limit: a sideswipe-like impact, which "
                        "CRASH3 cannot model (seed)")
    for index, (vehicle, c) in enumerate(zip(vehicles, crush)):
        if c is not None and abs(c.pdof - implied["pdof"]) > PDOF_MISMATCH_DEG:
            warnings.append(
                f"vehicles[{index}] ({vehicle.name}): PDOF entered {c.pdof:g} degrees, but the "
                f"common velocity CRASH3 assumes for |delta-V| (mu = mu_c = {implied['mu_c']:.3g}) "
                f"implies {implied['pdof']:.1f} degrees: CRASH3 takes |delta-V| from mu = mu_max "
                "and its direction from the entered PDOF (seed)")
    return warnings


def _unknown_crush_keys(scene: Scene) -> list[str]:
    """Warnings for keys of a crush table that CRASH3 does not read (likely typos)."""
    return [f"ignored unknown key vehicles[{i}].crush.{key}"
            for i, v in enumerate(scene.vehicles) if "crush" in v.extra
            for key in v.extra["crush"] if key not in CRUSH_KEYS]


def _cell(value: float | None) -> str:
    """A table cell: six significant digits, or n/a."""
    return "n/a" if value is None else f"{value + 0.0:.6g}"


def _short(value: Any) -> str:
    """A value shortened for a one-line error message."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
