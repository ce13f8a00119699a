"""The fit's uniqueness check (issue 23): every separation state it names
reaches the rest pose, no two are the same state, and a second state that
reaches the same rest pose is named.

The rows come from tests/runout_rows.py (seed 5, the benchmark's round trips).
Row 1 (steered, rolling, locked, locked): two separation states, 1.5 rad/s
apart in yaw rate, stop at the same rest pose; before the deflated search the
check missed the generating one. Row 16 (rolling, three braked): one state;
before the alternatives were polished, a start that stopped 2.8 mm short of
the rest pose was named as a second state.
"""

from __future__ import annotations

import math

import pytest

from impactsym.runout.batch import input_table, run_row
from impactsym.runout.fit import DISTINCT_SPEED, DISTINCT_YAW, fit_rest
from tests.runout_rows import reaches, round_trip


def _states(fit):
    return [(f.velocity[0], f.velocity[1], f.yaw_rate) for f in (fit, *fit.alternatives)]


@pytest.mark.parametrize("index", [1, 16])
def test_every_named_state_reaches_the_rest_pose_and_none_repeats(index):
    row, rest, vehicle = round_trip(index)
    fit = fit_rest(vehicle)
    assert fit.converged
    states = _states(fit)
    assert all(reaches(row, s, rest) for s in states)
    for i, a in enumerate(states):
        for b in states[:i]:
            assert math.hypot(a[0] - b[0], a[1] - b[1]) > DISTINCT_SPEED or abs(a[2] - b[2]) > DISTINCT_YAW


def test_a_second_state_reaching_the_same_rest_pose_is_named():
    row, rest, vehicle = round_trip(1)
    fit = fit_rest(vehicle)
    states = _states(fit)
    truth = (row["vx"], row["vy"], row["w"])
    assert len(states) >= 2
    assert any(
        math.hypot(s[0] - truth[0], s[1] - truth[1]) < 0.01 and abs(s[2] - truth[2]) < 0.01 for s in states
    )
    assert fit_rest(vehicle, check_unique=False).alternatives == []


def test_a_unique_slide_names_no_other_state():
    """All wheels locked, the rest pose of a slide: one state, nothing else named."""
    _, _, vehicle = round_trip(0)
    vehicle.row.update({f"state_{k}": 1.0 for k in ("fl", "fr", "rl", "rr")})
    vehicle.row.update({f"brake_{k}": 0.0 for k in ("fl", "fr", "rl", "rr")})
    values = dict(vehicle.row, vx=9.0, vy=-4.0, w=0.8)
    y, _, _, _, _ = run_row(input_table(values)[0])
    vehicle.rest = (float(y[0]), float(y[1]), float(y[2]))
    fit = fit_rest(vehicle)
    assert fit.converged and fit.alternatives == []
    assert fit.velocity == pytest.approx((9.0, -4.0), abs=0.01) and fit.yaw_rate == pytest.approx(
        0.8, abs=0.01
    )
