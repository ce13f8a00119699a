"""A ``rest`` evidence item: a vehicle's rest pose, read through its run-out.

``{"vehicle": k, "quantity": "rest", "value": {"position": [x, y], "heading": deg},
"sd": {"position": σ_p, "heading": σ_ψ}}`` with the scene's top-level ``runout``
block and the vehicle's run-out data (``wheelbase``, ``cg_to_front_axle``,
``track``, ``wheels``, optionally ``separation.position`` / ``.heading`` and
``friction``; conventions.md, "Post-impact run-out").

The run-out's separation state p = (V_kx, V_ky, W_k) is fitted to the rest pose
R (impactsym.runout.fit_rest). To first order dp = J⁻¹ dR, J = dR/dp the exact
sensitivity the run-out kernel integrates (runout.interval.separation_sensitivity),
so p is observed with covariance C = J⁻¹ diag(σ_p², σ_p², σ_ψ²) J⁻ᵀ. p is linear
in the fit's unknowns; the three correlated observations are whitened with the
Cholesky factor C = L Lᵀ in its unit-lower form: observation i is
(L_ii L⁻¹)_i · p with sd L_ii, i.e. V_kx, then V_ky given V_kx, then W_k given
both (the sum of the squared residuals is the full-covariance one). The
linearisation is at the fitted separation state: the run-out's own
nonlinearity over the rest pose's spread is not propagated (nor is friction).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

import numpy as np

from ..errors import SceneError, show_value
from ..runout import fit_rest, load_runout
from ..runout.fit import newton
from ..runout.interval import separation_sensitivity
from ..scene.casefile import LeafReader, check_keys
from .items import Observation, vehicle_index

#: A fit vehicle's keys that only a rest item reads (the run-out's chassis and tyres).
RUNOUT_VEHICLE_KEYS = ("wheelbase", "cg_to_front_axle", "track", "wheels", "separation", "friction")
POSE_KEYS = ("position", "heading")
NONLINEAR = 0.2  # sd of the separation state: a linearisation departing more is named
LABELS = ("Vx", "Vy given Vx", "W given Vx, Vy")  # V_kx, V_ky, W_k decorrelated in turn


def rest_observations(item: Mapping, k: int, data: Mapping, case_values, warnings: list) -> list[Observation]:
    """The three whitened observations of rest item `k` (module docstring).
    `case_values` = (units, names, fixed, params) of the fit case (scene
    units, radians); fit warnings are appended to `warnings`."""
    units, names, fixed, params = case_values
    path = f"evidence[{k}]"
    if "at" in item:
        raise SceneError("only delta_v_longitudinal and delta_v_lateral are read at a module", f"{path}.at")
    i = vehicle_index(item.get("vehicle"), names, f"{path}.vehicle")
    if fixed[i]:
        raise SceneError("vehicle is fixed: it has no run-out", f"{path}.vehicle")
    leaves = LeafReader(units)
    pose = _pose(item.get("value"), f"{path}.value", leaves, "value")
    sd = _pose(item.get("sd"), f"{path}.sd", leaves, "sd")
    vehicle = _runout_vehicle(data, i, pose, params)
    fit = fit_rest(vehicle)
    length = 0.3048 if units == "US" else 1.0
    label = f"vehicles[{i}].rest"
    if not fit.converged:
        warnings.append(
            f"{path} ({label}): the run-out fit to the rest pose did not converge in {fit.iterations} "
            f"iterations (residual {fit.residual_position / length:.3g} {_unit(units)}, "
            f"{math.degrees(fit.residual_heading):.3g} deg); its observations are where it stopped"
        )
    for alt in fit.alternatives:
        warnings.append(
            f"{path} ({label}): another separation state reaches the same rest pose: velocity "
            f"[{alt.velocity[0] / length:.3f}, {alt.velocity[1] / length:.3f}] {_unit(units)}/s, yaw rate "
            f"{alt.yaw_rate:.3f} rad/s (used: the one nearest the run-out's starting estimate)"
        )
    sigma = np.array([sd[0] * length, sd[1] * length, math.radians(sd[2])])  # SI, rad
    spread_si = _spread(vehicle, fit, sigma, path)
    spread = spread_si / np.array([length, length, 1.0])[:, None]  # scene units
    cov = spread @ spread.T
    p = np.array([fit.velocity[0] / length, fit.velocity[1] / length, fit.yaw_rate])
    try:
        chol = np.linalg.cholesky((cov + cov.T) / 2)
    except np.linalg.LinAlgError:
        raise SceneError(
            "the rest pose does not fix the separation state (singular covariance)", path
        ) from None
    departure = _nonlinearity(vehicle, fit, sigma, spread_si, chol * np.array([length, length, 1.0])[:, None])
    if departure > NONLINEAR:
        warnings.append(
            f"{path} ({label}): the run-out is not linear over the rest pose's sd (refitted at +-1 sd the "
            f"separation state is {departure:.2g} sd from the linear prediction): the item's observations "
            "are linearised at the fitted state, so the intervals it drives are too narrow; the rest "
            "pose's sd may be too large for it"
        )
    unit_lower = np.diag(np.diag(chol)) @ np.linalg.inv(chol)  # rows: 1 on the diagonal
    n = i + 1
    outputs = (f"V{n}x", f"V{n}y", f"W{n}")
    return [
        Observation(
            k,
            f"{label}: {LABELS[j]}",
            float(unit_lower[j] @ p),
            float(chol[j, j]),
            ("combination", tuple((float(unit_lower[j, m]), outputs[m]) for m in range(j + 1))),
        )
        for j in range(3)
    ]


def _spread(vehicle, fit, sigma, path: str) -> np.ndarray:
    """3 x 3: column j is the change of the separation state (SI) per sd of
    rest coordinate j (sigma: SI and rad), J^-1 sigma_j from the exact
    sensitivities at the fitted state."""
    try:
        inverse = separation_sensitivity(vehicle, fit)[:, :3]  # d(vx, vy, w)/d(x, y, psi)_rest, SI
    except (ValueError, np.linalg.LinAlgError):
        raise SceneError(
            "the run-out at the fitted separation state has no invertible sensitivity to it", path
        ) from None
    return inverse * sigma


def _nonlinearity(vehicle, fit, sigma, spread, chol_si) -> float:
    """The largest departure, in standard deviations of the separation state
    (whitened by its Cholesky factor, SI), of the state refitted to the rest
    pose moved by +-1 sd of each coordinate from the linear prediction
    p +- J^-1 sigma_j: how far the run-out is from linear over the rest
    pose's spread (Newton from the fitted state, runout.fit.newton)."""
    start = (*fit.velocity, fit.yaw_rate)
    p0 = np.array(start)
    worst = 0.0
    for j in range(3):
        for sign in (1.0, -1.0):
            rest = list(vehicle.rest)
            rest[j] += sign * sigma[j]
            moved = newton(dataclasses.replace(vehicle, rest=tuple(rest)), start)
            if not moved.converged:
                return math.inf
            error = np.array([*moved.velocity, moved.yaw_rate]) - p0 - sign * spread[:, j]
            worst = max(worst, float(np.linalg.norm(np.linalg.solve(chol_si, error))))
    return worst


def _pose(raw, path: str, leaves: LeafReader, what: str) -> tuple[float, float, float]:
    """(x, y, heading) of a rest value, or (σ_p, σ_p, σ_ψ) of its sd (scene
    length unit, degrees as given)."""
    if raw is None:
        hint = "(every evidence item needs its standard deviation)" if what == "sd" else ""
        raise SceneError(f"missing {hint}".strip(), path)
    if not isinstance(raw, Mapping):
        form = '{"position": sd, "heading": sd}' if what == "sd" else '{"position": [x, y], "heading": deg}'
        raise SceneError(f"must be {form}, got {show_value(raw)}", path)
    check_keys(raw, POSE_KEYS, path)
    for key in POSE_KEYS:
        if key not in raw:
            raise SceneError("missing", f"{path}.{key}")
    if what == "sd":
        sigma = leaves.number(raw["position"], f"{path}.position", "length", "positive")
        return (sigma, sigma, leaves.number(raw["heading"], f"{path}.heading", "angle", "positive"))
    position = raw["position"]
    if not isinstance(position, list) or len(position) != 2:
        raise SceneError(f"must be [x, y], got {show_value(position)}", f"{path}.position")
    x, y = (leaves.number(c, f"{path}.position[{j}]", "length") for j, c in enumerate(position))
    return (x, y, leaves.number(raw["heading"], f"{path}.heading", "angle"))


def _runout_vehicle(data: Mapping, i: int, pose, params: dict):
    """Vehicle i's run-out (impactsym.runout.load_runout) with the fit's mass,
    inertia, heading and impact point (scene units) and the rest pose `pose`."""
    if "runout" not in data:
        raise SceneError("missing (a rest item needs the run-out's tyre data)", "runout")
    entry = data["vehicles"][i]
    path = f"vehicles[{i}]"
    for key in ("wheelbase", "cg_to_front_axle", "track", "wheels"):
        if key not in entry:
            raise SceneError("missing (a rest item of this vehicle needs its run-out data)", f"{path}.{key}")
    separation = entry.get("separation", {})
    if isinstance(separation, Mapping):
        for key in ("velocity", "yaw_rate", "mark_directions"):
            if key in separation:
                raise SceneError(
                    "not read by fit: the rest item fits the separation state (give it as final_velocity, "
                    "final_yaw_rate or final_direction evidence)",
                    f"{path}.separation.{key}",
                )
    n = i + 1
    vehicle = {key: entry[key] for key in RUNOUT_VEHICLE_KEYS if key in entry}
    vehicle |= {
        "name": str(entry.get("name", f"vehicle {n}")),
        "mass": params[f"m{n}"],
        "yaw_inertia": params[f"I{n}"],
        "heading": math.degrees(params[f"theta{n}"]),
        "impact_point": [params[f"r{n}x"], params[f"r{n}y"]],
        "rest": {"position": [pose[0], pose[1]], "heading": pose[2]},
    }
    scene = {"units": data["units"], "runout": data["runout"], "vehicles": [vehicle]}
    impact = data.get("impact", {})
    if isinstance(impact, Mapping) and "position" in impact:
        scene["impact"] = {"position": impact["position"]}
    try:
        return load_runout(scene).vehicles[0]
    except SceneError as exc:  # the run-out reader names vehicles[0]: name the fit's vehicle
        field = exc.field or ""
        message = str(exc)[len(field) + 2 :] if field else str(exc)
        raise SceneError(message, field.replace("vehicles[0]", path, 1) or None) from None


def _unit(units: str) -> str:
    return "ft" if units == "US" else "m"
