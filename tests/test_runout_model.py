"""Run-out model: closed forms, the smoothing's effect on the rest pose, bad rows.

Closed forms (conventions.md, run-out): a locked slide stops at v^2/(2 mu g); a
pure locked spin of a vehicle with its centre of gravity mid-wheelbase turns
I w^2/(2 mu sum N_i |r_i|); rolling resistance alone stops at v^2/(2 f_r g).
Tolerances are the smoothing's documented effect (derive/runout.py):
eps^2/(2a) plus V_STOP eps/a of creep, a the deceleration.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from impactsym.runout import runout_batch
from impactsym.runout._door import plain
from impactsym.runout.batch import input_table, run_row
from tests.runout_rows import realistic_row, rows_table

G = 9.80665
EPS = plain().EPS
BASE = {
    "m": 1450.0,
    "I": 2400.0,
    "L": 2.7,
    "a": 1.1,
    "track": 1.5,
    "mu": 0.8,
    "alpha_max": math.radians(10),
    "f_r": 0.01,
    "g": G,
    "x": 1.0,
    "y": -2.0,
    "psi": 0.3,
    "vx": 0.0,
    "vy": 0.0,
    "w": 0.0,
}


def _row(state: float, **kw) -> dict:
    row = dict(BASE, **kw)
    for k in ("fl", "fr", "rl", "rr"):
        row.update({f"state_{k}": state, f"brake_{k}": 0.0, f"steer_{k}": 0.0})
    return row


def _one(row, **kw):
    return run_row(input_table(row)[0], **kw)


@pytest.mark.parametrize("speed", [5.0, 20.0, 35.0])
def test_locked_slide_stops_at_v2_over_2_mu_g(speed):
    psi = BASE["psi"]
    y, t, status, _, _ = _one(_row(1.0, vx=speed * math.cos(psi), vy=speed * math.sin(psi)))
    assert status == 0
    expected = speed**2 / (2 * 0.8 * G)
    assert abs(math.hypot(y[0] - 1.0, y[1] + 2.0) - expected) < 1e-4
    assert abs(y[2] - psi) < 1e-9  # symmetric: no yaw
    assert abs(t - speed / (0.8 * G)) < 2e-3


@pytest.mark.parametrize("w", [-4.0, 1.5, 6.0])
def test_pure_locked_spin_turns_I_w2_over_2_mu_sum_N_r(w):
    row = _row(1.0, a=1.35, w=w)  # cg mid-wheelbase: the wheel forces cancel, the cg stays
    y, _, status, _, _ = _one(row)
    radius = math.hypot(1.35, 0.75)
    expected = 2400.0 * w * w / (2 * 0.8 * 1450.0 * G * radius)  # sum N_i |r_i| = m g |r|
    assert status == 0
    assert abs(abs(y[2] - row["psi"]) - expected) < 1e-4  # rad
    assert math.hypot(y[0] - 1.0, y[1] + 2.0) < 1e-6


@pytest.mark.parametrize("speed", [3.0, 10.0])
def test_rolling_resistance_alone_stops_at_v2_over_2_fr_g(speed):
    psi = BASE["psi"]
    y, _, status, _, _ = _one(_row(0.0, vx=speed * math.cos(psi), vy=speed * math.sin(psi)))
    expected = speed**2 / (2 * 0.01 * G)
    assert status == 0
    assert abs(math.hypot(y[0] - 1.0, y[1] + 2.0) - expected) < 1e-3  # documented creep: micrometres
    assert abs(y[2] - psi) < 1e-9


def test_smoothing_moves_the_rest_pose_less_than_1_mm_and_001_deg():
    """eps against eps/10 (both at a tight tolerance) on random realistic run-outs,
    the sticking case of seed 7's fifth row included (0.3 mm, 0.005 deg)."""
    rng = np.random.default_rng(7)
    for _ in range(12):
        row = realistic_row(rng)
        a, _, s1, _, _ = _one(row, tol=1e-10)
        b, _, s2, _, _ = _one(row, tol=1e-10, eps=EPS / 10)
        assert s1 == s2 == 0
        assert math.hypot(a[0] - b[0], a[1] - b[1]) < 1e-3
        assert abs(math.degrees(a[2] - b[2])) < 0.01


def test_sensitivities_match_finite_differences():
    """d rest/d(vx, vy, w, mu) integrated with the motion against central
    differences of whole run-outs (a smooth case: all wheels locked)."""
    row = _row(1.0, vx=12.0, vy=4.0, w=1.5)
    y, _, _, _, _ = _one(row, sens=True, tol=1e-11)
    S = y[7:].reshape(6, 4)
    for j, key in enumerate(("vx", "vy", "w", "mu")):
        h = 1e-4
        up, _, _, _, _ = _one(dict(row, **{key: row[key] + h}), tol=1e-11)
        dn, _, _, _, _ = _one(dict(row, **{key: row[key] - h}), tol=1e-11)
        fd = (up[:3] - dn[:3]) / (2 * h)
        assert np.allclose(S[:3, j], fd, rtol=2e-3, atol=2e-3), (key, S[:3, j], fd)


def test_bad_rows_get_a_status_and_the_others_are_unaffected():
    rng = np.random.default_rng(3)
    rows = [realistic_row(rng) for _ in range(8)]
    bad = {
        1: ("m", math.nan, 1),
        2: ("I", 0.0, 2),
        3: ("a", 3.5, 20),
        4: ("mu", -0.1, 21),
        5: ("state_fl", 0.5, 23),
        6: ("brake_rr", 1.5, 23),
    }
    for i, (key, value, _) in bad.items():
        rows[i][key] = value
    rows[7].update(f_r=0.0, vx=5.0 * math.cos(rows[7]["psi"]), vy=5.0 * math.sin(rows[7]["psi"]), w=0.0)
    for k in ("fl", "fr", "rl", "rr"):
        rows[7].update({f"state_{k}": 0.0, f"brake_{k}": 0.0, f"steer_{k}": 0.0})
    out = runout_batch(rows_table(rows))
    for i, (_, _, code) in bad.items():
        assert out["status"][i] == code and math.isnan(out["x_rest"][i])
    assert out["status"][7] == 22  # rolls on without resistance: NOT_STOPPED
    assert out["status"][0] == 0 and math.isfinite(out["x_rest"][0])
    alone = runout_batch(rows_table(rows[:1]))
    assert alone["x_rest"][0] == out["x_rest"][0]


def test_batch_refuses_a_missing_or_unknown_column_naming_it():
    from impactsym.errors import SceneError

    row = _row(1.0, vx=5.0)
    cols = {k: np.array([v]) for k, v in row.items()}
    del cols["mu"]
    with pytest.raises(SceneError, match="^mu: missing column$"):
        runout_batch(cols)
    cols = {k: np.array([v]) for k, v in row.items()}
    cols["muu"] = np.array([0.8])
    with pytest.raises(SceneError, match="^muu: unknown column"):
        runout_batch(cols)


def test_extreme_rows_run_to_rest_or_get_a_status():
    """Stress: at rest already, 60 m/s, 20 rad/s, full brake (cap 0), steer 89
    deg, mu 2, a 5 deg slip angle, a light trailer-like body: every row either
    stops with finite outputs, or has a status and NaN outputs; never a
    solved row with NaN."""
    rows = [
        _row(1.0),  # at rest
        _row(0.0, vx=60.0),
        _row(1.0, w=20.0),
        _row(0.0, vx=10.0, vy=5.0, w=3.0, mu=2.0, alpha_max=math.radians(5)),
        _row(0.0, vx=8.0, vy=-8.0, m=300.0, I=150.0),
    ]
    rows.append(dict(_row(0.0, vx=12.0, w=1.0), brake_fl=1.0, brake_fr=1.0, steer_rl=math.radians(89)))
    out = runout_batch(rows_table(rows))
    assert (out["status"] == 0).all()
    for key in ("x_rest", "y_rest", "psi_rest", "t", "distance"):
        assert np.isfinite(out[key]).all(), key
    assert out["t"][0] == 0.0 and out["x_rest"][0] == BASE["x"] and out["distance"][0] == 0.0
    # a wheel that is fully braked pushes only along itself: the car still stops
    assert out["distance"][5] > 0


@pytest.mark.parametrize("speed", [5.0, 20.0, 35.0])
def test_a_locked_slide_ends_at_the_stopping_speed(speed):
    """The step in which the vehicle stops is cut back to the crossing of
    V_STOP, so the slide falls short of v^2/(2 mu g) by the travel below it,
    V_STOP^2/(2 mu g) = 6.4e-8 m, to 1e-9 m (the step's own end, before the
    cut-back, overshot the crossing by up to 3e-8 m)."""
    psi = BASE["psi"]
    y, _, status, _, _ = _one(_row(1.0, vx=speed * math.cos(psi), vy=speed * math.sin(psi)))
    assert status == 0
    short = (speed**2 - plain().V_STOP ** 2) / (2 * 0.8 * G)
    assert abs(math.hypot(y[0] - 1.0, y[1] + 2.0) - short) < 1e-9


def test_a_sticking_wheel_takes_stiff_steps():
    """examples/runout/sedan.json: the car pivots about its locked front wheel
    for 0.6 s with |lambda| ~ 1.2e4 1/s; explicit steps alone took 2,589 (0.25 ms
    each), the ROS34PW2 steps take the state (the forward kernel) in 581 at the
    default tolerance, and the rest pose agrees with the tight reference. (The
    row function with sensitivities takes 692 at the default: their own error control.)"""
    from impactsym.testing.runout_reference import reference_runout

    row = _sedan_row()
    assert runout_batch({k: [v] for k, v in row.items()})["steps"][0] < 1000
    y, _, status, _, _ = _one(row)
    assert status == 0
    x, yy, psi, _, _ = reference_runout(row)
    assert math.hypot(y[0] - x, y[1] - yy) < 1e-4 and abs(y[2] - psi) < 1e-5


def _sedan_row() -> dict:
    """examples/runout/sedan.json as a kernel row (a locked front wheel the car
    pivots about, a braked rear wheel holding)."""
    row = dict(_row(0.0, m=1450.0, I=2400.0, a=1.1, mu=0.75, x=-1.2, y=0.4, psi=math.radians(30)))
    row.update(vx=8.0, vy=3.0, w=1.2, state_fl=1.0, brake_rl=0.5, steer_rr=math.radians(-5))
    return row


@pytest.mark.parametrize("tol, bound", [(1e-6, 0.02), (1e-8, 0.002)])
def test_sensitivities_of_a_sticking_wheel_against_central_differences(tol, bound):
    """d(x, y, psi)_rest/d(vx, vy, w) integrated with the motion against central
    differences (1e-4) of run-outs at tol 1e-12: with explicit steps only, the
    sensitivity equations went unstable at tol 1e-6 (relative error 1e9 on
    b63ce3a) while the state did not."""
    assert _sensitivity_error(_sedan_row(), tol) < bound


@pytest.mark.parametrize("tol, bound", [(1e-6, 0.02), (1e-8, 0.002)])
def test_sensitivities_of_sticking_wheels_hold_on_every_variant(tol, bound):
    """The same on twelve variants of the sedan's separation velocity (vx
    x0.8-1.2, vy and w x0.6-1.4): while the sensitivities rode on the state's
    steps without error control of their own, the worst was 17 % at tol 1e-6
    and 3.3 % at 1e-8 (the sedan itself 0.9 % and 0.08 %, docs/runout.md)."""
    rng = np.random.default_rng(5)
    worst = 0.0
    for _ in range(12):
        row = _sedan_row()
        row["vx"] *= rng.uniform(0.8, 1.2)
        row["vy"] *= rng.uniform(0.6, 1.4)
        row["w"] *= rng.uniform(0.6, 1.4)
        worst = max(worst, _sensitivity_error(row, tol))
    assert worst < bound


def test_sensitivities_at_the_default_tolerance_on_random_rows():
    """d(x, y, psi)_rest/d(vx, vy, w) integrated at the default tolerance on 60
    random realistic rows (mixed wheel states), each within 1 % of central
    differences: with the sensitivities riding on the state's steps 22 of these
    rows were over 1 % and 7 over 5 % (worst 15 %); with their own error
    control the worst is 0.5 %, 0.08 % since the steps land on kinks (docs/runout.md, "Error control of the
    sensitivities")."""
    rng = np.random.default_rng(3)
    errors = [_sensitivity_error(realistic_row(rng), None) for _ in range(60)]
    assert max(errors) < 0.01


def _sensitivity_error(row: dict, tol: float) -> float:
    """Largest error of d(x, y, psi)_rest/d(vx, vy, w) integrated at `tol`
    against central differences (1e-4) of run-outs at tol 1e-12, relative to
    the largest entry."""
    S = _one(row, tol=tol, sens=True)[0][7:].reshape(6, 4)[:3, :3]
    fd = np.empty((3, 3))
    for j, key in enumerate(("vx", "vy", "w")):
        up, dn = dict(row), dict(row)
        up[key] += 1e-4
        dn[key] -= 1e-4
        fd[:, j] = (_one(up, tol=1e-12)[0][:3] - _one(dn, tol=1e-12)[0][:3]) / 2e-4
    return float(np.abs(S - fd).max() / np.abs(fd).max())


def test_rows_on_threads_equal_rows_in_one_call_bit_for_bit():
    """The batch's chunks of rows on threads (batch.CHUNK) give what one
    serial call over the whole table gives, row for row, with a bad row in the
    middle of a chunk."""
    rng = np.random.default_rng(31)
    table = rows_table([realistic_row(rng) for _ in range(150)])
    table["mu"][70] = -1.0
    threaded, serial = runout_batch(table, parallel=True), runout_batch(table, parallel=False)
    for key in ("x_rest", "y_rest", "psi_rest", "t", "distance", "status", "steps"):
        assert np.array_equal(threaded[key], serial[key], equal_nan=True), key
    assert threaded["status"][70] != 0 and (np.delete(threaded["status"], 70) == 0).all()


def test_a_scene_run_out_and_its_batch_row_agree_within_the_integrator_error():
    """A scene's single run-outs go through the row function with
    sensitivities, a batch through the forward driver: the same model, two
    error-controlled integrations, within 1 mm of each other (batch.run_row)."""
    rng = np.random.default_rng(32)
    rows = [realistic_row(rng) for _ in range(40)]
    out = runout_batch(rows_table(rows))
    for i, row in enumerate(rows):
        y, _, status, _, _ = run_row(input_table(row)[0])
        assert status == 0
        assert math.hypot(y[0] - out["x_rest"][i], y[1] - out["y_rest"][i]) < 1e-3
        assert abs(y[2] - out["psi_rest"][i]) < math.radians(0.01)


def test_rolling_wheel_shortcut_past_saturation_equals_the_clip():
    """The forward rolling wheel skips atan2 where its slip angle is past
    saturation (derive/runout.py, SaturatingPrinter): its (Fx, Fy, Mz) equal
    the Jacobian kernel's forces (printed with the plain clip) within 1e-13 of
    the force scale (mu N, and the round-off of u_l over max(|u_l|, eps)), on
    4,000 random states: half anywhere, half at the saturation boundary (a
    slip angle of cap alpha_max up to round-off, or within 0.1 % of it)."""
    from numba import njit

    from impactsym.runout._door import jit

    k = jit()

    # the wheel kernels are called only from kernels (no CPython wrapper): call them from one
    @njit
    def both(c, s, vx, vy, w, px, py, cd, sd, n, mu, amax, b, fre, cap, eps, tl):
        args = (c, s, vx, vy, w, px, py, cd, sd, n, mu, amax, b, fre, cap, eps)
        return k._wheel_rolling(*args, tl), k._wheel_rolling_jac(*args)[:3]

    rng = np.random.default_rng(23)
    saturated = unsaturated = 0
    for i in range(4000):
        psi, delta = rng.uniform(-math.pi, math.pi), rng.uniform(-0.5, 0.5)
        amax, brake = rng.uniform(0.02, 1.5), rng.choice([0.0, 1.0, rng.uniform(0, 1)])
        cap = math.sqrt((1 - brake) * (1 + brake))
        ul = rng.choice([0.0, 1e-4, rng.uniform(-20, 20)])
        near = 1e-14 if i % 4 == 1 else 1e-3  # at the boundary up to round-off, or within 0.1 %
        us = math.tan(cap * amax) * max(abs(ul), k.EPS) * (1 + rng.uniform(-near, near))
        us = us * rng.choice([-1, 1]) if i % 2 else rng.uniform(-20, 20)
        # the contact point of the wheel at (1.2, 0.75), yawing at 0.3 rad/s, moves at (ul, us)
        # in the wheel frame (axis at psi + delta): v = u - w (-ry, rx), r in the scene frame
        a, w = psi + delta, 0.3
        rx = 1.2 * math.cos(psi) - 0.75 * math.sin(psi)
        ry = 1.2 * math.sin(psi) + 0.75 * math.cos(psi)
        vx = ul * math.cos(a) - us * math.sin(a) + w * ry
        vy = ul * math.sin(a) + us * math.cos(a) - w * rx
        args = (math.cos(psi), math.sin(psi), vx, vy, w, 1.2, 0.75)
        args += (
            math.cos(delta),
            math.sin(delta),
            3500.0,
            0.8,
            amax,
            brake,
            0.0 if brake else 0.012,
            cap,
            k.EPS,
        )
        fast, plain_clip = (np.array(r) for r in both(*args, math.tan(cap * amax)))
        # the two kernels form u_l in different orders: a round-off of the contact
        # speeds' size in u_l moves the force by that over max(|u_l|, eps) times mu N
        scale = 3500.0 * 0.8 * (1.0 + (abs(ul) + abs(us) + 10.0) / max(abs(ul), k.EPS))
        assert np.abs(fast - plain_clip).max() <= 1e-13 * scale, (i, fast, plain_clip)
        if abs(us) >= math.tan(cap * amax) * max(abs(ul), k.EPS):
            saturated += 1
        else:
            unsaturated += 1
    assert saturated > 1000 and unsaturated > 500
