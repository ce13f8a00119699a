"""CRASH3 on a scene: crush energy per vehicle, then delta-V through the
kernels, with the warnings a reconstructionist needs (PDOF mismatch, caps)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

from .. import _kernels
from ..scene import Scene, SceneError, Vehicle, load_scene, scene_data
from ..scene.plausibility import crush_energy_warning
from ..single import solve
from .crush import (
    _capped,
    _check_crush_keys,
    _energy,
    _moment_arm,
    _options,
    _parse_crush,
    _radius_of_gyration,
    _run,
)
from .model import DELTA_V_KERNELS, PDOF_LIMIT_DEG, PDOF_MISMATCH_DEG, Crash3Result, Crash3Vehicle, Crush


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
        + crush_energy_warning(values["E"], parsed)
        + list(parsed.warnings)
    )
    return Crash3Result(parsed.units, options, vehicles, values["E"], out["P"], warnings)


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
