"""Issue 22 items 1 and 2: the sense of the crush-surface normal.

A sense the geometry does not decide (n·(r1 - r2) within rounding of the lever
arms) keeps the normal as given; a normal turned round and then refused says why.
"""

import copy

import numpy as np
import pytest

import impactsym
from impactsym import load_scene, solve
from impactsym.errors import SceneError
from impactsym.scene.casefile import used_normal_angle

# a bar struck square on: the impact points lie along the crush surface's
# tangent, so n·(r1 - r2) = 0 exactly and only rounding of cos(Γ) decides
SQUARE_ON = {
    "model": "rigid",
    "units": "SI",
    "impact": {"normal_angle": -90.0, "restitution": 0.2, "impulse_ratio": 0.0, "moment_restitution": 0.0},
    "vehicles": [
        {
            "name": "a",
            "mass": 1000,
            "yaw_inertia": 1500,
            "velocity": [0, -10],
            "yaw_rate": 0,
            "impact_point": [-1, 0],
        },
        {
            "name": "b",
            "mass": 1200,
            "yaw_inertia": 1800,
            "velocity": [0, 0],
            "yaw_rate": 0,
            "impact_point": [1, 0],
        },
    ],
}


def _with(angle, mirror=False):
    data = copy.deepcopy(SQUARE_ON)
    data["impact"]["normal_angle"] = angle
    if mirror:  # the mirror image in the y axis: x -> -x
        for vehicle in data["vehicles"]:
            vehicle["impact_point"][0] *= -1
            vehicle["velocity"][0] *= -1
    return data


@pytest.mark.parametrize("given", [-90.0, 270.0, -450.0, 630.0])
def test_undecided_sense_keeps_the_normal_as_given(given):
    scene = load_scene(_with(given))
    assert scene.impact.normal_angle == given
    assert not any("opposite sense" in w for w in scene.warnings)
    assert solve(scene).Pn < 0.0


def test_square_on_and_its_mirror_image_give_the_same_answer():
    plain, mirrored = solve(_with(-90.0)), solve(_with(-90.0, mirror=True))
    assert plain.vehicles[0].velocity[1] == pytest.approx(mirrored.vehicles[0].velocity[1])


def test_a_180_case_and_its_mirror_both_solve():
    # impact points along y, the normal along -x: cos(180°)·0 + sin(180°)·(r1y - r2y)
    data = copy.deepcopy(SQUARE_ON)
    data["impact"]["normal_angle"] = 180.0
    data["vehicles"][0].update(velocity=[-10, 0], impact_point=[0, 1])
    data["vehicles"][1].update(impact_point=[0, -1])
    mirror = copy.deepcopy(data)
    for vehicle in mirror["vehicles"]:
        vehicle["impact_point"][1] *= -1
    assert solve(data).vehicles[0].velocity[0] == pytest.approx(solve(mirror).vehicles[0].velocity[0])


def test_a_sense_the_geometry_decides_is_still_turned_round():
    # r1 - r2 = (-2, 0.001): far beyond rounding, the normal points from 2 toward 1
    angle, flipped = used_normal_angle(0.0, np.array([-1.0, 0.0005]), np.array([1.0, -0.0005]))
    assert flipped and angle == 180.0
    angles, flips = used_normal_angle(
        np.array([-90.0, 270.0, 0.0]), (np.array([-1.0] * 3), np.zeros(3)), (np.array([1.0] * 3), np.zeros(3))
    )
    assert list(flips) == [False, False, True]


@pytest.mark.parametrize("kind", ["inverse", "reconstruct"])
def test_invert_and_reconstruct_keep_an_undecided_normal(kind):
    data = _with(-90.0)
    for vehicle, final in zip(data["vehicles"], ([0.0, -6.0], [0.0, -3.3])):
        vehicle["final_velocity"] = final
        vehicle["final_yaw_rate"] = 0.0
        if kind == "reconstruct":
            vehicle["heading"] = -90.0
            del vehicle["velocity"]
    if kind == "reconstruct":
        data["vehicles"][1]["heading"] = 0.0
    scene = load_scene(data, kind=kind)
    assert scene.impact.normal_angle == -90.0


def test_turned_normal_refused_says_why():
    # the normal as given (0°) points from a toward b along the approach, but the
    # impact points put b's centre of gravity behind a's: it is turned round to 180°
    data = copy.deepcopy(SQUARE_ON)
    data["impact"]["normal_angle"] = 0.0
    data["vehicles"][0].update(velocity=[10, 0], impact_point=[-1, 0])
    data["vehicles"][1].update(impact_point=[1, 0])
    with pytest.raises(SceneError) as caught:
        solve(data)
    text = str(caught.value)
    assert "turned round" in text and "centres of gravity" in text
    assert "0 deg" in text and "180 deg" in text


def test_turned_normal_refused_by_reconstruct_says_why():
    import json
    from pathlib import Path

    data = json.loads(
        (Path(__file__).resolve().parents[1] / "examples" / "reconstruct_two_car_si.json").read_text()
    )
    first, second = (v["impact_point"] for v in data["vehicles"])
    data["vehicles"][0]["impact_point"], data["vehicles"][1]["impact_point"] = second, first
    with pytest.raises(SceneError) as caught:
        impactsym.reconstruct(data)
    assert "turned round" in str(caught.value) and "-30 deg" in str(caught.value)


def test_compare_keeps_an_undecided_normal():
    comparison = impactsym.compare(_with(-90.0))
    assert {"brach", "particle"} <= {row.model for row in comparison.rows}
