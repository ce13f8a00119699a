"""Issue 22 items 9-11: the words a user reads name the right thing."""

import json
from pathlib import Path

import impactsym
from impactsym import load_scene

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


# --------------------------------------------------------------------------- 9. compare, crash3 notes


def test_compare_on_a_crush_only_scene_names_what_each_model_needs():
    skipped = impactsym.compare(EXAMPLES / "crash3_two_car_us.json").skipped
    for name in ("limpert", "impac", "impac_sideswipe"):  # no coefficients: only the motion
        assert "restitution" not in skipped[name] and "vehicles[0].velocity" in skipped[name], skipped[name]
    for name in ("brach", "macmillan", "particle"):
        assert "impact.restitution" in skipped[name] and "impact.impulse_ratio" in skipped[name]
        assert "vehicles[0].velocity" in skipped[name]


def test_crash3_names_each_unused_coefficient_for_what_it_is():
    data = json.loads((EXAMPLES / "crash3_two_car_us.json").read_text())
    data["impact"].update(restitution=0.1, impulse_ratio=0.3, moment_restitution=1.0, slip=0.2)
    warnings = load_scene(data, kind="crash3").warnings
    for key in ("impulse_ratio", "moment_restitution", "slip"):
        (warning,) = [w for w in warnings if w.startswith(f"impact.{key} ")]
        assert "restitution from" not in warning
    (warning,) = [w for w in warnings if w.startswith("impact.restitution ")]
    assert "crash3 options" in warning
