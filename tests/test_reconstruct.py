"""Reconstruction of pre-impact speeds from post-impact motion and headings."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import impactsym
from impactsym.cli import main
from impactsym.testing import scenes


def _forward_then_columns(n=300, seed=21):
    """Forward-solve realistic scenes (e in [0.05, 0.5]), then build the
    reconstruction inputs a reconstructionist would have: finals and headings."""
    c = scenes.random_realistic(n, seed=seed)
    fwd = impactsym.solve_batch(c)
    speed1, speed2 = np.hypot(c["v1x"], c["v1y"]), np.hypot(c["v2x"], c["v2y"])
    cols = {k: c[k] for k in ("m1", "m2", "I1", "I2", "w1", "w2", "r1x", "r1y", "r2x", "r2y", "gamma")}
    cols.update({k: fwd[k] for k in ("V1x", "V1y", "W1", "V2x", "V2y", "W2")})
    cols["theta1"] = np.arctan2(c["v1y"], c["v1x"])
    cols["theta2"] = np.arctan2(c["v2y"], c["v2x"])
    return c, fwd, cols, speed1, speed2


def test_reconstruction_recovers_speeds_and_coefficients():
    c, fwd, cols, speed1, speed2 = _forward_then_columns()
    rec = impactsym.reconstruct_batch(cols)
    # Keep scenes that are well conditioned for this method: both vehicles moving,
    # headings at least ~6 degrees from collinear (flag 32 marks the others).
    usable = (rec["status"] == 0) & ((rec["flags"] & 32) == 0) & (speed1 > 1) & (speed2 > 1)
    assert usable.sum() > 200
    scale = np.maximum(speed1, speed2)[usable]
    assert np.max(np.abs(rec["s1"][usable] - speed1[usable]) / scale) < 1e-9
    assert np.max(np.abs(rec["s2"][usable] - speed2[usable]) / scale) < 1e-9
    np.testing.assert_allclose(rec["e"][usable], c["e"][usable], rtol=0, atol=1e-8)
    np.testing.assert_allclose(
        rec["mu"][usable], c["mu"][usable], rtol=0, atol=1e-8 * np.maximum(1, np.abs(c["mu"][usable])).max()
    )
    np.testing.assert_allclose(rec["mu_c"][usable], fwd["mu_c"][usable], rtol=1e-6)
    moment_scale = np.abs(fwd["Pn"][usable]) * 3.0
    assert np.max(np.abs(rec["M"][usable] - fwd["M"][usable]) / moment_scale) < 1e-9
    assert np.max(np.abs(rec["M_residual"][usable]) / moment_scale) < 1e-9
    np.testing.assert_allclose(rec["TL"][usable], fwd["TL"][usable], rtol=1e-7)


def test_collinear_headings_are_refused_and_other_rows_solved():
    _, _, cols, _, _ = _forward_then_columns(n=4)
    cols = {k: np.array(v, dtype=float) for k, v in cols.items()}
    cols["theta2"][0] = cols["theta1"][0] + np.pi
    rec = impactsym.reconstruct_batch(cols)
    assert rec["status"][0] == 9 and np.isnan(rec["s1"][0])
    assert "collinear" in impactsym.describe_status(9)


def test_cli_reconstruct_prints_the_documented_object(capsys):
    assert main(["reconstruct", "examples/reconstruct_two_car_si.json", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in (
        "vehicles",
        "impulse",
        "restitution",
        "impulse_ratio",
        "critical_impulse_ratio",
        "energy_loss",
        "warnings",
    ):
        assert key in out, key
    for vehicle in out["vehicles"]:
        assert {"speed", "velocity", "delta_v", "delta_v_magnitude"} <= set(vehicle)
    # The example's finals come from 18 and 12 m/s, e = 0.1, mu = 0.2 (rounded to 1 cm/s).
    assert [v["speed"] for v in out["vehicles"]] == pytest.approx([18.0, 12.0], abs=0.02)
    assert out["restitution"] == pytest.approx(0.1, abs=0.005)
    assert out["impulse_ratio"] == pytest.approx(0.2, abs=0.005)


def test_a_fixed_vehicle_cannot_be_reconstructed(tmp_path, capsys):
    scene = json.loads(Path("examples/reconstruct_two_car_si.json").read_text())
    scene["vehicles"][1] = {"name": "wall", "fixed": True}
    path = tmp_path / "wall.json"
    path.write_text(json.dumps(scene))
    assert main(["reconstruct", str(path)]) == 2
    assert "vehicles[1]" in capsys.readouterr().err
