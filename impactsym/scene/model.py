"""The scene as data: :class:`Vehicle`, :class:`Impact` and :class:`Scene`
(frozen dataclasses in the scene's units and frame) and what they turn into
(kernel inputs, scene-file form). Frame, signs and units: the package
docstring of :mod:`impactsym.scene` and conventions.md."""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    pass
else:
    pass

from .._kernels import PRESETS
from .casefile import Leaf

# Model names a scene may give (generated.presets.PRESETS): the general model
# ("rigid" or "brach"), "particle", and the seed's named models as presets.
MODELS = tuple(PRESETS)
UNITS = ("SI", "US")
CRITICAL = "critical"
KINDS = ("forward", "inverse", "reconstruct", "crash3")
#: Vehicle entries Scene.to_dict leaves out for a kind that does not read them.
_TO_DICT_LEFT_OUT = {"inverse": ("velocity", "yaw_rate"), "reconstruct": ("velocity",)}
#: The command that reads each kind of scene (for "not used" warnings).
COMMAND = {"forward": "solve", "inverse": "invert", "reconstruct": "reconstruct", "crash3": "crash3"}


@dataclass(frozen=True)
class Vehicle:
    """One vehicle at first contact, in the scene's units and frame.

    ``mass`` [kg | slug] and ``yaw_inertia`` [kg·m² | slug·ft²] are ``None``
    when not given (a fixed vehicle, or ``yaw_inertia`` in the particle model).
    ``velocity`` [m/s | ft/s] and ``yaw_rate`` [rad/s] are the initial motion
    (zero by default for a fixed vehicle); ``impact_point`` [m | ft] is the
    vector from the centre of gravity to the impact centre in the scene frame,
    (0, 0) when not needed.  ``fixed`` marks an immovable object (infinite
    mass and inertia).  ``extra`` holds the other keys of the vehicle entry,
    normalised: ``heading`` [deg], ``final_velocity`` (x, y), ``final_yaw_rate``,
    ``length``, ``width``, ``crush`` (its numbers in CRASH3's units).
    """

    name: str
    mass: float | None
    yaw_inertia: float | None
    velocity: tuple[float, float]
    yaw_rate: float = 0.0
    impact_point: tuple[float, float] = (0.0, 0.0)
    fixed: bool = False
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The vehicle entry in plain scene-file form (``None`` entries left out)."""
        entry = {
            "name": self.name,
            "mass": self.mass,
            "yaw_inertia": self.yaw_inertia,
            "velocity": list(self.velocity),
            "yaw_rate": self.yaw_rate,
            "impact_point": list(self.impact_point),
            "fixed": self.fixed,
        }
        entry.update(
            {key: list(value) if isinstance(value, tuple) else value for key, value in self.extra.items()}
        )
        return {key: value for key, value in entry.items() if value is not None}


@dataclass(frozen=True)
class Impact:
    """Impact coefficients.

    ``normal_angle``: Γ in degrees, in the sense used (from vehicle 1 toward
    vehicle 2; :attr:`Scene.warnings` says when the scene gave the other).
    ``restitution``: e.  ``impulse_ratio``: signed μ = Pt/Pn, or ``"critical"``
    for μ = μ_c (no sliding at separation).  ``moment_restitution``: e_m (1
    gives no moment impulse).  ``slip``: IMPAC's sideswipe constraint, the
    fraction of the initial tangential relative velocity at the impact centre
    left at separation.  A coefficient the scene's model fixes holds the fixed
    value (``limpert``: e = 0, ``"critical"``, e_m = 1); one the model does not
    use is ``None``.
    """

    normal_angle: float
    restitution: float | None
    impulse_ratio: float | str | None
    moment_restitution: float | None = 1.0
    slip: float | None = None

    @property
    def critical(self) -> bool:
        """True when the impulse ratio is the critical one."""
        return self.impulse_ratio == CRITICAL

    def to_dict(self) -> dict[str, Any]:
        """The ``impact`` table in scene-file form (unused coefficients left out)."""
        entry = {
            "normal_angle": self.normal_angle,
            "restitution": self.restitution,
            "impulse_ratio": self.impulse_ratio,
            "moment_restitution": self.moment_restitution,
            "slip": self.slip,
        }
        return {
            key: value
            for key, value in entry.items()
            if value is not None and not (isinstance(value, float) and math.isnan(value))
        }


@dataclass(frozen=True)
class Scene:
    """A validated scene: model, units, impact coefficients and two vehicles,
    in the scene's units and frame, at the nominal values of uncertain leaves.

    ``source`` is the file it was read from (``None`` for a dict).  ``extra``
    holds the top-level keys other than the four of the format (``title``,
    ``crash3``, ...; not ``correlations``); ``warnings`` lists what the reader
    should know: keys given but not used by the command, a normal angle turned
    round.  ``kind`` is what the scene was read for (:data:`KINDS`).
    ``leaves`` maps each numeric leaf the command uses to its
    :class:`~impactsym.scene.casefile.Leaf` (scene units, angles in degrees);
    ``correlations`` are ``(path_a, path_b, rho)``; ``data`` is the mapping as
    read (units, alternative forms and distributions included).
    """

    model: str
    units: str
    impact: Impact
    vehicles: tuple[Vehicle, Vehicle]
    source: Path | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    kind: str = "forward"
    leaves: dict[str, Leaf] = field(default_factory=dict, repr=False)
    correlations: tuple[tuple[str, str, float], ...] = ()
    data: Mapping | None = field(default=None, repr=False, compare=False)

    @property
    def uncertain(self) -> tuple[tuple[str, str, tuple[float, ...]], ...]:
        """The uncertain leaves as ``(path, kind, params)``, params in scene
        units (normal: mean, sd; uniform: low, high; triangular: low, mode,
        high; angles in degrees)."""
        return tuple(
            (leaf.path, leaf.kind, leaf.params) for leaf in self.leaves.values() if leaf.kind is not None
        )

    def to_dict(self) -> dict[str, Any]:
        """The scene in plain scene-file form (what :func:`load_scene` reads back):
        numbers in the scene's units, vectors in the scene frame, nominal values."""
        vehicles = [vehicle.to_dict() for vehicle in self.vehicles]
        for entry in vehicles:  # the initial motion is what these kinds compute
            for key in _TO_DICT_LEFT_OUT.get(self.kind, ()):
                entry.pop(key, None)
        data = {
            "model": self.model,
            "units": self.units,
            "impact": self.impact.to_dict(),
            "vehicles": vehicles,
        }
        data.update(self.extra)
        return data

    @property
    def family(self) -> str:
        """The kernel family that solves the scene's model: ``"rigid"``,
        ``"particle"`` or ``"impac_sideswipe"`` (generated.presets.PRESETS)."""
        return PRESETS[self.model]["kernel"]

    @property
    def uses_yaw(self) -> bool:
        """True when the model has yaw rates and lever arms (all but particles)."""
        return uses_yaw(self.model)

    def to_inputs(self) -> tuple[str, bool, dict[str, float]]:
        """Kernel inputs ``(family, critical, values)``.

        ``family`` is the kernel family of the scene's model (a preset such as
        ``limpert`` is the ``rigid`` family with its coefficients fixed).
        ``values`` uses the batch names of ``conventions.md``: ``gamma`` is Γ in
        radians, a fixed vehicle has ``m = I = inf``.  The particle model gets
        only ``m1 m2 v1x v1y v2x v2y gamma e mu``, IMPAC's sideswipe ``slip``
        in place of ``e mu e_m``.  With a critical impulse ratio ``mu`` is a
        placeholder 0.0, which the kernel ignores.
        """
        impact = self.impact
        values = {"gamma": math.radians(impact.normal_angle)}
        if self.family == "impac_sideswipe":
            values["slip"] = impact.slip
        else:
            values["e"] = impact.restitution
            values["mu"] = 0.0 if impact.critical else float(impact.impulse_ratio)
        if self.family == "rigid":
            values["e_m"] = impact.moment_restitution
        for number, vehicle in enumerate(self.vehicles, start=1):
            values.update(vehicle_inputs(vehicle, number, self.uses_yaw))
        return self.family, impact.critical, values


def uses_yaw(model: str) -> bool:
    """True for a model with yaw rates and lever arms (every kernel family but
    the particle one)."""
    return PRESETS[model]["kernel"] != "particle"


def pair(vector) -> tuple[float, float]:
    return float(vector[0]), float(vector[1])


def vehicle_inputs(vehicle: Vehicle, number: int, yaw: bool) -> dict[str, float]:
    """Batch-named inputs of vehicle ``number`` (1 or 2); ``yaw``: with yaw
    inertia, yaw rate and impact point (every model but particles)."""
    values = {
        f"m{number}": math.inf if vehicle.fixed else vehicle.mass,
        f"v{number}x": vehicle.velocity[0],
        f"v{number}y": vehicle.velocity[1],
    }
    if yaw:
        values[f"I{number}"] = math.inf if vehicle.fixed else vehicle.yaw_inertia
        values[f"w{number}"] = vehicle.yaw_rate
        values[f"r{number}x"] = vehicle.impact_point[0]
        values[f"r{number}y"] = vehicle.impact_point[1]
    return values
