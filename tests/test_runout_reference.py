"""Run-out kernels against an independent reference: scipy's solve_ivp (DOP853,
rtol 1e-10) on the contract's equations written by hand in
impactsym/testing/runout_reference.py. Random realistic run-outs with mixed
wheel states; the rest pose within 1 mm + 1e-5 of the path (conventions.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from impactsym.runout import runout_batch
from tests.runout_rows import realistic_row, rows_table

pytest.importorskip("scipy")
from impactsym.testing.runout_reference import reference_runout  # noqa: E402


def test_random_runouts_agree_with_solve_ivp():
    rng = np.random.default_rng(2024)
    rows = [realistic_row(rng) for _ in range(10)]
    out = runout_batch(rows_table(rows))
    assert (out["status"] == 0).all()
    for i, row in enumerate(rows):
        x, y, psi, t, dist = reference_runout(row)
        allowed = 1e-3 + 1e-5 * dist
        assert math.hypot(out["x_rest"][i] - x, out["y_rest"][i] - y) < allowed, i
        assert abs(out["distance"][i] - dist) < allowed, i
        assert abs(math.degrees(out["psi_rest"][i] - psi)) < 0.01, i
