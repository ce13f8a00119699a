"""The fit's grid search (`fit_rest(..., exhaustive=True)`, `runout --exhaustive`):
the local minima it starts from, the default range, and what it finds.

Rows come from tests/runout_rows.py (the benchmark's round trips, seed 5).
Row 1 (steered, rolling, locked, locked): the fit alone names two states
reaching the rest pose; the grid search finds a third, 0.6 rad/s from the
generating one. Row 13 (every wheel rolling, a 66 m spinning run-out): the fit
alone names one state, the grid's minima another; the generating state, whose
basin is narrower than the grid, only the refinement of the grid's open cells
finds (docs/runout.md, "The grid search"), as it does seed 6 row 18's.
Seed 6, row 19: no start of the fit converges; the grid search, its last
rescue, finds the generating state. (Seed 6's row 13 was that row until the
integrator's steps stopped growing after a rejection: its fit now converges
from its own starts.)
"""

from __future__ import annotations

import copy
import importlib
import json
import math

import numpy as np
import pytest

from impactsym.runout import runout
from impactsym.runout.fit import DISTINCT_SPEED, DISTINCT_YAW, fit_rest, plausible_range
from tests.helpers import EXAMPLES, one_line_error, run_cli
from tests.runout_rows import reaches, round_trip

grid = importlib.import_module("impactsym.runout.grid")


def _states(fit):
    return [(f.velocity[0], f.velocity[1], f.yaw_rate) for f in (fit, *fit.alternatives)]


def _distinct(states) -> bool:
    return all(
        math.hypot(a[0] - b[0], a[1] - b[1]) > DISTINCT_SPEED or abs(a[2] - b[2]) > DISTINCT_YAW
        for i, a in enumerate(states)
        for b in states[:i]
    )


def test_local_minima_are_the_points_no_neighbour_undercuts():
    """Two wells, a plateau of infinity (failed run-outs) and a minimum on the
    grid's face: the wells' bottoms and the face point, nothing else."""
    i, j, k = np.meshgrid(np.arange(9), np.arange(9), np.arange(7), indexing="ij")
    miss = np.minimum((i - 2) ** 2 + (j - 2) ** 2 + (k - 3) ** 2, (i - 6) ** 2 + (j - 7) ** 2 + k**2 + 0.5)
    miss = miss.astype(float)
    miss[:, :, 6] = np.inf
    found = {tuple(p) for p in np.argwhere(grid._local_minima(miss))}
    assert found == {(2, 2, 3), (6, 7, 0)}


def test_the_default_range_holds_every_generating_state_of_the_round_trips():
    """40 round trips (seeds 5 and 6): the generating separation state lies
    inside the grid's default range (speed and yaw rate)."""
    for seed in (5, 6):
        for index in range(20):
            row, _, vehicle = round_trip(index, seed)
            speed_max, yaw_max = plausible_range(vehicle)
            assert math.hypot(row["vx"], row["vy"]) < speed_max and abs(row["w"]) < yaw_max, (seed, index)


def test_the_grid_finds_a_third_state_of_row_1():
    row, rest, vehicle = round_trip(1)
    plain = _states(fit_rest(vehicle))
    fit = fit_rest(vehicle, exhaustive=True)
    states = _states(fit)
    assert len(states) >= len(plain) + 1 >= 3
    assert all(reaches(row, s, rest) for s in states)
    assert _distinct(states)
    truth = (row["vx"], row["vy"], row["w"])
    assert any(
        math.hypot(s[0] - truth[0], s[1] - truth[1]) < 0.01 and abs(s[2] - truth[2]) < 0.01 for s in states
    )
    minima = len(fit.grid.starts) - len(fit.grid.refined.starts)  # the minima's starts come first
    assert fit.grid.shape == (31, 31, 33) and 0 < minima <= min(grid.MAX_STARTS, fit.grid.minima)


def _has(states, row) -> bool:
    return any(
        math.hypot(s[0] - row["vx"], s[1] - row["vy"]) < 0.01 and abs(s[2] - row["w"]) < 0.01 for s in states
    )


@pytest.mark.slow
@pytest.mark.parametrize("seed, index", [(5, 13), (6, 18)])
def test_the_refined_cells_find_a_generating_state_narrower_than_the_grid(seed, index):
    """Seed 5 row 13 (every wheel rolling, a 66 m spinning run-out: 0.05 rad/s
    moves the rest by 13 m) and seed 6 row 18: the grid's local minima miss
    the generating state (its basin is narrower than the spacing); refining the
    open cells finds it, and every state named reaches the rest pose (before
    the refinement, f7f9799 and earlier, neither search named it)."""
    row, rest, vehicle = round_trip(index, seed)
    fit = fit_rest(vehicle, exhaustive=True)
    states = _states(fit)
    assert _has(states, row) and all(reaches(row, s, rest) for s in states) and _distinct(states)
    refined = fit.grid.refined
    assert refined.levels >= 1 and refined.runouts > 0 and len(refined.starts) >= 1
    assert refined.runouts <= grid.REFINE_RUNOUTS + grid.SETTLE_CELLS * (1 + 4 * grid.SETTLE_ITERATIONS)


def _narrow_map(p: np.ndarray) -> np.ndarray:
    """A map with a wide root at (0, 0, 0) and two within 0.03 of (1, 0, 0),
    narrower than the test's grid (spacing 0.25): x - 2 exp(-(|p - (1, 0, 0)|/0.03)^2), y, z."""
    bump = 2.0 * np.exp(-np.sum(((p - np.array([1.0, 0.0, 0.0])) / 0.03) ** 2, axis=-1))
    return np.stack([p[..., 0] - bump, p[..., 1], p[..., 2]], axis=-1)


def _newton_settle(starts, jacobians):
    """`refine`'s settle for _narrow_map: Newton from each start (forward
    differences), the distinct states within 1e-9 of a root."""
    p = np.array(starts, dtype=float)
    for _ in range(30):
        f = _narrow_map(p)
        J = np.stack([(_narrow_map(p + 1e-7 * e) - f) / 1e-7 for e in np.eye(3)], axis=-1)
        step = np.linalg.solve(J, -f[:, :, None])[:, :, 0]
        p += step / np.maximum(1.0, np.linalg.norm(step, axis=1) / 0.01)[:, None]  # a trust region of 0.01
    roots = p[np.linalg.norm(_narrow_map(p), axis=1) < 1e-9]
    states: list = []
    for q in roots:
        if all(np.linalg.norm(q - o) > 1e-6 for o in states):
            states.append(tuple(q))
    return states, 0


def test_refining_the_open_cells_finds_roots_between_grid_points():
    """On a grid of spacing 0.25 the narrow roots near (1, 0, 0) leave no local
    minimum of the miss there; the cells that may hold a root (their corners'
    box widened by the second differences) are refined three times and settle
    onto both narrow roots, and the cells far from every root are excluded."""
    axis = np.linspace(-2.0, 2.0, 17)
    points = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1)
    poses = _narrow_map(points)
    miss = np.sum(poses**2, axis=-1)
    minima = points[grid._local_minima(miss)]
    assert np.all(
        np.linalg.norm(minima - np.array([1.0, 0.0, 0.0]), axis=1) > 0.2
    )  # none near the narrow pair
    out = grid.refine(_narrow_map, poses, points[0, 0, 0], np.full(3, 0.25), np.zeros(3), _newton_settle)
    found = np.array(out.starts)
    narrow = found[np.abs(found[:, 0] - 1.0) < 0.1]
    assert len(narrow) == 2 and np.all(np.abs(narrow[:, 1:]) < 1e-9)
    assert out.levels == grid.REFINE_LEVELS and out.open_cells < 0.02 * 16**3


@pytest.mark.slow
def test_a_fit_whose_starts_all_fail_is_rescued_by_the_grid():
    row, rest, vehicle = round_trip(19, seed=6)
    fit = fit_rest(vehicle)
    assert fit.converged and fit.grid.shape == (31, 31, 33)  # the coarse grid first found nothing
    assert fit.velocity == pytest.approx((row["vx"], row["vy"]), abs=0.01)
    assert fit.yaw_rate == pytest.approx(row["w"], abs=0.01)
    assert reaches(row, _states(fit)[0], rest)


def test_a_locked_slide_stays_unique_under_the_grid():
    row, _, vehicle = round_trip(0)
    vehicle.row.update({f"state_{k}": 1.0 for k in ("fl", "fr", "rl", "rr")})
    vehicle.row.update({f"brake_{k}": 0.0 for k in ("fl", "fr", "rl", "rr")})
    vehicle.rest = _rest(dict(vehicle.row, vx=9.0, vy=-4.0, w=0.8))
    fit = fit_rest(vehicle, exhaustive=True, speed_max=20.0, yaw_rate_max=3.0)
    assert fit.converged and fit.alternatives == []
    assert (fit.grid.speed_max, fit.grid.yaw_rate_max) == (20.0, 3.0)
    assert fit.velocity == pytest.approx((9.0, -4.0), abs=0.01) and fit.yaw_rate == pytest.approx(
        0.8, abs=0.01
    )


def _rest(values: dict):
    from impactsym.runout.batch import input_table, run_row

    y, _, _, _, _ = run_row(input_table(values)[0])
    return float(y[0]), float(y[1]), float(y[2])


@pytest.mark.slow
def test_the_cli_reports_the_search_in_json(capsys):
    code, out, _ = run_cli(capsys, "runout", EXAMPLES / "runout" / "fit_tbone.json", "--exhaustive", "--json")
    assert code == 0
    for v in json.loads(out)["vehicles"]:
        search = v["fit"]["search"]
        assert search["grid"] == [31, 31, 33] and search["runouts"] == 23397
        assert search["states"] >= 1 and 0 < search["starts"] <= min(search["minima"], grid.MAX_STARTS)
        refined = search["refined"]
        assert refined["levels"] >= 1 and refined["runouts"] > 0 and refined["open_cells"] >= 1
        assert search["spacing"]["speed"] == pytest.approx(search["speed_max"] / grid.SPEED_CELLS)
    code, out, _ = run_cli(capsys, "runout", EXAMPLES / "runout" / "fit_tbone.json", "--exhaustive")
    assert code == 0 and out.count("grid search:") == 2


def test_the_range_is_in_the_scene_units():
    """US units: speed_max in ft/s, reported back as given."""
    scene = json.loads((EXAMPLES / "runout" / "fit_tbone.json").read_text())
    ft = 0.3048
    us = copy.deepcopy(scene)
    us["units"] = "US"
    for v in us["vehicles"]:
        v["mass"] /= 14.59390293720636
        v["yaw_inertia"] /= 14.59390293720636 * ft**2
        for key in ("wheelbase", "cg_to_front_axle", "track"):
            v[key] /= ft
        for pose in ("separation", "rest"):
            v[pose]["position"] = [p / ft for p in v[pose]["position"]]
    us["runout"]["gravity"] = 9.80665 / ft
    us["vehicles"] = us["vehicles"][:1]
    entry = runout(us, exhaustive=True, speed_max=60.0)["vehicles"][0]
    assert entry["fit"]["search"]["speed_max"] == pytest.approx(60.0)
    assert entry["fit"]["search"]["spacing"]["speed"] == pytest.approx(4.0)


@pytest.mark.parametrize(
    "argv, field",
    [
        (("--speed-max", "20"), "--speed-max"),
        (("--exhaustive", "--yaw-rate-max", "-2"), "--yaw-rate-max"),
        (("--exhaustive", "--speed-max", "nan"), "--speed-max"),
        (("--exhaustive", "--chain", "solve"), "--exhaustive"),
        (("--chain", "solve", "--yaw-rate-max", "0"), "--yaw-rate-max"),
    ],
)
def test_bad_grid_options_are_one_line_errors(capsys, argv, field):
    err = one_line_error(capsys, "runout", EXAMPLES / "runout" / "fit_tbone.json", *argv)
    assert f"error: {field}:" in err


def test_a_forward_scene_says_nothing_was_searched():
    res = runout(EXAMPLES / "runout" / "sedan.json", exhaustive=True)
    assert any("nothing was searched" in w for w in res["warnings"])
    assert "fit" not in res["vehicles"][0]


def test_an_evidence_fit_carries_its_search():
    entry = runout(EXAMPLES / "runout" / "fit_intermediate.json", exhaustive=True)["vehicles"][0]
    assert entry["fit"]["converged"] and entry["fit"]["search"]["states"] >= 1


def test_the_chained_reconstruct_gives_each_other_separation_state_its_speeds():
    """tests/runout_rest.py's scene (pre-impact 17 and 8 m/s, run forward to
    rest) with the sedan on a steered, a locked, a braked and a counter-steered
    wheel: its rest pose is reached from several separation states. Each other
    state is reconstructed too (its speeds those of a direct reconstruct with
    it), and with the grid search one of them gives back the generating speeds."""
    from impactsym.reconstruct import reconstruct
    from impactsym.runout.chain import _impact_part, reconstruct_from_rest
    from tests.runout_rest import nominal_scene, rest_scene

    wheels = {
        "front_left": {"state": "rolling", "steer": -15},
        "front_right": "locked",
        "rear_left": {"brake": 0.5},
        "rear_right": {"state": "rolling", "steer": 15},
    }
    scene = nominal_scene(rest_scene(wheels=wheels))
    out = reconstruct_from_rest(scene, exhaustive=True)
    others = out["alternatives"]
    listed = [
        (k, a) for k, v in enumerate(out["vehicles"]) for a in v["runout"]["fit"].get("alternatives", [])
    ]
    assert [(o["vehicle"], o["separation"]["velocity"]) for o in others] == [
        (k, a["velocity"]) for k, a in listed
    ]
    assert sum("another separation state reaching its rest pose" in w for w in out["warnings"]) == len(others)
    impact = _impact_part(scene)
    for v, entry in zip(impact["vehicles"], out["vehicles"]):
        v["final_velocity"], v["final_yaw_rate"] = (
            entry["runout"]["separation"]["velocity"],
            entry["runout"]["separation"]["yaw_rate"],
        )
    for o in others:
        direct = json.loads(json.dumps(impact))
        direct["vehicles"][o["vehicle"]].update(
            final_velocity=o["separation"]["velocity"], final_yaw_rate=o["separation"]["yaw_rate"]
        )
        assert o["speed"] == pytest.approx([v.speed for v in reconstruct(direct).vehicles], rel=1e-12)
    assert any(o["speed"] == pytest.approx([17.0, 8.0], abs=1e-3) for o in others)
