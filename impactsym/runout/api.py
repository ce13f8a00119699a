"""`runout(scene)`: each vehicle from separation to rest, as the contract's JSON.

A vehicle with a full separation state runs forward (and, if it also gives
``rest`` or ``intermediate`` poses, reports the residuals against them); one
that gives ``rest`` but no separation velocity and yaw rate has them fitted
(fit.py; its ``intermediate`` poses and tyre-mark directions enter the fit). Results are in the
scene's units, angles in degrees, yaw rates in rad/s.
"""

from __future__ import annotations

import math

from ..errors import SceneError
from . import via
from .batch import columns, run_row, status_text
from .fit import fit_rest
from .scene import RunoutScene, RunoutVehicle, load_runout, row_values

PATH_POINTS = 100_000


def runout(scene, path: bool = False, tol: float | None = None) -> dict:
    """The run-out of every vehicle of `scene` (path, mapping or Scene):
    ``{"vehicles": [...], "warnings": [...]}`` (conventions.md). With `path`,
    each entry also holds ``"path": [[t, x, y, psi_deg], ...]``."""
    sc = scene if isinstance(scene, RunoutScene) else load_runout(scene)
    warnings = list(sc.warnings)
    entries = [_vehicle(sc, v, i, path, tol, warnings) for i, v in enumerate(sc.vehicles)]
    return {"units": sc.units, "vehicles": entries, "warnings": warnings}


def _vehicle(sc: RunoutScene, v: RunoutVehicle, index: int, path: bool, tol, warnings: list) -> dict:
    length = sc.length()
    fit = None
    if v.fitted:
        fit = fit_rest(v, tol)
        if not fit.converged:
            warnings.append(
                f"vehicles[{index}] ({v.name}): the fit to rest did not converge in {fit.iterations} iterations "
                f"(residual {fit.residual_position / length:.3g} {_unit(sc)}, "
                f"{math.degrees(fit.residual_heading):.3g} deg)"
            )
        for alt in fit.alternatives:
            warnings.append(
                f"vehicles[{index}] ({v.name}): another separation state reaches the same rest pose: velocity "
                f"[{alt.velocity[0] / length:.3f}, {alt.velocity[1] / length:.3f}] {_unit(sc)}/s, yaw rate "
                f"{alt.yaw_rate:.3f} rad/s (reported: the one nearest the starting estimate)"
            )
        vx, vy, w = fit.velocity[0], fit.velocity[1], fit.yaw_rate
    else:
        (vx, vy), w = v.velocity, v.yaw_rate
    # One run-out gives the drawn path and, with intermediate poses, their misses
    # (the path then holds each step's whole state: t, x, y, psi, vx, vy, w, distance).
    points = max(PATH_POINTS if path else 0, via.PATH_ROWS if v.via else 0)
    y, t, status, _, pts = run_row(
        row_values(v, columns(), vx, vy, w), tol=tol, path_points=points, path_columns=8 if v.via else 4
    )
    if status != 0:
        raise SceneError(f"the run-out failed: {status_text(status)}", f"vehicles[{index}]")
    entry = {
        "name": v.name,
        "rest": {"position": [y[0] / length, y[1] / length], "heading": math.degrees(y[2])},
        "time": t,
        "distance": y[6] / length,
        "rotation": math.degrees(y[2] - v.heading),
        "separation": {
            "position": [v.position[0] / length, v.position[1] / length],
            "heading": round(
                math.degrees(v.heading), 12
            ),  # the given value back, without the radian round trip
            "velocity": [vx / length, vy / length],
            "speed": math.hypot(vx, vy) / length,
            "yaw_rate": w,
        },
    }
    residual = {}
    if v.rest is not None:
        residual["position"] = math.hypot(y[0] - v.rest[0], y[1] - v.rest[1]) / length
        residual["heading"] = abs(math.degrees(y[2] - v.rest[2]))
    if v.via:
        residual["intermediate"] = [
            {"position": d / length} | ({} if a is None else {"heading": math.degrees(a)})
            for d, a in via.misses(v.via, via.residuals(v.via, pts, 1.0, jacobian=False)[0], 1.0)
        ]
    if fit is not None:
        if v.marks:
            names = {"fl": "front_left", "fr": "front_right", "rl": "rear_left", "rr": "rear_right"}
            residual["marks"] = {names[k]: abs(math.degrees(d)) for k, d in zip(v.marks, fit.marks)}
        entry["fit"] = {"residual": residual, "iterations": fit.iterations, "converged": fit.converged}
    elif residual:
        entry["residual"] = residual
    if path:
        entry["path"] = [[p[0], p[1] / length, p[2] / length, math.degrees(p[3])] for p in pts]
    return entry


def _unit(sc: RunoutScene) -> str:
    return "ft" if sc.units == "US" else "m"
