"""Reading CRASH3's inputs: the options, each vehicle's ``crush`` table
(profile, stiffness from coefficients or category, PDOF), and what it gives:
crush energy with its PDOF correction, radius of gyration and moment arm."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .. import _kernels
from .._kernels import FLAG_PDOF_CAPPED
from ..codes import describe_status
from ..scene import Scene, SceneError, Vehicle, load_scene, scene_data
from ..scene.casefile import check_keys
from ..scene.fields import as_mapping, as_number, as_positive
from .model import (
    _INCHES_PER_LENGTH,
    CORRECTED_OUTPUT,
    CORRECTIONS,
    CRUSH_KEYS,
    ENERGY_FACTOR,
    ENERGY_MODES,
    OPTION_KEYS,
    PDOF_CAP_DEG,
    PDOF_LIMIT_DEG,
    PROFILE_SIZES,
    Crash3Options,
    Crush,
)
from .tables import CLASSES, FACES, class_dimensions, stiffness


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


def _check_crush_keys(scene: Scene) -> None:
    """An unknown key of a crush table (a likely typo) is an error naming it, with
    the nearest known key, as everywhere else in a scene."""
    for i, vehicle in enumerate(scene.vehicles):
        if "crush" in vehicle.extra:
            check_keys(vehicle.extra["crush"], CRUSH_KEYS, f"vehicles[{i}].crush")


def crush_tables(scene: Scene | Mapping | str | Path) -> tuple[Crush | None, ...]:
    """Each vehicle's validated ``crush`` table (None for a fixed body), as
    :func:`crash3` reads them (for the CRASH3 diagram of :mod:`impactsym.pictures.crash3`)."""
    parsed = load_scene(scene_data(scene), kind="crash3")
    return tuple(
        None if v.fixed else _parse_crush(v.extra["crush"], f"vehicles[{i}].crush", parsed.units)
        for i, v in enumerate(parsed.vehicles)
    )


def _run(ks: _kernels.KernelSet, values: dict, what: str) -> dict:
    """One row through a kernel; a non-zero status is a SceneError."""
    out = _kernels.run_one(ks, values, ks.outputs)
    if out["status"]:
        raise SceneError(f"{what}: {describe_status(out['status'])}")
    return out


def _short(value: Any) -> str:
    """A value shortened for a one-line error message."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
