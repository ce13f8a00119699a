"""Exact percentiles of sweep and sample rows, in memory or streamed in bounded memory.

`summary_frame` turns order statistics into the summary DataFrame (one row per
column, one column per percentile), with numpy.percentile's 'linear'
arithmetic step by step, so a streamed summary equals numpy's to the bit.
`InMemory` selects order statistics in memory (`impactsym.batch.selection`); `StreamSummary`
spills the values of solved rows to files and `OrderStatistics` selects from
them by radix passes over order-preserving 64-bit keys.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..scene import show_value

__all__ = [
    "add_counts",
    "check_q",
    "counts",
    "percentiles",
    "summary_frame",
    "InMemory",
    "StreamSummary",
    "OrderStatistics",
]


def check_q(q) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in np.atleast_1d(np.asarray(q, dtype=np.float64)))
    except (TypeError, ValueError):
        values = ()
    if not values or not all(0.0 <= v <= 100.0 for v in values):
        raise ValueError(f"q: percentiles must be between 0 and 100, got {show_value(q)}")
    return values


def counts(status: np.ndarray, flags: np.ndarray) -> dict:
    """Row counts: ``rows``, ``solved``, ``not_solved``, ``flagged`` and
    ``not_solved_by_status`` (status code -> rows: why rows were not solved,
    `impactsym.codes.describe_status`)."""
    solved = int(np.count_nonzero(status == 0))
    codes, numbers = np.unique(status[status != 0], return_counts=True)
    return {
        "rows": int(status.size),
        "solved": solved,
        "not_solved": int(status.size) - solved,
        "flagged": int(np.count_nonzero(flags)),
        "not_solved_by_status": {int(c): int(k) for c, k in zip(codes, numbers)},
    }


def add_counts(total: dict, more: dict) -> None:
    """Add the `counts` of more rows to ``total`` (in place)."""
    for key, value in more.items():
        if isinstance(value, dict):
            by = total.setdefault(key, {})
            for code, number in value.items():
                by[code] = by.get(code, 0) + number
            total[key] = dict(sorted(by.items()))
        else:
            total[key] = total.get(key, 0) + value


def _label(q: float) -> str:
    return f"p{q:g}"


def summary_frame(pd, stats: Mapping, q: tuple[float, ...], counts: dict):
    """The summary DataFrame: one row per column, one column per percentile."""
    labels = [_label(v) for v in q]
    rows = {name: _interpolate(stat, q) for name, stat in stats.items()}
    frame = (
        pd.DataFrame.from_dict(rows, orient="index", columns=labels)
        if rows
        else pd.DataFrame(columns=labels, dtype=np.float64)
    )
    frame.attrs["counts"] = {
        key: dict(value) if isinstance(value, dict) else value for key, value in counts.items()
    }
    return frame


def _interpolate(stat, q: tuple[float, ...]) -> np.ndarray:
    """Percentiles ``q`` from the order statistics of ``stat`` (``count`` and
    ``select(ranks)``), with numpy.percentile's default ('linear') arithmetic
    step by step, so the result equals numpy's to the bit."""
    n = stat.count
    if n == 0:
        return np.full(len(q), np.nan)
    virtual = (n - 1) * np.true_divide(np.asarray(q, dtype=np.float64), 100)
    previous = np.floor(virtual)
    gamma = virtual - previous
    lo = previous.astype(np.intp)
    hi = np.minimum(lo + 1, n - 1)
    values = stat.select(sorted({*lo.tolist(), *hi.tolist()}))
    a = np.array([values[i] for i in lo.tolist()])
    b = np.array([values[i] for i in hi.tolist()])
    diff = b - a
    result = np.add(a, diff * gamma)
    np.subtract(b, diff * (1 - gamma), out=result, where=gamma >= 0.5)
    return result


def percentiles(parts: list[np.ndarray], q: tuple[float, ...], bounds=None) -> np.ndarray:
    """numpy.percentile(concatenation of `parts`, q) (the 'linear' method),
    equal to it to the bit, without concatenating or sorting the parts (a
    NaN among the values makes every percentile NaN, as in numpy).
    `bounds`: the values' (min, max) when the caller has them (a NaN in
    either: some value is NaN)."""
    stat = InMemory(parts, bounds)
    if bounds is None:
        nan = any(np.isnan(p.min()) for p in stat.parts if p.size)
    else:
        nan = math.isnan(bounds[0]) or math.isnan(bounds[1])
    if nan:
        return np.full(len(q), np.nan)
    return _interpolate(stat, q)


class InMemory:
    """Order statistics of values held in memory: an array or a list of
    arrays (`impactsym.batch.selection`: exactly `numpy.partition`'s values)."""

    def __init__(self, values, bounds: tuple[float, float] | None = None):
        self.parts = list(values) if isinstance(values, (list, tuple)) else [values]
        self.count = sum(int(np.size(p)) for p in self.parts)
        self.bounds = bounds

    def select(self, ranks: list[int]) -> dict[int, float]:
        from .selection import select_ranks

        return select_ranks(self.parts, ranks, self.bounds)


class StreamSummary:
    """Counts and, per summary column, the values of solved rows spilled to
    files in ``directory``."""

    def __init__(self, columns: list[str], directory: Path):
        self.counts = {"rows": 0, "solved": 0, "not_solved": 0, "flagged": 0, "not_solved_by_status": {}}
        self.stats = {name: OrderStatistics(directory / f"{i}.f8") for i, name in enumerate(columns)}

    def add(self, frame) -> None:
        status = frame["status"].to_numpy()
        add_counts(self.counts, counts(status, frame["flags"].to_numpy()))
        solved = status == 0
        for name, stat in self.stats.items():
            stat.add(frame[name].to_numpy()[solved])

    def close(self) -> None:
        for stat in self.stats.values():
            stat.close()


_SIGN = np.uint64(1 << 63)
_RADIX = 16
_DIGITS = 1 << _RADIX


def _keys(values: np.ndarray) -> np.ndarray:
    """Unsigned 64-bit keys in the order of the float64 values (negative
    values' bits inverted, positive values' sign bit set)."""
    bits = np.ascontiguousarray(values, dtype=np.float64).view(np.uint64)
    return np.where((bits >> np.uint64(63)).astype(bool), ~bits, bits | _SIGN)


def _value(key: int) -> float:
    """The float64 of a key of `_keys`."""
    bits = key ^ (1 << 63) if key >> 63 else ~key & ((1 << 64) - 1)
    return float(np.array(bits, dtype=np.uint64).view(np.float64))


def _in_group(keys: np.ndarray, prefix: int, bits: int):
    """Index of the keys whose leading ``bits`` bits are ``prefix``."""
    if bits == 0:
        return slice(None)
    return (keys >> np.uint64(64 - bits)) == np.uint64(prefix)


class OrderStatistics:
    """Exact order statistics of a stream of finite float64 values in bounded memory.

    `add` appends values to ``path``. `select` finds the values of given
    0-based ranks of the sorted stream from order-preserving 64-bit keys
    (`_keys`), 16 bits at a time: each pass reads the file in blocks of
    `READ_BLOCK` values and, for every rank still open, counts the keys that
    share its known leading bits by their next 16 bits, which fixes 16 more
    bits of that rank's key and its rank within the narrower group. A group of
    at most `SORT_BUDGET` values is sorted in memory instead. At most five
    passes; memory about (READ_BLOCK + ranks·(2¹⁶ + SORT_BUDGET))·8 bytes.
    """

    READ_BLOCK = 1 << 20
    SORT_BUDGET = 1 << 19

    def __init__(self, path: Path):
        self.path, self.count = path, 0
        self._file = open(path, "wb")  # noqa: SIM115 (appended to by add, closed by close/select)

    def add(self, values: np.ndarray) -> None:
        # The file's own write, not ndarray.tofile (nor np.fromfile in `_pass`): numpy
        # 2.4 turns a KeyboardInterrupt that lands while it asks whether the file is
        # path-like into a TypeError, and a Ctrl-C during a sweep's spill then printed
        # a traceback instead of exiting 130 (CI, tests/test_first_use.py).
        self._file.write(np.ascontiguousarray(values, dtype=np.float64).data)
        self.count += values.size

    def close(self) -> None:
        self._file.close()

    def select(self, ranks: list[int]) -> dict[int, float]:
        self.close()
        # rank -> (key prefix, its bit count, rank within the group, group size)
        open_ = {rank: (0, 0, rank, self.count) for rank in ranks}
        found = {}
        while open_:
            for rank, (prefix, bits, _k, _size) in list(open_.items()):
                if bits == 64:  # every key of the group is the prefix
                    found[rank] = _value(prefix)
                    del open_[rank]
            small = {(p, b) for p, b, _k, size in open_.values() if size <= self.SORT_BUDGET}
            large = {(p, b) for p, b, _k, size in open_.values() if size > self.SORT_BUDGET}
            kept, counts = self._pass(small, large)
            for rank, (prefix, bits, k, _size) in list(open_.items()):
                if (prefix, bits) in kept:
                    found[rank] = _value(int(kept[(prefix, bits)][k]))
                    del open_[rank]
                else:
                    open_[rank] = _narrow(counts[(prefix, bits)], prefix, bits, k)
        return found

    def _pass(self, small: set, large: set) -> tuple[dict, dict]:
        """One read of the file: the sorted keys of each ``small`` group and
        the next-16-bit counts of each ``large`` group."""
        parts = {group: [] for group in small}
        counts = {group: np.zeros(_DIGITS, dtype=np.int64) for group in large}
        with open(self.path, "rb") as file:
            while (values := np.frombuffer(file.read(8 * self.READ_BLOCK), dtype=np.float64)).size:
                keys = _keys(values)
                for (prefix, bits), kept in parts.items():
                    kept.append(keys[_in_group(keys, prefix, bits)])
                for (prefix, bits), hist in counts.items():
                    group = keys[_in_group(keys, prefix, bits)]
                    digits = (group >> np.uint64(64 - bits - _RADIX)) & np.uint64(_DIGITS - 1)
                    hist += np.bincount(digits.astype(np.intp), minlength=_DIGITS)
        return {group: np.sort(np.concatenate(kept)) for group, kept in parts.items()}, counts


def _narrow(hist: np.ndarray, prefix: int, bits: int, k: int) -> tuple[int, int, int, int]:
    """The sub-group holding rank ``k`` of a group, from the counts of its
    keys' next 16 bits: (prefix, bits, rank within it, its size)."""
    cumulative = np.cumsum(hist)
    digit = int(np.searchsorted(cumulative, k, side="right"))
    below = int(cumulative[digit - 1]) if digit else 0
    return (prefix << _RADIX) | digit, bits + _RADIX, k - below, int(hist[digit])
