"""Quasi-static load transfer (a vehicle's ``cg_height``; batch column ``h``;
derive/load_transfer.py): closed forms, the independent solve_ivp reference
(which finds the loads by fixed-point iteration from the textbook statement),
the integrated sensitivities against central differences, the lift limit, and
a fit round trip. Tolerances were set before the first run."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest

from impactsym.errors import SceneError
from impactsym.runout import fit_rest, load_runout, runout, runout_batch
from impactsym.runout._door import plain
from impactsym.runout.batch import input_table, run_row
from tests.helpers import run_cli_subprocess
from tests.runout_rows import realistic_row, rows_table

G = 9.80665
SEDAN = {
    "units": "SI",
    "runout": {"friction": 0.75, "slip_angle_max": 10, "rolling_resistance": 0.01},
    "vehicles": [
        {
            "name": "sedan",
            "mass": 1450,
            "yaw_inertia": 2400,
            "heading": 30,
            "wheelbase": 2.7,
            "cg_to_front_axle": 1.1,
            "track": 1.5,
            "cg_height": 0.55,
            "wheels": {
                "front_left": "locked",
                "front_right": "rolling",
                "rear_left": {"brake": 0.5},
                "rear_right": {"state": "rolling", "steer": -5},
            },
            "separation": {"position": [-1.2, 0.4], "velocity": [8.0, 3.0], "yaw_rate": 1.2},
        }
    ],
}


def _straight(h: float, front: float, rear: float, f_r: float = 0.0, speed: float = 20.0) -> dict:
    """A car moving straight ahead at `speed`, wheel states front/rear (1 locked, 0 rolling)."""
    row = dict(m=1500.0, I=2500.0, L=2.7, a=1.2, track=1.5, mu=0.8, alpha_max=math.radians(10), f_r=f_r, g=G)
    row.update(x=0.0, y=0.0, psi=0.0, vx=speed, vy=0.0, w=0.0, h=h)
    for k in ("fl", "fr", "rl", "rr"):
        row[f"state_{k}"] = front if k[0] == "f" else rear
        row[f"brake_{k}"] = row[f"steer_{k}"] = 0.0
    return row


@pytest.mark.parametrize("h", [0.3, 0.55])
@pytest.mark.parametrize("f_r", [0.0, 0.015])
def test_front_locked_braking_stops_where_the_axle_loads_say(h, f_r):
    """Front wheels locked, rear rolling: m a = mu N_f + f_r N_r with
    N_f = m (g b + h a)/L, N_r = m (g a_cg - h a)/L, so
    a = g (mu b + f_r a_cg)/(L - mu h + f_r h) and the car stops at v^2/(2 a)."""
    row = _straight(h, 1.0, 0.0, f_r)
    out = runout_batch(rows_table([row]))
    b = row["L"] - row["a"]
    decel = G * (row["mu"] * b + f_r * row["a"]) / (row["L"] - row["mu"] * h + f_r * h)
    assert out["status"][0] == 0
    assert abs(out["x_rest"][0] - 20.0**2 / (2 * decel)) < 1e-3
    static = runout_batch(rows_table([_straight(0.0, 1.0, 0.0, f_r)]))["x_rest"][0]
    assert static - out["x_rest"][0] > 1.0  # the transfer shortens the slide by metres


def test_all_locked_slide_is_unchanged_by_the_transfer():
    """All wheels locked: the loads move but always sum to m g, so the slide is v^2/(2 mu g)."""
    out = runout_batch(rows_table([_straight(0.6, 1.0, 1.0)]))
    assert abs(out["x_rest"][0] - 20.0**2 / (2 * 0.8 * G)) < 1e-3


def _random_rows(seed: int, n: int) -> list[dict]:
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(n):
        row = realistic_row(rng)
        row["h"] = rng.uniform(0.4, 0.6)
        rows.append(row)
    return rows


@pytest.mark.slow
def test_random_runouts_agree_with_the_fixed_point_reference():
    pytest.importorskip("scipy")
    from impactsym.testing.runout_reference import reference_runout

    rows = _random_rows(77, 8)
    out = runout_batch(rows_table(rows))
    assert (out["status"] == 0).all()
    worst = [0.0, 0.0]
    for i, row in enumerate(rows):
        x, y, psi, _, dist = reference_runout(row)
        allowed = 1e-3 + 1e-5 * dist
        miss, turn = (
            math.hypot(out["x_rest"][i] - x, out["y_rest"][i] - y),
            abs(math.degrees(out["psi_rest"][i] - psi)),
        )
        worst = [max(worst[0], miss), max(worst[1], turn)]
        assert miss < allowed, i
        assert turn < 0.01, i
    print(f"\nload transfer vs the fixed-point reference, 8 rows: worst {worst[0]:.2g} m, {worst[1]:.2g} deg")


def _values(row: dict) -> np.ndarray:
    return input_table(row)[0]


@pytest.mark.parametrize("i", range(3))
def test_sensitivities_match_central_differences(i):
    """d(x, y, psi)_rest/d(vx, vy, w, mu) integrated with the transfer's terms
    against central differences of forward run-outs (tolerance 1e-12; steps 1e-5
    of the speed, 1e-5 rad/s, 1e-6 of mu): within 0.5 % of each column's norm."""
    row = _random_rows(5 + i, 1)[0]
    y, _, status, _, _ = run_row(_values(row), tol=1e-12, sens=True)
    assert status == 0
    S = y[7:31].reshape(6, 4)[:3]  # S[i, j] = d y_i/d p_j at y[7 + 4 i + j]
    steps = {"vx": 1e-5 * 20, "vy": 1e-5 * 20, "w": 1e-5, "mu": 1e-6}
    for j, name in enumerate(("vx", "vy", "w", "mu")):
        rest = []
        for sign in (1, -1):
            moved = dict(row, **{name: row[name] + sign * steps[name]})
            ym, *_ = run_row(_values(moved), tol=1e-12)
            rest.append(ym[:3])
        fd = (rest[0] - rest[1]) / (2 * steps[name])
        error = np.linalg.norm(S[:, j] - fd) / np.linalg.norm(fd)
        print(f"\nrow {i}, d rest/d {name}: relative error {error:.2g}")
        assert error < 5e-3, (name, S[:, j], fd)


def test_the_lift_limit_is_the_kernels_refusal():
    """Just under cg_height_limit runs; just over it the row's status is 24 (RUNOUT_WHEEL_LIFT)."""
    row = _straight(0.0, 1.0, 0.0, f_r=0.01)
    limit = plain().cg_height_limit(row["L"], row["a"], row["track"], row["mu"], row["f_r"])
    rows = [dict(row, h=limit * 0.999), dict(row, h=limit * 1.001), dict(row, h=-0.1)]
    status = runout_batch(rows_table(rows))["status"]
    assert list(status) == [0, 24, 20]
    assert "lift a wheel" in plain().STATUS_TEXT[24]


@pytest.mark.parametrize(("value", "words"), [(1.5, "too high"), (-0.2, ">= 0"), ("high", "number")])
def test_a_bad_cg_height_is_refused_naming_the_field(value, words):
    scene = copy.deepcopy(SEDAN)
    scene["vehicles"][0]["cg_height"] = value
    with pytest.raises(SceneError) as err:
        runout(scene)
    assert err.value.field == "vehicles[0].cg_height" and words in str(err.value)


def test_cli_refuses_a_lifting_cg_height_with_exit_2(tmp_path):
    scene = copy.deepcopy(SEDAN)
    scene["vehicles"][0]["cg_height"] = 1.5
    path = tmp_path / "high.json"
    path.write_text(json.dumps(scene))
    proc = run_cli_subprocess("runout", str(path), "--json")
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "vehicles[0].cg_height" in proc.stderr


def test_fit_round_trip_with_load_transfer():
    scene = copy.deepcopy(SEDAN)
    forward = runout(scene)["vehicles"][0]
    static = copy.deepcopy(SEDAN)
    del static["vehicles"][0]["cg_height"]
    moved = np.subtract(forward["rest"]["position"], runout(static)["vehicles"][0]["rest"]["position"])
    assert np.hypot(*moved) > 0.05  # the transfer matters here
    v = scene["vehicles"][0]
    del v["separation"]["velocity"], v["separation"]["yaw_rate"]
    v["rest"] = forward["rest"]
    fit = fit_rest(load_runout(scene).vehicles[0])
    found = [fit, *fit.alternatives]
    best = min(found, key=lambda f: math.hypot(f.velocity[0] - 8.0, f.velocity[1] - 3.0))
    assert fit.converged
    assert math.hypot(best.velocity[0] - 8.0, best.velocity[1] - 3.0) < 0.01
    assert abs(best.yaw_rate - 1.2) < 0.01


def test_us_units_give_the_same_run_out_in_feet():
    ft = 0.3048
    scene = copy.deepcopy(SEDAN)
    v = scene["vehicles"][0]
    scene["units"] = "US"
    v["mass"] /= 14.59390293720636
    v["yaw_inertia"] /= 14.59390293720636 * ft**2
    for key in ("wheelbase", "cg_to_front_axle", "track", "cg_height"):
        v[key] /= ft
    v["separation"] = {
        "position": [x / ft for x in v["separation"]["position"]],
        "velocity": [x / ft for x in v["separation"]["velocity"]],
        "yaw_rate": 1.2,
    }
    si = runout(SEDAN)["vehicles"][0]["rest"]["position"]
    us = runout(scene)["vehicles"][0]["rest"]["position"]
    assert np.allclose(np.multiply(us, ft), si, atol=1e-4)
