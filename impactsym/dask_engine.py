"""The dask engine: the local chunk code run as dask tasks.

The tasks run on the active ``dask.distributed`` client when there is one
(``distributed.get_client()``), otherwise on dask's default scheduler (with
its threads the numba kernels need a thread-safe numba threading layer, omp
or tbb, which numba picks when installed). Each task runs exactly the code the
local engine runs on the same rows, so results are identical, dtypes and row
order included. Needs the ``dask`` extra.
"""

from __future__ import annotations

import collections
import itertools
import os
from collections.abc import Iterable, Iterator

import numpy as np

from .sweep import CHUNK_SIZE

__all__ = ["solve_batch_dask", "chunk_frames"]

#: Chunks in flight per worker thread while streaming (memory: this many chunk results each).
CHUNKS_PER_THREAD = 2


def _require_dask():
    try:
        import dask
    except ImportError:
        raise ImportError("engine='dask' needs dask: pip install 'impactsym[dask]'") from None
    return dask


def _client():
    """The active dask.distributed client, or None."""
    try:
        from distributed import get_client
    except ImportError:
        return None
    try:
        return get_client()
    except ValueError:
        return None


def _frame(plan, start: int, stop: int):
    """A task: rows start..stop-1 of a sweep or sample plan, built and solved on the worker."""
    return plan.frame(start, stop)


def chunk_frames(plan, spans: Iterable[tuple[int, int]]) -> Iterator:
    """``plan.frame(start, stop)`` for every span, in order, computed as dask
    tasks with at most `CHUNKS_PER_THREAD` chunks per worker thread in flight
    or waiting to be consumed, so memory stays bounded. A task receives only
    the plan and its two row indices. ImportError at once without dask."""
    dask = _require_dask()
    client = _client()
    spans = iter(spans)
    if client is None:
        return _batched_frames(dask, plan, spans)
    return _windowed_frames(client, plan, spans)


def _batched_frames(dask, plan, spans: Iterator[tuple[int, int]]) -> Iterator:
    """On dask's default scheduler: one `dask.compute` per batch of chunks."""
    size = CHUNKS_PER_THREAD * (os.cpu_count() or 1)
    while batch := list(itertools.islice(spans, size)):
        shared = dask.delayed(plan, pure=True)
        tasks = [dask.delayed(_frame, pure=True)(shared, start, stop) for start, stop in batch]
        yield from dask.compute(*tasks)


def _windowed_frames(client, plan, spans: Iterator[tuple[int, int]]) -> Iterator:
    """On a distributed client: a sliding window of futures, so the workers
    compute the next chunks while the caller consumes (writes) this one. The
    plan is sent to each worker once."""
    size = CHUNKS_PER_THREAD * max(1, sum(client.nthreads().values()))
    shared = client.scatter(plan, broadcast=True)
    window = collections.deque()
    for start, stop in spans:
        window.append(client.submit(_frame, shared, start, stop, pure=False))
        if len(window) >= size:
            yield window.popleft().result()
    while window:
        yield window.popleft().result()


def _solve(chunk: tuple, outputs):
    """A task: `solve_batch` with the local engine on one chunk, (columns, model)."""
    from .batch import solve_batch

    columns, model = chunk
    return solve_batch(columns, model=model, outputs=outputs, engine="local")


def _rows(columns: dict) -> int:
    """The common length of the array columns (1 when every column is a scalar)."""
    n = None
    for name, column in columns.items():
        if np.ndim(column) == 0:
            continue
        if n is not None and len(column) != n:
            raise ValueError(f"{name}: length {len(column)} differs from the other columns ({n})")
        n = len(column) if n is None else n
    return 1 if n is None else n


def _slice(columns: dict, start: int, stop: int) -> dict:
    return {name: column if np.ndim(column) == 0 else column[start:stop]
            for name, column in columns.items()}


def solve_batch_dask(columns, model="rigid", outputs=None, chunk_size: int = CHUNK_SIZE):
    """`solve_batch` over chunks of ``chunk_size`` rows as dask tasks: the
    same arguments (``model`` a name or one per row) and the same result (a
    dict, or a DataFrame with the input's index) as the local engine.

    With a distributed client the chunks are scattered to the workers (not
    embedded in the task graph); on dask's default scheduler they are passed
    as they are."""
    dask = _require_dask()
    frame_index = columns.index if _is_dataframe(columns) else None
    data = {name: columns[name].to_numpy() if frame_index is not None else columns[name]
            for name in columns}
    n = _rows({**data, "model": model})
    spans = [(start, min(start + chunk_size, n)) for start in range(0, n, chunk_size)]
    chunks = [(_slice(data, *span), _slice({"model": model}, *span)["model"]) for span in spans]
    client = _client()
    if client is None:
        parts = dask.compute(*[dask.delayed(_solve)(chunk, outputs) for chunk in chunks])
    else:
        futures = [client.submit(_solve, part, outputs) for part in client.scatter(chunks)]
        parts = client.gather(futures)
    result = {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}
    if frame_index is None:
        return result
    import pandas as pd

    return pd.DataFrame(result, index=frame_index)


def _is_dataframe(obj) -> bool:
    return type(obj).__module__.startswith("pandas") and hasattr(obj, "columns")
