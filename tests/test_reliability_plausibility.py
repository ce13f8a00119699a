"""Issue 22 item 6: careless input is questioned (a warning naming the field
and the likely slip), never refused and never silently obeyed."""

import json
from pathlib import Path

import pytest

import impactsym
from impactsym import load_scene
from impactsym.laws.scene import is_law_scene, load_law_scene
from impactsym.scene.plausibility import RANGES, implausible
from tests.helpers import example_command, example_files

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _example(name):
    return json.loads((EXAMPLES / name).read_text())


#: The scene reader's kind for each example command (fit scenes are read by impactsym.evidence).
KIND = {"solve": "forward", "invert": "inverse", "reconstruct": "reconstruct", "crash3": "crash3"}


@pytest.mark.parametrize(
    "path", [p for p in example_files() if example_command(p) in KIND], ids=lambda p: p.name
)
def test_no_bundled_example_is_questioned(path):
    # a law scene is read as its rigid reading (impactsym.laws.scene), as solve reads it
    scene = (
        load_law_scene(path).scene
        if is_law_scene(path)
        else load_scene(path, kind=KIND[example_command(path)])
    )
    assert implausible(scene.leaves, scene.vehicles, scene.units) == []


def _solve_warnings(data):
    return load_scene(data).warnings  # a warning of the scene, never an error


def test_a_weight_given_as_mass_in_a_us_scene():
    data = _example("two_car_us.json")
    data["vehicles"][0]["mass"] = 2900.0  # 2,900 lb entered as slug
    assert impactsym.solve(data).warnings  # solved as given, with the warning
    (warning,) = [w for w in _solve_warnings(data) if w.startswith("vehicles[0].mass")]
    assert "2900 slug" in warning and "weight given as a mass" in warning


def test_a_mass_in_tonnes():
    data = _example("two_car_us.json")
    data["units"] = "SI"
    data["vehicles"][1]["mass"] = 1.5
    assert any(w.startswith("vehicles[1].mass") and "tonnes" in w for w in _solve_warnings(data))


def test_a_yaw_rate_in_deg_per_s():
    data = _example("two_car_us.json")
    data["vehicles"][1]["yaw_rate"] = 45.0
    assert any(w.startswith("vehicles[1].yaw_rate") and "deg/s" in w for w in _solve_warnings(data))


def test_all_angles_in_radians():
    data = _example("reconstruct_two_car_si.json")
    data["impact"]["normal_angle"] = -0.5236
    data["vehicles"][1]["heading"] = -1.5708
    warnings = load_scene(data, kind="reconstruct").warnings
    assert any("impact.normal_angle = -0.5236" in w and "radians given as degrees" in w for w in warnings)


def test_an_impact_point_farther_than_a_vehicle():
    data = _example("two_car_us.json")
    data["vehicles"][0]["impact_point"] = [66.0, 1.0]  # inches as feet
    assert any(w.startswith("vehicles[0].impact_point") for w in _solve_warnings(data))
    data["vehicles"][0]["impact_point"] = [8.0, 1.0]
    data["vehicles"][0]["length"] = 15.0  # its own length: 8 ft from the centre of gravity is fine
    assert not any(w.startswith("vehicles[0].impact_point") for w in _solve_warnings(data))
    data["vehicles"][0]["length"] = 6.0
    assert any("its length" in w for w in _solve_warnings(data))


def test_a_speed_beyond_any_road_vehicle():
    data = _example("two_car_us.json")
    data["vehicles"][0]["velocity"] = {"speed": 400.0, "direction": 0.0}  # 400 ft/s = 273 mph
    assert any(w.startswith("vehicles[0].velocity") and "mph" in w for w in _solve_warnings(data))


def test_crush_depths_all_zero_or_beyond_a_car():
    data = _example("crash3_two_car_us.json")
    data["vehicles"][1]["crush"]["depths"] = [0, 0, 0, 0]
    data["vehicles"][0]["crush"]["depths"] = [9, 11, 300, 12, 11, 9]  # 300 in = 7.6 m
    warnings = impactsym.crash3(data).warnings
    assert any(w.startswith("vehicles[1].crush.depths") and "every depth is 0" in w for w in warnings)
    assert any(w.startswith("vehicles[0].crush.depths[2]") for w in warnings)


def test_crush_energy_above_the_initial_kinetic_energy():
    data = _example("models_two_car_us.json")
    assert not any("kinetic energy" in w for w in impactsym.crash3(data).warnings)
    for vehicle in data["vehicles"]:
        vehicle["crush"]["A"] *= 30
        vehicle["crush"]["B"] *= 30
    assert any("crush energy" in w and "kinetic energy" in w for w in impactsym.crash3(data).warnings)


def test_the_ranges_are_documented_in_one_table():
    text = (Path(__file__).resolve().parents[1] / "docs" / "careless-use.md").read_text()
    for dimension, (limit, unit, _) in RANGES.items():
        assert f"| `{dimension}` | {limit:g} {unit} |" in text
