"""The draws' starts from their fitted neighbours (impactsym/runout/neighbours.py):
the local quadratic's intercept is exact where the fitted state is a quadratic
of the draw, and it declines where there are too few neighbours."""

import importlib

import numpy as np
import pytest

neighbours = importlib.import_module("impactsym.runout.neighbours")


def _quadratic(x: np.ndarray, rng, quad: int) -> np.ndarray:
    """A random map (rows, d) -> (rows, 3): quadratic in the first `quad` inputs, linear in the rest."""
    d = x.shape[1]
    c0, c1 = rng.normal(size=3), rng.normal(size=(d, 3))
    c2 = rng.normal(size=(quad, quad, 3))
    return c0 + x @ c1 + np.einsum("ni,nj,ijc->nc", x[:, :quad], x[:, :quad], c2)


@pytest.mark.parametrize("d", [1, 3, 6])
def test_a_quadratic_state_is_predicted_exactly(d):
    rng = np.random.default_rng(d)
    fitted, query = rng.normal(size=(400, d)), rng.normal(size=(50, d))
    truth = _quadratic(np.vstack([fitted, query]), rng, d)
    starts, nearest = neighbours.predict(fitted, truth[:400], query)
    assert np.allclose(starts, truth[400:], rtol=1e-8, atol=1e-8)
    # a state only linear to within its curvature is not (the test can fail)
    bent = truth + np.sin(np.vstack([fitted, query]))[:, :1] ** 3
    off, _ = neighbours.predict(fitted, bent[:400], query)
    assert not np.allclose(off, bent[400:], rtol=1e-6, atol=1e-6)
    dist = np.linalg.norm(fitted[None] - query[:, None], axis=2)
    # the nearest is nearest to within the approximate search's (1 + QUERY_EPS)
    assert np.all(dist[np.arange(50), nearest] <= (1 + neighbours.QUERY_EPS) * dist.min(axis=1) + 1e-12)


def test_beyond_quad_dims_the_widest_inputs_get_the_quadratic_terms():
    """9 inputs, the first QUAD_DIMS with the widest spread: a state quadratic in
    those and linear in the rest is exact; constant inputs are left out."""
    rng = np.random.default_rng(9)
    q = neighbours.QUAD_DIMS
    spread = np.r_[np.full(q, 1.0), np.full(9 - q, 0.1), 0.0]
    x = rng.normal(size=(2000, 10)) * spread
    truth = _quadratic(x[:, :9], rng, q)
    starts, _ = neighbours.predict(x[:1900], truth[:1900], x[1900:])
    assert np.allclose(starts, truth[1900:], rtol=1e-7, atol=1e-7)


def test_too_few_fitted_draws_give_no_prediction():
    rng = np.random.default_rng(1)
    d = 4
    k = neighbours.NEIGHBOURS_PER_TERM * neighbours.terms(d)
    x = rng.normal(size=(k, d))
    assert neighbours.predict(x[:-1], x[:-1, :3], x[:2]) is None
    assert neighbours.predict(x, x[:, :3], x[:2]) is not None
