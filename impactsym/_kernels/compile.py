"""`impactsym compile`: compile (or load from numba's cache) every batch driver.

Nothing compiles in the background: a batch compiles the one driver it needs
on its first use on a machine (docs/kernels.md gives the time), and this
compiles all of them at once, for a machine that should never wait.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from .registry import batch_kernels


def compile_all(progress: Callable[[str], None] | None = None) -> int:
    """Compile every driver with the one signature the runtime calls it with:
    float64 C arrays in and out, int32 status and flags. Returns how many."""
    from numba import types

    count = 0
    for ks in batch_kernels():
        start = time.perf_counter()
        floats = len(ks.driver_columns) + len(ks.outputs)
        ks.driver.compile((types.float64[::1],) * floats + (types.int32[::1],) * 2)
        count += 1
        if progress is not None:
            progress(f"{ks.name}: {time.perf_counter() - start:.1f} s")
    return count
