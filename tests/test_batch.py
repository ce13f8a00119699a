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
from impactsym._kernels import OUTPUTS
from impactsym.testing import scenes

ROOT = Path(__file__).resolve().parent.parent


def _rigid(n=8, seed=3):
    return scenes.random_realistic(n, seed=seed)  # fresh copies: tests may change them


def test_bad_rows_get_a_status_and_the_other_rows_are_untouched():
    c = _rigid(200)  # large enough for the parallel driver
    good = impactsym.solve_batch(c)
    assert (good["status"] == 0).all()
    c["m1"][1] = np.nan
    c["I2"][2] = 0.0
    c["m2"][3], c["I2"][3] = np.inf, 5.0  # infinite mass, finite inertia
    c["m1"][4] = c["I1"][4] = c["m2"][4] = c["I2"][4] = np.inf  # both fixed
    c["gamma"][5] += np.pi  # separating instead of approaching
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
    """A single scene runs the plain per-scene function: numba is never imported."""
    code = (
        "import sys, impactsym; "
        "impactsym.solve('examples/two_car_us.json'); "
        "assert 'numba' not in sys.modules, 'numba imported'"
    )
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr


def test_any_mix_of_scalars_and_arrays_uses_one_compiled_signature():
    """Scalar columns become filled arrays: whatever the mix, each driver sees
    C-contiguous float64 arrays only (one signature), and the rows agree bitwise."""
    from impactsym import _kernels

    c = _rigid(300, seed=5)
    ks = _kernels.kernel_for("rigid", False)
    reference = impactsym.solve_batch(c)
    signatures = set(ks.driver.signatures)  # other tests may have compiled other forms
    for scalars in (("m1", "m2", "I1", "I2"), ("e", "mu", "e_m"), ("r1x", "w2")):
        mixed = {k: (float(v[0]) if k in scalars else v) for k, v in c.items()}
        same = {k: (np.full(300, v[0]) if k in scalars else v) for k, v in c.items()}
        out, want = impactsym.solve_batch(mixed), impactsym.solve_batch(same)
        for name in OUTPUTS:
            np.testing.assert_array_equal(out[name], want[name], err_msg=f"{scalars} {name}")
    assert (reference["status"] == 0).all()
    assert set(ks.driver.signatures) == signatures


def test_scalars_are_filled_chunk_by_chunk(monkeypatch):
    """A batch longer than a chunk with scalar columns gives the rows a single
    call would give (each chunk its own slice of the outputs)."""
    from impactsym._kernels import runner

    c = _rigid(250, seed=6)
    mixed = {k: (float(v[0]) if k in ("m1", "e") else v) for k, v in c.items()}
    whole = impactsym.solve_batch(mixed)
    monkeypatch.setattr(runner, "FILL_BYTES", 8 * 2 * 64)  # two scalars: 64-row chunks
    monkeypatch.setattr(runner, "MIN_CHUNK", 64)
    chunked = impactsym.solve_batch(mixed)
    for name in (*OUTPUTS, "status", "flags"):
        np.testing.assert_array_equal(chunked[name], whole[name], err_msg=name)


def test_a_read_only_install_caches_compiled_drivers_in_the_user_directory(tmp_path):
    """generated/ not writable and NUMBA_CACHE_DIR unset: the drivers are cached
    under $XDG_CACHE_HOME/impactsym/numba, and a batch runs."""
    code = (
        "import os; real = os.access; "
        "os.access = lambda p, m, **k: False if m == os.W_OK else real(p, m, **k); "
        "import impactsym; "
        "out = impactsym.solve_batch({'m1': [1500.0], 'm2': [1200.0], 'v1x': [20.0], "
        "'v1y': [0.0], 'v2x': [0.0], 'v2y': [0.0], 'gamma': 0.0, 'e': 0.2, 'mu': 0.1}, "
        "model='particle'); "
        "assert out['status'][0] == 0, out; "
        "import numba.core.config as cfg; print(cfg.CACHE_DIR)"
    )
    env = {k: v for k, v in __import__("os").environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=600, env=env
    )
    assert proc.returncode == 0, proc.stderr
    cache = tmp_path / "impactsym" / "numba"
    assert proc.stdout.strip() == str(cache)
    assert any(cache.rglob("*.nbi")), "nothing cached in the user directory"


@pytest.mark.parametrize(
    "angles, beyond",
    [
        ([0.01, -0.3, 0.2], 0),
        ([1.0, -1.0], 0),  # at the limit: the angle loop still serves it
        ([np.nan, 1.1], 1),  # NaN does not hide an angle beyond the limit
        ([-1.1, np.nan, 0.0], 1),
        ([np.inf, -np.inf, 0.1], 0),  # ±inf is a bad row (status 1), not beyond
        ([np.inf, np.nan, -1.2, 1.3], 2),
        ([np.nan, np.nan], 0),
    ],
)
def test_the_angle_loop_counts_the_angles_beyond_the_sincos_limit(angles, beyond):
    """The driver's angle loop returns how many finite angles are beyond
    SINCOS_LIMIT (angles given here in units of the limit, the limit itself
    served), past NaN and ±inf; the runtime then solves the batch with NumPy's
    normals, as the per-scene function does."""
    from impactsym._kernels import kernel_for, solve_one
    from impactsym._kernels.registry import SINCOS_LIMIT
    from impactsym._kernels.runner import allocate

    ks = kernel_for("rigid", False)
    gamma = np.array(angles) * SINCOS_LIMIT
    n = len(gamma)
    columns = scenes.random_realistic(n, seed=3)
    inputs = [gamma if name == "gamma" else np.ascontiguousarray(columns[name][:n]) for name in ks.inputs]
    at = ks.inputs.index("gamma")
    driven = inputs[:at] + [gamma, None, None, None] + inputs[at + 1 :]
    outs = [*allocate(ks, n).values(), np.empty(n, np.int32), np.empty(n, np.int32)]
    assert ks.driver(*driven, *outs) == beyond
    got = impactsym.solve_batch({**{k: v[:n] for k, v in columns.items()}, "gamma": gamma})
    for i in range(n):
        one = solve_one("rigid", False, {k: float(v[i]) for k, v in columns.items()} | {"gamma": gamma[i]})
        assert got["status"][i] == one["status"]
        np.testing.assert_array_equal([got[k][i] for k in OUTPUTS], [one[k] for k in OUTPUTS])
