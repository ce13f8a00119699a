"""Issue 22 item 4: rounding residue of a zero (relative to the scene's own
scale) is printed and drawn as 0 in every command, picture and --json."""

import json
import re

import matplotlib
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import impactsym
from impactsym import plot
from impactsym.cli import main
from impactsym.residue import drop_residue, path_quantity, quantity_scales, without_json_residue

matplotlib.use("Agg")

# a car struck through its centre of gravity along the normal: it does not
# rotate, so its final yaw rate and μ_c are zero up to rounding
NO_ROTATION = {
    "model": "rigid",
    "units": "SI",
    "impact": {
        "normal_angle": 30.0,
        "restitution": {"uniform": [0.1, 0.3]},
        "impulse_ratio": 0.0,
        "moment_restitution": 0.0,
    },
    "vehicles": [
        {
            "name": "a",
            "mass": 1000,
            "yaw_inertia": 1500,
            "velocity": {"speed": 10, "direction": 30},
            "yaw_rate": 0,
            "heading": 30,
            "impact_point": {"distance": 1.5, "angle": 0},
        },
        {
            "name": "b",
            "mass": 1200,
            "yaw_inertia": 1800,
            "velocity": [0, 0],
            "yaw_rate": 0,
            "heading": 30,
            "impact_point": {"distance": 2, "angle": 180},
        },
    ],
}
RESIDUE_TEXT = re.compile(r"[0-9]e-1[0-9]|-0\.0\b|-0(?![.0-9])")


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "no_rotation.json"
    path.write_text(json.dumps(NO_ROTATION))
    return path


def test_the_scene_really_has_residue():
    result = impactsym.solve(NO_ROTATION)
    assert 0 < abs(result.vehicles[0].yaw_rate) < 1e-14  # the API keeps the computed value


@pytest.mark.parametrize(
    "extra",
    [
        [],
        ["--json"],
        ["--uncertainty", "--draws", "200", "--seed", "1"],
        ["--uncertainty", "--draws", "200", "--seed", "1", "--json"],
    ],
    ids=["table", "json", "uncertainty-table", "uncertainty-json"],
)
def test_commands_print_residue_as_zero(scene_file, capsys, extra):
    assert main(["solve", str(scene_file), *extra]) == 0
    out = capsys.readouterr().out
    assert not RESIDUE_TEXT.search(out), RESIDUE_TEXT.search(out)
    if "--json" in extra:
        data = json.loads(out)
        assert data["vehicles"][0]["yaw_rate"] == 0.0
        assert data["critical_impulse_ratio"] == 0.0
        if "--uncertainty" in extra:
            assert data["uncertainty"]["outputs"]["vehicles[0].yaw_rate"]["nominal"] == 0.0


def test_the_scene_picture_draws_no_residue_yaw_arc(scene_file):
    fig = Figure(figsize=(9.0, 6.5), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    ax = plot.scene(impactsym.solve(scene_file), fig.add_subplot(), scene=scene_file)
    texts = [t.get_text() for t in ax.texts] + [t.get_text() for t in ax.get_legend().get_texts()]
    assert not [t for t in texts if RESIDUE_TEXT.search(t)]
    assert not [t for t in texts if "yaw rate" in t]


def test_the_rule_keeps_small_true_values():
    assert drop_residue(-0.0, 1.0) == 0.0 and str(drop_residue(-0.0, 1.0)) == "0.0"
    assert drop_residue(1e-9, 50.0) == 1e-9 and drop_residue(4e-16, 10.0) == 0.0
    # a yaw rate is judged at least against the speeds per unit length
    scales = quantity_scales([("speed", 10.0), ("yaw_rate", 4e-16)])
    assert drop_residue(4e-16, scales["yaw_rate"]) == 0.0 and drop_residue(1e-6, scales["yaw_rate"]) == 1e-6
    assert path_quantity("vehicles[1].yaw_rate") == "yaw_rate" and path_quantity("impulse.moment") == "moment"
    assert path_quantity("energy_loss.total") == "energy" and path_quantity("flags") is None
    kept = without_json_residue({"energy_loss": {"total": 3e-20}, "other": 1e-20})
    assert kept == {"energy_loss": {"total": 3e-20}, "other": 1e-20}  # its own scale; unknown keys untouched


def test_compare_shows_residue_as_zero(tmp_path, capsys):
    data = json.loads(json.dumps(NO_ROTATION))
    data["impact"]["restitution"] = 0.2
    path = tmp_path / "plain.json"
    path.write_text(json.dumps(data))
    assert main(["compare", str(path)]) == 0
    table = capsys.readouterr().out
    assert "-0.00" not in table and not RESIDUE_TEXT.search(table)
    assert main(["compare", str(path), "--json"]) == 0
    models = json.loads(capsys.readouterr().out)["models"]
    assert all(v["yaw_rate"] in (0.0, None) for m in models for v in m["vehicles"])
