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
from .fit import determination, fit_rest
from .scene import FT, RunoutScene, RunoutVehicle, load_runout, row_values

PATH_POINTS = 100_000
# A rest pose read from a scene plan is rarely better than READING (0.1 m of
# position, 1 degree of heading). A fitted separation quantity that such a
# misreading moves by more than LOOSE (speed m/s, direction deg, yaw rate
# rad/s) is named in the warnings as loosely determined by the rest pose.
READING = (0.1, 1.0)
LOOSE = {"speed": 1.0, "direction": 10.0, "yaw_rate": 0.5}


def runout(
    scene,
    path: bool = False,
    tol: float | None = None,
    exhaustive: bool = False,
    speed_max: float | None = None,
    yaw_rate_max: float | None = None,
) -> dict:
    """The run-out of every vehicle of `scene` (path, mapping or Scene):
    ``{"vehicles": [...], "warnings": [...]}`` (conventions.md). With `path`,
    each entry also holds ``"path": [[t, x, y, psi_deg], ...]``. With
    `exhaustive`, each fitted vehicle's fit also runs the grid search over
    separation speeds up to `speed_max` (scene units per second) and yaw rates
    up to `yaw_rate_max` (rad/s), each by default fit.py's `plausible_range`;
    its entry's ``fit.search`` says what was searched and what was found."""
    sc = scene if isinstance(scene, RunoutScene) else load_runout(scene)
    warnings = list(sc.warnings)
    grid = _grid_options(sc, exhaustive, speed_max, yaw_rate_max, warnings)
    entries = [_vehicle(sc, v, i, path, tol, warnings, grid) for i, v in enumerate(sc.vehicles)]
    return {"units": sc.units, "vehicles": entries, "warnings": warnings}


def _grid_options(sc: RunoutScene, exhaustive: bool, speed_max, yaw_rate_max, warnings: list) -> dict:
    """`fit_rest`'s grid-search keywords (SI) from `runout`'s; a range given
    without `exhaustive`, or not a positive number, is refused naming it."""
    given = {"speed_max": speed_max, "yaw_rate_max": yaw_rate_max}
    for name, value in given.items():
        if value is None:
            continue
        if not exhaustive:
            raise SceneError("only applies to the grid search (exhaustive)", name)
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
            or value <= 0
        ):
            raise SceneError(f"must be a positive number, got {value!r}", name)
    if exhaustive and not any(v.fitted for v in sc.vehicles):
        warnings.append("exhaustive: no vehicle has its separation state fitted; nothing was searched")
    length = sc.length()
    return {
        "exhaustive": exhaustive,
        "speed_max": None if speed_max is None else speed_max * length,
        "yaw_rate_max": yaw_rate_max,
    }


def _vehicle(
    sc: RunoutScene, v: RunoutVehicle, index: int, path: bool, tol, warnings: list, grid: dict
) -> dict:
    length = sc.length()
    fit = None
    if v.fitted:
        fit = fit_rest(v, tol, **grid)
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
    if v.row.get("h", 0.0) > 0.0:  # the model used: quasi-static load transfer
        entry["cg_height"] = v.row["h"] / length
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
        if fit.alternatives:
            entry["fit"]["alternatives"] = [
                {
                    "velocity": [alt.velocity[0] / length, alt.velocity[1] / length],
                    "speed": math.hypot(*alt.velocity) / length,
                    "yaw_rate": alt.yaw_rate,
                }
                for alt in fit.alternatives
            ]
        if fit.grid is not None:
            states = 1 + len(fit.alternatives) if fit.converged else 0
            entry["fit"]["search"] = fit.grid.summary(length) | {"states": states}
        D = determination(v, fit)
        if D is not None:
            entry["fit"]["determination"] = _determination(D, vx, vy, length)
            warnings.extend(_loose(entry["fit"]["determination"], sc, index, v.name, length))
    elif residual:
        entry["residual"] = residual
    if path:
        entry["path"] = [[p[0], p[1] / length, p[2] / length, math.degrees(p[3])] for p in pts]
    return entry


def _determination(D, vx: float, vy: float, length: float) -> dict:
    """The fit's `determination`: how much the fitted separation speed [scene
    length/s], direction [deg] and yaw rate [rad/s] move per scene length unit
    of rest position (in its worst direction) and per degree of rest heading,
    from D = d(vx, vy, w)/d(x, y, psi)_rest (SI, `fit.determination`). Speed
    and direction are None for a fitted state without translation."""
    speed = math.hypot(vx, vy)
    rows = {"yaw_rate": D[2]}
    if speed > 0.0:
        rows["speed"] = (vx * D[0] + vy * D[1]) / speed
        rows["direction"] = (vx * D[1] - vy * D[0]) / speed**2
    # per scene unit of position: length metres; a speed in scene units is SI / length
    position = {"speed": 1.0, "direction": math.degrees(length), "yaw_rate": length}
    heading = {"speed": math.radians(1.0) / length, "direction": 1.0, "yaw_rate": math.radians(1.0)}
    return {
        "per_position": {k: _per(rows, k, position, slice(0, 2)) for k in LOOSE},
        "per_heading": {k: _per(rows, k, heading, slice(2, 3)) for k in LOOSE},
    }


def _per(rows: dict, key: str, unit: dict, cols: slice) -> float | None:
    return float(math.hypot(*rows[key][cols]) * unit[key]) if key in rows else None


def reading(units: str) -> float:
    """READING's position in scene length units (0.1 m, or 0.33 ft)."""
    return READING[0] / (FT if units == "US" else 1.0)


def misreading(determination: dict, units: str) -> dict:
    """Per fitted quantity (speed [scene length/s], direction [deg], yaw rate
    [rad/s]): (how far a rest position READING[0] metres off moves it, how far
    a rest heading READING[1] degrees off does), from the fit's
    `determination`; None where the fitted state has no direction."""
    return {
        key: None
        if determination["per_position"][key] is None
        else (
            determination["per_position"][key] * reading(units),
            determination["per_heading"][key] * READING[1],
        )
        for key in LOOSE
    }


def _loose(d: dict, sc: RunoutScene, index: int, name: str, length: float) -> list[str]:
    """Warnings for the fitted quantities a rest pose misread by READING moves by more than LOOSE."""
    units = {"speed": f"{_unit(sc)}/s", "direction": "deg", "yaw_rate": "rad/s"}
    out = []
    for key, moves in misreading(d, sc.units).items():
        if moves is not None and max(moves) * (length if key == "speed" else 1.0) > LOOSE[key]:
            out.append(
                f"vehicles[{index}] ({name}): the rest pose determines the separation {key.replace('_', ' ')} "
                f"only loosely: {reading(sc.units):.2g} {_unit(sc)} of rest position moves it by "
                f"{moves[0]:.2g} {units[key]}, {READING[1]:g} deg of rest heading by {moves[1]:.2g} {units[key]}"
            )
    return out


def _unit(sc: RunoutScene) -> str:
    return "ft" if sc.units == "US" else "m"
