"""The seed's named models as presets: each equals the general model with its
coefficients, IMPAC's sideswipe form meets its constraints and reduces to the
common-velocity form at slip = 0, and scenes, the API and the CLI select them by name."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

import impactsym
from derive import presets as derive_presets
from generated.presets import PRESETS
from impactsym.cli import main
from impactsym.scene import SceneError, load_scene
from impactsym.testing import reference as R
from impactsym.testing.scenes import random_realistic

ROOT = Path(__file__).resolve().parents[1]
TWO_CAR = json.loads((ROOT / "examples" / "two_car_us.json").read_text())
FINALS = ("V1x", "V1y", "W1", "V2x", "V2y", "W2", "Pn", "Pt", "M", "mu", "mu_c", "TL", "TLn", "TLt", "TLm")
COEFFICIENTS = ("e", "mu", "e_m")
TOL = 1e-12  # of each output's natural scale, as in tests/test_accuracy.py
REFERENCE_ROWS = 40  # two 50-digit solves a row


def scenes(n=400, seed=7, barrier=False):
    """Random realistic rigid scenes (SI) without the coefficients."""
    cols = random_realistic(n, seed, model="rigid", barrier=barrier)
    return {k: v for k, v in cols.items() if k not in COEFFICIENTS}, cols


def assert_same(a, b, rows=slice(None)):
    """Two batch results agree row by row to rounding (relative to each column's scale)."""
    assert np.array_equal(a["status"][rows], b["status"][rows])
    for name in FINALS:
        x, y = np.asarray(a[name])[rows], np.asarray(b[name])[rows]
        scale = np.nanmax(np.abs(y)) or 1.0
        assert np.allclose(x, y, rtol=0, atol=1e-12 * scale, equal_nan=True), name


@pytest.mark.parametrize("barrier", [False, True], ids=["two cars", "barrier"])
@pytest.mark.parametrize("model", ["limpert", "impac"])
def test_common_velocity_presets_are_the_general_model_at_e0_critical_em1(model, barrier):
    geometry, _ = scenes(barrier=barrier)
    preset = impactsym.solve_batch(geometry, model=model)
    general = impactsym.solve_batch({**geometry, "e": 0.0, "mu": "critical", "e_m": 1.0})
    assert (preset["status"] == 0).mean() > 0.9
    assert_same(preset, general)
    assert np.all(preset["M"][preset["status"] == 0] == 0.0)


def assert_matches_reference(out, cols, **fixed):
    """Every row of a batch result within TOL of its natural scale of the 50-digit
    reference solver (impactsym.testing.reference: an mpmath LU solve of the
    impulse-momentum equations, sharing no algebra with the kernels) on the same
    scene with the coefficients ``fixed`` (the ones a preset sets)."""
    for i in range(len(out["status"])):
        row = {**R.row_of(cols, i), **fixed}
        ref = R.solve_reference(row, "rigid")
        scales = R.natural_scales(row, ref, "rigid")
        errors = R.relative_errors({key: float(out[key][i]) for key in scales}, ref, scales)
        assert out["status"][i] == 0 and max(errors.values()) <= TOL, (i, errors)


def first(cols, n=REFERENCE_ROWS):
    return {key: value[:n] for key, value in cols.items()}


def test_macmillan_is_the_general_model_at_em1():
    """Macmillan's preset against the reference at e_m = 1 (the scenes' own e_m,
    not given to the preset, is not 1 in most of these rows: had the preset
    solved with it, those rows would differ)."""
    geometry, cols = scenes()
    geometry, cols = first(geometry), first(cols)
    assert np.mean(cols["e_m"] != 1.0) > 0.5
    preset = impactsym.solve_batch({**geometry, "e": cols["e"], "mu": cols["mu"]}, model="macmillan")
    assert_matches_reference(preset, cols, e_m=1.0)


def test_brach_is_the_general_rigid_model():
    """Brach's preset fixes nothing: it solves the scenes' own e, mu, e_m as the reference does."""
    _, cols = scenes()
    cols = first(cols)
    assert_matches_reference(impactsym.solve_batch(cols, model="brach"), cols)


@pytest.mark.parametrize("barrier", [False, True], ids=["two cars", "barrier"])
def test_sideswipe_at_slip_zero_is_the_common_velocity_form(barrier):
    geometry, _ = scenes(barrier=barrier)
    sideswipe = impactsym.solve_batch({**geometry, "slip": 0.0}, model="impac_sideswipe")
    common = impactsym.solve_batch(geometry, model="impac")
    assert_same(sideswipe, common)


def contact_relative_velocity(c, out, i, final):
    """n and t components of u2 - u1 at the impact centre, u = v + w (-ry, rx),
    before (c) or after (out) the impact of row i (independent of the kernels)."""
    n = out["V1x"].shape

    def col(name):
        return np.broadcast_to(c[name], n)[i]

    def motion(name):  # "v1x" -> out["V1x"] after the impact
        return out[name[0].upper() + name[1:]][i] if final else col(name)

    u = []
    for b in ("1", "2"):
        vx, vy, w = motion(f"v{b}x"), motion(f"v{b}y"), motion(f"w{b}")
        u.append((vx - w * col(f"r{b}y"), vy + w * col(f"r{b}x")))
    gx, gy = u[1][0] - u[0][0], u[1][1] - u[0][1]
    g = col("gamma")
    return gx * math.cos(g) + gy * math.sin(g), -gx * math.sin(g) + gy * math.cos(g)


def test_sideswipe_meets_its_constraints_and_conserves_momentum():
    geometry, _ = scenes(n=200, seed=11)
    slip = np.random.default_rng(3).uniform(0.0, 1.0, 200)
    out = impactsym.solve_batch({**geometry, "slip": slip}, model="impac_sideswipe")
    solved = np.flatnonzero(out["status"] == 0)
    assert solved.size > 150
    for i in solved:
        gn, gt = contact_relative_velocity(geometry, out, i, final=False)
        Gn, Gt = contact_relative_velocity(geometry, out, i, final=True)
        speed = math.hypot(gn, gt)
        assert abs(Gn) <= 1e-11 * speed
        assert abs(Gt - slip[i] * gt) <= 1e-11 * speed
    m1, m2 = (np.broadcast_to(geometry[k], slip.shape)[solved] for k in ("m1", "m2"))
    for axis in "xy":
        before = m1 * geometry[f"v1{axis}"][solved] + m2 * geometry[f"v2{axis}"][solved]
        after = m1 * out[f"V1{axis}"][solved] + m2 * out[f"V2{axis}"][solved]
        assert np.allclose(after, before, rtol=1e-12, atol=1e-9 * np.abs(before).max())
    assert np.all(out["M"][solved] == 0.0)
    assert np.allclose(out["TL"][solved], (out["TLn"] + out["TLt"])[solved], rtol=1e-12)


def test_a_wrong_sideswipe_formula_fails_its_proof(monkeypatch):
    """The sideswipe proofs are not vacuous: halve the slip term and they fail."""
    good = derive_presets._impulse_blocks

    def wrong():
        blocks = good()
        first = blocks[0]
        bad = tuple((s, x.xreplace({derive_presets.slip: derive_presets.slip / 2})) for s, x in first.assigns)
        return (type(first)(bad, first.guard),) + blocks[1:]

    monkeypatch.setattr(derive_presets, "_impulse_blocks", wrong)
    monkeypatch.setattr(derive_presets, "KERNELS", (derive_presets.sideswipe_kernel(),))
    results = dict(derive_presets._sideswipe_claims())
    assert not results["impac_sideswipe: momentum, angular impulse and M = 0 hold; Gn = 0 and Gt = slip*gt"]


# ---------------------------------------------------------------- scenes and CLI


def scene_of(model, **impact):
    return {**TWO_CAR, "model": model, "impact": {"normal_angle": 0.0, **impact}}


@pytest.mark.parametrize("model", sorted(PRESETS))
def test_every_model_name_solves_from_a_scene(model):
    impact = {"restitution": 0.1, "impulse_ratio": -0.2} if PRESETS[model]["required"] else {}
    result = impactsym.solve(scene_of(model, **impact))
    assert result.model == model
    assert all(math.isfinite(v.delta_v_magnitude) for v in result.vehicles)
    assert (result.vehicles[0].yaw_rate != 0.0) == (model != "particle")


def test_preset_fixes_its_coefficients_and_warns_about_given_ones():
    result = impactsym.solve(scene_of("limpert", restitution=0.3, impulse_ratio=0.5))
    general = impactsym.solve(scene_of("rigid", restitution=0.0, impulse_ratio="critical"))
    assert result.vehicles[0].velocity == general.vehicles[0].velocity
    assert any("restitution = 0.3 is not used: the limpert model fixes it" in w for w in result.warnings)
    assert result.critical and result.mu == result.mu_c


def test_preset_given_its_own_fixed_values_does_not_warn():
    result = impactsym.solve(scene_of("limpert", restitution=0.0, impulse_ratio="critical"))
    assert result.warnings == []


def test_macmillan_needs_restitution_and_impulse_ratio():
    with pytest.raises(SceneError, match=r"impact.restitution: missing"):
        load_scene(scene_of("macmillan", impulse_ratio=0.1))


def test_slip_is_only_for_the_sideswipe_model():
    result = impactsym.solve(scene_of("rigid", restitution=0.1, impulse_ratio=-0.2, slip=0.5))
    assert "impact.slip is not used by the rigid model" in result.warnings


def test_slip_outside_zero_one_warns():
    result = impactsym.solve(scene_of("impac_sideswipe", slip=1.5))
    assert any("impact.slip = 1.5 is outside [0, 1]" in w for w in result.warnings)


def test_unknown_model_lists_the_names():
    with pytest.raises(SceneError, match="limpert"):
        load_scene(scene_of("woolley"))


def test_sideswipe_has_no_inverse():
    data = {
        **scene_of("impac_sideswipe"),
        "vehicles": [
            {**v, "final_velocity": v["velocity"], "final_yaw_rate": 0.0} for v in TWO_CAR["vehicles"]
        ],
    }
    with pytest.raises(SceneError, match="no inverse solution"):
        impactsym.invert(data)


def test_batch_preset_refuses_a_column_it_fixes():
    geometry, _ = scenes(n=3)
    with pytest.raises(ValueError, match="e: the limpert model fixes e"):
        impactsym.solve_batch({**geometry, "e": 0.2}, model="limpert")


def test_batch_preset_keeps_a_dataframe_index():
    pd = pytest.importorskip("pandas")
    geometry, _ = scenes(n=4)
    frame = pd.DataFrame(geometry, index=list("abcd"))
    out = impactsym.solve_batch(frame, model="impac")
    assert list(out.index) == list("abcd") and "TL" in out


def test_a_preset_scene_round_trips_through_to_dict():
    scene = load_scene(scene_of("impac_sideswipe", slip=0.25))
    again = load_scene(scene.to_dict())
    assert again.impact == scene.impact and again.warnings == ()


@pytest.mark.parametrize(
    "name", ["limpert_two_car_us.json", "macmillan_intersection_si.json", "impac_sideswipe_si.json"]
)
def test_model_examples_solve_without_warnings(capsys, name):
    assert main(["solve", str(ROOT / "examples" / name), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["model"] == json.loads((ROOT / "examples" / name).read_text())["model"]
    assert out["warnings"] == []
