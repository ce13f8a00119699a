"""Exact order statistics of float64 values in memory, by counting them in bins (numba).

`select_ranks(parts, ranks)` returns the values of the given 0-based ranks of
the sorted concatenation of `parts` without concatenating or sorting them:
one pass counts the values per bin of ``SELECT_BINS`` equal bins over
[min, max] (bin ``floor((x - min)·scale)``, the last bin closed), a second
gathers the values of the few bins holding a wanted rank, and
`numpy.partition` of those gives the rank within its bin. The bin of a value
is a monotone function of the value (subtraction of a constant and
multiplication by a positive constant round monotonically, and so does the
floor), so every value of a lower bin is ≤ every value of a higher bin and
the result is exactly the value `numpy.partition` of the whole would give.
Values that are not all finite, or fewer than ``SELECT_MIN`` values, go to
`numpy.partition` of the concatenation (NaN sorts last there, as in numpy).

This module imports numba: it is imported on first use (`impactsym.batch.quantiles`).
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["select_ranks", "compile_loops", "SELECT_BINS", "SELECT_MIN"]

SELECT_BINS = 1 << 12
SELECT_MIN = 1 << 14


@numba.njit(cache=True, nogil=True)
def _count(x, lo, scale, counts):  # pragma: no cover (compiled)
    """Add the bin counts of `x` to `counts` (bins of width 1/scale from lo)."""
    top = counts.size - 1
    for v in x:
        b = (v - lo) * scale
        counts[min(int(b), top) if b < top else top] += 1


@numba.njit(cache=True, nogil=True)
def _gather(x, lo, scale, wanted, out, m):  # pragma: no cover (compiled)
    """Append the values of `x` whose bin is `wanted` to out[m:]; the new m."""
    top = wanted.size - 1
    for v in x:
        b = (v - lo) * scale
        if wanted[min(int(b), top) if b < top else top]:
            out[m] = v
            m += 1
    return m


def compile_loops() -> int:
    """Compile (or load from numba's cache) the two loops with the one
    signature `select_ranks` calls them with, so that no percentile waits
    for the compiler after `impactsym compile`; returns how many (2)."""
    f8, c8 = numba.types.float64, numba.types.float64[::1]
    _count.compile((c8, f8, f8, numba.types.int64[::1]))
    _gather.compile((c8, f8, f8, numba.types.boolean[::1], c8, numba.types.int64))
    return 2


def _bin_of(values: np.ndarray, lo: float, scale: float) -> np.ndarray:
    """The bins `_count` and `_gather` assign (the same arithmetic, in numpy)."""
    b = (values - lo) * scale
    return np.where(b < SELECT_BINS - 1, np.minimum(np.floor(b), SELECT_BINS - 1), SELECT_BINS - 1)


def select_ranks(
    parts: list[np.ndarray], ranks, bounds: tuple[float, float] | None = None
) -> dict[int, float]:
    """{rank: value} for the 0-based `ranks` of the sorted concatenation of
    the float64 arrays `parts` (module docstring). `bounds`: their minimum
    and maximum when the caller knows them (and knows there is no NaN)."""
    parts = [np.ascontiguousarray(p, dtype=np.float64) for p in parts if np.size(p)]
    ranks = sorted(set(int(r) for r in ranks))
    n = sum(p.size for p in parts)
    if n < SELECT_MIN:
        return _partition(parts, ranks)
    if bounds is None:
        bounds = min(float(p.min()) for p in parts), max(float(p.max()) for p in parts)
    lo, hi = bounds
    scale = SELECT_BINS / (hi - lo) if hi > lo else math.inf
    if not (math.isfinite(lo) and math.isfinite(hi) and math.isfinite(scale)):
        return _partition(parts, ranks)
    counts = np.zeros(SELECT_BINS, dtype=np.int64)
    for p in parts:
        _count(p, lo, scale, counts)
    cumulative = np.cumsum(counts)
    bins = np.searchsorted(cumulative, ranks, side="right")
    within = {r: r - (int(cumulative[b - 1]) if b else 0) for r, b in zip(ranks, bins.tolist())}
    wanted = np.zeros(SELECT_BINS, dtype=np.bool_)
    wanted[bins] = True
    gathered = np.empty(int(counts[wanted].sum()), dtype=np.float64)
    m = 0
    for p in parts:
        m = _gather(p, lo, scale, wanted, gathered, m)
    of = _bin_of(gathered, lo, scale)
    out = {}
    for b in sorted(set(bins.tolist())):
        group = gathered[of == b]
        ks = sorted({within[r] for r, rb in zip(ranks, bins.tolist()) if rb == b})
        group = np.partition(group, ks)
        out.update({r: float(group[within[r]]) for r, rb in zip(ranks, bins.tolist()) if rb == b})
    return out


def _partition(parts: list[np.ndarray], ranks: list[int]) -> dict[int, float]:
    values = np.concatenate(parts) if parts else np.empty(0)
    part = np.partition(values, ranks)
    return {r: float(part[r]) for r in ranks}
