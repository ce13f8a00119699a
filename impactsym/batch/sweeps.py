"""Parameter sweeps and Monte Carlo samples around a base scene, in chunks.

`sweep` solves the cartesian grid of the values it is given, `sample` draws the
inputs from distributions; both return a tidy pandas DataFrame, one row per
scene: the varied parameters (under the names the caller gave, in the scene's
units, ``normal_angle`` in degrees), then the outputs of `solve_batch`, then
``status`` and ``flags`` (see `impactsym.codes`). Every number comes from the
generated kernels through `solve_batch`; this module only builds inputs,
streams results and summarises them.

Before any work, a run that cannot fit is refused with a one-line ValueError
(`impactsym.batch.resources`): rows held in memory beyond half of the available
memory (use ``out=``), or percentile spill files beyond the free temporary
space. The spill files live in a temporary folder removed on every way out
(the end, an error, Ctrl-C; the command line turns SIGTERM into an exit so
they are removed then too).

Work runs in chunks of ``chunk_size`` rows: a chunk builds its own inputs from
its (start, stop) row indices (grid rows by `numpy.unravel_index`, sample rows
from fixed random blocks), so neither the grid nor the sample is ever held as
a whole, and a chunk runs the same way locally or as a dask task
(``engine="dask"``). With ``out=`` a ``.parquet`` or ``.csv`` file receives the
rows chunk by chunk and only a summary is returned (`percentiles`), computed
exactly in bounded memory.

Names (``**values`` of `sweep`, the keys of `sample`'s ``dists``): every kernel
input of the scene's model that the model does not fix, by its batch name
(``m1 m2 I1 I2 v1x v1y w1 v2x v2y w2 r1x r1y r2x r2y gamma e mu e_m``, ``slip``
for IMPAC's sideswipe; particles have no ``I``, ``w``, ``r``), in the scene's
units with ``gamma`` in radians, and the scene-file names ``normal_angle``
(degrees), ``restitution`` (e), ``impulse_ratio`` (mu) and
``moment_restitution`` (e_m).

Needs the ``sweep`` extra (pandas, pyarrow, tqdm); ``as_xarray`` the ``xarray``
extra, ``engine="dask"`` the ``dask`` extra.

This module is the API and runs the chunks; what a chunk computes is in
`impactsym.batch.plans`, the file writers in `impactsym.batch.sinks`, the exact
streaming percentiles in `impactsym.batch.quantiles`, and the dask executor in
`impactsym.batch.dask_engine`.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator, Mapping
from pathlib import Path

import numpy as np

from .._util import CHUNK_SIZE, require, spans
from ..scene import show_value
from .dask_engine import map_chunks
from .plans import BLOCK, DISTRIBUTIONS, GridPlan, SamplePlan, check_outputs, frame_of, is_integer
from .quantiles import InMemory, StreamSummary, check_q, counts, summary_frame
from .resources import check_disk, check_memory
from .sinks import sink, write_frame, writing
from .spill import spill_folder

__all__ = [
    "sweep",
    "sample",
    "percentiles",
    "summary_columns",
    "GridPlan",
    "SamplePlan",
    "collect",
    "summarize",
    "write_frame",
    "CHUNK_SIZE",
    "BLOCK",
    "DISTRIBUTIONS",
    "PERCENTILES",
    "SWEEP_PERCENTILES",
]

#: Work larger than this many rows shows a progress bar on a terminal (about a second).
PROGRESS_ROWS = 5_000_000
#: Summary columns and percentiles of `percentiles` and of `sample(out=...)`.
SUMMARY_COLUMNS = ("dV1", "dV2", "TL")
PERCENTILES = (5, 25, 50, 75, 95)
#: Percentiles of `sweep(out=...)`: minimum, median, maximum.
SWEEP_PERCENTILES = (0, 50, 100)


# --------------------------------------------------------------------------- public API


def sweep(
    scene,
    *,
    outputs=None,
    engine: str = "local",
    chunk_size: int = CHUNK_SIZE,
    out=None,
    progress=None,
    as_xarray: bool = False,
    **values,
):
    """Solve the cartesian grid of ``values`` around a base scene.

    ``scene`` is a scene file path, a mapping in scene-file form or a
    `Scene`; it gives the model, the units and every input not in ``values``.
    Each keyword names an input (see the module docstring) and gives a scalar
    (a constant replacing the scene's value) or a non-empty 1-D sequence (a
    grid axis); ``mu`` values may include ``"critical"`` (μ = μ_c). Units are
    the scene's, ``gamma`` radians, ``normal_angle`` degrees.

    Rows run over the axes in C order, the first axis given slowest, as
    ``np.meshgrid(*axes, indexing="ij")`` flattened. Columns: the axes (as
    given; a ``mu`` axis mixing numbers and ``"critical"`` is an object column),
    then ``outputs`` of `solve_batch` (the ``mu`` output, the impulse ratio
    used, is left out when an axis is named ``mu``: it is the axis value, or
    ``mu_c`` on a critical row), then ``status`` and ``flags`` (int32). A row that
    cannot be solved (a negative mass, NaN, not approaching) has a non-zero
    ``status`` and NaN outputs; the other rows are unaffected.

    Returns the DataFrame (index 0..rows-1), or with ``as_xarray=True`` an
    `xarray.Dataset` with one dimension per axis. With ``out`` (a ``.parquet``
    file, one row group per chunk, or ``.csv``, header once; a mixed ``mu``
    column is text there) the rows are written chunk by chunk, memory stays
    bounded by ``chunk_size``, and the return value is the summary
    ``percentiles(rows, q=(0, 50, 100))`` (minimum, median, maximum of ``dV1
    dV2 TL``, those the outputs include: `summary_columns`), exact: the summarised values of
    solved rows spill to a temporary file (8 bytes each), not to memory.

    ``engine="dask"`` runs the chunks as dask tasks on the active
    ``dask.distributed`` client (or dask's default scheduler); the result is
    identical. ``progress``: a tqdm bar on stderr; None shows it on a terminal
    for more than `PROGRESS_ROWS` rows. Raises ValueError (one line, naming
    the parameter) for an unknown or fixed name or a bad value.
    """
    if as_xarray and out is not None:
        raise ValueError("as_xarray: cannot be combined with out (the file holds the rows)")
    if as_xarray:
        require("xarray", extra="xarray", what="sweep(as_xarray=True)")
    plan = GridPlan.build(scene, values, outputs)
    if out is not None:
        return summarize(
            plan, out=out, q=SWEEP_PERCENTILES, engine=engine, chunk_size=chunk_size, progress=progress
        )
    frame = collect(plan, engine=engine, chunk_size=chunk_size, progress=progress)
    return plan.to_xarray(frame) if as_xarray else frame


def sample(
    scene,
    dists: Mapping,
    n: int,
    *,
    seed=None,
    outputs=None,
    engine: str = "local",
    chunk_size: int = CHUNK_SIZE,
    out=None,
    progress=None,
):
    """Monte Carlo: solve ``n`` scenes whose inputs are drawn from ``dists``.

    ``dists`` maps input names (as for `sweep`, in the scene's units,
    ``normal_angle`` in degrees) to ``("uniform", low, high)``,
    ``("normal", mean, sd)``, ``("triangular", left, mode, right)`` or
    ``("lognormal", mean_of_log, sd_of_log)``; the other inputs are the
    scene's. Draws that make a row unsolvable (a negative mass from a normal)
    give that row a non-zero ``status``.

    Reproducible: rows come in blocks of `BLOCK`; block b is drawn from
    ``PCG64(SeedSequence(entropy, spawn_key=(b,)))``, one full block per
    parameter in the order of ``dists``, so row i is the same whatever
    ``n`` (beyond i), ``chunk_size`` and ``engine``. ``seed`` is a
    non-negative int (the entropy) or None for fresh entropy; the entropy used
    is ``result.attrs["seed"]``. Adding a parameter at the end of ``dists``
    keeps the others' draws.

    Returns the DataFrame of ``n`` rows (drawn columns under their names, then
    outputs, ``status``, ``flags``; see `sweep`). With ``out`` (``.parquet`` or
    ``.csv``) the rows go to the file chunk by chunk, memory stays bounded by
    ``chunk_size`` as for `sweep`, and the return value is the exact summary
    ``percentiles(rows)`` (`summary_columns`: ``dV1 dV2 TL`` or the velocities, at
    5, 25, 50, 75, 95 %), with ``attrs["seed"]`` too.
    """
    plan = SamplePlan.build(scene, dists, n, seed, outputs)
    if out is not None:
        result = summarize(
            plan, out=out, q=PERCENTILES, engine=engine, chunk_size=chunk_size, progress=progress
        )
    else:
        result = collect(plan, engine=engine, chunk_size=chunk_size, progress=progress)
    result.attrs["seed"] = plan.entropy
    return result


def summary_columns(outputs) -> list[str]:
    """The outputs a summary reports: those of `SUMMARY_COLUMNS` that
    ``outputs`` (a `solve_batch` tier or list) includes, or, when it includes
    none of them (``"velocities"``), every output it has."""
    names = check_outputs(outputs)
    return [name for name in SUMMARY_COLUMNS if name in names] or list(names)


def percentiles(df, columns=SUMMARY_COLUMNS, q=PERCENTILES):
    """Percentiles of ``columns`` over the solved rows (``status == 0``) of a
    sweep or sample frame.

    Returns a DataFrame with one row per column and one column per percentile
    (``p5 p25 ...``), computed as ``numpy.percentile`` does (linear
    interpolation), NaN when no row is solved. ``attrs["counts"]`` holds
    ``rows``, ``solved``, ``not_solved`` and ``flagged`` (rows with any flag
    bit: solved but physically impossible; they are included in the
    percentiles).
    """
    pd = require("pandas", extra="sweep", what="percentiles")
    q = check_q(q)
    _check_columns(df, ("status", "flags", *columns))
    solved = np.asarray(df["status"]) == 0
    stats = {name: InMemory(np.asarray(df[name], dtype=np.float64)[solved]) for name in columns}
    return summary_frame(pd, stats, q, counts(np.asarray(df["status"]), np.asarray(df["flags"])))


# --------------------------------------------------------------------------- running chunks


def _frames(plan, engine: str, chunk_size: int) -> Iterator:
    """Every chunk of ``plan`` solved, in row order, by the chosen engine."""
    if not is_integer(chunk_size) or chunk_size < 1:
        raise ValueError(f"chunk_size: must be a positive integer, got {show_value(chunk_size)}")
    chunks = spans(plan.rows, chunk_size)
    if engine == "dask":
        return map_chunks(frame_of, plan, chunks)
    if engine != "local":
        raise ValueError(f"engine: unknown engine {show_value(engine)} (use local or dask)")
    return (frame_of(plan, span) for span in chunks)


def collect(plan, *, engine: str = "local", chunk_size: int = CHUNK_SIZE, progress=None):
    """Every row of ``plan`` in one DataFrame (index 0..rows-1)."""
    pd = require("pandas", extra="sweep", what="collect")
    check_memory(plan.rows, _values_per_row(plan), _kind(plan))
    frames = list(_with_progress(_frames(plan, engine, chunk_size), plan.rows, progress))
    return frames[0] if len(frames) == 1 else pd.concat(frames)


def summarize(
    plan, *, out=None, q=PERCENTILES, engine: str = "local", chunk_size: int = CHUNK_SIZE, progress=None
):
    """Stream every chunk of ``plan`` to ``out`` (a ``.parquet`` or ``.csv``
    path, or None for no file) and return ``percentiles`` of the rows for the
    default summary columns the outputs include, with bounded memory: the
    summarised values of solved rows spill to a temporary file (8 bytes per
    value) and the percentiles are selected exactly from it. The columns are
    `summary_columns` of the plan's outputs."""
    pd = require("pandas", extra="sweep", what="streaming")
    q = check_q(q)
    columns = summary_columns(plan.outputs)
    check_disk(plan.rows, len(columns), _kind(plan))
    frames = _frames(plan, engine, chunk_size)
    writer = sink(out, plan.repeated)
    frames = _with_progress(frames, plan.rows, progress)
    with spill_folder() as spill:  # stale folders of killed runs removed first
        summary = StreamSummary(columns, Path(spill))
        try:
            with writing(writer):
                for frame in frames:
                    writer.write(frame)
                    summary.add(frame)
        finally:
            summary.close()
        return summary_frame(pd, summary.stats, q, summary.counts)


def _kind(plan) -> str:
    return "sweep" if isinstance(plan, GridPlan) else "sample"


def _values_per_row(plan) -> int:
    """8-byte values of one row of a plan's frame: the varied inputs, the
    outputs, and status and flags (4 bytes each)."""
    return len(plan.names) + len(check_outputs(plan.outputs)) + 1


def _with_progress(frames: Iterator, rows: int, progress) -> Iterator:
    """``frames`` unchanged, advancing a progress bar (rows) on stderr."""
    bar = _progress_bar(rows, progress)
    try:
        for frame in frames:
            yield frame
            if bar is not None:
                bar.update(len(frame))
    finally:
        if bar is not None:
            bar.close()


def _progress_bar(rows: int, progress):
    """A tqdm bar over ``rows`` on stderr, or None: ``progress=True`` forces
    it, False hides it, None shows it on a terminal for more than
    `PROGRESS_ROWS` rows (when tqdm is installed)."""
    if progress is None:
        if rows <= PROGRESS_ROWS or not sys.stderr.isatty():
            return None
        try:
            tqdm = require("tqdm", extra="sweep", what="a progress bar").tqdm
        except ImportError:  # shown only when tqdm is there
            return None
    elif progress:
        tqdm = require("tqdm", extra="sweep", what="progress=True").tqdm
    else:
        return None
    return tqdm(total=rows, unit="row", unit_scale=True, file=sys.stderr, smoothing=0.1)


def _check_columns(df, names) -> None:
    for name in names:
        if name not in df:
            raise ValueError(f"{name}: not a column of the result")
