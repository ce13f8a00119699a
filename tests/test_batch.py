"""solve_batch: row statuses, model agreement, column errors, no compile for one scene."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import impactsym
from impactsym import codes
from impactsym.testing import scenes

ROOT = Path(__file__).resolve().parent.parent
OUTPUTS = ("V1x", "V1y", "W1", "V2x", "V2y", "W2", "Pn", "Pt", "M",
           "mu", "mu_c", "TL", "TLn", "TLt", "TLm")


def _rigid(n=8, seed=3):
    return {k: v.copy() for k, v in scenes.random_realistic(n, seed=seed).items()}


def test_bad_rows_get_a_status_and_the_other_rows_are_untouched():
    c = _rigid(200)  # large enough for the parallel driver
    good = impactsym.solve_batch(c)
    assert (good["status"] == 0).all()
    c["m1"][1] = np.nan
    c["I2"][2] = 0.0
    c["m2"][3], c["I2"][3] = np.inf, 5.0          # infinite mass, finite inertia
    c["m1"][4] = c["I1"][4] = c["m2"][4] = c["I2"][4] = np.inf   # both fixed
    c["gamma"][5] += np.pi                         # separating instead of approaching
    c["v1x"][6] = np.inf
    out = impactsym.solve_batch(c)
    assert list(out["status"][1:7]) == [1, 2, 2, 4, 3, 1]
    bad = np.zeros(200, bool)
    bad[1:7] = True
    for name in OUTPUTS:
        assert np.isnan(out[name][bad]).all(), name
        np.testing.assert_array_equal(out[name][~bad], good[name][~bad], err_msg=name)
    assert (out["flags"][bad] == 0).all()
    for code in out["status"][bad]:
        assert codes.describe_status(code) != "solved"


PARTICLE_COLUMNS = ("m1", "m2", "v1x", "v1y", "v2x", "v2y", "gamma", "e", "mu")


@pytest.mark.parametrize("critical", [False, True])
def test_rigid_with_zero_lever_arms_is_the_particle_model(critical):
    """Seed eqs 10-15: central impacts of rigid bodies are particle impacts."""
    c = _rigid(300)
    for k in ("r1x", "r1y", "r2x", "r2y"):
        c[k] = np.zeros_like(c[k])
    c["e_m"] = np.ones_like(c["e"])
    if critical:
        c["mu"] = "critical"
    rigid = impactsym.solve_batch(c, model="rigid")
    # Only the particle model's columns: the yaw columns would be refused as not used.
    particle = impactsym.solve_batch({k: c[k] for k in PARTICLE_COLUMNS}, model="particle")
    ok = (rigid["status"] == 0) & (particle["status"] == 0)
    assert ok.sum() > 250
    for name in ("V1x", "V1y", "V2x", "V2y", "Pn", "Pt", "TL", "TLn", "TLt", "mu_c"):
        scale = np.max(np.abs(particle[name][ok])) + 1e-300
        assert np.max(np.abs(rigid[name][ok] - particle[name][ok])) <= 1e-13 * scale, name
    np.testing.assert_array_equal(rigid["W1"][ok], c["w1"][ok])
    np.testing.assert_array_equal(rigid["M"][ok], 0.0)


def test_dataframe_in_dataframe_out():
    df = pd.DataFrame(_rigid(5))
    out = impactsym.solve_batch(df)
    assert isinstance(out, pd.DataFrame) and list(out.index) == list(df.index)
    np.testing.assert_array_equal(out["TL"].to_numpy(), impactsym.solve_batch(_rigid(5))["TL"])


def test_scalars_broadcast_like_arrays():
    c = _rigid(6)
    arrays = {**c, "e": np.full(6, 0.2), "e_m": np.full(6, 1.0)}
    scalars = {**c, "e": 0.2, "e_m": 1.0}
    a, s = impactsym.solve_batch(arrays), impactsym.solve_batch(scalars)
    for name in OUTPUTS:
        np.testing.assert_array_equal(a[name], s[name], err_msg=name)


def test_column_errors_name_the_column():
    c = _rigid(4)
    del c["e_m"]
    with pytest.raises(ValueError, match="^e_m: missing column"):
        impactsym.solve_batch(c)
    c = _rigid(4)
    c["v2y"] = np.zeros(3)
    with pytest.raises(ValueError, match="^v2y: length 3"):
        impactsym.solve_batch(c)
    with pytest.raises(ValueError, match="^model: unknown model"):
        impactsym.solve_batch(_rigid(4), model="stronge")


def test_a_single_scene_compiles_nothing():
    code = ("import impactsym, generated.planar as p; "
            "impactsym.solve('examples/two_car_us.json'); "
            "assert p.rigid.signatures == [] and p.rigid_batch.signatures == [], 'compiled'")
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
