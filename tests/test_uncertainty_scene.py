"""Uncertainty through scene files: the API and ``--uncertainty`` on the four commands."""

import json
from pathlib import Path

import pytest

import impactsym
from tests.helpers import run_cli_subprocess

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
INTEGER_CODES = ("flags", "pdof_clock")


def _numeric_paths(obj, prefix=""):
    """Paths of every number of a JSON object, as conventions.md names them."""
    if isinstance(obj, dict):
        for key, value in obj.items():
            if key not in INTEGER_CODES:
                yield from _numeric_paths(value, f"{prefix}.{key}" if prefix else key)
    elif isinstance(obj, list):
        for i, value in enumerate(obj):
            yield from _numeric_paths(value, f"{prefix}[{i}]")
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool):
        yield prefix


def _uncertain(name: str, edit) -> dict:
    data = json.loads((EXAMPLES / name).read_text())
    edit(data)
    return data


def _forward(d):
    # The example's mu = 0.3 is beyond critical (mu_c = -0.206): half of mu_c is physical.
    d["impact"]["impulse_ratio"] = {"normal": [-0.103, 0.01]}
    d["impact"]["restitution"] = {"uniform": [0.05, 0.15]}
    d["vehicles"][0]["mass"] = {"normal": [d["vehicles"][0]["mass"], 2.0]}


def _inverse(d):
    d["impact"]["restitution"] = {"uniform": [0.15, 0.25]}


def _crash3(d):
    d["vehicles"][0]["crush"]["pdof"] = {"normal": [d["vehicles"][0]["crush"]["pdof"], 5.0]}


# CRASH3's restitution is an option, not a result; the impulse-momentum
# comparison fields come from a separate forward solve (docs/uncertainty.md).
NOT_PROPAGATED = {
    "crash3": {"restitution", "options.restitution"}
    | {
        f"vehicles[{i}].{key}"
        for i in (0, 1)
        for key in ("pdof_implied", "delta_v_magnitude_impulse_momentum")
    }
}

CASES = [
    ("solve", "two_car_us.json", _forward),
    ("invert", "invert_two_car_si.json", _inverse),
    ("reconstruct", "reconstruct_intersection_uncertain.json", lambda d: None),
    ("crash3", "crash3_two_car_us.json", _crash3),
]


@pytest.mark.parametrize("command,name,edit", CASES, ids=[c[0] for c in CASES])
def test_every_numeric_output_has_an_entry(tmp_path, command, name, edit):
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(_uncertain(name, edit)))
    run = run_cli_subprocess(command, "--uncertainty", "--draws", "3000", "--seed", "5", "--json", scene)
    assert run.returncode == 0, run.stderr
    obj = json.loads(run.stdout)
    u = obj.pop("uncertainty")
    assert set(u["outputs"]) == set(_numeric_paths(obj)) - NOT_PROPAGATED.get(command, set())
    assert u["draws"] == 3000 and 0 < u["accepted"] <= 3000
    for entry in u["outputs"].values():
        assert entry["p5"] is None or entry["p5"] <= entry["p50"] <= entry["p95"]
        if entry["budget"]:
            assert abs(sum(entry["budget"].values()) - 1) < 1e-9


def test_api_reconstruction_speeds_and_plot(tmp_path):
    from impactsym.uncertainty.plot import save_uncertainty_plot

    u = impactsym.uncertainty(
        EXAMPLES / "reconstruct_intersection_uncertain.json", command="reconstruct", draws=20_000, seed=3
    )
    assert "vehicles[0].final_velocity.speed" in u.inputs
    nominal = impactsym.reconstruct(EXAMPLES / "reconstruct_intersection_uncertain.json")
    speed = u.outputs["vehicles[0].speed"]
    assert speed["nominal"] == pytest.approx(nominal.vehicles[0].speed, rel=1e-12)
    assert speed["p5"] < speed["nominal"] < speed["p95"]
    save_uncertainty_plot(u, tmp_path / "u.png")
    assert (tmp_path / "u.png").stat().st_size > 10_000


def test_bad_draws_is_a_one_line_error(tmp_path):
    scene = EXAMPLES / "reconstruct_intersection_uncertain.json"
    run = run_cli_subprocess("reconstruct", "--uncertainty", "--draws", "1", scene)
    assert run.returncode == 2
    assert run.stderr.count("\n") == 1 and "draws" in run.stderr


def test_a_scene_without_distributions_is_refused(tmp_path):
    run = run_cli_subprocess("solve", "--uncertainty", EXAMPLES / "two_car_us.json")
    assert run.returncode == 2
    assert "no uncertain inputs" in run.stderr
