"""Small batches before numba loads: the per-scene functions row by row.

A batch of fewer than `_kernels.PYTHON_BELOW` rows, in a process that has not
loaded the model's numba drivers, runs the kernel's per-scene function row by
row. Which path a batch takes must not show in its results: for every kernel
the runtime drives, random rows (and rows that fail every way a row can)
give the same bits, status and flags through the per-scene functions as
through the numba drivers.
"""

from __future__ import annotations

import dataclasses
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from impactsym import _kernels

# The runtime's threshold, read when this module is imported: conftest.py sets
# it to 0 for each test of the rest of the suite.
PYTHON_BELOW = _kernels.PYTHON_BELOW

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
    by_name = {}
    for ks, _parallel, _normal in _kernels.batch_drivers():
        by_name.setdefault(ks.name, ks)
    return list(by_name.values())


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


def _both_paths(ks, inputs: list, n: int, monkeypatch):
    """(per-scene rows, numba drivers) results of run_batch on the same inputs."""
    with monkeypatch.context() as m:
        m.setattr(_kernels, "_JIT_MODULES", {})
        m.setattr(_kernels, "PYTHON_BELOW", PYTHON_BELOW)
        m.setattr(_kernels, "_python_rows", 0)
        m.setattr(_kernels, "_after_first_batch", lambda: None)
        python = _kernels.run_batch(ks, [c.copy() if isinstance(c, np.ndarray) else c for c in inputs], n)
        assert _kernels._JIT_MODULES == {}, "the small batch loaded the numba drivers"
    with monkeypatch.context() as m:
        m.setattr(_kernels, "PYTHON_BELOW", 0)
        drivers = _kernels.run_batch(ks, inputs, n)
    return python, drivers


def _assert_same(python, drivers, label: str) -> None:
    (p_outs, p_status, p_flags), (d_outs, d_status, d_flags) = python, drivers
    np.testing.assert_array_equal(p_status, d_status, err_msg=f"{label}: status")
    np.testing.assert_array_equal(p_flags, d_flags, err_msg=f"{label}: flags")
    for name in d_outs:
        same = (p_outs[name] == d_outs[name]) | (np.isnan(p_outs[name]) & np.isnan(d_outs[name]))
        assert same.all(), f"{label}: {name} differs in {np.count_nonzero(~same)} rows"


@pytest.mark.parametrize("ks", _kernel_sets(), ids=lambda ks: ks.name)
def test_rows_in_python_equal_the_drivers_bitwise(ks, monkeypatch):
    """Per-row columns, the special rows among them: the same bits both ways, and
    the per-scene path really ran (it did not fall back to the drivers)."""
    n = 400
    inputs = _columns(ks, n, seed=len(ks.name))
    python, drivers = _both_paths(ks, inputs, n, monkeypatch)
    _assert_same(python, drivers, ks.name)
    # the ordinary rows alone: the per-scene path itself ran (no fallback)
    rows = [c[len(SPECIAL) :] for c in inputs]
    m = n - len(SPECIAL)
    outs = {name: np.empty(m) for name in ks.outputs}
    status, flags = np.empty(m, np.int32), np.empty(m, np.int32)
    columns, normal = _kernels._columns_for(ks, rows, m)
    assert _kernels._run_rows(ks, columns, normal, outs, status, flags), f"{ks.name}: a row raised"
    _assert_same((outs, status, flags), _both_paths(ks, rows, m, monkeypatch)[1], f"{ks.name} (_run_rows)")
    ok = np.count_nonzero(drivers[1] == 0)
    assert ok >= n // 10, f"{ks.name}: only {ok} of {n} random rows solved: the test checks too little"


@pytest.mark.parametrize("family", ["rigid", "particle"])
def test_scalar_columns_and_one_normal(family, monkeypatch):
    """Scalars for masses, coefficients and the angle (the normal form with a
    length-1 normal): the same bits both ways."""
    ks = _kernels.kernel_for(family, False)
    n = 300
    inputs = _columns(ks, n, seed=11)
    for name in ("m1", "I2", "e", "mu", "gamma"):
        if name in ks.inputs:
            inputs[ks.inputs.index(name)] = float(inputs[ks.inputs.index(name)][-1])
    python, drivers = _both_paths(ks, inputs, n, monkeypatch)
    _assert_same(python, drivers, f"{family} scalars")


def test_a_row_python_cannot_evaluate_falls_back_to_the_drivers(monkeypatch):
    """A per-scene function that raises (Python float arithmetic raises where
    numba's returns inf or NaN): the batch runs through the drivers instead."""
    ks = _kernels.kernel_for("particle", False)

    def raising(*args):
        raise ValueError("math domain error")

    broken = dataclasses.replace(ks, scene=raising)

    n = 50
    inputs = _columns(ks, n, seed=3)
    with monkeypatch.context() as m:
        m.setattr(_kernels, "PYTHON_BELOW", 0)
        want = _kernels.run_batch(ks, inputs, n)
    with monkeypatch.context() as m:
        m.setattr(_kernels, "_JIT_MODULES", {})
        m.setattr(_kernels, "PYTHON_BELOW", PYTHON_BELOW)
        m.setattr(_kernels, "_python_rows", 0)
        m.setattr(_kernels, "_after_first_batch", lambda: None)
        got = _kernels.run_batch(broken, inputs, n)
    _assert_same(got, want, "fallback")


def test_a_small_first_batch_does_not_import_numba():
    """In a fresh process, a first sweep of 900 points and a 5,000-row
    solve_batch return without importing numba; a batch of PYTHON_BELOW rows
    loads the drivers."""
    code = (
        "import sys, numpy as np, impactsym\n"
        "from impactsym import _kernels\n"
        "impactsym.sweep('examples/intersection_si.toml', e=np.linspace(0, 1, 30), "
        "mu=np.linspace(-0.3, 0.3, 30))\n"
        "impactsym.solve_batch(dict(m1=1500.0, m2=1200.0, I1=2500.0, I2=2000.0, "
        "v1x=np.full(5000, 15.0), v1y=0.0, w1=0.0, v2x=0.0, v2y=10.0, w2=0.0, r1x=1.5, "
        "r1y=0.5, r2x=-0.5, r2y=1.0, gamma=0.3, e=0.2, mu=0.1, e_m=0.5))\n"
        "print('numba' in sys.modules)\n"
        "impactsym.solve_batch(dict(m1=1500.0, m2=1200.0, I1=2500.0, I2=2000.0, "
        "v1x=np.full(_kernels.PYTHON_BELOW, 15.0), v1y=0.0, w1=0.0, v2x=0.0, v2y=10.0, "
        "w2=0.0, r1x=1.5, r1y=0.5, r2x=-0.5, r2y=1.0, gamma=0.3, e=0.2, mu=0.1, e_m=0.5))\n"
        "print('numba' in sys.modules)\n"
    )
    env = {"IMPACTSYM_BACKGROUND_COMPILE": "0"}
    run = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env={**os.environ, **env},
        cwd=Path(__file__).resolve().parents[1],
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["False", "True"], run.stdout


def test_the_budget_is_per_process_not_per_call(monkeypatch):
    """Small batches run in Python only until the process has run PYTHON_BELOW
    rows that way; then the drivers load, so a loop of small batches is not left
    in Python."""
    ks = _kernels.kernel_for("particle", False)
    inputs = _columns(ks, 400, seed=5)
    with monkeypatch.context() as m:
        m.setattr(_kernels, "_JIT_MODULES", {})
        m.setattr(_kernels, "PYTHON_BELOW", 1000)
        m.setattr(_kernels, "_python_rows", 0)
        m.setattr(_kernels, "_after_first_batch", lambda: None)
        for _ in range(2):
            _kernels.run_batch(ks, inputs, 400)
        assert _kernels._JIT_MODULES == {} and _kernels._python_rows == 800
        _kernels.run_batch(ks, inputs, 400)
        assert ks.model in _kernels._JIT_MODULES, "the third batch did not load the drivers"
        assert _kernels._python_rows == 800
