"""What a chunk of a sweep or a sample computes: plans built from a base scene.

`GridPlan` (a sweep's cartesian grid) and `SamplePlan` (Monte Carlo draws)
check the caller's names and values against the base scene once, then
`plan.frame(start, stop)` builds and solves any range of rows from the two
row indices alone (grid rows by `numpy.unravel_index`, sample rows from fixed
random blocks), so a chunk runs the same way locally or as a dask task
(`frame_of`, a picklable chunk function). Names and units: see `impactsym.sweep`.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from .. import _kernels
from .._util import require
from ..laws.scene import is_law_scene, load_law_scene
from ..scene import CRITICAL, load_scene, show_value
from .resources import check_axis
from .solve import solve_batch

__all__ = [
    "GridPlan",
    "SamplePlan",
    "frame_of",
    "check_outputs",
    "is_integer",
    "ALIASES",
    "BLOCK",
    "DISTRIBUTIONS",
]

#: Rows per random block of `sample`: block b is drawn from its own stream.
BLOCK = 1 << 16
#: Scene-file names accepted in place of kernel inputs.
ALIASES = {"normal_angle": "gamma", "restitution": "e", "impulse_ratio": "mu", "moment_restitution": "e_m"}
ALIASES["friction"] = "mu_f"  # the impact laws (impactsym.laws)
#: Distributions of `sample`: kind -> names of its parameters.
DISTRIBUTIONS = {
    "uniform": ("low", "high"),
    "normal": ("mean", "sd"),
    "triangular": ("left", "mode", "right"),
    "lognormal": ("mean_of_log", "sd_of_log"),
}


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
    def load(cls, scene) -> _Base:
        if is_law_scene(scene):  # impactsym.laws: model "coulomb:energetic" etc., nothing fixed
            law = load_law_scene(scene)
            return cls(f"{law.model}:{law.law}", law.scene.units, law.inputs(), {})
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
        return np.array(
            [v if isinstance(v, str) and v == CRITICAL else _float(name, v, expected) for v in items],
            dtype=object,
        )
    return np.array([_float(name, v, expected) for v in items], dtype=np.float64)


def _float(name: str, value, expected: str) -> float:
    if not _is_number(value):
        raise ValueError(f"{name}: values must be {expected}, got {show_value(value)}")
    return float(value)


def check_outputs(outputs) -> tuple[str, ...]:
    """The output names `solve_batch` will return for ``outputs``."""
    names, _tier = _kernels.requested_outputs(outputs)
    return names


# --------------------------------------------------------------------------- plans: what a chunk computes


def _solved_frame(plan, shown: dict, varied: dict, start: int, stop: int):
    """Solve rows start..stop-1: ``varied`` kernel inputs (arrays) over the
    plan's constants (scalars); the frame has the ``shown`` columns, then the
    outputs not already shown, ``status`` and ``flags``."""
    pd = require("pandas", extra="sweep", what="sweep and sample")
    result = solve_batch({**plan.constants, **varied}, model=plan.model, outputs=plan.outputs)
    columns = dict(shown)
    columns.update((name, column) for name, column in result.items() if name not in shown)
    return pd.DataFrame(columns, index=pd.RangeIndex(start, stop), copy=False)


@dataclass(frozen=True)
class _Plan:
    """What every plan holds: the base scene's model and units, the requested
    outputs, the constant inputs (kernel units, scalars), and the varied
    inputs' names as the caller gave them and as kernel inputs."""

    model: str
    units: str
    outputs: object
    constants: dict
    names: tuple
    kernels: tuple


@dataclass(frozen=True)
class GridPlan(_Plan):
    """A sweep: the axes both as given (``shown``) and in kernel units
    (``axes``). `frame` solves any range of grid rows from its indices alone."""

    shown: tuple
    axes: tuple

    @classmethod
    def build(cls, scene, values: Mapping, outputs) -> GridPlan:
        """Check names and values against the base scene; see `sweep`."""
        require("pandas", extra="sweep", what="sweep")
        check_outputs(outputs)
        base = _Base.load(scene)
        kernels = base.kernel_names(values)
        constants, names, varied, shown, axes = dict(base.constants), [], [], [], []
        for name, kernel in zip(values, kernels):
            if np.ndim(values[name]) == 1:
                check_axis(name, len(values[name]))  # before its copies are made
            given = _grid_values(name, kernel, values[name])
            if np.ndim(given) == 0:
                constants[kernel] = _to_kernel_units(name, given)
                continue
            names.append(name)
            varied.append(kernel)
            shown.append(given)
            axes.append(_to_kernel_units(name, given))
        return cls(
            base.model, base.units, outputs, constants, tuple(names), tuple(varied), tuple(shown), tuple(axes)
        )

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

        data = {
            name: (self.names, frame[name].to_numpy().reshape(self.shape))
            for name in frame.columns
            if name not in self.names
        }
        coords = dict(zip(self.names, self.shown))
        return xarray.Dataset(data, coords=coords, attrs={"model": self.model, "units": self.units})


@dataclass(frozen=True)
class SamplePlan(_Plan):
    """A Monte Carlo sample: the distributions of the drawn inputs; `frame`
    draws and solves any range of rows."""

    dists: tuple
    entropy: int
    rows: int

    @classmethod
    def build(cls, scene, dists: Mapping, n, seed, outputs) -> SamplePlan:
        """Check names, distributions, ``n`` and ``seed``; see `sample`."""
        require("pandas", extra="sweep", what="sample")
        if not is_integer(n) or n < 1:
            raise ValueError(f"n: must be a positive integer, got {show_value(n)}")
        if seed is not None and (not is_integer(seed) or seed < 0):
            raise ValueError(f"seed: must be a non-negative integer or None, got {show_value(seed)}")
        check_outputs(outputs)
        if not isinstance(dists, Mapping) or not dists:
            raise ValueError("dists: must map at least one input name to a distribution")
        base = _Base.load(scene)
        kernels = base.kernel_names(dists)
        checked = tuple(_distribution(name, dists[name]) for name in dists)
        constants = {k: v for k, v in base.constants.items() if k not in kernels}
        entropy = np.random.SeedSequence(seed).entropy
        return cls(
            base.model, base.units, outputs, constants, tuple(dists), kernels, checked, entropy, int(n)
        )

    repeated = ()  # drawn columns hardly ever repeat a value

    def _stream(self, b: int) -> np.random.Generator:
        """Block ``b``'s own stream (independent of every other block)."""
        return np.random.Generator(np.random.PCG64(np.random.SeedSequence(self.entropy, spawn_key=(b,))))

    def block(self, b: int) -> list[np.ndarray]:
        """Block ``b``: BLOCK draws of each parameter, in the caller's units,
        from the block's own stream (independent of every other block)."""
        rng = self._stream(b)
        return [getattr(rng, kind)(*params, size=BLOCK) for kind, params in self.dists]

    def draws_into(self, start: int, stop: int, out: np.ndarray) -> np.ndarray:
        """`draws` written into the rows of ``out`` (float64, one row per
        parameter, stop - start columns): the same values, without the
        per-block copies; a standard normal of a whole block is drawn in place
        (``rng.standard_normal(out=…)`` gives the values of
        ``rng.normal(0.0, 1.0, size=BLOCK)``, tests/test_uncertainty_exact.py)."""
        for b in range(start // BLOCK, (stop - 1) // BLOCK + 1):
            lo, hi = max(start, b * BLOCK) - b * BLOCK, min(stop, (b + 1) * BLOCK) - b * BLOCK
            at = b * BLOCK + lo - start
            rng = self._stream(b)
            for row, (kind, params) in zip(out, self.dists):
                if kind == "normal" and tuple(params) == (0.0, 1.0) and (lo, hi) == (0, BLOCK):
                    rng.standard_normal(out=row[at : at + BLOCK])
                else:
                    row[at : at + hi - lo] = getattr(rng, kind)(*params, size=BLOCK)[lo:hi]
        return out

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
        varied = {
            kernel: _to_kernel_units(name, column)
            for name, kernel, column in zip(self.names, self.kernels, drawn)
        }
        return _solved_frame(self, shown, varied, start, stop)


def is_integer(value) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _distribution(name: str, spec) -> tuple[str, tuple[float, ...]]:
    """``(kind, parameters)`` of a distribution, checked; ValueError naming ``name``."""
    kinds = ", ".join(DISTRIBUTIONS)
    if not isinstance(spec, (tuple, list)) or not spec or not isinstance(spec[0], str):
        raise ValueError(
            f"{name}: expected a tuple (kind, parameters...) with kind one of {kinds}, got {show_value(spec)}"
        )
    kind, params = spec[0], spec[1:]
    if kind not in DISTRIBUTIONS:
        raise ValueError(f"{name}: unknown distribution {kind!r} (use one of {kinds})")
    wanted = DISTRIBUTIONS[kind]
    if len(params) != len(wanted) or not all(_is_number(p) and math.isfinite(p) for p in params):
        raise ValueError(
            f"{name}: {kind} takes {len(wanted)} finite numbers ({', '.join(wanted)}), "
            f"got {show_value(tuple(params))}"
        )
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


def frame_of(plan, span: tuple[int, int]):
    """A chunk task: rows span[0]..span[1]-1 of ``plan`` built and solved."""
    return plan.frame(*span)
