"""`impactsym compile` compiles the signatures the runtime calls: for every batch
kernel, the types of the arguments the runner passes its driver (an angle per
row, one normal for the batch) are among the signatures `compile_all` compiles,
int64 class columns included. Checked without compiling (numba.typeof)."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from impactsym._kernels import registry, runner
from impactsym._kernels.compile import _signatures


def _runtime_signature(ks, angle) -> tuple:
    n = 4
    inputs = [np.ones(n) for _ in ks.inputs]
    if ks.angle is not None:
        inputs[ks.inputs.index(ks.angle)] = angle
    columns = runner._driver_columns(ks, inputs)
    outs = [*runner.allocate(ks, n).values(), np.empty(n, np.int32), np.empty(n, np.int32)]
    return tuple(numba.typeof(a) for a in (*columns, *outs))


@pytest.mark.parametrize("ks", registry.batch_kernels(), ids=lambda ks: ks.name)
def test_compile_all_compiles_what_the_runner_calls(ks):
    compiled = [tuple(s) for s in _signatures(ks)]
    forms = [np.full(4, 0.3), 0.3] if ks.angle is not None else [None]
    for angle in forms:
        assert _runtime_signature(ks, angle) in compiled, f"{ks.name}: angle {type(angle).__name__}"
