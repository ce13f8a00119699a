"""Synthetic truth for the evidence tests: forward scenes solved by the 50-digit
reference (impactsym.testing.reference), and fit scenes built from them.

Geometry: vehicle 1 heads along +x and hits vehicle 2's side with its front
(impact centre ahead of 1's centre of gravity, beside 2's); vehicle 2 crosses
at 60-120 degrees. e and mu are drawn (mu a fraction of the critical ratio).
"""

from __future__ import annotations

import math

import numpy as np

from impactsym.testing.reference import mu_critical, solve_reference


def truth(seed: int) -> dict:
    """One physical scene and its reference solution (floats), SI units."""
    rng = np.random.default_rng(seed)
    for _ in range(100):
        th2 = math.radians(rng.uniform(60, 120))
        m1, m2 = rng.uniform(1100, 2000, 2)
        k1, k2 = rng.uniform(1.2, 1.6, 2)
        s1, s2 = rng.uniform(8, 25, 2)
        r1 = (2.2, rng.uniform(-0.6, 0.6))
        side = rng.uniform(-1.2, 1.2)  # along vehicle 2
        r2 = (side * math.cos(th2) + 0.9 * math.sin(th2), side * math.sin(th2) - 0.9 * math.cos(th2))
        gamma = math.radians(rng.uniform(-10, 10))
        row = {
            "m1": m1, "m2": m2, "I1": m1 * k1**2, "I2": m2 * k2**2,
            "v1x": s1, "v1y": 0.0, "w1": 0.0,
            "v2x": s2 * math.cos(th2), "v2y": s2 * math.sin(th2), "w2": 0.0,
            "r1x": r1[0], "r1y": r1[1], "r2x": r2[0], "r2y": r2[1],
            "gamma": gamma, "e": rng.uniform(0.05, 0.3), "mu": 0.0, "e_m": 1.0,
        }  # fmt: skip
        gn = math.cos(gamma) * (row["v2x"] - s1) + math.sin(gamma) * (row["v2y"] - 0.0)
        if gn >= -1.0:
            continue
        row["mu"] = float(mu_critical(row)) * rng.uniform(0.3, 0.95)
        ref = {k: float(v) for k, v in solve_reference(row).items()}
        if ref["Pn"] >= 0 or ref["TL"] <= 0:
            continue
        return {"row": row, "ref": ref, "theta": (0.0, th2), "speeds": (s1, s2)}
    raise RuntimeError("no physical scene drawn")


def base_scene(t: dict, normal: bool = True) -> dict:
    """The fit scene of a truth, without evidence."""
    row = t["row"]
    scene = {
        "units": "SI",
        "vehicles": [
            {
                "name": f"car {i + 1}",
                "mass": row[f"m{i + 1}"],
                "yaw_inertia": row[f"I{i + 1}"],
                "heading": math.degrees(t["theta"][i]),
                "impact_point": [row[f"r{i + 1}x"], row[f"r{i + 1}y"]],
            }
            for i in range(2)
        ],
        "evidence": [],
    }
    if normal:
        scene["impact"] = {"normal_angle": math.degrees(row["gamma"])}
    return scene


def observed(t: dict, quantity: str, vehicle: int | None = None) -> float | list:
    """The true value of an evidence quantity (SI, degrees)."""
    ref, row, n = t["ref"], t["row"], (vehicle or 0) + 1
    V = (ref[f"V{n}x"], ref[f"V{n}y"])
    v = (row[f"v{n}x"], row[f"v{n}y"])
    th = t["theta"][vehicle or 0]
    dv = (V[0] - v[0], V[1] - v[1])
    h = (math.cos(th), math.sin(th))
    return {
        "speed": t["speeds"][vehicle or 0],
        "final_speed": math.hypot(*V),
        "final_direction": math.degrees(math.atan2(V[1], V[0])),
        "final_velocity": list(V),
        "final_yaw_rate": ref[f"W{n}"],
        "delta_v": math.hypot(*dv),
        "delta_v_longitudinal": dv[0] * h[0] + dv[1] * h[1],
        "delta_v_lateral": -dv[0] * h[1] + dv[1] * h[0],
        "energy_loss": ref["TL"],
    }[quantity]
