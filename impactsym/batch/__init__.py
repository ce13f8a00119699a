"""The batch room: many scenes at once through the generated numba drivers.

`solve_batch` (solve.py; its columns checked and normalised in columns.py),
parameter sweeps and Monte Carlo samples around a scene (sweeps.py, planned in
plans.py, written by sinks.py, summarised by quantiles.py with selection.py,
within the memory and disk of resources.py) and the dask executor
(dask_engine.py).
"""

from __future__ import annotations

from .solve import run_columns, solve_batch, solve_batch_dask
from .sweeps import percentiles, sample, sweep

__all__ = ["percentiles", "run_columns", "sample", "solve_batch", "solve_batch_dask", "sweep"]
