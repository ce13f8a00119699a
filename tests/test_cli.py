"""The command line: every example solves to the documented JSON; bad scenes fail in one line."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from impactsym.codes import FLAG_MESSAGES
from impactsym.laws.scene import is_law_scene, load_law_scene
from impactsym.scene import load_scene
from tests.helpers import forward_examples
from tests.helpers import run_cli as run

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
EXAMPLE_FILES = forward_examples()
ENERGY_CREATED = 1

CONVENTIONS_SCENE = json.loads((EXAMPLES / "two_car_us.json").read_text())


def solve_json(capsys, path):
    """The parsed ``solve --json`` output of a scene file that must solve."""
    code, out, err = run(capsys, "solve", path, "--json")
    assert (code, err) == (0, "")
    return json.loads(out)


def assert_documented_shape(result):
    """The ``solve --json`` object of conventions.md, with finite numbers where documented."""
    assert len(result["vehicles"]) == 2
    for vehicle in result["vehicles"]:
        assert {"velocity", "yaw_rate", "delta_v", "delta_v_magnitude"} <= set(vehicle)
        assert len(vehicle["velocity"]) == 2 and len(vehicle["delta_v"]) == 2
        numbers = [*vehicle["velocity"], *vehicle["delta_v"], vehicle["delta_v_magnitude"]]
        assert all(isinstance(x, float) and math.isfinite(x) for x in numbers)
    assert set(result["impulse"]) == {"normal", "tangential", "moment"}
    assert set(result["energy_loss"]) == {"total", "normal", "tangential", "moment"}
    scalars = [
        *result["impulse"].values(),
        *result["energy_loss"].values(),
        result["impulse_ratio"],
        result["critical_impulse_ratio"],
    ]
    assert all(isinstance(x, float) and math.isfinite(x) for x in scalars)
    assert isinstance(result["warnings"], list) and all(isinstance(w, str) for w in result["warnings"])


def test_examples_exist():
    names = {path.name for path in EXAMPLE_FILES}
    assert {
        "table2_e0_mu1.json",
        "table2_e1_mu1p5.toml",
        "two_car_us.json",
        "intersection_si.toml",
        "barrier_si.json",
    } <= names


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda path: path.name)
def test_every_example_prints_the_documented_json(capsys, path):
    result = solve_json(capsys, path)
    assert_documented_shape(result)
    # velocities in the scene frame and units, whatever the file's form (a law scene: its rigid reading)
    scene = load_law_scene(path).scene if is_law_scene(path) else load_scene(path)
    for given, solved in zip(scene.vehicles, result["vehicles"]):
        initial = given.velocity
        final = solved["velocity"]
        assert solved["delta_v"] == [final[0] - initial[0], final[1] - initial[1]]
        assert solved["delta_v_magnitude"] == pytest.approx(math.hypot(*solved["delta_v"]), rel=1e-15)


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda path: path.name)
def test_every_example_prints_a_table(capsys, path):
    code, out, err = run(capsys, "solve", path)
    assert (code, err) == (0, "")
    assert "energy loss" in out and "warnings" in out


def test_table2_e0_mu1_energy_loss(capsys):
    """Seed Table 2: e = 0, μ = 1 gives TL = 192000 ft·lb with μ_max = 1/(1 + e) = 1."""
    result = solve_json(capsys, EXAMPLES / "table2_e0_mu1.json")
    assert result["energy_loss"]["total"] == pytest.approx(192000.0, rel=1e-6)
    assert result["critical_impulse_ratio"] == pytest.approx(1.0, rel=1e-9)
    assert result["impulse_ratio"] == 1.0


def test_table2_e1_mu1p5_creates_energy_and_warns(capsys):
    """Seed Table 2: e = 1, μ = 1.5 > μ_max = 0.5 gives TL = -288000 ft·lb, physically unrealistic."""
    result = solve_json(capsys, EXAMPLES / "table2_e1_mu1p5.toml")
    assert result["energy_loss"]["total"] == pytest.approx(-288000.0, rel=1e-6)
    assert result["critical_impulse_ratio"] == pytest.approx(0.5, rel=1e-9)
    assert FLAG_MESSAGES[ENERGY_CREATED] in result["warnings"]


def test_table_has_us_unit_labels_and_warnings(capsys):
    code, out, _ = run(capsys, "solve", EXAMPLES / "table2_e1_mu1p5.toml")
    assert code == 0
    assert "ft/s" in out and "lb·s" in out and "ft·lb" in out
    assert FLAG_MESSAGES[ENERGY_CREATED] in out


def test_table_has_si_unit_labels(capsys):
    code, out, _ = run(capsys, "solve", EXAMPLES / "intersection_si.toml")
    assert code == 0
    assert "m/s" in out and "N·s" in out and "[J]" in out and "ft" not in out


def test_conventions_scene_conserves_momentum(capsys):
    result = solve_json(capsys, EXAMPLES / "two_car_us.json")
    masses = [vehicle["mass"] for vehicle in CONVENTIONS_SCENE["vehicles"]]
    for axis in (0, 1):
        total = sum(m * v["delta_v"][axis] for m, v in zip(masses, result["vehicles"]))
        assert total == pytest.approx(0.0, abs=1e-9 * masses[0] * 50.0)


def test_barrier_keeps_still_and_warns_about_nothing(capsys):
    result = solve_json(capsys, EXAMPLES / "barrier_si.json")
    assert result["vehicles"][1]["velocity"] == [0.0, 0.0]
    assert result["vehicles"][1]["delta_v_magnitude"] == 0.0
    assert result["warnings"] == []


def test_python_dash_m_runs_the_cli():
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    )
    done = subprocess.run(
        [sys.executable, "-m", "impactsym", "solve", str(EXAMPLES / "two_car_us.json"), "--json"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert_documented_shape(json.loads(done.stdout))


def scene_variant(edit):
    """The conventions scene after ``edit(data)``."""
    data = json.loads(json.dumps(CONVENTIONS_SCENE))
    edit(data)
    return json.dumps(data)


BAD_SCENES = {
    "nan_mass.json": (
        json.dumps(CONVENTIONS_SCENE).replace('"mass": 100.0', '"mass": NaN'),
        "vehicles[0].mass",
    ),
    "missing_field.json": (
        scene_variant(lambda d: d["impact"].pop("restitution")),
        "impact.restitution: missing",
    ),
    "unknown_units.json": (
        scene_variant(lambda d: d.update(units="metric")),
        "units: unknown units 'metric'",
    ),
    "not_approaching.json": (
        scene_variant(lambda d: d["vehicles"][0].update(velocity=[-50.0, 0.0])),
        "not approaching",
    ),
    "malformed.json": ('{"model": "rigid", "units": "US",', "invalid JSON"),
    "malformed.toml": ('units = "US"\n[[vehicles]\n', "invalid TOML"),
    "wrong_count.toml": (
        'units = "SI"\n[impact]\nnormal_angle = 0\nrestitution = 0\nimpulse_ratio = 0\n'
        "[[vehicles]]\nmass = 1\nvelocity = [1, 0]\n",
        "vehicles: must be a list of exactly 2",
    ),
}


def assert_one_line_error(code, out, err, text):
    assert code == 2
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("impactsym: error: ")
    assert text in lines[0]
    assert "Traceback" not in err


@pytest.mark.parametrize("name", sorted(BAD_SCENES))
@pytest.mark.parametrize("as_json", [True, False], ids=["json", "table"])
def test_bad_scene_exits_2_with_one_line(capsys, tmp_path, name, as_json):
    content, text = BAD_SCENES[name]
    path = tmp_path / name
    path.write_text(content)
    argv = ["solve", path] + (["--json"] if as_json else [])
    assert_one_line_error(*run(capsys, *argv), text)


def test_bad_scene_in_a_subprocess_has_no_traceback(tmp_path):
    path = tmp_path / "nan_mass.json"
    path.write_text(BAD_SCENES["nan_mass.json"][0])
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    )
    done = subprocess.run(
        [sys.executable, "-m", "impactsym", "solve", str(path), "--json"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        timeout=300,
    )
    assert_one_line_error(done.returncode, done.stdout, done.stderr, "vehicles[0].mass")


@pytest.mark.parametrize(
    ("argv", "text"),
    [
        ([], "required"),
        (["bogus"], "invalid choice"),
        (["solve"], "required"),
        (["solve", "x.json", "--jsn"], "unrecognized arguments"),
    ],
)
def test_argument_problems_exit_2_with_one_line(capsys, argv, text):
    assert_one_line_error(*run(capsys, *argv), text)


def test_missing_file_exits_2_with_one_line(capsys, tmp_path):
    path = tmp_path / "absent.json"
    assert_one_line_error(*run(capsys, "solve", path, "--json"), str(path))


def test_help_exits_0(capsys):
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "solve" in out
