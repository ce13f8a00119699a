"""Random realistic run-out rows for the run-out tests and benchmark (SI, rad)."""

from __future__ import annotations

import math

import numpy as np

WHEELS = ("fl", "fr", "rl", "rr")


def realistic_row(rng: np.random.Generator) -> dict:
    """A passenger car after an impact: 900-2500 kg, separation speed 3-20 m/s,
    yaw rate up to 3 rad/s, wheels rolling, locked, braked or steered at random."""
    m = rng.uniform(900, 2500)
    wb = rng.uniform(2.3, 3.1)
    row = {
        "m": m,
        "I": m * rng.uniform(1.3, 2.0),
        "L": wb,
        "a": wb * rng.uniform(0.38, 0.55),
        "track": rng.uniform(1.4, 1.7),
        "mu": rng.uniform(0.5, 0.95),
        "alpha_max": math.radians(rng.uniform(6, 14)),
        "f_r": rng.uniform(0.008, 0.02),
        "g": 9.80665,
        "x": rng.uniform(-3, 3),
        "y": rng.uniform(-3, 3),
        "psi": rng.uniform(-math.pi, math.pi),
    }
    speed, direction = rng.uniform(3, 20), rng.uniform(-math.pi, math.pi)
    row.update(vx=speed * math.cos(direction), vy=speed * math.sin(direction), w=rng.uniform(-3, 3))
    for k in WHEELS:
        kind = rng.integers(0, 4)  # rolling, locked, braked, steered
        row[f"state_{k}"] = 1.0 if kind == 1 else 0.0
        row[f"brake_{k}"] = rng.uniform(0.2, 1.0) if kind == 2 else 0.0
        row[f"steer_{k}"] = math.radians(rng.uniform(-20, 20)) if kind == 3 else 0.0
    return row


def rows_table(rows: list[dict]) -> dict:
    """Columns of a list of rows."""
    return {key: np.array([r[key] for r in rows]) for key in rows[0]}
