"""Intervals through the run-out: pre-impact speeds from rest poses with
uncertain rest poses and friction.

Linear through the run-out, Monte Carlo through the impact: at the fitted
separation state p of each vehicle the rest pose R(p, mu) satisfies
R(p, mu) = R_measured, so to first order
``dp = J^-1 (dR_measured - S_mu dmu)`` with J = dR/dp and S_mu = dR/dmu, the
sensitivities the kernel integrates with the motion (`separation_sensitivity`).
Draws of the rest poses (independent normal, per vehicle) and of mu (one
normal draw shared by both vehicles: the same road) give draws of the
separation states, which `reconstruct_batch` turns into pre-impact speeds.
Which input drives a speed: the share of its variance when only that input
group varies (rest of vehicle 1, rest of vehicle 2, friction). A scene with
tyre-mark directions or intermediate poses is refused (their least squares is
`reconstruct --uncertainty`'s, uncertain.py).
"""

from __future__ import annotations

import copy
import math

import numpy as np

from ..errors import SceneError
from ..reconstruct import reconstruct_batch
from ..scene import load_scene, scene_columns, scene_data
from .batch import columns, run_row
from .chain import _impact_part
from .fit import Fit, fit_rest
from .scene import RunoutVehicle, load_runout, row_values


def separation_sensitivity(vehicle: RunoutVehicle, fit: Fit) -> np.ndarray:
    """d(vx, vy, w)/d(x_rest, y_rest, psi_rest, mu) at the fitted state (SI, rad), 3 x 4."""
    y, _, status, _, _ = run_row(row_values(vehicle, columns(), *fit.velocity, fit.yaw_rate), sens=True)
    if status != 0:
        raise ValueError("the run-out at the fitted state failed")
    S = y[7:].reshape(6, 4)
    inv = np.linalg.inv(S[:3, :3])
    return np.hstack([inv, -(inv @ S[:3, 3])[:, None]])


def reconstruct_interval(
    scene,
    rest_position_sd: float,
    rest_heading_sd: float,
    friction_sd: float,
    draws: int = 100_000,
    seed: int = 0,
    percentiles=(5.0, 50.0, 95.0),
) -> dict:
    """Pre-impact speeds (scene units) with percentiles from rest poses known to
    ``rest_position_sd`` (scene length unit, per coordinate), ``rest_heading_sd``
    (deg) and friction to ``friction_sd`` (absolute). Returns the nominal fits,
    the percentiles of s1 and s2 and the variance shares of each input group."""
    data = scene_data(scene)
    ro = copy.deepcopy(dict(data))
    for v in ro["vehicles"]:
        v.get("separation", {}).pop("velocity", None)
        v.get("separation", {}).pop("yaw_rate", None)
    rs = load_runout(ro)
    # J^-1 is the rest pose's alone: a least squares over marks or poses is not linearised here
    for i, v in enumerate(rs.vehicles):
        for given, key in ((v.marks, "separation.mark_directions"), (v.via, "intermediate")):
            if given:
                raise SceneError(
                    "not read by the linear interval (reconstruct --uncertainty reads it)",
                    f"vehicles[{i}].{key}",
                )
    length = rs.length()
    fits = [fit_rest(v) for v in rs.vehicles]
    sens = [separation_sensitivity(v, f) for v, f in zip(rs.vehicles, fits)]
    rng = np.random.default_rng(seed)
    position_sd, heading_sd = rest_position_sd * length, math.radians(rest_heading_sd)
    rest = [
        np.column_stack(
            [
                rng.normal(size=draws) * position_sd,
                rng.normal(size=draws) * position_sd,
                rng.normal(size=draws) * heading_sd,
            ]
        )
        for _ in fits
    ]
    mu = rng.normal(size=draws) * friction_sd
    groups = {
        "rest of vehicle 1": (True, False, False),
        "rest of vehicle 2": (False, True, False),
        "friction": (False, False, True),
    }
    impact = _impact_part(data)
    for v, f in zip(impact["vehicles"], fits):
        v["final_velocity"] = [f.velocity[0] / length, f.velocity[1] / length]
        v["final_yaw_rate"] = f.yaw_rate
    base = load_scene(impact, kind="reconstruct")

    def speeds(use):
        over = {}
        for k, (f, A) in enumerate(zip(fits, sens)):
            d = np.column_stack([rest[k] * use[k], mu * use[2]])
            dp = d @ A.T
            over[f"vehicles[{k}].final_velocity[0]"] = (f.velocity[0] + dp[:, 0]) / length
            over[f"vehicles[{k}].final_velocity[1]"] = (f.velocity[1] + dp[:, 1]) / length
            over[f"vehicles[{k}].final_yaw_rate"] = f.yaw_rate + dp[:, 2]
        out = reconstruct_batch(scene_columns(base, over).columns)
        return np.asarray(out["s1"]), np.asarray(out["s2"]), np.asarray(out["status"])

    s1, s2, status = speeds((True, True, True))
    ok = status == 0
    result = {
        "fits": [
            {
                "velocity": [f.velocity[0] / length, f.velocity[1] / length],
                "yaw_rate": f.yaw_rate,
                "converged": f.converged,
            }
            for f in fits
        ],
        "draws": draws,
        "solved": int(ok.sum()),
        "speed_percentiles": {
            "vehicle 1": dict(zip(map(str, percentiles), np.percentile(s1[ok], percentiles).tolist())),
            "vehicle 2": dict(zip(map(str, percentiles), np.percentile(s2[ok], percentiles).tolist())),
        },
    }
    shares = {}
    variances = {name: [np.nanvar(x) for x in speeds(use)[:2]] for name, use in groups.items()}
    for i in range(2):
        total = sum(v[i] for v in variances.values())
        shares[f"vehicle {i + 1}"] = {name: float(v[i] / total) for name, v in variances.items()}
    result["variance_shares"] = shares
    return result
