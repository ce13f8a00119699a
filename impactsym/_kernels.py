"""The runtime's one door into generated/: which kernel serves which scene.

Only this module imports `generated`. A single scene runs the kernel's
per-scene function from the plain module ``generated/<model>.py`` (no numba
import, nothing compiles). Batches run the numba drivers of
``generated/<model>_jit.py``, imported on the first batch call of at least
`PYTHON_BELOW` rows (a smaller batch before that runs the per-scene function
row by row: the same bits, without waiting for numba to load): the serial one
below `SERIAL_BELOW` rows (a `prange` launch costs more than it saves), the
parallel one above. Every driver argument is a C-contiguous float64 array, so
each driver compiles once per machine (numba's on-disk cache) whatever mix of
scalar and array columns a caller gives: a scalar column becomes a filled
array, reused chunk after chunk (`FILL_BYTES`).
"""

from __future__ import annotations

import importlib
import itertools
import math
import os
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

try:  # an installed wheel maps generated/ into the package
    from . import _generated as generated
except ImportError:  # a checkout (or editable install): generated/ at the top
    import generated

if getattr(generated, "IMPACTSYM_GENERATED", None) != "impactsym":
    raise ImportError(
        f"the module 'generated' at {getattr(generated, '__file__', '?')} is not "
        "impactsym's generated kernels (another package named 'generated' shadows it)"
    )

import numpy as np

from . import warmup


def _generated(name: str):
    """generated/<name>.py (plain Python, or numba for a *_jit module)."""
    return importlib.import_module(f"{generated.__name__}.{name}")


crash3, delta_v, inverse, particle, planar, presets, reconstruct, report = (
    _generated(name)
    for name in ("crash3", "delta_v", "inverse", "particle", "planar", "presets", "reconstruct", "report")
)
CODES = _generated("codes")
PRESETS = presets.PRESETS
COEFFICIENT_INPUTS = presets.COEFFICIENT_INPUTS

STATUS_NOT_APPROACHING = CODES.STATUS_NOT_APPROACHING
STATUS_OVERFLOW = CODES.STATUS_OVERFLOW
STATUS_PDOF_BEYOND_LIMIT = CODES.STATUS_PDOF_BEYOND_LIMIT
FLAG_PDOF_CAPPED = CODES.FLAG_PDOF_CAPPED

SERIAL_BELOW = 64

# A process's first PYTHON_BELOW rows of batches run through the kernels'
# per-scene functions (plain Python, row by row) while the model's numba
# drivers are not loaded: importing numba and loading the drivers from its
# cache takes 0.5-1 s, the per-scene function 3-30 us a row, so a small first
# batch (a sweep of a few hundred points, a sample of a few thousand draws)
# returns without that wait. The budget is per process, not per call: once
# the rows run in Python would have paid for the load, the drivers load (a
# loop of small batches is not left in Python). The results are the same
# bits: the per-scene function and the drivers evaluate the same emitted
# expressions in the same order with IEEE semantics (numba without fast-math);
# tests/test_python_rows.py checks it for every kernel.
PYTHON_BELOW = 10_000
_python_rows = 0  # rows this process has run through the per-scene functions

OUTPUTS = (
    "V1x",
    "V1y",
    "W1",
    "V2x",
    "V2y",
    "W2",
    "Pn",
    "Pt",
    "M",
    "mu",
    "mu_c",
    "dV1",
    "dV2",
    "TL",
    "TLn",
    "TLt",
    "TLm",
)


# Output tiers of solve_batch(outputs=...): each adds to the one before.
TIERS = {
    "velocities": OUTPUTS[:6],
    "impulses": OUTPUTS[:13],
    "energy": OUTPUTS,
}


def requested_outputs(outputs) -> tuple[tuple[str, ...], str]:
    """(names to return, smallest tier that has them) for solve_batch's
    `outputs`: None or "all" (every output), a tier name, or a list of names."""
    if outputs is None or outputs == "all":
        return OUTPUTS, "energy"
    if isinstance(outputs, str):
        if outputs not in TIERS:
            raise ValueError(
                f"outputs: unknown tier {outputs!r} (use one of "
                f"{', '.join(TIERS)}, all, or a list of output names)"
            )
        return TIERS[outputs], outputs
    names = tuple(outputs)
    unknown = [name for name in names if name not in OUTPUTS]
    if unknown or not names:
        raise ValueError(
            f"outputs: unknown output {', '.join(unknown) or '(none given)'} "
            f"(outputs are {' '.join(OUTPUTS)})"
        )
    tier = next(t for t, have in TIERS.items() if set(names) <= set(have))
    return names, tier


# Scalar columns become filled arrays of at most FILL_BYTES together (and at
# least MIN_CHUNK rows), reused chunk after chunk. Few large chunks: on a busy
# machine every parallel call waits for its threads to be scheduled. The
# fills live in one scratch buffer per thread, kept between calls (at most
# FILL_BYTES, or MIN_CHUNK rows per scalar column): a fresh allocation of
# that size lands on fresh pages, and their page faults cost more than
# filling them (measured: two 1.6 MB fills added ~10 ns/scene to a 200,000-row
# constant-normal call).
FILL_BYTES = 16 << 20
MIN_CHUNK = 1 << 16
_SCRATCH = threading.local()

# Seconds a driver may compile before the user is told why the call waits
# (IMPACTSYM_COMPILE_NOTICE_AFTER overrides; "inf" silences the notice).
COMPILE_NOTICE_AFTER = float(os.environ.get("IMPACTSYM_COMPILE_NOTICE_AFTER", "2"))


def _set_numba_cache_dir() -> None:
    """A read-only install (generated/ not writable) caches compiled drivers
    in the user's cache directory; NUMBA_CACHE_DIR, when set, wins. Numba
    reads the variable when it is first imported, so this runs before that."""
    if "NUMBA_CACHE_DIR" in os.environ or "numba" in sys.modules:
        return
    here = Path(generated.__file__).resolve().parent
    if not os.access(here, os.W_OK):
        base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
        os.environ["NUMBA_CACHE_DIR"] = str(Path(base) / "impactsym" / "numba")


_JIT_MODULES: dict = {}


def _jit_module(model: str):
    """generated/<model>_jit.py, imported (with numba) on first use."""
    if model not in _JIT_MODULES:
        _set_numba_cache_dir()
        _JIT_MODULES[model] = _generated(f"{model}_jit")
    return _JIT_MODULES[model]


@dataclass(frozen=True)
class KernelSet:
    """One generated kernel: its MANIFEST row, per-scene function and drivers.

    `inputs` are the batch columns, `outputs` the computed outputs and
    `constants` the outputs the kernel fixes to a number (e_m = 1: M = 0).
    A kernel in normal form (`arguments` not None) takes the normal's
    components (nx, ny) in place of `angle`: `unit_normal` forms them, and
    `batch_normal`/`serial_normal` are its drivers that take them as given.
    `scene` and `unit_normal` are plain Python; the drivers are numba
    dispatchers, imported on first access."""

    name: str
    model: str
    scene: Callable
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    constants: dict = field(default_factory=dict)
    arguments: tuple[str, ...] | None = None
    angle: str | None = None
    unit_normal: Callable | None = None
    operations: int = 0

    def driver(self, parallel: bool, normal: bool = False):
        """The numba driver: parallel or serial, taking the angle or (nx, ny)."""
        suffix = ("_normal" if normal else "") + ("" if parallel else "_serial")
        return getattr(_jit_module(self.model), f"{self.name}_batch{suffix}")

    @property
    def batch(self):
        return self.driver(True)

    @property
    def serial(self):
        return self.driver(False)

    @property
    def batch_normal(self):
        return self.driver(True, True) if self.angle else None

    @property
    def serial_normal(self):
        return self.driver(False, True) if self.angle else None


def _kernel_set(module, name: str) -> KernelSet:
    row = module.MANIFEST[name]
    angle = row["angle"]
    return KernelSet(
        name=name,
        model=module.__name__.rsplit(".", 1)[-1],
        scene=getattr(module, name),
        inputs=row["columns"],
        outputs=row["outputs"],
        constants=row["constants"],
        arguments=row["arguments"] if angle else None,
        angle=angle,
        unit_normal=module.unit_normal if angle else None,
        operations=row["operations"],
    )


def _forward_name(family: str, critical: bool, no_moment: bool, tier: str) -> str:
    """Generated kernel name: rigid[_critical][_em1][_velocities|_impulses]."""
    return (
        family
        + ("_critical" if critical else "")
        + ("_em1" if no_moment else "")
        + ("" if tier == "energy" else f"_{tier}")
    )


def _forward_kernels() -> dict:
    """(family, critical, e_m = 1, tier) → KernelSet for every forward kernel."""
    table = {}
    for module, family, moment in ((planar, "rigid", (False, True)), (particle, "particle", (False,))):
        for critical in (False, True):
            for no_moment in moment:
                for tier in TIERS:
                    name = _forward_name(family, critical, no_moment, tier)
                    table[(family, critical, no_moment, tier)] = _kernel_set(module, name)
    table[("impac_sideswipe", False, False, "energy")] = _kernel_set(presets, "impac_sideswipe")
    return table


KERNELS = _forward_kernels()

DELTA_V = _kernel_set(delta_v, "delta_v_from_energy")

INVERSE = {
    "rigid": _kernel_set(inverse, "rigid_inverse"),
    "particle": _kernel_set(inverse, "particle_inverse"),
}
RECONSTRUCT = _kernel_set(reconstruct, "reconstruct")

INVERSE_OUTPUTS = ("v1x", "v1y", "w1", "v2x", "v2y", "w2", "Pn", "Pt", "M", "mu_c", "TL", "TLn", "TLt", "TLm")

# Kernel families; the model names a scene may give, and the family each
# selects with its fixed coefficients, are generated.presets.PRESETS.
MODELS = ("rigid", "particle", "impac_sideswipe")
INVERSE_MODELS = ("rigid", "particle")

CRASH3_ENERGY = {n: _kernel_set(crash3, f"crash3_energy_{n}") for n in (2, 4, 6)}
CRASH3_DELTA_V = _kernel_set(crash3, "crash3_delta_v")
CRASH3_DELTA_V_ABSORBED = _kernel_set(crash3, "crash3_delta_v_absorbed")
CRASH3_MOMENT_ARM = _kernel_set(crash3, "crash3_moment_arm")
CRASH3_RADIUS_OF_GYRATION = _kernel_set(crash3, "crash3_radius_of_gyration")
CRASH3_IMPLIED_PDOF = _kernel_set(crash3, "crash3_implied_pdof")
KINETIC_ENERGY = _kernel_set(report, "kinetic_energy")

# Exact first derivatives (derive/jacobian.py), by value-kernel name: the value
# outputs plus d_<output>__d_<input> (angles in radians, inputs as the batch
# columns, gamma rather than the normal's components).
JACOBIAN_KERNELS = (
    "rigid",
    "rigid_critical",
    "particle",
    "particle_critical",
    "rigid_inverse",
    "particle_inverse",
    "reconstruct",
    "crash3_energy_2",
    "crash3_energy_4",
    "crash3_energy_6",
    "crash3_delta_v",
    "crash3_moment_arm",
    "crash3_radius_of_gyration",
    "crash3_delta_v_absorbed",
)
_LAZY: dict = {}


def __getattr__(name: str):
    """`JACOBIAN` is built on first use: generated/jacobian.py is large, and
    only uncertainty propagation needs it, so `import impactsym` does not pay
    for it (PEP 562 module attribute)."""
    if name != "JACOBIAN":
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    if name not in _LAZY:
        module = _generated("jacobian")
        _LAZY[name] = {k: _kernel_set(module, f"{k}_jacobian") for k in JACOBIAN_KERNELS}
    return _LAZY[name]


def _check_model(model: str, models: tuple[str, ...] = MODELS) -> None:
    if model not in models:
        raise ValueError(f"model: unknown model {model!r} (use one of {', '.join(models)})")


def preset(model: str) -> tuple[str, dict]:
    """The kernel family of a model name of generated.presets.PRESETS and the
    coefficients it fixes, by kernel input name (``limpert`` → ``("rigid",
    {"e": 0.0, "mu": "critical", "e_m": 1.0})``); ValueError if unknown."""
    _check_model(model, tuple(PRESETS))
    row = PRESETS[model]
    return row["kernel"], {COEFFICIENT_INPUTS[k]: v for k, v in row["fixed"].items()}


def kernel_for(model: str, critical: bool, no_moment: bool = False, tier: str = "energy") -> KernelSet:
    """The forward kernel of a kernel family for an impulse-ratio mode, e_m = 1
    (rigid only: no moment impulse) and an output tier; a family without a
    specialised kernel gets its full one. ValueError if the family is unknown."""
    _check_model(model)
    key = (model, bool(critical), bool(no_moment) and model == "rigid", tier)
    return KERNELS.get(key) or KERNELS[(model, bool(critical), False, "energy")]


def inverse_kernel_for(model: str) -> KernelSet:
    """The inverse kernel (pre-impact from post-impact) of a model."""
    _check_model(model, INVERSE_MODELS)
    return INVERSE[model]


def _as_input(value):
    """A batch input: a float scalar (the same for every row) or a writable
    C-contiguous float64 array (one value per row). A read-only array (pandas'
    copy-on-write columns, memory maps) is copied: numba types it differently,
    and a second signature would mean a second compile."""
    if np.ndim(value) == 0:
        return float(value)
    arr = np.ascontiguousarray(value, dtype=np.float64)
    return arr if arr.flags.writeable else arr.copy()


def _columns_for(ks: KernelSet, inputs: list, n: int) -> tuple[list, bool]:
    """The driver's columns (scalars still scalars) and whether the normal
    form runs. One angle for every row: its normal once (`unit_normal`), not
    per row, as length-1 arrays that the normal driver reads once. Per-row
    angles within SINCOS_LIMIT: the angle driver (`_sincos` per row).
    Otherwise NumPy's cos/sin give the normal of each row."""
    if ks.angle is None:
        return inputs, False
    at = ks.inputs.index(ks.angle)
    angle = inputs[at]
    if not isinstance(angle, np.ndarray):
        normal = [np.array([component]) for component in ks.unit_normal(angle)]
        return inputs[:at] + normal + inputs[at + 1 :], True
    if _beyond(angle, _generated(ks.model).SINCOS_LIMIT):
        with np.errstate(invalid="ignore"):
            normal = [np.cos(angle), np.sin(angle)]
        return inputs[:at] + normal + inputs[at + 1 :], True
    return inputs, False


def _beyond(angle: np.ndarray, limit: float) -> bool:
    """Whether a finite angle of the column is beyond ±`limit`. Two reductions
    without temporaries decide almost every batch (fmax/fmin skip NaN); the
    mask (four passes, the column evicted by the kernel's last call) only when
    one of them is beyond: then it may be ±inf, which does not count."""
    if -limit <= np.fmin.reduce(angle) and np.fmax.reduce(angle) <= limit:
        return False
    return bool(np.any(np.isfinite(angle) & (np.abs(angle) > limit)))


def _compile_notice(ks: KernelSet, driver, parallel: bool):
    """A timer that says, after COMPILE_NOTICE_AFTER seconds, that the call
    waits for numba (once per machine); None when the driver is compiled."""
    if driver.signatures or math.isinf(COMPILE_NOTICE_AFTER):
        return None
    seconds = max(2, round(ks.operations / (20 if parallel else 35)))
    message = f"impactsym: compiling the {ks.name} batch kernel for this machine (once; about {seconds} s)"
    timer = threading.Timer(COMPILE_NOTICE_AFTER, print, (message,), {"file": sys.stderr})
    timer.daemon = True
    timer.start()
    return timer


def _call(ks: KernelSet, driver, parallel: bool, columns: list, outs: list) -> None:
    """Run `driver` over all rows; scalar columns become filled arrays, a
    chunk of rows at a time (every argument a C-contiguous float64 array, so
    the driver has one compiled signature)."""
    n = outs[-1].shape[0]
    timer = _compile_notice(ks, driver, parallel)
    try:
        if all(isinstance(c, np.ndarray) for c in columns):
            driver(*columns, *outs)
            return
        scalars = sum(not isinstance(c, np.ndarray) for c in columns)
        size = min(n, max(MIN_CHUNK, FILL_BYTES // (8 * scalars)))
        fills = _fills(columns, size, scalars)
        for start in range(0, n, size):
            stop = min(start + size, n)
            args = [
                _rows_of(c, start, stop, n) if f is None else f[: stop - start]
                for c, f in zip(columns, fills)
            ]
            driver(*args, *(o[start:stop] for o in outs))
    finally:
        if timer is not None:
            timer.cancel()
    _after_first_batch()


def _in_python(ks: KernelSet, n: int) -> bool:
    """Whether a batch of `n` rows runs the per-scene function (`PYTHON_BELOW`);
    if so, its rows are counted against the process's budget."""
    global _python_rows
    if ks.model in _JIT_MODULES or _python_rows + n >= PYTHON_BELOW:
        return False
    _python_rows += n
    return True


def _run_rows(ks: KernelSet, columns: list, normal: bool, outs: dict, status, flags) -> bool:
    """Fill `outs`, `status` and `flags` row by row with the per-scene function
    (no numba); `columns` as `_columns_for` gives them. False, with nothing
    promised about the outputs, when a row raises (Python's float arithmetic
    raises where numba's returns inf or NaN, e.g. math.sqrt of a negative
    number): then the drivers run the batch."""
    n = status.shape[0]
    rows = [_values_of(c, n) for c in columns]
    if ks.angle is not None and not normal:
        at = ks.inputs.index(ks.angle)
        nx, ny = zip(*map(ks.unit_normal, rows[at]))
        rows[at : at + 1] = [nx, ny]
    try:
        results = list(map(ks.scene, *rows))
    except (ArithmeticError, ValueError):
        return False
    for target, values in zip((*outs.values(), status, flags), zip(*results)):
        target[:] = values
    return True


def _values_of(column, n: int):
    """A driver column as n Python floats: an array of the batch's length as a
    list, a scalar or a length-1 array (one normal for every row) repeated."""
    if isinstance(column, np.ndarray) and column.shape[0] == n:
        return column.tolist()
    return itertools.repeat(float(column[0] if isinstance(column, np.ndarray) else column), n)


def _rows_of(column: np.ndarray, start: int, stop: int, n: int) -> np.ndarray:
    """Rows start..stop-1 of an array column; a length-1 array in an n-row
    batch (one normal for every row) is passed whole."""
    return column if column.shape[0] == 1 < n else column[start:stop]


def _fills(columns: list, size: int, scalars: int) -> list:
    """Per column: None for an array, else `size` copies of the scalar in
    this thread's scratch buffer (grown when too small, then kept)."""
    scratch = getattr(_SCRATCH, "buffer", None)
    if scratch is None or scratch.shape[0] < size * scalars:
        scratch = _SCRATCH.buffer = np.empty(size * scalars)
    fills, k = [], 0
    for column in columns:
        if isinstance(column, np.ndarray):
            fills.append(None)
            continue
        fill = scratch[k * size : (k + 1) * size]
        fill.fill(column)
        fills.append(fill)
        k += 1
    return fills


_STARTED: list = []


def _after_first_batch() -> None:
    """Once per process, after its first batch: compile every other driver in
    the background unless that was done on this machine (impactsym.warmup)."""
    if not _STARTED:
        _STARTED.append(True)
        warmup.start_background(generated.__file__, generated_digest())


def generated_digest() -> str:
    """The derive-source hash in generated/'s header: names this generated code."""
    with open(generated.__file__, encoding="utf-8") as handle:
        for line in handle:
            if "sha256" in line:
                return line.rsplit(" ", 1)[-1].strip()
    return "unknown"


def batch_drivers():
    """(kernel, parallel, normal) for every numba driver the runtime calls
    (the Jacobian drivers are not among them: uncertainty evaluates the
    Jacobian at one scene, with the per-scene function)."""
    sets = [
        *KERNELS.values(),
        DELTA_V,
        *INVERSE.values(),
        RECONSTRUCT,
        *CRASH3_ENERGY.values(),
        CRASH3_DELTA_V,
        CRASH3_DELTA_V_ABSORBED,
        CRASH3_MOMENT_ARM,
        CRASH3_RADIUS_OF_GYRATION,
        CRASH3_IMPLIED_PDOF,
        KINETIC_ENERGY,
    ]
    for ks in sets:
        for parallel in (True, False):
            for normal in (False, True) if ks.angle else (False,):
                yield ks, parallel, normal


def compile_all(progress: Callable[[str], None] | None = None) -> int:
    """Compile (or load from numba's cache) every driver of `batch_drivers`
    with the one signature the runtime calls it with: float64 C arrays in
    and out, int32 status and flags. Returns how many; then no batch call on
    this machine waits for the compiler (impactsym.warmup leaves the marker)."""
    from numba import types

    count = 0
    for ks, parallel, normal in batch_drivers():
        driver = ks.driver(parallel, normal)
        start = time.perf_counter()
        floats = driver.py_func.__code__.co_argcount - 2
        driver.compile((types.float64[::1],) * floats + (types.int32[::1],) * 2)
        count += 1
        if progress is not None:
            kind = ("parallel" if parallel else "serial") + (", normal form" if normal else "")
            progress(f"{ks.name} ({kind}): {time.perf_counter() - start:.1f} s")
    return count


def run_batch(ks: KernelSet, inputs: list, n: int | None = None) -> tuple[dict, np.ndarray, np.ndarray]:
    """Run a kernel's batch driver over `inputs` (in `ks.inputs` order; each a
    float64 array of the batch length or a scalar for every row) and return
    (computed outputs by name, status, flags) in freshly allocated arrays.

    Below `SERIAL_BELOW` rows the serial driver runs (a parallel launch costs
    more than it saves)."""
    inputs = [_as_input(x) for x in inputs]
    if n is None:
        n = max((x.shape[0] for x in inputs if isinstance(x, np.ndarray)), default=1)
    outs = {name: np.empty(n) for name in ks.outputs}
    status = np.empty(n, dtype=np.int32)
    flags = np.empty(n, dtype=np.int32)
    if n == 0:
        return outs, status, flags
    columns, normal = _columns_for(ks, inputs, n)
    if _in_python(ks, n) and _run_rows(ks, columns, normal, outs, status, flags):
        _after_first_batch()
        return outs, status, flags
    parallel = n >= SERIAL_BELOW
    _call(ks, ks.driver(parallel, normal), parallel, columns, [*outs.values(), status, flags])
    return outs, status, flags


def run_one(ks: KernelSet, values: dict, outputs: tuple[str, ...]) -> dict:
    """Run one scene through a kernel's per-scene function (plain Python: no
    numba, no compile).

    Returns every name of `outputs` (0.0 for a quantity the kernel's model does
    not have, NaN on a failed row) plus int `status` and `flags`."""
    args = [float(values[name]) for name in ks.inputs]
    if ks.arguments is not None:
        at = ks.inputs.index(ks.angle)
        args[at : at + 1] = ks.unit_normal(args[at])
    *outs, status, flags = ks.scene(*args)
    result = dict(zip(ks.outputs, outs))
    for name in outputs:
        if name not in result:
            value = ks.constants.get(name, 0.0)
            result[name] = value if status == 0 else math.nan
    result["status"], result["flags"] = int(status), int(flags)
    return result


def solve_one(model: str, critical: bool, values: dict) -> dict:
    """Solve one scene without compiling: `values` maps input names to floats
    (gamma in radians; `mu` is ignored and may be absent when `critical`).
    Returns every name of `OUTPUTS` plus int `status` and `flags`."""
    values = {"mu": 0.0, **values} if critical else values
    return run_one(kernel_for(model, critical), values, OUTPUTS)
