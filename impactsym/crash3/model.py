"""CRASH3's vocabulary: its constants (units of the crush inputs, PDOF limits,
option words) and the frozen results (:class:`Crush`, :class:`Crash3Vehicle`,
:class:`Crash3Result`, :class:`Crash3Options`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .. import _kernels
from ..result import UNIT_LABELS, road_speed_rows

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


def _cell(value: float | None) -> str:
    """A table cell: six significant digits, or n/a."""
    return "n/a" if value is None else f"{value + 0.0:.6g}"
