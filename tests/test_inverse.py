"""Inverse problem: round trips, refusals that name the missing information, CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import impactsym
from impactsym.cli import main
from impactsym.testing import scenes

FWD_IN = ("v1x", "v1y", "w1", "v2x", "v2y", "w2")
FWD_OUT = ("V1x", "V1y", "W1", "V2x", "V2y", "W2")


def _scenes(model, n=300, seed=5):
    c = scenes.random_realistic(n, seed=seed, model=model)
    rng = np.random.default_rng(seed)
    c["e"] = rng.uniform(0.05, 0.6, n)
    if model == "rigid":
        c["e_m"] = np.where(rng.random(n) < 0.5, 1.0, rng.uniform(0.05, 1.0, n))
    return c


def _speed_scale(c, fwd):
    """The scene's speed scale: the largest initial or final speed."""
    return np.max(
        [
            np.hypot(c["v1x"], c["v1y"]),
            np.hypot(c["v2x"], c["v2y"]),
            np.hypot(fwd["V1x"], fwd["V1y"]),
            np.hypot(fwd["V2x"], fwd["V2y"]),
        ],
        axis=0,
    )


def _finals_as_inputs(c, fwd, model):
    out = dict(c)
    for low, up in zip(FWD_IN, FWD_OUT):
        if low in c:
            out[up] = fwd[up]
            del out[low]
    return out


@pytest.mark.parametrize("model", ["rigid", "particle"])
def test_invert_of_forward_gives_back_the_initials(model):
    c = _scenes(model)
    fwd = impactsym.solve_batch(c, model=model)
    assert (fwd["status"] == 0).all()
    inv = impactsym.invert_batch(_finals_as_inputs(c, fwd, model), model=model)
    assert (inv["status"] == 0).all()
    scale = _speed_scale(c, fwd)
    for low in FWD_IN:
        if low in c:
            err = np.abs(inv[low] - c[low]) / scale
            assert err.max() <= 1e-12, (low, err.max())
    for name in ("Pn", "Pt", "TL"):
        np.testing.assert_allclose(inv[name], fwd[name], rtol=1e-9, atol=0, err_msg=name)


@pytest.mark.parametrize("model", ["rigid", "particle"])
def test_forward_of_invert_gives_back_the_finals(model):
    c = _scenes(model, seed=8)
    fwd = impactsym.solve_batch(c, model=model)
    finals = _finals_as_inputs(c, fwd, model)
    inv = impactsym.invert_batch(finals, model=model)
    again = dict(c)
    for low in FWD_IN:
        if low in c:
            again[low] = inv[low]
    fwd2 = impactsym.solve_batch(again, model=model)
    scale = _speed_scale(c, fwd)
    for up in FWD_OUT:
        if up in finals:
            err = np.abs(fwd2[up] - finals[up]) / scale
            assert err.max() <= 1e-12, (up, err.max())


def test_coefficients_that_erase_information_are_refused():
    c = _scenes("rigid", n=6)
    fwd = impactsym.solve_batch(c)
    finals = _finals_as_inputs(c, fwd, "rigid")
    finals["e"] = np.array([0.0, 1e-7, 0.3, 0.3, 0.3, 0.3])
    finals["e_m"] = np.array([1.0, 1.0, 0.0, -1e-8, 1.0, 1.0])
    finals["gamma"] = finals["gamma"].copy()
    finals["gamma"][4] += np.pi  # the finals now approach instead of separating
    out = impactsym.invert_batch(finals)
    assert list(out["status"][:5]) == [7, 7, 8, 8, 3]
    assert out["status"][5] == 0 and np.isfinite(out["v1x"][5])
    assert np.isnan(out["v1x"][:5]).all()
    assert "headings" in impactsym.describe_status(7)
    assert "yaw rates" in impactsym.describe_status(8)


def test_cli_invert_prints_the_documented_object(capsys):
    assert main(["invert", "examples/invert_two_car_si.json", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("vehicles", "impulse", "energy_loss", "warnings"):
        assert key in out
    for vehicle in out["vehicles"]:
        assert {"velocity", "yaw_rate", "delta_v", "delta_v_magnitude"} <= set(vehicle)
    # The example's finals come from v1 = (20, 2), v2 = (-3, 12) m/s, rounded to 1 cm/s.
    assert out["vehicles"][0]["velocity"] == pytest.approx([20.0, 2.0], abs=0.05)
    assert out["vehicles"][1]["velocity"] == pytest.approx([-3.0, 12.0], abs=0.05)


def test_cli_invert_with_zero_restitution_exits_2_naming_what_is_missing(tmp_path, capsys):
    scene = json.loads(Path("examples/invert_two_car_si.json").read_text())
    scene["impact"]["restitution"] = 0.0
    path = tmp_path / "e0.json"
    path.write_text(json.dumps(scene))
    assert main(["invert", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "headings" in err[0] and "denominator" in err[0]


def test_cli_invert_refuses_a_critical_impulse_ratio(tmp_path, capsys):
    scene = json.loads(Path("examples/invert_two_car_si.json").read_text())
    scene["impact"]["impulse_ratio"] = "critical"
    path = tmp_path / "crit.json"
    path.write_text(json.dumps(scene))
    assert main(["invert", str(path)]) == 2
    assert "impact.impulse_ratio" in capsys.readouterr().err


def test_round_trip_on_the_stress_scenes():
    """invert(forward(x)) = x on the accuracy benchmark's stress rows where the
    inverse is determined (e, |e_m| >= 0.05) and the forward result is physical."""
    from benchmarks.sets import stress_set

    columns, families = stress_set()
    fwd = impactsym.solve_batch(columns)
    usable = (
        (fwd["status"] == 0) & (fwd["flags"] == 0) & (columns["e"] >= 0.05) & (np.abs(columns["e_m"]) >= 0.05)
    )
    assert len(set(families[usable])) >= 5, set(families[usable])
    inv = impactsym.invert_batch(_finals_as_inputs(columns, fwd, "rigid"))
    assert (inv["status"][usable] == 0).all()
    scale = _speed_scale(columns, fwd)[usable]
    for low in ("v1x", "v1y", "v2x", "v2y"):
        err = np.abs(inv[low][usable] - columns[low][usable]) / scale
        assert err.max() <= 1e-12, (low, err.max(), families[usable][np.argmax(err)])
