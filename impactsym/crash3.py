"""CRASH3: delta-V from crush energy, and its inconsistency with impulse-momentum.

The formulas are derive/crash3.py's (emitted to generated/crash3.py): crush energy
of each vehicle from its damage profile, the oblique correction (CRASH3's
1 + tan²α or Woolley's 1/cos α, capped at α = 45° as EDCRASH does), the
effective-mass factor γ = k²/(k² + h²), and delta-V from the total energy with
a common velocity (restitution e = 0 unless given).

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
  to the PDOF line) and ``radius_of_gyration`` [m | ft] (k);
- instead of ``A`` and ``B``: ``category`` (1-9) and ``face`` (``front``,
  ``rear``, ``side``), the EDCRASH default stiffness of
  :mod:`impactsym.crash3_tables` (Day & Hargens, SAE 870045); a scene may mix
  categories and explicit A, B; ``class`` (1-7, 10) supplies the class default
  k² when the vehicle has no ``yaw_inertia`` and no ``radius_of_gyration``.

Options (the scene's top-level ``"crash3"`` object; the arguments of
:func:`crash3` and the CLI flags of the same names override it):

- ``restitution`` e (default 0: CRASH3's common velocity);
- ``energy``: ``"dissipated"`` (default: the crush energy is the energy lost
  over the whole impact, |P| = √(2 E m̄ (1 + e)/(1 - e))) or ``"absorbed"`` (the
  crush energy is absorbed up to maximum crush: the approach delta-V comes from
  it, |P| = (1 + e)·√(2 E m̄); Rose, Fenton & Beauchamp, SAE 2006-01-0908);
- ``correction``: ``"crash3"`` (default, E·(1 + tan²α)) or ``"woolley"``
  (E/cos α). Both are capped as EDCRASH caps CRASH3's factor at 2: the angle
  is taken as min(|α|, 45°) and a capped vehicle gets a warning; |α| ≥ 90° is
  an error.

Which delta-V: ``delta_v_magnitude`` is the change of velocity of the centre of
gravity, |P|/m (what Brach, Neades and Rose report and a CG accelerometer
measures). ``delta_v_effective_mass`` is EDCRASH's printed value, the change of
velocity of the effective mass γ·m, |P|/(γ m); the two are related by
ΔV_cg = γ·ΔV_eff with γ = k²/(k² + h²) (derive/crash3.py proves it).

A crash3 scene needs no ``impact`` block: without it the delta-V has no
direction in the scene frame (``delta_v`` is null), moment arms must be given
as ``moment_arm`` (or are 0), and there is no impulse-momentum comparison.

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
from typing import Any

from . import _kernels
from ._kernels import FLAG_PDOF_CAPPED
from .codes import describe_status
from .crash3_tables import CLASSES, FACES, class_dimensions, stiffness
from .result import UNIT_LABELS, road_speed_rows
from .scene import Scene, SceneError, Vehicle, load_scene, scene_data
from .scene.casefile import check_keys
from .scene.fields import as_mapping, as_number, as_positive
from .single import solve

__all__ = [
    "crash3",
    "Crash3Result",
    "Crash3Vehicle",
    "Crash3Options",
    "crash3_options",
    "Crush",
    "INCHES_PER_FOOT",
    "PDOF_MISMATCH_DEG",
    "ENERGY_MODES",
    "CORRECTIONS",
    "PDOF_CAP_DEG",
]

INCHES_PER_FOOT = 12.0
# Energy of crush inputs in the scene's energy unit: SI J per (N/m·m²), US ft·lb per in·lb.
ENERGY_FACTOR = {"SI": 1.0, "US": 1.0 / INCHES_PER_FOOT}
PROFILE_SIZES = tuple(_kernels.CRASH3_ENERGY)
# Entered and implied PDOFs further apart than this are reported as a warning [deg].
PDOF_MISMATCH_DEG = 5.0
PDOF_CAP_DEG = 45.0  # EDCRASH: the correction factor 1 + tan²α is capped at 2
PDOF_LIMIT_DEG = 90.0  # beyond it the force would pull the damaged face out
CRUSH_KEYS = (
    "A",
    "B",
    "width",
    "depths",
    "pdof",
    "moment_arm",
    "radius_of_gyration",
    "category",
    "face",
    "class",
)
ENERGY_MODES = ("dissipated", "absorbed")
CORRECTIONS = ("crash3", "woolley")
OPTION_KEYS = ("restitution", "energy", "correction")
# The energy kernel's output for each correction, and the delta-V kernel for
# each energy mode (also used by the uncertainty of CRASH3).
CORRECTED_OUTPUT = {"crash3": "E", "woolley": "E_woolley"}
DELTA_V_KERNELS = {"dissipated": _kernels.CRASH3_DELTA_V, "absorbed": _kernels.CRASH3_DELTA_V_ABSORBED}
# Inches per scene length unit, for class k² (published in in²).
_INCHES_PER_LENGTH = {"SI": 1.0 / 0.0254, "US": INCHES_PER_FOOT}


@dataclass(frozen=True)
class Crash3Options:
    """CRASH3 options (module docstring): restitution e, what the crush energy
    is (``energy``) and the oblique correction (``correction``)."""

    restitution: float = 0.0
    energy: str = "dissipated"
    correction: str = "crash3"

    def to_json_dict(self) -> dict[str, Any]:
        return {"restitution": self.restitution, "energy": self.energy, "correction": self.correction}


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
    vehicle_class: int | None = None


@dataclass(frozen=True)
class Crash3Vehicle:
    """CRASH3 outcome for one vehicle: energies [J | ft·lb], PDOF [deg],
    effective-mass factor γ, moment arm [m | ft], delta-V [m/s | ft/s] along
    the PDOF. ``pdof_implied`` [deg] and ``delta_v_magnitude_impulse_momentum``
    come from the common-velocity impulse-momentum solution (None without it).
    ``delta_v_magnitude`` is the centre-of-gravity delta-V, ``delta_v_effective_mass``
    EDCRASH's effective-mass delta-V (= delta_v_magnitude / mass_factor);
    ``delta_v`` is None without an impact block (no scene-frame direction)."""

    name: str
    crush_energy: float
    crush_energy_uncorrected: float
    pdof: float
    mass_factor: float
    moment_arm: float
    delta_v: tuple[float, float] | None
    delta_v_magnitude: float
    delta_v_effective_mass: float
    pdof_implied: float | None = None
    delta_v_magnitude_impulse_momentum: float | None = None

    def to_json_dict(self) -> dict[str, Any]:
        """The vehicle entry of ``impactsym crash3 --json``."""
        return {
            "name": self.name,
            "crush_energy": self.crush_energy,
            "crush_energy_uncorrected": self.crush_energy_uncorrected,
            "pdof": self.pdof,
            "effective_mass_factor": self.mass_factor,
            "moment_arm": self.moment_arm,
            "delta_v": None if self.delta_v is None else list(self.delta_v),
            "delta_v_magnitude": self.delta_v_magnitude,
            "delta_v_effective_mass": self.delta_v_effective_mass,
            "pdof_implied": self.pdof_implied,
            "delta_v_magnitude_impulse_momentum": self.delta_v_magnitude_impulse_momentum,
        }


@dataclass(frozen=True)
class Crash3Result:
    """CRASH3 for a scene: both vehicles, the total energy and the impulse
    magnitude |P| [N·s | lb·s], in the scene's units."""

    units: str
    options: Crash3Options
    vehicles: tuple[Crash3Vehicle, Crash3Vehicle]
    energy_total: float
    impulse: float
    warnings: list[str] = field(default_factory=list)

    @property
    def restitution(self) -> float:
        return self.options.restitution

    def to_json_dict(self) -> dict[str, Any]:
        """The object printed by ``impactsym crash3 --json`` (conventions.md)."""
        return {
            "units": self.units,
            "restitution": self.restitution,
            "options": self.options.to_json_dict(),
            "delta_v_reported": "centre of gravity (|P|/m); delta_v_effective_mass is "
            "|P|/(gamma m) = delta_v_magnitude/gamma",
            "vehicles": [v.to_json_dict() for v in self.vehicles],
            "energy_total": self.energy_total,
            "impulse": self.impulse,
            "warnings": list(self.warnings),
        }

    def table(self) -> str:
        """A plain-text table for people."""
        labels = UNIT_LABELS[self.units]
        energy, speed = labels["energy"], labels["velocity"]
        one, two = self.vehicles
        rows = [
            (f"crush energy [{energy}]", one.crush_energy_uncorrected, two.crush_energy_uncorrected),
            ("PDOF alpha [deg]", one.pdof, two.pdof),
            (f"  corrected ({self.options.correction}) [{energy}]", one.crush_energy, two.crush_energy),
            ("effective-mass factor gamma", one.mass_factor, two.mass_factor),
            (f"|delta-V| of the CG [{speed}]", one.delta_v_magnitude, two.delta_v_magnitude),
            (f"|delta-V| effective mass [{speed}]", one.delta_v_effective_mass, two.delta_v_effective_mass),
            *road_speed_rows(
                self.units, [("|delta-V| of the CG", (one.delta_v_magnitude, two.delta_v_magnitude))]
            ),
            (f"delta-V x [{speed}]", *(v.delta_v and v.delta_v[0] for v in self.vehicles)),
            (f"delta-V y [{speed}]", *(v.delta_v and v.delta_v[1] for v in self.vehicles)),
            ("PDOF implied by impulse-momentum [deg]", one.pdof_implied, two.pdof_implied),
            (
                f"|delta-V| impulse-momentum [{speed}]",
                one.delta_v_magnitude_impulse_momentum,
                two.delta_v_magnitude_impulse_momentum,
            ),
        ]
        width = max(14, len(one.name) + 2, len(two.name) + 2)
        opts = self.options
        lines = [
            f"CRASH3, {self.units} units, restitution e = {opts.restitution:g}, crush energy "
            f"{opts.energy}, {opts.correction} oblique correction",
            "",
            f"{'':<40}{one.name:>{width}}{two.name:>{width}}",
        ]
        lines += [f"{label:<40}{_cell(a):>{width}}{_cell(b):>{width}}" for label, a, b in rows]
        lines += ["", f"{'total energy [' + energy + ']':<40}{_cell(self.energy_total):>{width}}", ""]
        lines += (
            (["warnings:"] + [f"  - {w}" for w in self.warnings]) if self.warnings else ["warnings: none"]
        )
        return "\n".join(lines)


def crash3(
    scene: Scene | Mapping | str | Path,
    restitution: float | None = None,
    energy: str | None = None,
    correction: str | None = None,
) -> Crash3Result:
    """CRASH3 delta-V of a scene whose moving vehicles carry ``crush`` tables.

    ``restitution`` e (0 ≤ e < 1 dissipated, ≤ 1 absorbed), ``energy``
    (``"dissipated"`` | ``"absorbed"``) and ``correction`` (``"crash3"`` |
    ``"woolley"``) override the scene's ``"crash3"`` options (module
    docstring). A fixed vehicle (a barrier) needs no crush table and absorbs no
    energy. Raises :class:`SceneError` (one line, naming the field) for a bad
    scene, crush table or option.
    """
    data = scene_data(scene)
    parsed = load_scene(data, kind="crash3")
    _check_crush_keys(parsed)
    options = _options(data, restitution, energy, correction)
    geometry = not math.isnan(parsed.impact.normal_angle)
    gamma = math.radians(parsed.impact.normal_angle) if geometry else 0.0
    crush = [
        None if v.fixed else _parse_crush(v.extra["crush"], f"vehicles[{i}].crush", parsed.units)
        for i, v in enumerate(parsed.vehicles)
    ]
    energies = [
        _energy(c, parsed.units, f"vehicles[{i}].crush", options.correction) if c else (0.0, 0.0, False)
        for i, c in enumerate(crush)
    ]
    alphas = [math.radians(c.pdof) if c else 0.0 for c in crush]
    values = {
        "E": energies[0][1] + energies[1][1],
        "e": options.restitution,
        "gamma": gamma,
        "alpha1": alphas[0],
        "alpha2": alphas[1],
    }
    for number, (vehicle, c) in enumerate(zip(parsed.vehicles, crush), start=1):
        values[f"m{number}"] = math.inf if vehicle.fixed else vehicle.mass
        values[f"rg{number}"] = _radius_of_gyration(vehicle, c, parsed.units)
        values[f"h{number}"] = _moment_arm(data, vehicle, c, gamma, geometry, number - 1)
    out = _run(DELTA_V_KERNELS[options.energy], values, "cannot compute the CRASH3 delta-V")
    implied = _implied(data, options.restitution) if geometry else None
    vehicles = tuple(
        _vehicle(v, c, energies[i], out, values, i + 1, implied, geometry)
        for i, (v, c) in enumerate(zip(parsed.vehicles, crush))
    )
    warnings = (
        _capped(crush, energies, options.correction)
        + _warnings(vehicles, crush, implied)
        + list(parsed.warnings)
    )
    return Crash3Result(parsed.units, options, vehicles, values["E"], out["P"], warnings)


def crash3_options(
    scene: Scene | Mapping | str | Path,
    restitution: float | None = None,
    energy: str | None = None,
    correction: str | None = None,
) -> Crash3Options:
    """The CRASH3 options of a scene (its ``"crash3"`` object) overridden by
    the arguments given (not None), checked as :func:`crash3` checks them."""
    return _options(scene_data(scene), restitution, energy, correction)


def _options(data: Mapping, restitution, energy, correction) -> Crash3Options:
    """The scene's ``"crash3"`` options overridden by the arguments given (not None)."""
    table = as_mapping(data.get("crash3", {}), "crash3")
    for key in table:
        if key not in OPTION_KEYS:
            raise SceneError(f"unknown CRASH3 option (use {', '.join(OPTION_KEYS)})", f"crash3.{key}")
    given = {"restitution": restitution, "energy": energy, "correction": correction}
    pick = {k: (v if v is not None else table.get(k)) for k, v in given.items()}
    where = {k: (k if given[k] is not None else f"crash3.{k}") for k in given}
    mode = _word(pick["energy"], where["energy"], ENERGY_MODES, "dissipated")
    return Crash3Options(
        restitution=_restitution(pick["restitution"], where["restitution"], mode),
        energy=mode,
        correction=_word(pick["correction"], where["correction"], CORRECTIONS, "crash3"),
    )


def _word(value: Any, path: str, allowed: tuple[str, ...], default: str) -> str:
    """An option that is one of `allowed` (None: the default)."""
    if value is None:
        return default
    if value not in allowed:
        raise SceneError(f"must be one of {', '.join(allowed)}, got {_short(value)}", path)
    return value


def _restitution(value: Any, path: str = "restitution", energy: str = "dissipated") -> float:
    """CRASH3's restitution: 0 ≤ e < 1 when the energy is dissipated (e = 1 would
    dissipate nothing), 0 ≤ e ≤ 1 when it is absorbed to maximum crush."""
    if value is None:
        return 0.0
    e = as_number(value, path)
    if energy == "dissipated" and not 0.0 <= e < 1.0:
        raise SceneError(f"must be in [0, 1) when the crush energy is dissipated, got {e:g}", path)
    if not 0.0 <= e <= 1.0:
        raise SceneError(f"must be in [0, 1], got {e:g}", path)
    return e


def _parse_crush(raw: Any, path: str, units: str = "SI") -> Crush:
    """Validate a ``crush`` table; each bad entry is an error naming its field and
    the rule it breaks (the kernels check the ranges again)."""
    data = as_mapping(raw, path)
    for key in ("width", "depths", "pdof"):
        if key not in data:
            raise SceneError("missing", f"{path}.{key}")
    a, b = _stiffness(data, path, units)
    depths = data["depths"]
    if not isinstance(depths, list) or len(depths) not in PROFILE_SIZES:
        raise SceneError(f"must be a list of 2, 4 or 6 crush depths, got {_short(depths)}", f"{path}.depths")
    crush_depths = tuple(as_number(c, f"{path}.depths[{i}]") for i, c in enumerate(depths))
    for i, c in enumerate(crush_depths):
        if c < 0.0:
            raise SceneError(f"must be >= 0 (a crush depth), got {c:g}", f"{path}.depths[{i}]")
    width = as_number(data["width"], f"{path}.width")
    if width <= 0.0:
        raise SceneError(f"must be > 0 (the damage width), got {width:g}", f"{path}.width")
    pdof = as_number(data["pdof"], f"{path}.pdof")
    if abs(pdof) >= PDOF_LIMIT_DEG:
        raise SceneError(
            f"|pdof| = {abs(pdof):g} must be < {PDOF_LIMIT_DEG:g} degrees from the "
            "inward normal of the damaged face (the force must push the face in)",
            f"{path}.pdof",
        )
    optional = {}
    if "moment_arm" in data:
        optional["moment_arm"] = as_number(data["moment_arm"], f"{path}.moment_arm")
    if "radius_of_gyration" in data:
        optional["radius_of_gyration"] = as_positive(data["radius_of_gyration"], f"{path}.radius_of_gyration")
    if "class" in data:
        if data["class"] not in CLASSES:
            raise SceneError(
                f"must be one of {', '.join(map(str, CLASSES))}, got {_short(data['class'])}", f"{path}.class"
            )
        optional["vehicle_class"] = data["class"]
    return Crush(A=a, B=b, width=width, depths=crush_depths, pdof=pdof, **optional)


def _stiffness(data: Mapping, path: str, units: str) -> tuple[float, float]:
    """(A, B) in the scene's units: given, or the category default for the face."""
    explicit = [k for k in ("A", "B") if k in data]
    by_category = [k for k in ("category", "face") if k in data]
    if explicit and by_category:
        raise SceneError(
            f"give either A and B or category and face, not both ({explicit[0]} and {by_category[0]})",
            f"{path}.{by_category[0]}",
        )
    if by_category:
        for key in ("category", "face"):
            if key not in data:
                raise SceneError(f"missing (category needs face: {', '.join(FACES)})", f"{path}.{key}")
        category, face = data["category"], data["face"]
        if isinstance(category, bool) or not isinstance(category, int) or not 1 <= category <= 9:
            raise SceneError(f"must be an integer 1-9, got {_short(category)}", f"{path}.category")
        if face not in FACES:
            raise SceneError(f"must be one of {', '.join(FACES)}, got {_short(face)}", f"{path}.face")
        try:
            table = stiffness(category, face, units)
        except ValueError as exc:
            raise SceneError(str(exc), f"{path}.face") from None
        return table.A, table.B
    for key in ("A", "B"):
        if key not in data:
            raise SceneError("missing (give A and B, or category and face)", f"{path}.{key}")
    a, b = as_number(data["A"], f"{path}.A"), as_number(data["B"], f"{path}.B")
    if a < 0.0:
        raise SceneError(f"must be >= 0 (the force per unit width at zero crush), got {a:g}", f"{path}.A")
    if b <= 0.0:
        raise SceneError(
            f"must be > 0 (the slope of force per unit width against crush), got {b:g}", f"{path}.B"
        )
    return a, b


def _energy(crush: Crush, units: str, path: str, correction: str) -> tuple[float, float, bool]:
    """(crush energy, corrected energy, capped) in the scene's energy unit."""
    values = {"A": crush.A, "B": crush.B, "width": crush.width, "alpha": math.radians(crush.pdof)}
    values.update({f"C{i}": c for i, c in enumerate(crush.depths, start=1)})
    ks = _kernels.CRASH3_ENERGY[len(crush.depths)]
    out = _kernels.run_one(ks, values, ks.outputs)
    if out["status"]:
        raise SceneError(describe_status(out["status"]), path)
    factor = ENERGY_FACTOR[units]
    return (
        out["E_crush"] * factor,
        out[CORRECTED_OUTPUT[correction]] * factor,
        bool(out["flags"] & FLAG_PDOF_CAPPED),
    )


def _capped(crush, energies, correction: str) -> list[str]:
    """A warning per vehicle whose oblique correction was capped (EDCRASH)."""
    cap = {"crash3": "1 + tan^2(alpha) <= 2", "woolley": "1/cos(alpha) <= sqrt(2)"}[correction]
    return [
        f"vehicles[{i}].crush.pdof = {c.pdof:g} degrees: the oblique correction is capped at "
        f"{PDOF_CAP_DEG:g} degrees ({cap}), as EDCRASH does"
        for i, (c, energy) in enumerate(zip(crush, energies))
        if c is not None and energy[2]
    ]


def _radius_of_gyration(vehicle: Vehicle, crush: Crush | None, units: str = "SI") -> float:
    """k [m | ft]: given, from the yaw inertia, from the class default k², or inf
    (no rotation: γ = 1)."""
    if crush is None:
        return math.inf
    if crush.radius_of_gyration is not None:
        return crush.radius_of_gyration
    if vehicle.yaw_inertia is None:
        if crush.vehicle_class is None:
            return math.inf
        return math.sqrt(class_dimensions(crush.vehicle_class)["k_squared_in2"]) / _INCHES_PER_LENGTH[units]
    out = _run(
        _kernels.CRASH3_RADIUS_OF_GYRATION,
        {"mass": vehicle.mass, "inertia": vehicle.yaw_inertia},
        "radius of gyration",
    )
    return out["rg"]


def _moment_arm(
    data: Mapping, vehicle: Vehicle, crush: Crush | None, gamma: float, geometry: bool, index: int
) -> float:
    """h [m | ft]: given, from the impact point and the PDOF (needs the impact
    block), or 0."""
    if crush is None:
        return 0.0
    if crush.moment_arm is not None:
        return crush.moment_arm
    if not geometry:
        if "impact_point" in data["vehicles"][index]:
            raise SceneError(
                "missing: the moment arm from vehicles[{index}].impact_point needs the "
                "crush-surface angle (or give crush.moment_arm)".replace("{index}", str(index)),
                "impact.normal_angle",
            )
        return 0.0
    rx, ry = vehicle.impact_point
    out = _run(
        _kernels.CRASH3_MOMENT_ARM,
        {"rx": rx, "ry": ry, "theta": gamma + math.radians(crush.pdof)},
        "moment arm",
    )
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
    variant = {
        **data,
        "model": "rigid",
        "impact": {
            "normal_angle": data["impact"]["normal_angle"],
            "restitution": e,
            "impulse_ratio": "critical",
            "moment_restitution": 1.0,
        },
    }
    try:
        result = solve(variant)
    except SceneError:
        return None
    out = _run(_kernels.CRASH3_IMPLIED_PDOF, {"Pn": result.Pn, "Pt": result.Pt}, "implied PDOF")
    return {
        "pdof": math.degrees(out["pdof"]),
        "mu_c": result.mu_c,
        "delta_v": [v.delta_v_magnitude for v in result.vehicles],
    }


def _vehicle(
    vehicle: Vehicle,
    crush: Crush | None,
    energy,
    out,
    values,
    number: int,
    implied: dict | None,
    geometry: bool = True,
) -> Crash3Vehicle:
    """Vehicle ``number``'s result from its energies, the delta-V kernel's output and
    the implied impulse-momentum solution (a fixed vehicle: zero energy and delta-V)."""
    return Crash3Vehicle(
        name=vehicle.name,
        crush_energy=energy[1],
        crush_energy_uncorrected=energy[0],
        pdof=crush.pdof if crush else 0.0,
        mass_factor=out[f"mass_factor{number}"],
        moment_arm=values[f"h{number}"],
        delta_v=(out[f"dV{number}x"], out[f"dV{number}y"]) if geometry else None,
        delta_v_magnitude=out[f"dV{number}"],
        delta_v_effective_mass=out[f"dV{number}_eff"],
        pdof_implied=None if implied is None or vehicle.fixed else implied["pdof"],
        delta_v_magnitude_impulse_momentum=None if implied is None else implied["delta_v"][number - 1],
    )


def _warnings(vehicles, crush, implied: dict | None) -> list[str]:
    """The seed's CRASH3 criticisms, where the scene shows them."""
    warnings = []
    entered = [c.pdof for c in crush if c is not None]
    if len(entered) == 2 and abs(entered[0] - entered[1]) > 1e-9:
        warnings.append(
            f"the entered PDOFs differ ({entered[0]:g} and {entered[1]:g} degrees): "
            "the impulses on the two vehicles are not equal and opposite, so "
            "momentum is not conserved"
        )
    if implied is None:
        return warnings
    if abs(implied["pdof"]) > PDOF_LIMIT_DEG:
        warnings.append(
            f"the impulse-momentum solution's PDOF ({implied['pdof']:.1f} degrees) "
            "is beyond CRASH3's 45-degree limit: a sideswipe-like impact, which "
            "CRASH3 cannot model (seed)"
        )
    for index, (vehicle, c) in enumerate(zip(vehicles, crush)):
        if c is not None and abs(c.pdof - implied["pdof"]) > PDOF_MISMATCH_DEG:
            warnings.append(
                f"vehicles[{index}] ({vehicle.name}): PDOF entered {c.pdof:g} degrees, but the "
                f"common velocity CRASH3 assumes for |delta-V| (mu = mu_c = {implied['mu_c']:.3g}) "
                f"implies {implied['pdof']:.1f} degrees: CRASH3 takes |delta-V| from mu = mu_max "
                "and its direction from the entered PDOF (seed)"
            )
    return warnings


def _check_crush_keys(scene: Scene) -> None:
    """An unknown key of a crush table (a likely typo) is an error naming it, with
    the nearest known key, as everywhere else in a scene."""
    for i, vehicle in enumerate(scene.vehicles):
        if "crush" in vehicle.extra:
            check_keys(vehicle.extra["crush"], CRUSH_KEYS, f"vehicles[{i}].crush")


def _cell(value: float | None) -> str:
    """A table cell: six significant digits, or n/a."""
    return "n/a" if value is None else f"{value + 0.0:.6g}"


def _short(value: Any) -> str:
    """A value shortened for a one-line error message."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def crush_tables(scene: Scene | Mapping | str | Path) -> tuple[Crush | None, ...]:
    """Each vehicle's validated ``crush`` table (None for a fixed body), as
    :func:`crash3` reads them (for the CRASH3 diagram of :mod:`impactsym.pictures.crash3`)."""
    parsed = load_scene(scene_data(scene), kind="crash3")
    return tuple(
        None if v.fixed else _parse_crush(v.extra["crush"], f"vehicles[{i}].crush", parsed.units)
        for i, v in enumerate(parsed.vehicles)
    )
