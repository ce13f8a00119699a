"""The run-out room's threads: one pool for the batch's chunks of rows, the
fit's scan and its uniqueness starts. The kernels they call release the GIL
(generated/runout_jit.py: `runout_batch` and `runout_row_sens` are nogil), so
the threads share out the run-outs; the Python between two run-outs is small
against one (50-800 microseconds).
"""

from __future__ import annotations

import functools
import os
from concurrent.futures import ThreadPoolExecutor


def workers() -> int:
    """Threads: NUMBA_NUM_THREADS when set (the limit a numba user already
    sets), else one per CPU."""
    return int(os.environ.get("NUMBA_NUM_THREADS") or 0) or os.cpu_count() or 1


@functools.cache
def pool() -> ThreadPoolExecutor:
    """The pool (created on first use, idle threads otherwise)."""
    return ThreadPoolExecutor(max_workers=workers(), thread_name_prefix="impactsym-runout")
