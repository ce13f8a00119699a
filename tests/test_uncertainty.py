"""Uncertainty: exact derivatives against 50-digit references, and checks of the method.

Tolerances, fixed before looking at results:
- Jacobian kernels (float64) against mpmath.diff of the independent 50-digit
  reference: each entry within 1e-8 of the largest |entry| of its output's
  row (float64 closed forms lose a few digits to cancellation; 1e-8 leaves
  room for that and nothing else).
- Monte Carlo sd against the linear sd on a near-linear scene (input sds of
  about 1 % of the values): within 3 % (the Monte Carlo sd of 40 000 draws has
  a relative standard error of 0.35 %; the remaining room is for curvature).
- Coverage: 300 seeded trials, the 90 % interval must hold the truth in a
  fraction within the 99.9 % binomial bounds of 0.9 ([0.845, 0.945]).
"""

import math

import numpy as np
import pytest
from mpmath import mp

from impactsym import _kernels, solve_batch
from impactsym.testing import reference
from impactsym.uncertainty import propagation as U
from tests.helpers import assert_gradient_close, mp_gradient

SCENE = {
    "m1": 1500.0,
    "m2": 1200.0,
    "I1": 2500.0,
    "I2": 2000.0,
    "v1x": 20.0,
    "v1y": 0.0,
    "w1": 0.1,
    "v2x": 0.0,
    "v2y": 15.0,
    "w2": 0.0,
    "r1x": 2.0,
    "r1y": 0.3,
    "r2x": -0.5,
    "r2y": -2.0,
    "gamma": 0.3,
    "e": 0.2,
    "mu": -0.4,
    "e_m": 0.8,
}


@pytest.mark.parametrize(
    "model,critical", [("rigid", False), ("rigid", True), ("particle", False), ("particle", True)]
)
def test_forward_jacobian_matches_reference(model, critical):
    names = reference.RIGID_INPUTS if model == "rigid" else reference.PARTICLE_INPUTS
    point = {k: SCENE[k] for k in names}
    if critical:
        names = [n for n in names if n != "mu"]
    outputs = ["V1x", "V1y", "V2x", "V2y", "Pn", "Pt", "TL", "TLn", "TLt", "mu_c"]
    if model == "rigid":
        outputs += ["W1", "W2", "M", "TLm"]
    ks = _kernels.JACOBIAN[model + ("_critical" if critical else "")]
    got = _kernels.run_one(ks, point, ks.outputs)
    assert got["status"] == 0
    want = mp_gradient(lambda p: reference.solve_reference(p, model, critical), point, names, outputs)
    assert_gradient_close(got, want, names, outputs)


def _mp_reconstruct(p: dict) -> dict:
    """Independent reconstruction at 50 digits: the 2x2 momentum system solved
    by mpmath's LU, then P = m1 (V1 - v1) and e = -Gn/gn at the impact centre."""
    h1 = (mp.cos(p["theta1"]), mp.sin(p["theta1"]))
    h2 = (mp.cos(p["theta2"]), mp.sin(p["theta2"]))
    A = mp.matrix([[p["m1"] * h1[0], p["m2"] * h2[0]], [p["m1"] * h1[1], p["m2"] * h2[1]]])
    b = mp.matrix([p["m1"] * p["V1x"] + p["m2"] * p["V2x"], p["m1"] * p["V1y"] + p["m2"] * p["V2y"]])
    s = mp.lu_solve(A, b)
    v1 = (s[0] * h1[0], s[0] * h1[1])
    v2 = (s[1] * h2[0], s[1] * h2[1])
    n = (mp.cos(p["gamma"]), mp.sin(p["gamma"]))
    t = (-n[1], n[0])
    P = (p["m1"] * (p["V1x"] - v1[0]), p["m1"] * (p["V1y"] - v1[1]))

    def rel(a, b, wa, wb):
        ua = (a[0] - wa * p["r1y"], a[1] + wa * p["r1x"])
        ub = (b[0] - wb * p["r2y"], b[1] + wb * p["r2x"])
        return (ub[0] - ua[0]) * n[0] + (ub[1] - ua[1]) * n[1]

    gn = rel(v1, v2, p["w1"], p["w2"])
    Gn = rel((p["V1x"], p["V1y"]), (p["V2x"], p["V2y"]), p["W1"], p["W2"])
    return {
        "s1": s[0],
        "s2": s[1],
        "v1x": v1[0],
        "v2y": v2[1],
        "e": -Gn / gn,
        "Pn": P[0] * n[0] + P[1] * n[1],
        "Pt": P[0] * t[0] + P[1] * t[1],
    }


def _reconstruct_point():
    """The finals of SCENE solved forward, with its headings."""
    fwd = solve_batch({k: np.array([v]) for k, v in SCENE.items()})
    point = {k: SCENE[k] for k in ("m1", "m2", "I1", "I2", "w1", "w2", "r1x", "r1y", "r2x", "r2y", "gamma")}
    point.update({k: float(fwd[k][0]) for k in ("V1x", "V1y", "W1", "V2x", "V2y", "W2")})
    point.update(theta1=math.atan2(SCENE["v1y"], SCENE["v1x"]), theta2=math.atan2(SCENE["v2y"], SCENE["v2x"]))
    return point


def test_reconstruct_jacobian_matches_reference():
    point = _reconstruct_point()
    ks = _kernels.JACOBIAN["reconstruct"]
    got = _kernels.run_one(ks, point, ks.outputs)
    assert got["status"] == 0
    names = list(ks.inputs)
    outputs = ["s1", "s2", "v1x", "v2y", "e", "Pn", "Pt"]
    assert_gradient_close(got, mp_gradient(_mp_reconstruct, point, names, outputs), names, outputs)


# --------------------------------------------------------------------------- the method

FINALS = ("V1x", "V1y", "V2x", "V2y")


def _source(point: dict, sd: dict, measured: dict | None = None):
    """A column-level reconstruction source: each name of `sd` is an uncertain
    input (normal, centred on `measured` or the point) named by its column."""
    centre = measured or point
    inputs = tuple(U.Input(name, "normal", (centre[name], s)) for name, s in sd.items())

    def columns(overrides):
        n = len(next(iter(overrides.values())))
        return {**point, **overrides}, np.full(n, "")

    return U.Source(U.RECONSTRUCT, inputs, columns)


def test_monte_carlo_and_linear_sd_agree_on_a_near_linear_scene():
    point = _reconstruct_point()
    sd = {name: 0.01 * abs(point[name]) + 0.01 for name in FINALS + ("m1", "m2")}
    result = U.propagate(_source(point, sd), draws=40_000, seed=7)
    assert result.accepted > 0.99 * result.n_draws
    for path in ("vehicles[0].speed", "vehicles[1].speed", "energy_loss.total"):
        out = result.outputs[path]
        assert out["sd_linear"] > 0
        assert abs(out["sd"] / out["sd_linear"] - 1) < 0.03, (path, out)
        assert abs(sum(result.budget[path].values()) - 1) < 1e-12


def test_budget_names_the_input_that_drives_the_speed():
    point = _reconstruct_point()
    sd = {"V1x": 0.01, "V1y": 2.0, "V2x": 0.01, "V2y": 0.01}
    result = U.propagate(_source(point, sd), draws=4096, seed=1)
    # Vehicle 1 heads along x, vehicle 2 along y: momentum along y (V1y, V2y)
    # gives vehicle 2's speed and none of vehicle 1's.
    shares = result.budget["vehicles[1].speed"]
    assert max(shares, key=shares.get) == "V1y"
    assert abs(result.budget["vehicles[0].speed"]["V1y"]) < 1e-12


def test_seed_reproduces_and_chunking_does_not_change_the_draws():
    point = _reconstruct_point()
    sd = {name: 0.05 * abs(point[name]) + 0.05 for name in FINALS}
    a = U.propagate(_source(point, sd), draws=70_000, seed=11)
    b = U.propagate(_source(point, sd), draws=70_000, seed=11, chunk_size=U.BLOCK)
    ja, jb = a.to_json_dict(), b.to_json_dict()
    assert (ja["accepted"], ja["rejected"]) == (jb["accepted"], jb["rejected"])
    for path, entry in ja["outputs"].items():
        for key in ("p5", "p50", "p95", "nominal", "sd_linear"):  # order statistics: exact
            assert entry[key] == jb["outputs"][path][key]
        for key in ("mean", "sd"):  # sums over chunks: the same up to rounding
            assert entry[key] == pytest.approx(jb["outputs"][path][key], rel=1e-12)
    c = U.propagate(_source(point, sd), draws=70_000, seed=12)
    assert c.outputs["vehicles[0].speed"]["mean"] != a.outputs["vehicles[0].speed"]["mean"]


def test_correlation_is_honoured_by_both_methods():
    point = _reconstruct_point()
    sd = {"V1x": 0.1, "V2x": 0.1}  # small: hardly a draw rejected, which would truncate
    src = _source(point, sd)
    pos = U.propagate(
        U.Source(src.command, src.inputs, src.columns, (("V1x", "V2x", 0.9),)), draws=40_000, seed=3
    )
    neg = U.propagate(
        U.Source(src.command, src.inputs, src.columns, (("V1x", "V2x", -0.9),)), draws=40_000, seed=3
    )
    for r in (pos, neg):
        assert r.accepted > 0.99 * r.n_draws
        drawn = np.corrcoef(r.draws["V1x"], r.draws["V2x"])[0, 1]
        assert abs(drawn - (0.9 if r is pos else -0.9)) < 0.01
        out = r.outputs["vehicles[0].speed"]
        assert abs(out["sd"] / out["sd_linear"] - 1) < 0.03
    assert pos.outputs["vehicles[0].speed"]["sd"] != pytest.approx(
        neg.outputs["vehicles[0].speed"]["sd"], rel=0.1
    )


def test_rejected_draws_are_counted_by_reason():
    point = _reconstruct_point()
    # A restitution near 0 at the truth: noise on the finals pushes e below 0.
    sd = {name: 3.0 for name in FINALS}
    result = U.propagate(_source(point, sd), draws=20_000, seed=5)
    assert result.accepted < result.n_draws
    assert set(result.rejected) <= {
        "energy_created",
        "tensile_impulse",
        "mu_beyond_critical",
        "e_out_of_range",
        "negative_speed",
        "not_approaching",
        "singular",
    }
    assert result.rejected
    assert len(result.draws) == result.accepted
    assert (result.draws["restitution"].between(0, 1)).all()


def test_interval_covers_the_truth_at_the_nominal_rate():
    """True scene → measurements with known noise → 90 % interval of the speed."""
    truth = _reconstruct_point()
    true_speed = math.hypot(SCENE["v1x"], SCENE["v1y"])
    sd = {"V1x": 0.3, "V1y": 0.3, "V2x": 0.3, "V2y": 0.3, "m1": 30.0, "m2": 30.0}
    rng = np.random.default_rng(2026)
    trials, hits = 300, 0
    for _ in range(trials):
        measured = {k: truth[k] + s * rng.standard_normal() for k, s in sd.items()}
        result = U.propagate(
            _source({**truth, **measured}, sd, measured), draws=2000, seed=int(rng.integers(2**31))
        )
        out = result.outputs["vehicles[0].speed"]
        hits += out["p5"] <= true_speed <= out["p95"]
    assert 0.845 <= hits / trials <= 0.945, hits / trials


def test_json_object_has_the_documented_keys():
    point = _reconstruct_point()
    result = U.propagate(_source(point, {"V1x": 0.2, "V2y": 0.2}), draws=1000, seed=2)
    obj = result.to_json_dict()
    assert set(obj) >= {"draws", "accepted", "rejected", "inputs", "outputs"}
    assert obj["inputs"] == ["V1x", "V2y"]
    expected = {
        "vehicles[0].speed",
        "vehicles[1].speed",
        "vehicles[0].delta_v_magnitude",
        "energy_loss.total",
        "restitution",
        "impulse_ratio",
        "impulse.normal",
    }
    assert expected <= set(obj["outputs"])
    for entry in obj["outputs"].values():
        assert set(entry) == {"nominal", "mean", "sd", "p5", "p50", "p95", "sd_linear", "budget"}


def test_sobol_first_order_indices_rank_the_dominant_input():
    point = _reconstruct_point()
    sd = {"V1x": 0.01, "V1y": 2.0, "V2x": 0.01, "V2y": 0.01}
    result = U.propagate(_source(point, sd), draws=4096, seed=4, sobol=True)
    s1 = result.sobol["vehicles[1].speed"]["S1"]
    assert max(s1, key=s1.get) == "V1y"
    assert s1["V1y"] > 0.9


def test_jacobian_proof_catches_a_wrong_derivative():
    """The proof of derive/jacobian.py fails when one derivative formula is off."""
    import random
    from dataclasses import replace

    from derive import jacobian
    from derive.kernel import Block

    index = next(i for i, k in enumerate(jacobian.BASES) if k.name == "particle")
    knl, base = jacobian.KERNELS[index], jacobian.BASES[index]
    assert jacobian._agrees(knl, base, random.Random(1), points=1)
    blocks = list(knl.blocks)
    at = next(i for i, b in enumerate(blocks) if any(s.name == "d_TL__d_e" for s, _ in b.assigns))
    blocks[at] = Block(
        tuple((s, x * 1.000001 if s.name == "d_TL__d_e" else x) for s, x in blocks[at].assigns),
        blocks[at].guard,
    )
    assert not jacobian._agrees(replace(knl, blocks=tuple(blocks)), base, random.Random(1), points=1)
