"""The impact laws against the independent 50-digit phase-by-phase reference
(impactsym/testing/laws.py), and the per-scene functions against the numba drivers."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from impactsym import laws
from impactsym.laws import batches, kernels
from impactsym.laws._door import LAWS, kernel
from impactsym.testing import laws as L

TOL = 1e-12
"""Largest accepted error of every output, relative to its natural scale."""
CASES = [
    ("kudlich_slibar", "full"),
    ("kudlich_slibar", "sliding"),
    ("coulomb", "newton"),
    ("coulomb", "poisson"),
    ("coulomb", "energetic"),
]


def _worst(model, law, c):
    """(largest error over rows and outputs, its output, slip-class / contact mismatches)."""
    out = batches.run_batch(model, law, c)
    assert np.all(out["status"] == 0)
    worst, where, mismatched = 0.0, None, 0
    for i in range(len(c["e"])):
        row = L.row_of(c, i)
        if model == "coulomb":
            ref = L.coulomb_reference(row, law)
            mismatched += ref["slip_class"] != out["slip_class"][i]
        else:
            ref = L.kudlich_slibar_reference(row, law)
            mismatched += ref["sliding"] != out["sliding"][i]
        errors = L.errors_against({k: out[k][i] for k in L.OUTPUTS}, ref, row)
        key = max(errors, key=errors.get)
        if errors[key] > worst:
            worst, where = errors[key], (i, key)
    return worst, where, mismatched


@pytest.mark.parametrize("model, law", CASES)
@pytest.mark.parametrize("which", ["realistic", "stress"])
def test_every_output_within_1e_12_of_scale(model, law, which):
    c = L.realistic(400, 31) if which == "realistic" else L.stress(400, 32)
    worst, where, mismatched = _worst(model, law, c)
    print(f"\n{which} {model} {law}: worst {worst:.2e} at {where}")
    assert worst <= TOL, (worst, where)
    assert mismatched == 0


def test_the_reference_sees_every_slip_class():
    """The stress set exercises continuing, stopping and reversing slip."""
    c = L.stress(400, 32)
    classes = {L.coulomb_reference(L.row_of(c, i), "newton")["slip_class"] for i in range(len(c["e"]))}
    assert classes == {0, 1, 2}


@pytest.mark.parametrize("model, law", CASES)
def test_per_scene_function_and_drivers_give_the_same_bits(model, law):
    """The per-scene function (solve / compare) and the numba driver (batches of
    300 and of 50 rows, through the door's runner) give the same bits."""
    c = L.stress(300, 41)
    whole = batches.run_batch(model, law, c)
    part = batches.run_batch(model, law, {k: v[:50] for k, v in c.items()})
    for i in range(50):
        one = kernels.solve_one(model, law, L.row_of(c, i))
        for key, value in part.items():
            assert np.array_equal(value[i], whole[key][i], equal_nan=True), key
            expected = -1 if key in ("sliding", "slip_class") and not math.isfinite(one[key]) else one[key]
            assert np.array_equal(value[i], expected, equal_nan=True), (i, key)


@pytest.mark.parametrize("model", list(LAWS))
def test_per_scene_functions_never_raise(model):
    """Any mix of zeros, signs, infinities, NaN and extreme magnitudes gives a row."""
    values = (0.0, -0.0, -1.0, 1.0, 2.5, -3.0, math.inf, -math.inf, math.nan, 1e-300, 1e300, 5e-324)
    rng = random.Random(7)
    for law in LAWS[model]:
        ks = kernel(model, law)
        for _ in range(3000):
            args = [rng.choice(values) for _ in ks.arguments]
            assert len(ks.scene(*args)) == len(ks.outputs) + 2, (ks.name, args)


def test_bad_rows_get_a_status_and_leave_the_others():
    c = L.realistic(100, 5)
    c["m1"][3] = -1.0
    c["e"][5] = math.nan
    c["mu_f"][7] = -0.2
    out = laws.coulomb_batch(c, "newton")
    assert out["status"][3] == 2 and out["status"][5] == 1 and out["status"][7] == 14
    assert np.isnan(out["Pn"][[3, 5, 7]]).all()
    assert np.all(out["status"][[0, 1, 2, 4, 6, 8]] == 0)
    with pytest.raises(ValueError, match="mu_f"):
        laws.coulomb_batch({k: v for k, v in c.items() if k != "mu_f"}, "newton")
    with pytest.raises(ValueError, match="'mu' is not read.*mu_f"):
        laws.coulomb_batch(dict(c, mu=0.3), "newton")
    with pytest.raises(ValueError, match="unknown column 'm_1'"):
        laws.kudlich_slibar_batch(dict(c, m_1=1.0), "full")
    with pytest.raises(ValueError, match="e: must be numbers"):
        laws.coulomb_batch(dict(c, e=np.array(["0.3"] * len(c["e"]))), "newton")
