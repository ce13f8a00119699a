"""Specialised kernels and batch dispatch (issue 4, part 1).

* every specialised kernel (e_m = 1 without a moment impulse, output tiers,
  normal-component drivers) agrees with the general kernel on the rows it
  serves, and with the 50-digit reference;
* solve_batch picks the specialised kernel (recorded, not assumed);
* constant inputs given as scalars give the answers of broadcast arrays;
* mixed batches (models, critical and given μ) keep row order and give each
  row what a batch of that row alone gives, bad rows included;
* a batch of a few rows gives the rows of a large one (one driver serves both).
"""

import numpy as np
import pytest

import impactsym
from impactsym import _kernels
from impactsym.testing import reference as R
from impactsym.testing import scenes

TIERS = ("velocities", "impulses", "energy")
N = 150


@pytest.fixture(scope="module")
def rigid():
    """Realistic rigid scenes with e_m = 1 on every row."""
    return dict(scenes.random_realistic(N, 4404), e_m=np.ones(N))


@pytest.fixture(scope="module")
def particle():
    return scenes.random_realistic(N, 4405, model="particle")


def _run(ks, columns, critical=False):
    inputs = [0.0 if (critical and k == "mu") else columns[k] for k in ks.inputs]
    outs, status, flags = _kernels.run_batch(ks, inputs)
    return outs, status, flags


def _assert_close(got, want, label, rtol=4e-15):
    """Equal to a few units in the last place of the row's scale."""
    scale = np.maximum(np.abs(want), 1.0)
    err = np.abs(got - want) / scale
    assert np.all(err <= rtol), f"{label}: worst {err.max():.3g} at row {int(np.argmax(err))}"


@pytest.mark.parametrize("critical", [False, True], ids=["given_mu", "critical"])
@pytest.mark.parametrize("tier", TIERS)
def test_no_moment_kernel_equals_general_at_em1(rigid, critical, tier):
    """The e_m = 1 kernels (every tier) give the general kernel's outputs, and
    publish M = TLm = 0 as constants rather than computing them."""
    general, gs, gf = _run(_kernels.kernel_for("rigid", critical), rigid, critical)
    ks = _kernels.kernel_for("rigid", critical, no_moment=True, tier=tier)
    assert "e_m" not in ks.inputs and "M" not in ks.outputs
    outs, status, flags = _run(ks, rigid, critical)
    assert np.array_equal(status, gs) and np.array_equal(flags, gf)
    assert np.all(general["M"] == 0.0)
    for name in ks.outputs:
        _assert_close(outs[name], general[name], f"{ks.scene.__name__}.{name}")


def test_the_impulses_tier_is_the_full_kernel():
    """Pruned to the impulses, a kernel kept every operation of the full one
    (the energies are differences of velocities it computes anyway): derive
    emits no such kernel, and the full one serves the tier."""
    for family in ("rigid", "particle"):
        for critical in (False, True):
            full = _kernels.kernel_for(family, critical)
            assert _kernels.kernel_for(family, critical, tier="impulses") is full
            assert _kernels.kernel_for(family, critical, tier="velocities").operations < full.operations


@pytest.mark.parametrize("family", ["rigid", "particle"])
@pytest.mark.parametrize("critical", [False, True], ids=["given_mu", "critical"])
@pytest.mark.parametrize("tier", TIERS[:1])
def test_tier_kernels_equal_full_kernel(rigid, particle, family, critical, tier):
    """A tier kernel computes exactly the full kernel's numbers for its outputs,
    with the same status and flags (flags are computed in every tier)."""
    columns = rigid if family == "rigid" else particle
    full, fs, ff = _run(_kernels.kernel_for(family, critical), columns, critical)
    ks = _kernels.kernel_for(family, critical, tier=tier)
    assert set(ks.outputs) < set(full)
    outs, status, flags = _run(ks, columns, critical)
    assert np.array_equal(status, fs) and np.array_equal(flags, ff)
    for name in ks.outputs:
        _assert_close(outs[name], full[name], f"{family} {tier} {name}", rtol=0.0)


@pytest.mark.parametrize("tier", TIERS)
def test_specialised_kernels_match_reference(rigid, tier):
    """e_m = 1 kernel of each tier against the 50-digit solution of the six equations."""
    rows = [R.row_of(rigid, i) for i in range(40)]
    refs = [R.solve_reference(row, "rigid") for row in rows]
    cols = {k: v[:40] for k, v in rigid.items()}
    out = impactsym.solve_batch(cols, outputs=tier)
    for i, (row, ref) in enumerate(zip(rows, refs)):
        scales = R.natural_scales(row, ref, "rigid")
        got = {k: float(out[k][i]) for k in scales if k in out}
        errs = R.relative_errors(got, {k: ref[k] for k in got}, {k: scales[k] for k in got})
        assert max(errs.values()) <= 1e-12, (i, errs)


def test_solve_batch_runs_the_specialised_kernel(rigid, monkeypatch):
    """e_m = 1 on every row and outputs="velocities" → rigid_em1_velocities;
    one e_m ≠ 1 → the general kernel of the tier."""
    used = []
    real = _kernels.run

    def spy(ks, inputs, n=None):
        used.append(ks.scene.__name__)
        return real(ks, inputs, n)

    monkeypatch.setattr(_kernels, "run", spy)
    impactsym.solve_batch(rigid, outputs="velocities")
    impactsym.solve_batch(dict(rigid, e_m=1.0), outputs=["TL"])
    mixed = rigid["e_m"].copy()
    mixed[3] = 0.5
    impactsym.solve_batch(dict(rigid, e_m=mixed), outputs="impulses")
    impactsym.solve_batch(dict(rigid, mu="critical"))
    assert used == ["rigid_em1_velocities", "rigid_em1", "rigid", "rigid_critical_em1"]


def test_constants_as_scalars_equal_arrays(rigid):
    """A sweep keeps the geometry fixed: scalars give the broadcast arrays' answers
    (the constant angle through the normal-component driver)."""
    row = R.row_of(rigid, 7)
    varied = {"e": np.linspace(0.0, 0.9, 200), "mu": np.linspace(-0.3, 0.3, 200)}
    for em in (1.0, 0.4):
        scalars = {**{k: row[k] for k in rigid}, **varied, "e_m": em}
        arrays = {k: np.full(200, v) if np.ndim(v) == 0 else v for k, v in scalars.items()}
        got, want = impactsym.solve_batch(scalars), impactsym.solve_batch(arrays)
        for name in want:
            np.testing.assert_array_equal(got[name], want[name], err_msg=f"{name} e_m={em}")


def test_single_row_scalar_batch():
    """Every column a scalar: a batch of one row, equal to solve()."""
    scene = impactsym.load_scene("examples/intersection_si.toml")
    family, critical, values = scene.to_inputs()
    if critical:
        values["mu"] = "critical"
    out = impactsym.solve_batch(values, model=family)
    assert out["status"].shape == (1,)
    assert out["V1x"][0] == pytest.approx(impactsym.solve(scene).vehicles[0].velocity[0], rel=1e-15)


def _mixed_batch(rigid, particle, n=300, seed=11):
    """Rows of rigid, particle, limpert and macmillan scenes, critical and given μ,
    with bad rows of each kind sprinkled in."""
    rng = np.random.default_rng(seed)
    models = rng.choice(np.array(["rigid", "particle", "limpert", "macmillan"], dtype=object), n)
    src = rng.integers(0, N, n)
    cols = {k: rigid[k][src].copy() for k in rigid}
    for k in ("m1", "m2", "v1x", "v1y", "v2x", "v2y", "gamma", "e", "mu"):
        cols[k] = np.where(models == "particle", particle[k][src], cols[k])
    cols["e_m"] = rng.choice([1.0, 0.3], n)
    mu = cols["mu"].astype(object)
    mu[rng.random(n) < 0.3] = "critical"
    preset = (models == "limpert") | (models == "macmillan")
    cols["e_m"][preset] = np.nan
    cols["e"][models == "limpert"] = np.nan
    mu[models == "limpert"] = np.nan
    cols["mu"] = mu
    cols["m1"][5], cols["v2y"][17], cols["I2"][40] = -1.0, np.nan, 0.0
    for k in ("v1x", "v1y", "v2x", "v2y", "w1", "w2"):
        cols[k][60] = -cols[k][60]  # every velocity reversed: receding
    return models, cols


PARTICLE_COLUMNS = ("m1", "m2", "v1x", "v1y", "v2x", "v2y", "gamma", "e", "mu")


def _row_alone(models, cols, i):
    model = models[i]
    row = {k: np.asarray(v)[i : i + 1] for k, v in cols.items()}
    mu = row["mu"][0]
    row["mu"] = "critical" if mu == "critical" else np.array([float(mu)])
    if model in ("limpert", "macmillan"):
        row.pop("e_m")
    if model == "limpert":
        row.pop("e"), row.pop("mu")
    if model == "particle":  # alone, the yaw columns would be refused as not used
        row = {k: v for k, v in row.items() if k in PARTICLE_COLUMNS}
    return impactsym.solve_batch(row, model=model)


def test_mixed_batch_keeps_row_order(rigid, particle):
    """Grouped, solved and returned in order: every row equals the batch of that
    row alone (to the last bits: alone, a rigid row with e_m = 1 runs the kernel
    without a moment impulse, in the mixed group the general one), bad rows
    keep their status, the other rows are solved."""
    models, cols = _mixed_batch(rigid, particle)
    out = impactsym.solve_batch(cols, model=models)
    assert set(np.unique(out["status"])) >= {0, 1, 2, 3}
    for i in range(len(models)):
        alone = _row_alone(models, cols, i)
        assert (out["status"][i], out["flags"][i]) == (alone["status"][0], alone["flags"][0]), i
        for name in out:
            np.testing.assert_allclose(
                out[name][i], alone[name][0], rtol=4e-15, atol=4e-15, err_msg=f"row {i} ({models[i]}) {name}"
            )


def test_mixed_batch_dataframe_index(rigid, particle):
    pd = pytest.importorskip("pandas")
    models, cols = _mixed_batch(rigid, particle, n=80, seed=3)
    frame = pd.DataFrame(cols, index=np.arange(1000, 1080))
    out = impactsym.solve_batch(frame, model=models, outputs="velocities")
    assert list(out.index) == list(frame.index)
    assert list(out.columns) == ["V1x", "V1y", "W1", "V2x", "V2y", "W2", "status", "flags"]


def test_mixed_batch_rejects_a_preset_column_that_disagrees(rigid):
    models = np.array(["rigid", "macmillan"] * 5, dtype=object)
    cols = {k: v[:10] for k, v in rigid.items()}
    cols["e_m"] = np.full(10, 0.5)
    with pytest.raises(ValueError, match="^e_m: the macmillan model fixes"):
        impactsym.solve_batch(cols, model=models)


def test_bad_mu_string_is_a_column_error(rigid):
    mu = rigid["mu"].astype(object)
    mu[4] = "sticky"
    with pytest.raises(ValueError, match="^mu: "):
        impactsym.solve_batch(dict(rigid, mu=mu))


@pytest.mark.parametrize("outputs", [["dV1", "TL"], "impulses"])
def test_outputs_selection(rigid, outputs):
    out = impactsym.solve_batch(rigid, outputs=outputs)
    full = impactsym.solve_batch(rigid)
    names = outputs if isinstance(outputs, list) else _kernels.TIERS[outputs]
    assert list(out) == [*names, "status", "flags"]
    for name in names:
        np.testing.assert_allclose(out[name], full[name], rtol=0, atol=0)


def test_unknown_outputs_are_errors(rigid):
    with pytest.raises(ValueError, match="^outputs: unknown tier"):
        impactsym.solve_batch(rigid, outputs="speeds")
    with pytest.raises(ValueError, match="^outputs: unknown output V3x"):
        impactsym.solve_batch(rigid, outputs=["V1x", "V3x"])


def test_delta_v_is_the_velocity_change(rigid):
    out = impactsym.solve_batch(rigid)
    dv1 = np.hypot(out["V1x"] - rigid["v1x"], out["V1y"] - rigid["v1y"])
    np.testing.assert_allclose(out["dV1"], dv1, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("rows", [1, 2, 5])
def test_a_few_rows_equal_the_rows_of_a_large_batch(rigid, rows):
    """One driver serves every batch size: the first rows alone give the bits
    they get in the whole batch."""
    small = {k: v[:rows] for k, v in rigid.items()}
    big = impactsym.solve_batch(rigid)
    part = impactsym.solve_batch(small)
    for name in part:
        np.testing.assert_array_equal(part[name], big[name][:rows])
