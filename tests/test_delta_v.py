"""Delta-V from energy (seed eqs 27–29) against the forward rigid-body model."""

from __future__ import annotations

import math

import numpy as np
import pytest

import impactsym
from impactsym.testing import scenes


def _approach_ratio(c):
    """r = gt/gn at the impact centre, from the scene columns (test-side kinematics)."""
    nx, ny = np.cos(c["gamma"]), np.sin(c["gamma"])
    gx = (c["v2x"] - c["w2"] * c["r2y"]) - (c["v1x"] - c["w1"] * c["r1y"])
    gy = (c["v2y"] + c["w2"] * c["r2x"]) - (c["v1y"] + c["w1"] * c["r1x"])
    return (gy * nx - gx * ny) / (gx * nx + gy * ny)


def test_forward_energy_loss_gives_back_the_forward_delta_v():
    c = scenes.random_realistic(200, seed=11)
    c = {**c, "e_m": np.ones_like(c["e"])}
    fwd = impactsym.solve_batch(c)
    ok = fwd["status"] == 0
    dv = impactsym.delta_v_from_energy(
        fwd["TL"],
        c["m1"],
        c["m2"],
        e=c["e"],
        mu=c["mu"],
        r=_approach_ratio(c),
        gamma=c["gamma"],
        I1=c["I1"],
        I2=c["I2"],
        r1x=c["r1x"],
        r1y=c["r1y"],
        r2x=c["r2x"],
        r2y=c["r2y"],
    )
    want1 = np.hypot(fwd["V1x"] - c["v1x"], fwd["V1y"] - c["v1y"])
    want2 = np.hypot(fwd["V2x"] - c["v2x"], fwd["V2y"] - c["v2y"])
    solved = ok & (dv["status"] == 0)
    assert solved.sum() > 150
    scale = np.maximum(want1, want2).max()
    assert np.max(np.abs(dv["dV1"][solved] - want1[solved])) < 1e-9 * scale
    assert np.max(np.abs(dv["dV2"][solved] - want2[solved])) < 1e-9 * scale


def test_table2_particle_case_matches_the_seed():
    """e = 0, mu = 1, r = 1: T_L = 192000 ft·lb and |P| = m̄ |gn| √2 (seed Table 2)."""
    out = impactsym.delta_v_from_energy(192000.0, 100.0, 150.0, e=0.0, mu=1.0, r=1.0)
    expected = 60.0 * math.sqrt(3200.0) * math.sqrt(2.0)
    assert out["dV1"] == pytest.approx(expected / 100.0, rel=1e-14)
    assert out["dV2"] == pytest.approx(expected / 150.0, rel=1e-14)
    assert out["q"] == pytest.approx(1.0, rel=1e-15)


def test_negative_energy_is_an_error_not_nan():
    with pytest.raises(ValueError, match="energy loss"):
        impactsym.delta_v_from_energy(-1.0, 100.0, 150.0)
    arr = impactsym.delta_v_from_energy(np.array([1.0, -1.0]), 100.0, 150.0)
    assert list(arr["status"]) == [0, 6] and np.isfinite(arr["dV1"][0])
