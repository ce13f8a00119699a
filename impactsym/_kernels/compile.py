"""`impactsym compile`: compile (or load from numba's cache) every batch driver.

Nothing compiles in the background: a batch compiles the one driver it needs
(for the form of the normal it gives) on its first use on a machine (docs/kernels.md gives the time), and this
compiles all of them at once, for a machine that should never wait.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from .registry import batch_kernels


def compile_all(progress: Callable[[str], None] | None = None) -> int:
    """Compile every driver with the signatures the runtime calls it with:
    float64 C arrays in and out (int64 for a class code), int32 status and flags, and for a kernel in
    normal form the two forms of the normal a batch of real angles uses (an
    angle per row, one normal for the batch; the forms not given are None).
    The third, (nx, ny) columns, serves only angles beyond SINCOS_LIMIT (about
    262,000 turns) and compiles on the first such batch: compiling it here too
    would add half again to this command (151 s against 106 s,
    docs/kernels.md). Returns how many drivers."""
    count = 0
    for ks in batch_kernels():
        start = time.perf_counter()
        for signature in _signatures(ks):
            ks.driver.compile(signature)
        count += 1
        if progress is not None:
            progress(f"{ks.name}: {time.perf_counter() - start:.1f} s")
    return count


def _signatures(ks) -> list[tuple]:
    """The driver's signatures: one, or one per form of the normal."""
    from numba import types

    array, none = types.float64[::1], types.none
    outs = tuple(types.int64[::1] if name in ks.integers else array for name in ks.driver_outputs)
    outs += (types.int32[::1],) * 2
    columns = [array] * len(ks.driver_columns)
    if ks.angle is None:
        return [(*columns, *outs)]
    at = ks.driver_columns.index(ks.angle)
    forms = ((array, none, none, none), (none, none, none, array))
    return [(*columns[:at], *form, *columns[at + 4 :], *outs) for form in forms]
