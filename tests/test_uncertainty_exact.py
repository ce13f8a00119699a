"""The fast paths of the uncertainty engine give the numbers of the plain ones, to the bit.

- `impactsym.batch.selection.select_ranks` (bin counting) against `numpy.partition`
  of the concatenation, and `impactsym.batch.quantiles.percentiles` against
  `numpy.percentile` (the definition docs/uncertainty.md states), on data
  chosen to stress the bins: ties, a constant array, heavy tails, tiny and
  huge scales, values at the bin edges, NaN and infinities (which take the
  plain path), arrays below and above the size where binning starts.
- `SamplePlan.draws_into` against `SamplePlan.draws` (standard normals drawn in
  place, other distributions and partial blocks copied), and the in-place
  normal transform against the plain one.
"""

import numpy as np
import pytest

from impactsym.batch import selection as _selection
from impactsym.batch.plans import BLOCK, SamplePlan
from impactsym.batch.quantiles import percentiles
from impactsym.uncertainty.inputs import CHOICE, Input

Q = (5.0, 50.0, 95.0)


def _datasets():
    rng = np.random.default_rng(20261123)
    big = _selection.SELECT_MIN * 4
    yield "normal", [rng.standard_normal(big // 3) for _ in range(3)]
    yield "offset_tiny_scale", [1e3 + 1e-9 * rng.standard_normal(big)]
    yield "huge_scale", [1e300 * rng.standard_normal(big)]
    yield "cauchy", [rng.standard_cauchy(big), rng.standard_cauchy(7)]
    yield "ties", [rng.integers(0, 5, big).astype(np.float64)]
    yield "constant", [np.full(big, 2.5)]
    yield "two_values", [np.r_[np.zeros(big), np.ones(3)]]
    edges = np.linspace(-1.0, 1.0, _selection.SELECT_BINS + 1)
    yield "bin_edges", [np.repeat(edges, 8), rng.uniform(-1, 1, big)]
    yield "small", [rng.standard_normal(100), rng.standard_normal(5)]
    yield "one", [np.array([3.0])]
    yield "nan", [np.r_[rng.standard_normal(big), np.nan]]
    yield "inf", [np.r_[rng.standard_normal(big), np.inf, -np.inf]]
    yield "skewed", [np.exp(3 * rng.standard_normal(big))]


@pytest.mark.parametrize("name,parts", list(_datasets()), ids=[d[0] for d in _datasets()])
def test_selection_and_percentiles_equal_numpy(name, parts):
    whole = np.concatenate(parts)
    n = whole.size
    ranks = sorted({0, 1, n // 20, n // 2, n - 2, n - 1, (n - 1) * 95 // 100} & set(range(n)))
    got = _selection.select_ranks(parts, ranks)
    want = np.partition(whole, ranks)
    for r in ranks:
        assert got[r] == want[r] or (np.isnan(got[r]) and np.isnan(want[r])), (name, r)
    pct, ref = percentiles(parts, Q), np.percentile(whole, Q)
    assert np.array_equal(pct, ref, equal_nan=True), (name, pct, ref)


@pytest.mark.parametrize("start,stop", [(0, 3 * BLOCK), (100, 2 * BLOCK + 17), (BLOCK, BLOCK + 1)])
def test_draws_into_equals_draws(start, stop):
    dists = (("normal", (0.0, 1.0)), ("uniform", (-1.0, 2.0)), ("normal", (0.0, 1.0)), ("normal", (1.0, 2.0)))
    plan = SamplePlan("", "", None, {}, ("a", "b", "c", "d"), (), dists, 12345, stop)
    want = plan.draws(start, stop)
    got = plan.draws_into(start, stop, np.empty((len(dists), stop - start)))
    for w, g in zip(want, got):
        assert np.array_equal(w, g)


def test_normal_transform_in_place_gives_the_same_numbers():
    z = np.random.default_rng(3).standard_normal(1000)
    x = Input("v", "normal", (17.3, 0.37))
    want = x.from_scores(z)
    assert np.array_equal(x.from_scores(z.copy(), in_place=True), want)


@pytest.mark.parametrize("name,parts", list(_datasets()), ids=[d[0] for d in _datasets()])
def test_streamed_stats_give_numpy_percentiles(name, parts):
    """`Stats` fed chunk by chunk (its running extremes passed to the
    selection) gives numpy.percentile of all the values."""
    from impactsym.uncertainty.result import Stats

    stats = Stats(0.0)
    with np.errstate(over="ignore", invalid="ignore"):  # the sums of 1e300s and infinities
        for p in parts:
            stats.add(p)
    got, want = stats.percentiles(Q), np.percentile(np.concatenate(parts), Q)
    assert np.array_equal(got, want, equal_nan=True), (name, got, want)


def test_a_choice_is_one_with_its_probability_and_monotone_in_the_score():
    x = Input("vehicles[0].wheels.rear_left.state", CHOICE, (0.3,))
    u = (np.arange(100_000) + 0.5) / 100_000
    drawn = x.from_unit(u)
    assert set(np.unique(drawn)) == {0.0, 1.0} and drawn.mean() == pytest.approx(0.3, abs=1e-4)
    assert np.all(
        np.diff(drawn) >= 0.0
    )  # a higher score never gives the lower value (correlations keep their sign)
    assert x.nominal == 0.0 and Input(x.path, CHOICE, (0.7,)).nominal == 1.0
    assert (
        x.sd == pytest.approx(np.sqrt(0.21)) and x.discrete and not Input("a", "normal", (0.0, 1.0)).discrete
    )
