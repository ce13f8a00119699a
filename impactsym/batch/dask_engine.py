"""The dask executor: runs chunk functions as dask tasks, and nothing else.

`map_chunks(fn, shared, items)` computes ``fn(shared, item)`` for every item
as a dask task and yields the results in order. The callers (`batch`,
`sweep`) pass their own module-level chunk functions and arguments, so this
module imports nothing of impactsym's runtime: ``fn``, ``shared`` and the
items must be picklable, and each task runs exactly the code the local engine
runs on the same rows, so results are identical, dtypes and row order included.

The tasks run on the active ``dask.distributed`` client when there is one
(``distributed.get_client()``), otherwise on dask's default scheduler (with
its threads the numba kernels need a thread-safe numba threading layer, omp
or tbb, which numba picks when installed). Needs the ``dask`` extra.
"""

from __future__ import annotations

import collections
import itertools
import os
from collections.abc import Callable, Iterable, Iterator

from .._util import require

__all__ = ["map_chunks", "CHUNKS_PER_THREAD"]

#: Chunks in flight per worker thread (memory: this many chunk results each).
CHUNKS_PER_THREAD = 2


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


def map_chunks(fn: Callable, shared, items: Iterable, *, scatter_items: bool = False) -> Iterator:
    """``fn(shared, item)`` for every item, in order, computed as dask tasks
    with at most `CHUNKS_PER_THREAD` tasks per worker thread in flight or
    waiting to be consumed, so memory stays bounded while the caller consumes
    (writes) the results. ``shared`` (a plan, options) is sent to each worker
    once; ``scatter_items`` sends each item to the cluster ahead of its task
    (large items: array chunks) instead of inside the task. ImportError at
    once, naming the extra, without dask."""
    dask = require("dask", extra="dask", what="engine='dask'")
    client = _client()
    items = iter(items)
    if client is None:
        return _batched(dask, fn, shared, items)
    return _windowed(client, fn, shared, items, scatter_items)


def _batched(dask, fn: Callable, shared, items: Iterator) -> Iterator:
    """On dask's default scheduler: one `dask.compute` per batch of items."""
    size = CHUNKS_PER_THREAD * (os.cpu_count() or 1)
    while batch := list(itertools.islice(items, size)):
        common = dask.delayed(shared, pure=True)
        yield from dask.compute(*[dask.delayed(fn, pure=False)(common, item) for item in batch])


def _windowed(client, fn: Callable, shared, items: Iterator, scatter_items: bool) -> Iterator:
    """On a distributed client: a sliding window of futures, so the workers
    compute the next chunks while the caller consumes this one."""
    size = CHUNKS_PER_THREAD * max(1, sum(client.nthreads().values()))
    # scatter([x])[0]: scatter splits a list, tuple or dict argument into many futures.
    # hash=False: a fresh key per call; with content-hashed keys a second call scattering
    # the same value races the release of the first call's copy ("lost dependencies").
    common = client.scatter([shared], broadcast=True, hash=False)[0]
    window = collections.deque()
    for item in items:
        argument = client.scatter([item], hash=False)[0] if scatter_items else item
        window.append(client.submit(fn, common, argument, pure=False))
        if len(window) >= size:
            yield window.popleft().result()
    while window:
        yield window.popleft().result()
