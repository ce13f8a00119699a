"""The inverse problem: pre-impact motion from post-impact motion (seed ref. [21]).

Given the final velocities and yaw rates and the coefficients e, μ, e_m, the six
equations fix the initial motion in one step. e = 0 erases the normal approach
speed and e_m = 0 the initial relative yaw rate: such scenes are refused with a
status (batch) or a SceneError (one scene) that says what would fix it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

from . import _kernels
from ._kernels import STATUS_NOT_APPROACHING
from .batch import run_columns
from .codes import describe_flags, describe_status
from .result import Result, VehicleResult, scene_warnings
from .scene import Scene, SceneError, load_scene
from .single import overflow_error

_HINTS = {
    STATUS_NOT_APPROACHING: "for e > 0 the final velocities must separate at the impact centre, "
    "n·(U2 - U1) > 0; check impact.normal_angle and the final velocities",
}


def invert_batch(columns, model: str = "rigid"):
    """Pre-impact motion for one scene per row.

    `columns` holds ``m1 m2 I1 I2 V1x V1y W1 V2x V2y W2 r1x r1y r2x r2y gamma e
    mu e_m`` (particles: ``m1 m2 V1x V1y V2x V2y gamma e mu``), float64 arrays or
    scalars, units as in `solve_batch` (the normal angle ``gamma`` in RADIANS:
    degrees given by mistake give a wrong result and no flag; columns checked
    as strictly as there). Returns ``v1x v1y w1 v2x v2y w2 Pn Pt M
    mu_c TL TLn TLt TLm status flags``; status 7 (e too small) and 8 (e_m too
    small) mark rows whose finals do not determine the initials.
    """
    everywhere = tuple(
        c for name in _kernels.INVERSE_MODELS for c in _kernels.inverse_kernel_for(name).inputs
    )
    return run_columns(
        _kernels.inverse_kernel_for(model),
        columns,
        _kernels.INVERSE_OUTPUTS,
        f"the {model} model",
        everywhere,
    )


def invert(scene: Scene | Mapping | str | Path) -> Result:
    """Pre-impact motion of an inverse scene (vehicles give ``final_velocity``
    and ``final_yaw_rate``). The Result's vehicle velocities and yaw rates are
    the INITIAL ones; delta-V is final minus initial."""
    scene = load_scene(scene, kind="inverse")
    values = _inputs(scene)
    out = _kernels.run_one(_kernels.inverse_kernel_for(scene.family), values, _kernels.INVERSE_OUTPUTS)
    if out["status"] != 0:
        overflow = overflow_error(scene, out["status"])
        if overflow:
            raise overflow
        hint = _HINTS.get(out["status"])
        reason = f"cannot invert the scene: {describe_status(out['status'])}"
        raise SceneError(f"{reason}; {hint}" if hint else reason)
    flags = out["flags"]
    return Result(
        model=scene.model,
        units=scene.units,
        critical=False,
        vehicles=tuple(_vehicle(v, out, values, i) for i, v in enumerate(scene.vehicles, 1)),
        Pn=out["Pn"],
        Pt=out["Pt"],
        M=out["M"],
        mu=scene.impact.impulse_ratio,
        mu_c=out["mu_c"],
        TL=out["TL"],
        TLn=out["TLn"],
        TLt=out["TLt"],
        TLm=out["TLm"],
        flags=flags,
        warnings=describe_flags(flags) + scene_warnings(scene),
        direction="inverse",
    )


def _inputs(scene: Scene) -> dict:
    """Kernel inputs of an inverse scene: the forward inputs with the finals."""
    _, _, values = scene.to_inputs()
    for number, vehicle in enumerate(scene.vehicles, start=1):
        final = (0.0, 0.0) if vehicle.fixed else vehicle.extra["final_velocity"]
        values[f"V{number}x"], values[f"V{number}y"] = final
        values[f"W{number}"] = float(vehicle.extra.get("final_yaw_rate", 0.0))
    return values


def _vehicle(vehicle, out, values, number: int) -> VehicleResult:
    initial = (out[f"v{number}x"], out[f"v{number}y"])
    delta = (values[f"V{number}x"] - initial[0], values[f"V{number}y"] - initial[1])
    return VehicleResult(
        name=vehicle.name,
        velocity=initial,
        yaw_rate=out[f"w{number}"],
        delta_v=delta,
        delta_v_magnitude=math.hypot(*delta),
    )
