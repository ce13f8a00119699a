"""Scene reading and validation: bad values name their field, files agree, inputs convert."""

import copy
import json
import math

import pytest

from impactsym.scene import Scene, SceneError, Vehicle, load_scene

# The scene of conventions.md.
BASE = {
    "model": "rigid",
    "units": "US",
    "impact": {"normal_angle": 0.0, "restitution": 0.1, "impulse_ratio": 0.3, "moment_restitution": 1.0},
    "vehicles": [
        {
            "name": "car 1",
            "mass": 100.0,
            "yaw_inertia": 1800.0,
            "velocity": [50.0, 0.0],
            "yaw_rate": 0.0,
            "impact_point": [6.0, 1.0],
        },
        {
            "name": "car 2",
            "mass": 150.0,
            "yaw_inertia": 2600.0,
            "velocity": [0.0, 30.0],
            "yaw_rate": 0.0,
            "impact_point": [-1.5, -4.0],
        },
    ],
}

BASE_TOML = """
model = "rigid"
units = "US"

[impact]
normal_angle = 0.0
restitution = 0.1
impulse_ratio = 0.3
moment_restitution = 1.0

[[vehicles]]
name = "car 1"
mass = 100.0
yaw_inertia = 1800.0
velocity = [50.0, 0.0]
yaw_rate = 0.0
impact_point = [6.0, 1.0]

[[vehicles]]
name = "car 2"
mass = 150.0
yaw_inertia = 2600.0
velocity = [0.0, 30.0]
yaw_rate = 0.0
impact_point = [-1.5, -4.0]
"""

MISSING = object()


def scene_with(path, value):
    """A deep copy of BASE with the entry at `path` (a tuple of keys/indices) set, or removed for MISSING."""
    data = copy.deepcopy(BASE)
    *parents, last = path
    target = data
    for key in parents:
        target = target[key]
    if value is MISSING:
        del target[last]
    else:
        target[last] = value
    return data


BAD_VALUES = [
    (("vehicles", 1, "mass"), -5, "vehicles[1].mass", "positive finite"),
    (("vehicles", 1, "mass"), 0.0, "vehicles[1].mass", "positive finite"),
    (("vehicles", 0, "mass"), math.nan, "vehicles[0].mass", "positive finite"),
    (("vehicles", 0, "mass"), math.inf, "vehicles[0].mass", "positive finite"),
    (("vehicles", 0, "mass"), True, "vehicles[0].mass", "positive finite"),
    (("vehicles", 0, "mass"), "100", "vehicles[0].mass", "needs a mass (kg, lb, slug)"),
    (("vehicles", 0, "mass"), MISSING, "vehicles[0].mass", "missing"),
    (("vehicles", 1, "yaw_inertia"), -1.0, "vehicles[1].yaw_inertia", "positive finite"),
    (("vehicles", 1, "yaw_inertia"), MISSING, "vehicles[1].yaw_inertia", "missing"),
    (("vehicles", 0, "impact_point"), MISSING, "vehicles[0].impact_point", "missing"),
    (("vehicles", 0, "impact_point"), [1.0, 2.0, 3.0], "vehicles[0].impact_point", "list of 2"),
    (("vehicles", 0, "velocity"), [50.0], "vehicles[0].velocity", "list of 2 numbers"),
    (("vehicles", 0, "velocity"), "fast", "vehicles[0].velocity", "list of 2 numbers"),
    (("vehicles", 0, "velocity"), [50.0, math.nan], "vehicles[0].velocity[1]", "finite"),
    (("vehicles", 0, "velocity"), [50.0, False], "vehicles[0].velocity[1]", "finite"),
    (("vehicles", 0, "velocity"), MISSING, "vehicles[0].velocity", "missing"),
    (("vehicles", 0, "yaw_rate"), math.inf, "vehicles[0].yaw_rate", "finite"),
    (("vehicles", 0, "fixed"), "yes", "vehicles[0].fixed", "true or false"),
    (("vehicles", 0, "name"), 7, "vehicles[0].name", "string"),
    (("vehicles", 0, "final_velocity"), [1.0], "vehicles[0].final_velocity", "list of 2"),
    (("vehicles", 0, "heading"), math.nan, "vehicles[0].heading", "finite"),
    (("vehicles", 0), [1, 2], "vehicles[0]", "object"),
    (("vehicles",), BASE["vehicles"][:1], "vehicles", "exactly 2"),
    (("vehicles",), BASE["vehicles"] * 2, "vehicles", "exactly 2"),
    (("vehicles",), {"car": 1}, "vehicles", "exactly 2"),
    (("vehicles",), MISSING, "vehicles", "missing"),
    (("impact", "restitution"), MISSING, "impact.restitution", "missing"),
    (("impact", "restitution"), math.nan, "impact.restitution", "finite"),
    (("impact", "normal_angle"), math.inf, "impact.normal_angle", "finite"),
    (("impact", "normal_angle"), MISSING, "impact.normal_angle", "missing"),
    (("impact", "impulse_ratio"), "sometimes", "impact.impulse_ratio", '"critical"'),
    (("impact", "impulse_ratio"), math.nan, "impact.impulse_ratio", '"critical"'),
    (("impact", "impulse_ratio"), True, "impact.impulse_ratio", '"critical"'),
    (("impact", "impulse_ratio"), MISSING, "impact.impulse_ratio", "missing"),
    (("impact", "moment_restitution"), None, "impact.moment_restitution", "finite"),
    (("impact",), 3.0, "impact", "object"),
    (("impact",), MISSING, "impact", "missing"),
    (("units",), "metric", "units", 'unknown units \'metric\' (use "SI" or "US")'),
    (("units",), MISSING, "units", "missing"),
    (("model",), "soft", "model", "unknown model"),
]


@pytest.mark.parametrize(("path", "value", "field", "text"), BAD_VALUES)
def test_bad_value_names_its_field(path, value, field, text):
    with pytest.raises(SceneError) as info:
        load_scene(scene_with(path, value))
    message = str(info.value)
    assert info.value.field == field
    assert message.startswith(f"{field}: ")
    assert text in message
    assert "\n" not in message


def test_error_message_shows_the_value():
    with pytest.raises(SceneError, match=r"^vehicles\[1\]\.mass: must be a positive finite number, got -5$"):
        load_scene(scene_with(("vehicles", 1, "mass"), -5))


def test_both_vehicles_fixed_is_rejected():
    data = copy.deepcopy(BASE)
    for vehicle in data["vehicles"]:
        vehicle["fixed"] = True
    with pytest.raises(SceneError, match=r"^vehicles: "):
        load_scene(data)


def test_top_level_must_be_an_object(tmp_path):
    path = tmp_path / "list.json"
    path.write_text("[1, 2]")
    with pytest.raises(SceneError, match="must be an object"):
        load_scene(path)


@pytest.mark.parametrize(
    ("name", "text", "kind"),
    [
        ("broken.json", '{"model": "rigid",, }', "invalid JSON"),
        ("broken.toml", 'model = "rigid"\n[impact\nrestitution = 0.1\n', "invalid TOML"),
    ],
)
def test_malformed_file_is_one_line_naming_the_file(tmp_path, name, text, kind):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    message = str(info.value)
    assert message.startswith(f"{path}: {kind}: ")
    assert "\n" not in message


def test_unknown_file_type(tmp_path):
    path = tmp_path / "scene.yaml"
    path.write_text("model: rigid\n")
    with pytest.raises(SceneError, match=r"unknown scene file type '\.yaml'"):
        load_scene(path)


def test_missing_file_is_an_os_error(tmp_path):
    with pytest.raises(OSError):
        load_scene(tmp_path / "absent.json")


def test_json_nan_literal_is_rejected(tmp_path):
    path = tmp_path / "nan.json"
    path.write_text(json.dumps(BASE).replace('"mass": 150.0', '"mass": NaN'))
    with pytest.raises(SceneError, match=r"^vehicles\[1\]\.mass: .*NaN"):
        load_scene(path)


def test_toml_inf_is_rejected(tmp_path):
    path = tmp_path / "inf.toml"
    path.write_text(BASE_TOML.replace("yaw_inertia = 2600.0", "yaw_inertia = inf"))
    with pytest.raises(SceneError, match=r"^vehicles\[1\]\.yaw_inertia: "):
        load_scene(path)


def test_json_and_toml_give_identical_inputs(tmp_path):
    json_path = tmp_path / "scene.json"
    toml_path = tmp_path / "scene.toml"
    json_path.write_text(json.dumps(BASE))
    toml_path.write_text(BASE_TOML)
    from_json = load_scene(json_path)
    from_toml = load_scene(toml_path)
    assert from_json.to_inputs() == from_toml.to_inputs()
    assert from_json.source == json_path
    assert from_toml.source == toml_path


def test_inputs_of_the_conventions_scene():
    model, critical, values = load_scene(BASE).to_inputs()
    assert (model, critical) == ("rigid", False)
    assert values == {
        "m1": 100.0,
        "m2": 150.0,
        "I1": 1800.0,
        "I2": 2600.0,
        "v1x": 50.0,
        "v1y": 0.0,
        "w1": 0.0,
        "v2x": 0.0,
        "v2y": 30.0,
        "w2": 0.0,
        "r1x": 6.0,
        "r1y": 1.0,
        "r2x": -1.5,
        "r2y": -4.0,
        "gamma": 0.0,
        "e": 0.1,
        "mu": 0.3,
        "e_m": 1.0,
    }
    assert all(type(value) is float for value in values.values())


@pytest.mark.parametrize(("degrees", "radians"), [(30.0, math.pi / 6), (-90, -math.pi / 2), (180.0, math.pi)])
def test_normal_angle_degrees_become_radians(degrees, radians):
    # particles: no impact points, so the normal's sense is kept as given
    data = scene_with(("impact", "normal_angle"), degrees)
    data["model"] = "particle"
    scene = load_scene(data)
    assert scene.impact.normal_angle == degrees
    assert scene.to_inputs()[2]["gamma"] == pytest.approx(radians, rel=1e-15, abs=1e-15)


def test_fixed_vehicle_is_infinite_mass_and_inertia():
    data = scene_with(("vehicles", 1), {"name": "barrier", "fixed": True})
    scene = load_scene(data)
    barrier = scene.vehicles[1]
    assert barrier.fixed and barrier.mass is None and barrier.yaw_inertia is None
    _, _, values = scene.to_inputs()
    assert values["m2"] == math.inf and values["I2"] == math.inf
    assert (values["v2x"], values["v2y"], values["w2"]) == (0.0, 0.0, 0.0)
    assert (values["r2x"], values["r2y"]) == (0.0, 0.0)


def test_fixed_vehicle_keeps_given_motion_and_ignores_mass():
    data = scene_with(("vehicles", 1, "fixed"), True)
    values = load_scene(data).to_inputs()[2]
    assert values["m2"] == math.inf and values["I2"] == math.inf
    assert (values["v2x"], values["v2y"]) == (0.0, 30.0)


def test_defaults():
    data = scene_with(("impact", "moment_restitution"), MISSING)
    del data["model"]
    del data["vehicles"][0]["yaw_rate"]
    del data["vehicles"][1]["name"]
    scene = load_scene(data)
    assert scene.model == "rigid"
    assert scene.impact.moment_restitution == 1.0
    assert scene.vehicles[0].yaw_rate == 0.0
    assert scene.vehicles[1].name == "vehicle 2"
    values = scene.to_inputs()[2]
    assert values["e_m"] == 1.0 and values["w1"] == 0.0


def test_particle_model_needs_no_inertia_or_impact_point():
    data = copy.deepcopy(BASE)
    data["model"] = "particle"
    for vehicle in data["vehicles"]:
        for key in ("yaw_inertia", "yaw_rate", "impact_point"):
            del vehicle[key]
    model, critical, values = load_scene(data).to_inputs()
    assert model == "particle" and not critical
    assert set(values) == {"m1", "m2", "v1x", "v1y", "v2x", "v2y", "gamma", "e", "mu"}


def test_particle_model_still_checks_given_values():
    data = scene_with(("vehicles", 0, "yaw_inertia"), -3.0)
    data["model"] = "particle"
    with pytest.raises(SceneError, match=r"^vehicles\[0\]\.yaw_inertia: "):
        load_scene(data)


def test_critical_impulse_ratio():
    scene = load_scene(scene_with(("impact", "impulse_ratio"), "critical"))
    assert scene.impact.critical
    model, critical, values = scene.to_inputs()
    assert critical and math.isfinite(values["mu"])


def test_integer_values_are_accepted_as_floats():
    scene = load_scene(scene_with(("vehicles", 0, "mass"), 100))
    assert scene.to_inputs()[2]["m1"] == 100.0


def test_documented_extras_are_kept_and_unused_keys_reported():
    data = copy.deepcopy(BASE)
    data["description"] = "a test"
    data["vehicles"][0].update(heading=0.0, final_velocity=[20, 5], crush={"A": 1.0})
    scene = load_scene(data)
    extra = scene.vehicles[0].extra
    assert extra["heading"] == 0.0 and extra["final_velocity"] == (20.0, 5.0) and extra["crush"] == {"A": 1.0}
    assert scene.extra == {"description": "a test"}
    assert [w.split(" is given")[0] for w in scene.warnings] == [
        "vehicles[0].final_velocity",
        "vehicles[0].crush",
    ]


@pytest.mark.parametrize(
    ("where", "key", "suggestion"),
    [
        (("impact",), "restitusion", "restitution"),
        (("vehicles", 0), "yaw_rat", "yaw_rate"),
        ((), "unit", "units"),
        (("impact",), "moment_restitutoin", "moment_restitution"),
    ],
)
def test_unknown_key_is_an_error_with_a_suggestion(where, key, suggestion):
    data = copy.deepcopy(BASE)
    target = data
    for step in where:
        target = target[step]
    target[key] = 0.5
    path = ".".join(f"[{s}]" if isinstance(s, int) else s for s in (*where, key)).replace(".[", "[")
    with pytest.raises(SceneError) as info:
        load_scene(data)
    assert str(info.value) == f'{path}: unknown key; did you mean "{suggestion}"?'


def test_load_scene_accepts_a_scene_and_revalidates_it():
    scene = load_scene(BASE)
    assert load_scene(scene) == scene
    bad = Scene(
        scene.model, scene.units, scene.impact, (scene.vehicles[0], Vehicle("car 2", -1.0, 1.0, (0.0, 0.0)))
    )
    with pytest.raises(SceneError, match=r"^vehicles\[1\]\.mass: "):
        load_scene(bad)


def test_to_dict_round_trips():
    scene = load_scene(BASE)
    assert load_scene(json.loads(json.dumps(scene.to_dict()))) == scene
