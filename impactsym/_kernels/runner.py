"""Columns in, outputs out: one kernel over a batch (its numba driver) or one
scene (its per-scene function).

Every driver argument is a C-contiguous float64 array (or None for the
normal's forms the batch does not use), so each driver compiles once per
machine and form of the normal (numba's on-disk cache) whatever mix of scalar
and array columns a caller gives: a scalar column becomes a filled array,
reused chunk after chunk (`FILL_BYTES`). An angle column is passed as it is
(the driver forms the normal per row and counts the finite angles beyond
SINCOS_LIMIT in the same loop: a batch with any is solved again with NumPy's
cos/sin as (nx, ny) columns); one angle for the batch becomes its normal,
once, as the length-2 `normal` that the driver reads before its loop. Every batch runs the driver's
`prange` loop, however small: on one row the launch costs a few microseconds
more than a serial loop, measured in benchmarks/results/performance.md.
"""

from __future__ import annotations

import math
import threading

import numpy as np

from .registry import KernelSet

# Scalar columns become filled arrays of at most FILL_BYTES together (and at
# least MIN_CHUNK rows), reused chunk after chunk. Few large chunks: on a busy
# machine every parallel call waits for its threads to be scheduled. The
# fills live in one scratch buffer per thread, kept between calls: a fresh
# allocation of that size lands on fresh pages, whose page faults cost more
# than filling them (docs/kernels.md).
FILL_BYTES = 16 << 20
MIN_CHUNK = 1 << 16
_SCRATCH = threading.local()


def as_input(value):
    """A batch input: a float scalar (the same for every row) or a writable
    C-contiguous float64 array (one value per row). A read-only array (pandas'
    copy-on-write columns, memory maps) is copied: numba types it differently,
    and a second signature would mean a second compile."""
    if np.ndim(value) == 0:
        return float(value)
    arr = np.ascontiguousarray(value, dtype=np.float64)
    return arr if arr.flags.writeable else arr.copy()


def run_batch(ks: KernelSet, inputs: list, n: int | None = None) -> tuple[dict, np.ndarray, np.ndarray]:
    """`run` after `as_input` on every input (for callers whose columns are
    not normalised yet)."""
    return run(ks, [as_input(x) for x in inputs], n)


def run(ks: KernelSet, inputs: list, n: int | None = None) -> tuple[dict, np.ndarray, np.ndarray]:
    """Run a kernel's driver over `inputs` (in `ks.inputs` order, each as
    `as_input` gives it: an array of the batch length or a float for every
    row) and return (every output the driver writes by name: computed and
    constant, status, flags) in freshly allocated arrays."""
    if n is None:
        n = max((x.shape[0] for x in inputs if isinstance(x, np.ndarray)), default=1)
    outs = allocate(ks, n)
    status = np.empty(n, dtype=np.int32)
    flags = np.empty(n, dtype=np.int32)
    columns = [*outs.values(), status, flags]
    if n and _call(ks.driver, _driver_columns(ks, inputs), columns):
        _call(ks.driver, _driver_columns(ks, inputs, numpy_normal=True), columns)
    return outs, status, flags


def allocate(ks: KernelSet, n: int) -> dict:
    """Empty output columns of `n` rows for the driver of `ks`, by name in its
    order: float64, int64 for a class code."""
    return {
        name: np.empty(n, dtype=np.int64 if name in ks.integers else np.float64) for name in ks.driver_outputs
    }


def _driver_columns(ks: KernelSet, inputs: list, numpy_normal: bool = False) -> list:
    """The driver's columns in its order (scalars still scalars). For a kernel
    in normal form, (angle, nx, ny, normal): the angle column, or one normal
    for every row as the length-2 `normal`, or with `numpy_normal` per-row
    normals from NumPy (for angles beyond SINCOS_LIMIT); None for the other
    forms (the driver compiles only the loop of the form it is given:
    derive/emit.py `driver_function`)."""
    if ks.angle is None:
        return inputs
    at = ks.inputs.index(ks.angle)
    angle = inputs[at]
    if not isinstance(angle, np.ndarray):
        normal = [None, None, None, np.array(ks.unit_normal(angle))]
    elif numpy_normal:
        with np.errstate(invalid="ignore"):
            normal = [None, np.cos(angle), np.sin(angle), None]
    else:
        normal = [angle, None, None, None]
    return inputs[:at] + normal + inputs[at + 1 :]


def _call(driver, columns: list, outs: list) -> int:
    """Run `driver` over all rows; scalar columns become filled arrays, a
    chunk of rows at a time. Returns how many finite angles were beyond
    SINCOS_LIMIT (0 for a driver without an angle loop)."""
    n = outs[-1].shape[0]
    if all(c is None or isinstance(c, np.ndarray) for c in columns):
        return driver(*columns, *outs) or 0
    scalars = sum(isinstance(c, float) for c in columns)
    size = min(n, max(MIN_CHUNK, FILL_BYTES // (8 * scalars)))
    fills = _fills(columns, size, scalars)
    beyond = 0
    for start in range(0, n, size):
        stop = min(start + size, n)
        args = [
            _rows_of(c, start, stop, n) if f is None else f[: stop - start] for c, f in zip(columns, fills)
        ]
        beyond += driver(*args, *(o[start:stop] for o in outs)) or 0
    return beyond


def _rows_of(column: np.ndarray, start: int, stop: int, n: int) -> np.ndarray:
    """Rows start..stop-1 of an array column; the one normal (length 2) and
    an absent form of the normal (None) are passed whole."""
    return column[start:stop] if column is not None and column.shape[0] == n else column


def _fills(columns: list, size: int, scalars: int) -> list:
    """Per column: None for an array, else `size` copies of the scalar in
    this thread's scratch buffer (grown when too small, then kept)."""
    scratch = getattr(_SCRATCH, "buffer", None)
    if scratch is None or scratch.shape[0] < size * scalars:
        scratch = _SCRATCH.buffer = np.empty(size * scalars)
    fills, k = [], 0
    for column in columns:
        if not isinstance(column, float):
            fills.append(None)
            continue
        fill = scratch[k * size : (k + 1) * size]
        fill.fill(column)
        fills.append(fill)
        k += 1
    return fills


def run_one(ks: KernelSet, values: dict, outputs: tuple[str, ...]) -> dict:
    """Run one scene through a kernel's per-scene function (plain Python: no
    numba, no compile).

    Returns every name of `outputs` (computed, or the kernel's constant; NaN
    on a failed row) plus int `status` and `flags`."""
    args = [float(values[name]) for name in ks.inputs]
    if ks.angle is not None:
        at = ks.inputs.index(ks.angle)
        args[at : at + 1] = ks.unit_normal(args[at])
    *outs, status, flags = ks.scene(*args)
    result = dict(zip(ks.outputs, outs))
    for name in outputs:
        if name not in result:
            result[name] = ks.constants[name] if status == 0 else math.nan
    result["status"], result["flags"] = int(status), int(flags)
    return result
