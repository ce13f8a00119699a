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


def round_trip(index: int, seed: int = 5):
    """(row, rest pose reached, vehicle to fit) of row `index` of the benchmark's
    round trips (`realistic_row` with `seed`): the vehicle without its separation state."""
    from impactsym.runout.batch import input_table, run_row
    from impactsym.runout.scene import RunoutVehicle

    rng = np.random.default_rng(seed)
    rows = [realistic_row(rng) for _ in range(index + 1)]
    row = rows[index]
    y, _, status, _, _ = run_row(input_table(row)[0])
    assert status == 0
    fixed = {k: v for k, v in row.items() if k not in ("vx", "vy", "w")}
    rest = (float(y[0]), float(y[1]), float(y[2]))
    return row, rest, RunoutVehicle("r", fixed, (row["x"], row["y"]), row["psi"], None, None, rest)


def reaches(row: dict, state, rest) -> bool:
    """`state` = (vx, vy, w), run forward at the default tolerance, stops within
    1 mm and 0.01 deg of `rest`."""
    from impactsym.runout.batch import input_table, run_row

    values = dict(row, vx=state[0], vy=state[1], w=state[2])
    y, _, status, _, _ = run_row(input_table(values)[0])
    return status == 0 and math.hypot(y[0] - rest[0], y[1] - rest[1]) < 1e-3 and abs(y[2] - rest[2]) < 1.75e-4
