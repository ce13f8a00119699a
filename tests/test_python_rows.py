"""The per-scene functions and the numba drivers give the same bits.

A single scene runs a kernel's per-scene function (generated/<model>.py, plain
Python); a batch runs its numba driver (generated/<model>_jit.py). Which path a
row takes must not show in its results: for every kernel with a driver, random
rows (and rows that fail every way a row can) give the same bits, status and
flags through the per-scene function, row by row, as through `run_batch`.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from impactsym import _kernels
from impactsym._kernels import registry

# Ranges of the random inputs by name (anything else: uniform in [-3, 3]).
POSITIVE = {"m1", "m2", "I1", "I2", "A", "B", "width", "rg1", "rg2", "mass", "inertia", "E", "r", "TL"}
RANGES = {
    "C1": (0.0, 0.8),
    "C2": (0.0, 0.8),
    "C3": (0.0, 0.8),
    "C4": (0.0, 0.8),
    "C5": (0.0, 0.8),
    "C6": (0.0, 0.8),
    "e": (0.0, 1.0),
    "e_m": (0.0, 1.0),
    "mu": (-0.6, 0.6),
    "slip": (0.0, 1.0),
    "alpha": (-1.2, 1.2),
}
# Rows that fail or stress a kernel: (input name, value) set on one row each.
SPECIAL = [
    ("m1", math.nan),
    ("m1", 0.0),
    ("m2", -1.0),
    ("m1", math.inf),
    ("e", math.nan),
    ("gamma", 2.0e6),  # beyond SINCOS_LIMIT: NumPy's cos/sin give the normal
    ("gamma", -math.inf),
    ("v1x", 1e300),
    ("V1x", 1e300),
    ("alpha", 1.5707963267948966),
    ("C1", -1.0),
    ("width", 1e-320),
    ("inertia", 1e-320),
]


def _kernel_sets():
    return list(registry.batch_kernels())


def _columns(ks, n: int, seed: int) -> list:
    rng = np.random.default_rng(seed)
    columns = []
    for name in ks.inputs:
        if name in POSITIVE:
            column = rng.uniform(0.5, 3.0, n)
        else:
            column = rng.uniform(*RANGES.get(name, (-3.0, 3.0)), n)
        columns.append(column)
    for row, (name, value) in enumerate(SPECIAL):
        if name in ks.inputs and row < n:
            columns[ks.inputs.index(name)][row] = value
    return columns


def _values(column, n: int) -> list:
    """A column as n Python floats (a scalar repeated)."""
    if isinstance(column, np.ndarray):
        return column.tolist()
    return [float(column)] * n


def _scene_rows(ks, inputs: list, n: int):
    """(outputs, status, flags) of the per-scene function, row by row. The
    normal of a row as the runtime forms it (conventions of the runner): the
    kernel's `unit_normal` of the angle, except when a finite angle of the
    column lies beyond SINCOS_LIMIT: then NumPy's cos/sin for the column."""
    rows = [_values(c, n) for c in inputs]
    if ks.angle is not None:
        at = ks.inputs.index(ks.angle)
        angle = np.asarray(rows[at])
        beyond = np.isfinite(angle) & (np.abs(angle) > registry.SINCOS_LIMIT)
        if isinstance(inputs[at], np.ndarray) and beyond.any():
            with np.errstate(invalid="ignore"):
                nx, ny = np.cos(angle).tolist(), np.sin(angle).tolist()
        else:
            nx, ny = zip(*map(ks.unit_normal, rows[at]))
        rows[at : at + 1] = [nx, ny]
    results = list(map(ks.scene, *rows))
    columns = list(zip(*results))
    outs = {name: np.array(columns[k], dtype=float) for k, name in enumerate(ks.outputs)}
    status = np.array(columns[-2], dtype=np.int32)
    # What a driver writes besides: a class code as int64, -1 where the row
    # failed (NaN here); the kernel's constants, NaN where the row failed.
    for name in ks.integers:
        outs[name] = np.where(np.isnan(outs[name]), -1, outs[name]).astype(np.int64)
    for name, value in ks.constants.items():
        outs[name] = np.where(status == 0, value, np.nan)
    return outs, status, np.array(columns[-1], dtype=np.int32)


def _assert_same(python, drivers, label: str) -> None:
    (p_outs, p_status, p_flags), (d_outs, d_status, d_flags) = python, drivers
    np.testing.assert_array_equal(p_status, d_status, err_msg=f"{label}: status")
    np.testing.assert_array_equal(p_flags, d_flags, err_msg=f"{label}: flags")
    assert list(d_outs) == list(p_outs), f"{label}: the driver's columns"
    for name in d_outs:
        assert d_outs[name].dtype == p_outs[name].dtype, f"{label}: {name} dtype"
        same = (p_outs[name] == d_outs[name]) | (np.isnan(p_outs[name]) & np.isnan(d_outs[name]))
        assert same.all(), f"{label}: {name} differs in {np.count_nonzero(~same)} rows"


@pytest.mark.parametrize("ks", _kernel_sets(), ids=lambda ks: ks.name)
def test_rows_in_python_equal_the_drivers_bitwise(ks):
    """Per-row columns, the special rows among them, and the ordinary rows
    alone (per-row angles within SINCOS_LIMIT: `_sincos` in the driver): the
    same bits both ways."""
    n = 400
    inputs = _columns(ks, n, seed=len(ks.name))
    drivers = _kernels.run_batch(ks, inputs, n)
    _assert_same(_scene_rows(ks, inputs, n), drivers, ks.name)
    rows = [c[len(SPECIAL) :] for c in inputs]
    m = n - len(SPECIAL)
    _assert_same(_scene_rows(ks, rows, m), _kernels.run_batch(ks, rows, m), f"{ks.name} (ordinary rows)")
    ok = np.count_nonzero(drivers[1] == 0)
    assert ok >= n // 10, f"{ks.name}: only {ok} of {n} random rows solved: the test checks too little"


@pytest.mark.parametrize("family", ["rigid", "particle"])
@pytest.mark.parametrize("n", [1, 300])
def test_scalar_columns_and_one_normal(family, n):
    """Scalars for masses, coefficients and the angle (one normal for the
    batch, read once by the driver), one row or many: the same bits both ways."""
    ks = _kernels.kernel_for(family, False)
    inputs = _columns(ks, n, seed=11)
    for name in ("m1", "I2", "e", "mu", "gamma"):
        if name in ks.inputs:
            inputs[ks.inputs.index(name)] = float(inputs[ks.inputs.index(name)][-1])
    _assert_same(_scene_rows(ks, inputs, n), _kernels.run_batch(ks, inputs, n), f"{family} scalars")
