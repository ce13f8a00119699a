"""Small helpers every runtime module shares, each kept in this one place.

- `require`: an optional dependency, or a one-line ImportError naming the
  extra that installs it (``pip install 'impactsym[sweep]'``).
- `is_dataframe`: a pandas DataFrame, recognised without importing pandas.
- `row_count`: the common length of a set of columns (scalars broadcast).
- `spans`: the ``(start, stop)`` row ranges of a chunked run.

Imports nothing of impactsym, so any module may use it.
"""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Iterable, Iterator

import numpy as np

__all__ = ["CHUNK_SIZE", "require", "is_dataframe", "row_count", "spans"]

#: Rows per chunk by default (sweeps, samples, dask batches): about 50 MB of results.
CHUNK_SIZE = 1 << 18


def require(module: str, *, extra: str, what: str, load: bool = True):
    """The module ``module`` imported, or ImportError ``"{what} needs
    {module}: pip install 'impactsym[{extra}]'"``. With ``load=False`` only
    checks that it is installed (no import cost: argument parsing) and returns None."""
    hint = f"{what} needs {module}: pip install 'impactsym[{extra}]'"
    if not load:
        if importlib.util.find_spec(module) is None:
            raise ImportError(hint)
        return None
    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(hint) from None


def is_dataframe(obj) -> bool:
    """True for a pandas DataFrame (checked by type, so pandas is never imported here)."""
    return type(obj).__module__.startswith("pandas") and hasattr(obj, "columns")


def row_count(columns, names: Iterable[str] | None = None) -> int:
    """The common length of the array columns among ``names`` (default: all),
    1 when every one is a scalar; columns not present are skipped.
    ValueError ``"{name}: length L differs from the other columns (N)"`` names
    the first column whose length differs from those before it."""
    n = None
    for name in columns if names is None else names:
        if name not in columns or np.ndim(columns[name]) == 0:
            continue
        length = len(columns[name])
        if n is not None and length != n:
            raise ValueError(f"{name}: length {length} differs from the other columns ({n})")
        n = length
    return 1 if n is None else n


def spans(rows: int, chunk_size: int) -> Iterator[tuple[int, int]]:
    """``(start, stop)`` of each chunk of ``chunk_size`` rows out of ``rows``, in order."""
    return ((start, min(start + chunk_size, rows)) for start in range(0, rows, chunk_size))
