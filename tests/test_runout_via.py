"""Intermediate poses as evidence of the fit to rest (issue 23, item 4;
impactsym/runout/via.py): the pose on the path nearest a given position, its
derivatives with respect to the separation state, and the fit that uses them.

Tolerances chosen before looking: the interpolated path within 0.1 mm of a
point of a 1e-11 path (the integrator's own error at its default tolerance is
below 1e-4 m, benchmarks/results/runout.md); the derivatives within 1 % of
central differences of run-outs at 1e-11 (a Newton step needs no better); a
round trip within 0.01 m/s and 0.01 rad/s, as the rest-only round trips.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest

from impactsym.errors import SceneError
from impactsym.runout import load_runout, runout
from impactsym.runout import via as V
from impactsym.runout.batch import columns, input_table, run_row
from impactsym.runout.fit import fit_rest
from impactsym.runout.scene import RunoutVehicle
from tests.helpers import run_cli_subprocess
from tests.runout_rows import realistic_row

ROOT = Path(__file__).resolve().parents[1]
SEDAN = ROOT / "examples" / "runout" / "sedan.json"
TIGHT = 1e-11


def _path(values, tol=None):
    y, _, status, _, path = run_row(
        values, tol=tol, sens=True, path_points=V.PATH_ROWS, path_columns=V.PATH_COLUMNS
    )
    assert status == 0
    return path


def _rows(n: int, seed: int):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        row = realistic_row(rng)
        out.append((row, input_table(row)[0]))
    return out


@pytest.mark.parametrize("row, values", _rows(6, 3))
def test_a_point_of_a_tight_path_is_met_by_the_interpolated_default_path(row, values):
    tight = _path(values, TIGHT)
    mid = tight[tight.shape[0] // 2]
    r, _ = V.residuals([(mid[1], mid[2], mid[3])], _path(values), 1.0, jacobian=False)
    assert np.abs(r).max() < 1e-4


@pytest.mark.parametrize("row, values", _rows(6, 4))
def test_the_pose_derivatives_match_central_differences(row, values):
    """A pose 0.3 m and 3 deg off the path: the exact derivatives of its
    residuals against central differences of run-outs (steps 1e-6)."""
    tight = _path(values, TIGHT)
    mid = tight[tight.shape[0] // 3]
    pose = [(mid[1] + 0.3, mid[2] - 0.2, mid[3] + 0.05)]
    _, J = V.residuals(pose, tight, 2.0, jacobian=True)
    cols = columns()
    fd = np.empty_like(J)
    for j, name in enumerate(("vx", "vy", "w")):
        h = 1e-6 * max(1.0, abs(row[name]))
        up, down = values.copy(), values.copy()
        up[cols.index(name)] += h
        down[cols.index(name)] -= h
        r_up = V.residuals(pose, _path(up, TIGHT), 2.0, jacobian=False)[0]
        r_down = V.residuals(pose, _path(down, TIGHT), 2.0, jacobian=False)[0]
        fd[:, j] = (r_up - r_down) / (2 * h)
    assert np.abs(J - fd).max() < 0.01 * np.abs(fd).max()


def _fit_scene(seed_row: int = 2):
    """The sedan scene with its first vehicle to be fitted to its rest pose and
    an intermediate pose taken from its forward path (40 % of the time)."""
    scene = json.loads(SEDAN.read_text())
    forward = runout(scene, path=True)["vehicles"][0]
    sep = scene["vehicles"][0]["separation"]
    truth = (*sep.pop("velocity"), sep.pop("yaw_rate"))
    point = forward["path"][int(0.4 * len(forward["path"]))]
    scene["vehicles"][0]["rest"] = forward["rest"]
    scene["vehicles"][0]["intermediate"] = [{"position": point[1:3], "heading": point[3]}]
    return scene, truth


def test_fit_with_an_intermediate_pose_recovers_the_separation_state():
    scene, truth = _fit_scene()
    entry = runout(scene)["vehicles"][0]
    assert entry["fit"]["converged"]
    assert entry["separation"]["velocity"] == pytest.approx(truth[:2], abs=0.01)
    assert entry["separation"]["yaw_rate"] == pytest.approx(truth[2], abs=0.01)
    (miss,) = entry["fit"]["residual"]["intermediate"]
    assert miss["position"] < 1e-3 and miss["heading"] < 0.01


def test_an_inconsistent_intermediate_pose_is_fitted_in_least_squares():
    """Moved 0.5 m off the path, the pose cannot be met with the rest pose:
    the fit lowers the squared misses below those of the generating state
    (which meets the rest pose and misses the pose), and moves away from it."""
    scene, truth = _fit_scene()
    pose = scene["vehicles"][0]["intermediate"][0]
    psi = math.radians(pose["heading"])
    pose["position"] = [pose["position"][0] + 0.5 * math.sin(psi), pose["position"][1] - 0.5 * math.cos(psi)]
    entry = runout(scene)["vehicles"][0]
    assert entry["fit"]["converged"]
    fitted = entry["fit"]["residual"]
    forward = copy.deepcopy(scene)
    forward["vehicles"][0]["separation"].update(velocity=list(truth[:2]), yaw_rate=truth[2])
    at_truth = runout(forward)["vehicles"][0]["residual"]
    assert at_truth["position"] < 1e-4 and at_truth["intermediate"][0]["position"] > 0.3
    assert fitted["position"] ** 2 + fitted["intermediate"][0]["position"] ** 2 < (
        at_truth["intermediate"][0]["position"] ** 2
    )
    assert math.dist(entry["separation"]["velocity"], truth[:2]) > 0.01


def test_a_forward_vehicle_reports_how_far_it_passes_from_its_poses():
    scene = json.loads(SEDAN.read_text())
    forward = runout(scene, path=True)["vehicles"][0]
    point = forward["path"][len(forward["path"]) // 2]
    scene["vehicles"][0]["intermediate"] = [{"position": [point[1] + 0.2, point[2]]}]
    (miss,) = runout(scene)["vehicles"][0]["residual"]["intermediate"]
    assert set(miss) == {"position"}
    assert 0.0 < miss["position"] <= 0.2 + 1e-4


def test_an_intermediate_pose_picks_the_generating_state_of_two():
    """Seed-5 row 1 of the round trips (tests/test_runout_unique.py): two
    separation states reach the same rest pose. A pose of the generating path
    names it, and the other (which misses the pose) is no alternative."""
    rng = np.random.default_rng(5)
    row = [realistic_row(rng) for _ in range(2)][1]
    values = input_table(row)[0]
    y, _, _, _, path = run_row(values, path_points=V.PATH_ROWS, path_columns=8)
    mid = path[path.shape[0] // 2]
    fixed = {k: v for k, v in row.items() if k not in ("vx", "vy", "w")}
    rest = (float(y[0]), float(y[1]), float(y[2]))
    plain = RunoutVehicle("r", fixed, (row["x"], row["y"]), row["psi"], None, None, rest)
    assert fit_rest(plain).alternatives  # the check this test leans on
    with_pose = RunoutVehicle(
        "r", fixed, (row["x"], row["y"]), row["psi"], None, None, rest, via=((mid[1], mid[2], mid[3]),)
    )
    fit = fit_rest(with_pose)
    assert fit.converged and not fit.alternatives
    assert math.hypot(fit.velocity[0] - row["vx"], fit.velocity[1] - row["vy"]) < 0.01
    assert abs(fit.yaw_rate - row["w"]) < 0.01


@pytest.mark.parametrize(
    "value, field",
    [
        ({"position": [1, 2]}, "vehicles[0].intermediate"),
        ([{"heading": 10}], "vehicles[0].intermediate[0].position"),
        ([{"position": [1, 2], "speed": 3}], "vehicles[0].intermediate[0]"),
        ([{"position": [1, "x"]}], "vehicles[0].intermediate[0].position[1]"),
        ([{"position": [1, 2], "heading": float("nan")}], "vehicles[0].intermediate[0].heading"),
    ],
)
def test_a_bad_intermediate_pose_names_its_field(value, field):
    scene = json.loads(SEDAN.read_text())
    scene["vehicles"][0]["intermediate"] = value
    with pytest.raises(SceneError) as err:
        load_runout(scene)
    assert field in str(err.value)


def test_the_cli_exits_2_on_a_bad_intermediate_pose(tmp_path):
    scene = json.loads(SEDAN.read_text())
    scene["vehicles"][0]["intermediate"] = [{"position": [1]}]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(scene))
    proc = run_cli_subprocess("runout", bad, "--json")
    assert proc.returncode == 2
    assert "vehicles[0].intermediate[0].position" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_the_plot_draws_the_intermediate_poses(tmp_path):
    scene, _ = _fit_scene()
    out = tmp_path / "via.png"
    proc = run_cli_subprocess("runout", _write(tmp_path, scene), "--plot", out)
    assert proc.returncode == 0, proc.stderr
    assert out.stat().st_size > 10_000


def _write(tmp_path, scene) -> Path:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(copy.deepcopy(scene)))
    return path
