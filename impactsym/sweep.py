"""Parameter sweeps and Monte Carlo samples around a base scene, in chunks.

`sweep` solves the cartesian grid of the values it is given, `sample` draws the
inputs from distributions; both return a tidy pandas DataFrame, one row per
scene: the varied parameters (under the names the caller gave, in the scene's
units, ``normal_angle`` in degrees), then the outputs of `solve_batch`, then
``status`` and ``flags`` (see `impactsym.codes`). Every number comes from the
generated kernels through `solve_batch`; this module only builds inputs,
streams results and summarises them.

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
"""

from __future__ import annotations

import importlib
import math
import numbers
import sys
import tempfile
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import _kernels
from .batch import solve_batch
from .scene import CRITICAL, load_scene, show_value

__all__ = ["sweep", "sample", "percentiles", "GridPlan", "SamplePlan", "collect", "summarize",
           "write_frame",
           "CHUNK_SIZE", "BLOCK", "DISTRIBUTIONS", "PERCENTILES", "SWEEP_PERCENTILES"]

#: Rows per chunk by default: a multiple of BLOCK, about 50 MB of results per chunk.
CHUNK_SIZE = 1 << 18
#: Rows per random block of `sample`: block b is drawn from its own stream.
BLOCK = 1 << 16
#: Work larger than this many rows shows a progress bar on a terminal (about a second).
PROGRESS_ROWS = 5_000_000
#: Summary columns and percentiles of `percentiles` and of `sample(out=...)`.
SUMMARY_COLUMNS = ("dV1", "dV2", "TL")
PERCENTILES = (5, 25, 50, 75, 95)
#: Percentiles of `sweep(out=...)`: minimum, median, maximum.
SWEEP_PERCENTILES = (0, 50, 100)

#: Scene-file names accepted in place of kernel inputs.
ALIASES = {"normal_angle": "gamma", "restitution": "e", "impulse_ratio": "mu",
           "moment_restitution": "e_m"}
#: Distributions of `sample`: kind -> names of its parameters.
DISTRIBUTIONS = {
    "uniform": ("low", "high"),
    "normal": ("mean", "sd"),
    "triangular": ("left", "mode", "right"),
    "lognormal": ("mean_of_log", "sd_of_log"),
}
SINKS = (".parquet", ".csv")


# --------------------------------------------------------------------------- public API

def sweep(scene, *, outputs=None, engine: str = "local", chunk_size: int = CHUNK_SIZE, out=None,
          progress=None, as_xarray: bool = False, **values):
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
    dV2 TL``, those the outputs include), exact: the summarised values of
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
        _require("xarray", "xarray", "sweep(as_xarray=True)")
    plan = GridPlan.build(scene, values, outputs)
    if out is not None:
        return summarize(plan, out=out, q=SWEEP_PERCENTILES, engine=engine, chunk_size=chunk_size,
                         progress=progress)
    frame = collect(plan, engine=engine, chunk_size=chunk_size, progress=progress)
    return plan.to_xarray(frame) if as_xarray else frame


def sample(scene, dists: Mapping, n: int, *, seed=None, outputs=None, engine: str = "local",
           chunk_size: int = CHUNK_SIZE, out=None, progress=None):
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
    ``percentiles(rows)`` (``dV1 dV2 TL``, those the outputs include, at
    5, 25, 50, 75, 95 %), with ``attrs["seed"]`` too.
    """
    plan = SamplePlan.build(scene, dists, n, seed, outputs)
    if out is not None:
        result = summarize(plan, out=out, q=PERCENTILES, engine=engine, chunk_size=chunk_size,
                           progress=progress)
    else:
        result = collect(plan, engine=engine, chunk_size=chunk_size, progress=progress)
    result.attrs["seed"] = plan.entropy
    return result


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
    pd = _require("pandas", "sweep", "percentiles")
    q = _check_q(q)
    _check_columns(df, ("status", "flags", *columns))
    solved = np.asarray(df["status"]) == 0
    stats = {name: _InMemory(np.asarray(df[name], dtype=np.float64)[solved]) for name in columns}
    counts = _counts(np.asarray(df["status"]), np.asarray(df["flags"]))
    return _summary_frame(pd, stats, q, counts)


# --------------------------------------------------------------------------- names and values

@dataclass(frozen=True)
class _Base:
    """A base scene as kernel inputs: its model, units, and the constant
    inputs it gives (batch names, gamma in radians; mu ``"critical"`` when the
    scene says so), without the coefficients its model fixes."""

    model: str
    units: str
    constants: dict
    fixed: dict

    @classmethod
    def load(cls, scene) -> "_Base":
        scene = load_scene(scene)
        _, critical, values = scene.to_inputs()
        _, fixed = _kernels.preset(scene.model)
        constants = {name: value for name, value in values.items() if name not in fixed}
        if critical and "mu" in constants:
            constants["mu"] = CRITICAL
        return cls(scene.model, scene.units, constants, fixed)

    def kernel_names(self, names: Iterable[str]) -> tuple[str, ...]:
        """The kernel input each name sets; ValueError for an unknown or fixed
        name or two names for the same input."""
        kernels = []
        for name in names:
            kernel = ALIASES.get(name, name)
            if kernel in self.fixed:
                raise ValueError(f"{name}: the {self.model} model fixes {kernel} = {self.fixed[kernel]!r}")
            if kernel not in self.constants:
                known = ", ".join([*self.constants, *(a for a, k in ALIASES.items() if k in self.constants)])
                raise ValueError(f"{name}: not an input of the {self.model} model (use one of {known})")
            if kernel in kernels:
                raise ValueError(f"{name}: sets {kernel}, which another name already sets")
            kernels.append(kernel)
        return tuple(kernels)


def _to_kernel_units(name: str, values):
    """Values in the caller's units -> kernel units (only ``normal_angle``,
    degrees, becomes ``gamma``, radians)."""
    if name != "normal_angle":
        return values
    return math.radians(values) if np.ndim(values) == 0 else np.deg2rad(values)


def _is_number(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _grid_values(name: str, kernel: str, raw):
    """A sweep value: a float or ``"critical"`` (a constant), or a non-empty
    1-D array (an axis; object dtype when a ``mu`` axis lists ``"critical"``)."""
    critical_ok = kernel == "mu"
    expected = 'numbers or "critical"' if critical_ok else "numbers"
    if critical_ok and isinstance(raw, str) and raw == CRITICAL:
        return CRITICAL
    if _is_number(raw):
        return float(raw)
    if isinstance(raw, np.ndarray) and raw.dtype.kind in "fiu":
        items = raw
    elif isinstance(raw, Iterable) and not isinstance(raw, (str, bytes, Mapping)):
        items = list(raw)
    else:
        raise ValueError(f"{name}: expected a scalar or a 1-D sequence of {expected}, got {show_value(raw)}")
    if isinstance(items, np.ndarray) and items.ndim != 1 or len(items) == 0:
        raise ValueError(f"{name}: expected a non-empty 1-D sequence of {expected}, got {show_value(raw)}")
    if isinstance(items, np.ndarray):
        return items.astype(np.float64)
    if critical_ok and any(isinstance(v, str) and v == CRITICAL for v in items):
        return np.array([v if isinstance(v, str) and v == CRITICAL else _float(name, v, expected)
                         for v in items], dtype=object)
    return np.array([_float(name, v, expected) for v in items], dtype=np.float64)


def _float(name: str, value, expected: str) -> float:
    if not _is_number(value):
        raise ValueError(f"{name}: values must be {expected}, got {show_value(value)}")
    return float(value)


def _check_outputs(outputs) -> tuple[str, ...]:
    """The output names `solve_batch` will return for ``outputs``."""
    names, _tier = _kernels.requested_outputs(outputs)
    return names


# --------------------------------------------------------------------------- plans: what a chunk computes

def _solved_frame(plan, shown: dict, varied: dict, start: int, stop: int):
    """Solve rows start..stop-1: ``varied`` kernel inputs (arrays) over the
    plan's constants (scalars); the frame has the ``shown`` columns, then the
    outputs not already shown, ``status`` and ``flags``."""
    import pandas as pd

    result = solve_batch({**plan.constants, **varied}, model=plan.model, outputs=plan.outputs)
    columns = dict(shown)
    columns.update((name, column) for name, column in result.items() if name not in shown)
    return pd.DataFrame(columns, index=pd.RangeIndex(start, stop), copy=False)


@dataclass(frozen=True)
class GridPlan:
    """A sweep: constants (kernel units, scalars) and axes, both as given
    (``shown``) and in kernel units (``axes``). `frame` solves any range of
    grid rows from its indices alone."""

    model: str
    units: str
    outputs: object
    constants: dict
    names: tuple
    kernels: tuple
    shown: tuple
    axes: tuple

    @classmethod
    def build(cls, scene, values: Mapping, outputs) -> "GridPlan":
        """Check names and values against the base scene; see `sweep`."""
        _require("pandas", "sweep", "sweep")
        _check_outputs(outputs)
        base = _Base.load(scene)
        kernels = base.kernel_names(values)
        constants, names, varied, shown, axes = dict(base.constants), [], [], [], []
        for name, kernel in zip(values, kernels):
            given = _grid_values(name, kernel, values[name])
            if np.ndim(given) == 0:
                constants[kernel] = _to_kernel_units(name, given)
                continue
            names.append(name)
            varied.append(kernel)
            shown.append(given)
            axes.append(_to_kernel_units(name, given))
        return cls(base.model, base.units, outputs, constants, tuple(names), tuple(varied),
                   tuple(shown), tuple(axes))

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(axis) for axis in self.axes)

    @property
    def rows(self) -> int:
        return math.prod(self.shape)

    @property
    def repeated(self) -> tuple[str, ...]:
        """Columns with few distinct values: the axes."""
        return self.names

    def frame(self, start: int, stop: int):
        """Grid rows start..stop-1 solved, as a DataFrame indexed start..stop-1."""
        index = np.unravel_index(np.arange(start, stop), self.shape) if self.names else ()
        shown = {name: axis[i] for name, axis, i in zip(self.names, self.shown, index)}
        varied = {kernel: axis[i] for kernel, axis, i in zip(self.kernels, self.axes, index)}
        return _solved_frame(self, shown, varied, start, stop)

    def to_xarray(self, frame):
        """The grid frame as an `xarray.Dataset`: one dimension per axis
        (coordinates as given), one variable per output, ``status``, ``flags``."""
        import xarray

        data = {name: (self.names, frame[name].to_numpy().reshape(self.shape))
                for name in frame.columns if name not in self.names}
        coords = dict(zip(self.names, self.shown))
        return xarray.Dataset(data, coords=coords, attrs={"model": self.model, "units": self.units})


@dataclass(frozen=True)
class SamplePlan:
    """A Monte Carlo sample: constants (kernel units) and the distributions of
    the drawn inputs; `frame` draws and solves any range of rows."""

    model: str
    units: str
    outputs: object
    constants: dict
    names: tuple
    kernels: tuple
    dists: tuple
    entropy: int
    rows: int

    @classmethod
    def build(cls, scene, dists: Mapping, n, seed, outputs) -> "SamplePlan":
        """Check names, distributions, ``n`` and ``seed``; see `sample`."""
        _require("pandas", "sweep", "sample")
        if not _is_integer(n) or n < 1:
            raise ValueError(f"n: must be a positive integer, got {show_value(n)}")
        if seed is not None and (not _is_integer(seed) or seed < 0):
            raise ValueError(f"seed: must be a non-negative integer or None, got {show_value(seed)}")
        _check_outputs(outputs)
        if not isinstance(dists, Mapping) or not dists:
            raise ValueError("dists: must map at least one input name to a distribution")
        base = _Base.load(scene)
        kernels = base.kernel_names(dists)
        checked = tuple(_distribution(name, dists[name]) for name in dists)
        constants = {k: v for k, v in base.constants.items() if k not in kernels}
        entropy = np.random.SeedSequence(seed).entropy
        return cls(base.model, base.units, outputs, constants, tuple(dists), kernels, checked,
                   entropy, int(n))

    repeated = ()  # drawn columns hardly ever repeat a value

    def block(self, b: int) -> list[np.ndarray]:
        """Block ``b``: BLOCK draws of each parameter, in the caller's units,
        from the block's own stream (independent of every other block)."""
        seq = np.random.SeedSequence(self.entropy, spawn_key=(b,))
        rng = np.random.Generator(np.random.PCG64(seq))
        return [getattr(rng, kind)(*params, size=BLOCK) for kind, params in self.dists]

    def draws(self, start: int, stop: int) -> list[np.ndarray]:
        """Rows start..stop-1 of each parameter: slices of whole blocks."""
        parts = []
        for b in range(start // BLOCK, (stop - 1) // BLOCK + 1):
            lo, hi = max(start, b * BLOCK) - b * BLOCK, min(stop, (b + 1) * BLOCK) - b * BLOCK
            parts.append([column[lo:hi] for column in self.block(b)])
        return [np.concatenate(columns) for columns in zip(*parts)]

    def frame(self, start: int, stop: int):
        """Rows start..stop-1 drawn and solved, as a DataFrame indexed start..stop-1."""
        drawn = self.draws(start, stop)
        shown = dict(zip(self.names, drawn))
        varied = {kernel: _to_kernel_units(name, column)
                  for name, kernel, column in zip(self.names, self.kernels, drawn)}
        return _solved_frame(self, shown, varied, start, stop)


def _is_integer(value) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _distribution(name: str, spec) -> tuple[str, tuple[float, ...]]:
    """``(kind, parameters)`` of a distribution, checked; ValueError naming ``name``."""
    kinds = ", ".join(DISTRIBUTIONS)
    if not isinstance(spec, (tuple, list)) or not spec or not isinstance(spec[0], str):
        raise ValueError(f"{name}: expected a tuple (kind, parameters...) with kind one of {kinds}, "
                         f"got {show_value(spec)}")
    kind, params = spec[0], spec[1:]
    if kind not in DISTRIBUTIONS:
        raise ValueError(f"{name}: unknown distribution {kind!r} (use one of {kinds})")
    wanted = DISTRIBUTIONS[kind]
    if len(params) != len(wanted) or not all(_is_number(p) and math.isfinite(p) for p in params):
        raise ValueError(f"{name}: {kind} takes {len(wanted)} finite numbers ({', '.join(wanted)}), "
                         f"got {show_value(tuple(params))}")
    params = tuple(float(p) for p in params)
    problem = _distribution_problem(kind, params)
    if problem:
        raise ValueError(f"{name}: {kind} needs {problem}, got {params!r}")
    return kind, params


def _distribution_problem(kind: str, params: tuple[float, ...]) -> str | None:
    """What is wrong with finite parameters of a distribution, or None."""
    if kind == "uniform" and not params[0] <= params[1]:
        return "low <= high"
    if kind in ("normal", "lognormal") and params[1] < 0:
        return "a non-negative standard deviation"
    if kind == "triangular" and not (params[0] <= params[1] <= params[2] and params[0] < params[2]):
        return "left <= mode <= right and left < right"
    return None


# --------------------------------------------------------------------------- running chunks

def _spans(rows: int, chunk_size: int) -> Iterator[tuple[int, int]]:
    return ((start, min(start + chunk_size, rows)) for start in range(0, rows, chunk_size))


def _frames(plan, engine: str, chunk_size: int) -> Iterator:
    """Every chunk of ``plan`` solved, in row order, by the chosen engine."""
    if not _is_integer(chunk_size) or chunk_size < 1:
        raise ValueError(f"chunk_size: must be a positive integer, got {show_value(chunk_size)}")
    spans = _spans(plan.rows, chunk_size)
    if engine == "dask":
        from .dask_engine import chunk_frames

        return chunk_frames(plan, spans)
    if engine != "local":
        raise ValueError(f"engine: unknown engine {show_value(engine)} (use local or dask)")
    return (plan.frame(start, stop) for start, stop in spans)


def collect(plan, *, engine: str = "local", chunk_size: int = CHUNK_SIZE, progress=None):
    """Every row of ``plan`` in one DataFrame (index 0..rows-1)."""
    import pandas as pd

    frames = list(_with_progress(_frames(plan, engine, chunk_size), plan.rows, progress))
    return frames[0] if len(frames) == 1 else pd.concat(frames)


def summarize(plan, *, out=None, q=PERCENTILES, engine: str = "local", chunk_size: int = CHUNK_SIZE,
              progress=None):
    """Stream every chunk of ``plan`` to ``out`` (a ``.parquet`` or ``.csv``
    path, or None for no file) and return ``percentiles`` of the rows for the
    default summary columns the outputs include, with bounded memory: the
    summarised values of solved rows spill to a temporary file (8 bytes per
    value) and the percentiles are selected exactly from it."""
    pd = _require("pandas", "sweep", "streaming")
    q = _check_q(q)
    columns = [name for name in SUMMARY_COLUMNS if name in _check_outputs(plan.outputs)]
    frames = _frames(plan, engine, chunk_size)
    sink = _sink(out, plan.repeated)
    frames = _with_progress(frames, plan.rows, progress)
    with tempfile.TemporaryDirectory(prefix="impactsym-summary-") as spill:
        summary = _StreamSummary(columns, Path(spill))
        try:
            with _writing(sink):
                for frame in frames:
                    sink.write(frame)
                    summary.add(frame)
        finally:
            summary.close()
        return _summary_frame(pd, summary.stats, q, summary.counts)


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
            from tqdm import tqdm
        except ImportError:
            return None
    elif progress:
        tqdm = _require("tqdm", "sweep", "progress=True").tqdm
    else:
        return None
    return tqdm(total=rows, unit="row", unit_scale=True, file=sys.stderr, smoothing=0.1)


# --------------------------------------------------------------------------- files

def _file_frame(frame):
    """A frame as files hold it: an object column (a ``mu`` axis mixing
    numbers and ``"critical"``) becomes text, as CSV writes it anyway."""
    text = {name: str for name in frame.columns if frame[name].dtype == object}
    return frame.astype(text) if text else frame


class _FileSink:
    """A file opened at once (an unwritable path fails before any work),
    removed again by `abort`."""

    def __init__(self, path: Path, mode: str, **options):
        self.path, self._file = path, open(path, mode, **options)

    def close(self) -> None:
        self._file.close()

    def abort(self) -> None:
        self.close()
        self.path.unlink(missing_ok=True)


class _ParquetSink(_FileSink):
    """Parquet through one pyarrow ParquetWriter, one row group per chunk.
    Dictionary encoding only for ``repeated`` columns (grid axes, status,
    flags): on the float outputs it costs time and saves nothing."""

    def __init__(self, path: Path, repeated: tuple[str, ...]):
        super().__init__(path, "wb")
        self._writer, self._repeated = None, repeated

    def write(self, frame) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pandas(_file_frame(frame), preserve_index=False)
        if self._writer is None:
            dictionary = [name for name in table.column_names if name in self._repeated]
            self._writer = pq.ParquetWriter(self._file, table.schema, use_dictionary=dictionary)
        self._writer.write_table(table, row_group_size=max(table.num_rows, 1))

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
        super().close()


class _CsvSink(_FileSink):
    """CSV: the header once, then each chunk appended; floats as their
    shortest round-trip text, NaN as an empty field (pandas reads it back
    exactly; ``status`` and ``flags`` come back as int64)."""

    def __init__(self, path: Path):
        super().__init__(path, "w", newline="", encoding="utf-8")
        self._header = True

    def write(self, frame) -> None:
        _file_frame(frame).to_csv(self._file, header=self._header, index=False)
        self._header = False


class _NoSink:
    """No file: only the summary is kept."""

    def write(self, frame) -> None:
        pass

    def close(self) -> None:
        pass

    def abort(self) -> None:
        pass


def _sink(out, repeated: tuple[str, ...] = ()):
    """The writer for ``out`` (None: no file); ValueError for another suffix.
    ``repeated``: columns besides status and flags with few distinct values."""
    if out is None:
        return _NoSink()
    path = Path(out)
    suffix = path.suffix.lower()
    if suffix == ".parquet":
        _require("pyarrow", "sweep", "out=*.parquet")
        return _ParquetSink(path, ("status", "flags", *repeated))
    if suffix == ".csv":
        return _CsvSink(path)
    raise ValueError(f"out: unknown file type {suffix or '(none)'!r} for {path} "
                     f"(use {' or '.join(SINKS)})")


def write_frame(frame, out, repeated: tuple[str, ...] = ()) -> None:
    """Write a whole frame to ``out`` as `sweep`/`sample` would (``.parquet``
    or ``.csv``); ``repeated`` as for the grid axes of a sweep."""
    sink = _sink(out, repeated)
    with _writing(sink):
        sink.write(frame)


@contextmanager
def _writing(sink):
    """Close ``sink`` after the block, or remove its partial file if the block fails."""
    try:
        yield sink
    except BaseException:
        sink.abort()
        raise
    sink.close()


# --------------------------------------------------------------------------- summaries

def _check_q(q) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in np.atleast_1d(np.asarray(q, dtype=np.float64)))
    except (TypeError, ValueError):
        values = ()
    if not values or not all(0.0 <= v <= 100.0 for v in values):
        raise ValueError(f"q: percentiles must be between 0 and 100, got {show_value(q)}")
    return values


def _check_columns(df, names) -> None:
    for name in names:
        if name not in df:
            raise ValueError(f"{name}: not a column of the result")


def _counts(status: np.ndarray, flags: np.ndarray) -> dict[str, int]:
    solved = int(np.count_nonzero(status == 0))
    return {"rows": int(status.size), "solved": solved, "not_solved": int(status.size) - solved,
            "flagged": int(np.count_nonzero(flags))}


def _label(q: float) -> str:
    return f"p{q:g}"


def _summary_frame(pd, stats: Mapping, q: tuple[float, ...], counts: dict):
    """The summary DataFrame: one row per column, one column per percentile."""
    labels = [_label(v) for v in q]
    rows = {name: _interpolate(stat, q) for name, stat in stats.items()}
    frame = (pd.DataFrame.from_dict(rows, orient="index", columns=labels) if rows
             else pd.DataFrame(columns=labels, dtype=np.float64))
    frame.attrs["counts"] = dict(counts)
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


class _InMemory:
    """Order statistics of values held in memory (`numpy.partition`)."""

    def __init__(self, values: np.ndarray):
        self.values, self.count = values, values.size

    def select(self, ranks: list[int]) -> dict[int, float]:
        part = np.partition(self.values, ranks)
        return {rank: float(part[rank]) for rank in ranks}


class _StreamSummary:
    """Counts and, per summary column, the values of solved rows spilled to
    files in ``directory``."""

    def __init__(self, columns: list[str], directory: Path):
        self.counts = {"rows": 0, "solved": 0, "not_solved": 0, "flagged": 0}
        self.stats = {name: _OrderStatistics(directory / f"{i}.f8") for i, name in enumerate(columns)}

    def add(self, frame) -> None:
        status = frame["status"].to_numpy()
        for key, value in _counts(status, frame["flags"].to_numpy()).items():
            self.counts[key] += value
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


class _OrderStatistics:
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
        self._file = open(path, "wb")

    def add(self, values: np.ndarray) -> None:
        np.ascontiguousarray(values, dtype=np.float64).tofile(self._file)
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
            for rank, (prefix, bits, k, size) in list(open_.items()):
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
            while (values := np.fromfile(file, dtype=np.float64, count=self.READ_BLOCK)).size:
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


# --------------------------------------------------------------------------- optional dependencies

def _require(module: str, extra: str, what: str):
    """Import ``module`` or raise ImportError naming the extra that installs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(f"{what} needs {module}: pip install 'impactsym[{extra}]'") from None
