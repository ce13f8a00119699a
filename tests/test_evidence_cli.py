"""`impactsym fit` on the command line: JSON per the contract, one-line errors, exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.helpers import run_cli_subprocess as run

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "fit_intersection_us.json"


def test_fit_json_has_the_contract_keys():
    proc = run("fit", str(EXAMPLE), "--json", "--draws", "50")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    for key in ("vehicles", "impulse", "restitution", "impulse_ratio", "critical_impulse_ratio",
                "energy_loss", "identifiability", "residuals", "warnings"):  # fmt: skip
        assert key in out
    vehicle = out["vehicles"][1]
    for key in ("speed", "speed_sd", "speed_interval", "velocity", "yaw_rate", "final_velocity",
                "final_yaw_rate", "delta_v", "delta_v_magnitude"):  # fmt: skip
        assert key in vehicle
    low, high = vehicle["speed_interval"]
    assert low < vehicle["speed"] < high
    assert set(out["impulse"]) >= {"x", "y", "normal", "tangential", "moment"}
    ident = out["identifiability"]
    assert set(ident) >= {"unknowns", "rank", "condition", "determined", "not_determined"}
    assert ident["rank"] == 4 and ident["not_determined"] == []
    assert [r["evidence"] for r in out["residuals"]] == list(range(6))


def test_fit_table_for_people():
    proc = run("fit", str(EXAMPLE), "--draws", "20")
    assert proc.returncode == 0, proc.stderr
    assert "90 % interval" in proc.stdout and "determined" in proc.stdout


def test_residual_chart_and_scene_picture(tmp_path):
    pytest.importorskip("matplotlib")
    out, scene = tmp_path / "res.png", tmp_path / "scene.png"
    proc = run("fit", str(EXAMPLE), "--draws", "0", "--plot", str(out), "--scene-plot", str(scene))
    assert proc.returncode == 0, proc.stderr
    assert out.stat().st_size > 1000 and scene.stat().st_size > 1000


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda s: s["evidence"][0].update(quantity="velocity"), "evidence[0].quantity: unknown quantity"),
        (lambda s: s["evidence"][1].pop("sd"), "evidence[1].sd: missing"),
        (lambda s: s["evidence"][2].update(sd="0 mph"), "evidence[2].sd: must be a positive"),
        (lambda s: s["evidence"][3].update(vehicle="bus"), "evidence[3].vehicle: unknown vehicle"),
    ],
)
def test_bad_evidence_exits_2_with_one_line(tmp_path, change, message):
    scene = json.loads(EXAMPLE.read_text())
    change(scene)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene))
    proc = run("fit", str(path), "--json")
    assert proc.returncode == 2
    assert proc.stdout == "" and proc.stderr.count("\n") == 1
    assert message in proc.stderr and "Traceback" not in proc.stderr
