"""Run time against error: every way of solving the rigid model on one chart.

``python -m benchmarks accuracy [--n 1000000] [--repeat 5] [--out benchmarks/results]``

Methods (rigid model, sliding, given impulse ratio; every method returns the 15
outputs ``V1x V1y W1 V2x V2y W2 Pn Pt M mu mu_c TL TLn TLt TLm``):

* ``default``: the generated kernels, ``generated.planar.rigid_batch`` (strict IEEE
  float64, ``prange``), as ``impactsym.solve_batch`` runs them;
* ``fastmath``, ``float32``: the same closed forms rendered by the project's emitter
  with ``derive.emit.VARIANTS["fastmath"]`` / ``["float32"]`` (float32 inputs and
  outputs);
* ``KE difference``: ``derive.planar.ke_difference_kernel()`` (TL as kinetic energy
  before minus after), default style;
* ``linear solve``: the 9x9 system of conventions.md assembled with NumPy for all
  rows and solved by ``numpy.linalg.solve`` (batched LAPACK gesv), a second solve
  with the sticking equation for ``mu_c``, energies as the work formulas;
* ``lambdify``: ``sympy.lambdify(inputs, outputs, "numpy", cse=True)`` of the same
  closed forms expanded down to the inputs, on whole NumPy arrays.

Variants are rendered into a temporary directory as real ``.py`` files and imported
(numba cannot cache code that was exec'd), so each run compiles them afresh.

Error of an output = |got - reference| / its natural scale (``impactsym.testing.reference``);
error of a row = the largest over the 15 outputs; a row whose output is NaN or
infinite where the reference is finite has infinite error ("fail"). Reported per
set: the worst row and the 99th percentile (the smallest error that at least 99 %
of rows stay within). Separately, the energy's own relative error |TL - TL_ref| /
|TL_ref| on rows with |TL_ref| >= 1e-10 of the initial kinetic energy.

Run time: every method on the same ``--n`` rows (the realistic set tiled), outputs
preallocated where the method allows, one untimed warm-up call (JIT compile), then
``--repeat`` timed calls taken round-robin over the methods; the median, in ns per
scene, and its ratio to the default kernel.
"""

from __future__ import annotations

import contextlib
import importlib.util
import math
import os
import platform
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from impactsym.testing.reference import OUTPUTS as REFERENCE_OUTPUTS
from impactsym.testing.reference import RIGID_INPUTS

RESULTS = Path(__file__).resolve().parent / "results"
OUTPUTS = tuple(REFERENCE_OUTPUTS)
INPUTS = tuple(RIGID_INPUTS)
SET_NAMES = ("realistic", "stress")
EXACT_Y = 1e-19  # where an error of exactly 0 is drawn
FAIL_Y = 1e3  # where a failed (infinite) error is drawn
UNIT_ROUNDOFF = 2.0**-53
TEST_TOL = 1e-12  # tests/test_accuracy.py


# ------------------------------------------------------------------ methods


@dataclass
class Method:
    """One way of solving the batch. ``bind(columns)`` does the untimed setup (casts,
    output allocation) and returns a zero-argument callable that solves every row
    and returns ``{output name: array}``."""

    key: str
    label: str
    note: str
    bind: Callable[[dict], Callable[[], dict]]
    opt_in: bool = True


_TMP: tempfile.TemporaryDirectory | None = None
_VARIANTS: dict[str, object] = {}


def variant_source(kind: str) -> tuple[str, str]:
    """``(text, kernel name)`` of a variant module rendered by ``derive.emit``:
    ``kind`` is ``"fastmath"``, ``"float32"`` or
    ``"ke_difference"`` (the naive-energy kernel, default style)."""
    from derive import emit

    kernels, style = _variant_kernels(kind)
    text = emit.render_jit_module("planar.py", kernels, emit.source_hash(), style)
    return text, kernels[0].name


def _variant_kernels(kind: str) -> tuple[list, object]:
    """(the kernels, the emitter style) of a variant."""
    from derive import emit, planar

    if kind == "ke_difference":
        return [planar.ke_difference_kernel()], emit.DEFAULT
    return list(planar.KERNELS[:1]), emit.VARIANTS[kind]


def variant_module(kind: str):
    """The rendered variant as an imported module (written to a temporary directory
    as a real file; numba caches and compiles it like generated/planar.py).
    The kernel is ``module.KERNEL_NAME``; batch driver ``<name>_batch``."""
    global _TMP
    if kind in _VARIANTS:
        return _VARIANTS[kind]
    if _TMP is None:
        _TMP = tempfile.TemporaryDirectory(prefix="impactsym_bench_")
    from derive import emit

    text, name = variant_source(kind)
    modname = f"_impactsym_bench_{kind}"
    path = Path(_TMP.name) / f"{modname}.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location(modname, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[modname] = module  # numba's cache re-imports the module by name
    spec.loader.exec_module(module)
    module.KERNEL_NAME = name
    module.MANIFEST = {k.name: emit.manifest_entry(k, 0) for k in _variant_kernels(kind)[0]}
    _VARIANTS[kind] = module
    return module


def _kernel_bind(module, name: str, dtype) -> Callable[[dict], Callable[[], dict]]:
    """A batch driver with inputs cast to ``dtype`` and preallocated outputs."""
    driver = getattr(module, f"{name}_batch")
    inputs = module.MANIFEST[name]["columns"]
    outputs = module.MANIFEST[name]["outputs"]

    def bind(columns):
        args = [np.ascontiguousarray(columns[k], dtype=dtype) for k in inputs]
        n = args[0].shape[0]
        outs = {k: np.empty(n, dtype=dtype) for k in outputs}
        status = np.empty(n, dtype=np.int32)
        flags = np.empty(n, dtype=np.int32)

        def run():
            driver(*args, *outs.values(), status, flags)
            return outs

        return run

    return bind


# --- per-row linear solve (NumPy, float64)

LINEAR_CHUNK = 1 << 16


def _linear_bind(columns):
    """The 9x9 system of conventions.md in (V1x V1y W1 V2x V2y W2 Px Py M), one per
    row, solved in chunks of LINEAR_CHUNK rows by ``numpy.linalg.solve``."""
    cols = {k: np.ascontiguousarray(columns[k], dtype=np.float64) for k in INPUTS}
    n = cols["m1"].shape[0]
    outs = {k: np.empty(n) for k in OUTPUTS}
    m = min(n, LINEAR_CHUNK)
    A = np.zeros((m, 9, 9))
    b = np.zeros((m, 9, 1))
    for i in range(6):
        A[:, i, i] = 1.0

    def run():
        for start in range(0, n, LINEAR_CHUNK):
            stop = min(start + LINEAR_CHUNK, n)
            _linear_chunk(cols, slice(start, stop), A[: stop - start], b[: stop - start], outs)
        return outs

    return run


def _solve_stack(A, b):
    """numpy.linalg.solve on a stack; a singular matrix gives a NaN row, not an error."""
    try:
        return np.linalg.solve(A, b)[..., 0]
    except np.linalg.LinAlgError:
        x = np.full(b.shape[:2], np.nan)
        for i in range(A.shape[0]):
            with contextlib.suppress(np.linalg.LinAlgError):  # a singular row stays NaN
                x[i] = np.linalg.solve(A[i], b[i])[:, 0]
        return x


def _linear_chunk(cols, sl, A, b, outs):
    c = {k: v[sl] for k, v in cols.items()}
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        k1, k2, j1, j2 = 1.0 / c["m1"], 1.0 / c["m2"], 1.0 / c["I1"], 1.0 / c["I2"]
        r1x, r1y, r2x, r2y = c["r1x"], c["r1y"], c["r2x"], c["r2y"]
        nx, ny = np.cos(c["gamma"]), np.sin(c["gamma"])
        tx, ty = -ny, nx
        mu, em = c["mu"], c["e_m"]
        u1x, u1y = c["v1x"] - c["w1"] * r1y, c["v1y"] + c["w1"] * r1x
        u2x, u2y = c["v2x"] - c["w2"] * r2y, c["v2y"] + c["w2"] * r2x
        gn = nx * (u2x - u1x) + ny * (u2y - u1y)
        gt = tx * (u2x - u1x) + ty * (u2y - u1y)
        # momentum and angular impulse (columns V1x V1y W1 V2x V2y W2 Px Py M)
        A[:, 0, 6] = -k1
        A[:, 1, 7] = -k1
        A[:, 2, 6], A[:, 2, 7], A[:, 2, 8] = j1 * r1y, -j1 * r1x, -j1
        A[:, 3, 6] = k2
        A[:, 4, 7] = k2
        A[:, 5, 6], A[:, 5, 7], A[:, 5, 8] = -j2 * r2y, j2 * r2x, j2
        # restitution: n.(U2 - U1) = -e gn
        A[:, 6, 0], A[:, 6, 1], A[:, 6, 2] = -nx, -ny, -(r1x * ny - r1y * nx)
        A[:, 6, 3], A[:, 6, 4], A[:, 6, 5] = nx, ny, r2x * ny - r2y * nx
        # moment restitution: (W2 - W1)(1 - e_m) = e_m M (j1 + j2)
        A[:, 8, 2], A[:, 8, 5], A[:, 8, 8] = -(1.0 - em), 1.0 - em, -em * (j1 + j2)
        b[:, 0, 0], b[:, 1, 0], b[:, 2, 0] = c["v1x"], c["v1y"], c["w1"]
        b[:, 3, 0], b[:, 4, 0], b[:, 5, 0] = c["v2x"], c["v2y"], c["w2"]
        b[:, 6, 0] = -c["e"] * gn
        # impulse ratio: P.t - mu P.n = 0
        A[:, 7, :] = 0.0
        A[:, 7, 6], A[:, 7, 7] = tx - mu * nx, ty - mu * ny
        x = _solve_stack(A, b)
        # sticking: t.(U2 - U1) = 0, for mu_c = Pt/Pn of that solution
        A[:, 7, :] = 0.0
        A[:, 7, 0], A[:, 7, 1], A[:, 7, 2] = -tx, -ty, -(r1x * ty - r1y * tx)
        A[:, 7, 3], A[:, 7, 4], A[:, 7, 5] = tx, ty, r2x * ty - r2y * tx
        xc = _solve_stack(A, b)
        V1x, V1y, W1, V2x, V2y, W2, Px, Py, M = x.T
        Pn, Pt = nx * Px + ny * Py, tx * Px + ty * Py
        mu_c = (tx * xc[:, 6] + ty * xc[:, 7]) / (nx * xc[:, 6] + ny * xc[:, 7])
        U1x, U1y = V1x - W1 * r1y, V1y + W1 * r1x
        U2x, U2y = V2x - W2 * r2y, V2y + W2 * r2x
        Gn = nx * (U2x - U1x) + ny * (U2y - U1y)
        Gt = tx * (U2x - U1x) + ty * (U2y - U1y)
        TLn = Pn * (gn + Gn) / 2
        TLt = Pt * (gt + Gt) / 2
        TLm = M * ((c["w2"] - c["w1"]) + (W2 - W1)) / 2
    values = dict(
        V1x=V1x,
        V1y=V1y,
        W1=W1,
        V2x=V2x,
        V2y=V2y,
        W2=W2,
        Pn=Pn,
        Pt=Pt,
        M=M,
        mu=mu,
        mu_c=mu_c,
        TL=TLn + TLt + TLm,
        TLn=TLn,
        TLt=TLt,
        TLm=TLm,
    )
    for k, v in values.items():
        outs[k][sl] = v


# --- sympy.lambdify of the closed forms


def _lambdify_bind_factory():
    import sympy as sp

    from derive import planar

    knl = planar.KERNELS[0]
    exprs = [knl.expanded(sym) for sym in knl.outputs]
    func = sp.lambdify(list(knl.inputs), exprs, "numpy", cse=True)
    names = knl.output_names()
    inputs = [str(s) for s in knl.inputs]

    def bind(columns):
        args = [np.ascontiguousarray(columns[k], dtype=np.float64) for k in inputs]
        n = args[0].shape[0]

        def run():
            with np.errstate(all="ignore"):
                res = func(*args)
            return {k: np.broadcast_to(np.asarray(v, dtype=np.float64), (n,)) for k, v in zip(names, res)}

        return run

    return bind


def build_methods() -> list[Method]:
    """Every method, the default first. Renders and imports the variants."""
    import impactsym  # noqa: F401  (checks that `generated` is impactsym's)
    from generated import planar, planar_jit

    gen = planar_jit
    gen.MANIFEST = planar.MANIFEST

    methods = [
        Method(
            "default",
            "default",
            "generated/planar.py `rigid_batch`: strict IEEE float64, prange "
            "(what `impactsym.solve_batch` runs)",
            _kernel_bind(gen, "rigid", np.float64),
            opt_in=False,
        )
    ]
    for key, label, dtype, note in (
        (
            "fastmath",
            "fastmath",
            np.float64,
            'same formulas, `derive.emit.VARIANTS["fastmath"]` (`fastmath=True`)',
        ),
        (
            "float32",
            "float32",
            np.float32,
            '`derive.emit.VARIANTS["float32"]`: float32 inputs, literals, arithmetic and outputs',
        ),
        (
            "ke_difference",
            "KE difference",
            np.float64,
            "`derive.planar.ke_difference_kernel()`: TL = kinetic energy before - after "
            "(the other outputs are the default's)",
        ),
    ):
        module = variant_module(key)
        methods.append(Method(key, label, note, _kernel_bind(module, module.KERNEL_NAME, dtype)))
    methods.append(
        Method(
            "linear",
            "linear solve",
            "9x9 system per row (conventions.md), `numpy.linalg.solve` batched in "
            f"chunks of {LINEAR_CHUNK} rows; a second solve (sticking) for mu_c; "
            "energies as work of Pn, Pt, M",
            _linear_bind,
        )
    )
    methods.append(
        Method(
            "lambdify",
            "lambdify",
            '`sympy.lambdify(inputs, outputs, "numpy", cse=True)` of the kernel\'s '
            "outputs expanded down to the inputs, on whole arrays",
            _lambdify_bind_factory(),
        )
    )
    return methods


# ------------------------------------------------------------------ errors


@dataclass
class SetErrors:
    """Per-row errors of one method on one set."""

    row: np.ndarray  # max over outputs of the natural-scale error
    which: list  # the output that gave it
    energy: np.ndarray  # |TL - TL_ref| / |TL_ref| where defined, else NaN

    @property
    def fails(self) -> int:
        return int(np.sum(~np.isfinite(self.row)))

    def worst(self) -> float:
        return float(np.max(self.row))

    def p99(self) -> float:
        return float(np.quantile(self.row, 0.99, method="higher"))

    def energy_worst(self) -> float:
        e = self.energy[~np.isnan(self.energy)]
        return float(np.max(e)) if e.size else math.nan

    def energy_p99(self) -> float:
        e = self.energy[~np.isnan(self.energy)]
        return float(np.quantile(e, 0.99, method="higher")) if e.size else math.nan


def set_errors(outs: dict, scene_set, energy_floor: float = 1e-10) -> SetErrors:
    """Natural-scale errors of ``outs`` (arrays by output name) against the set's references."""
    from mpmath import mp

    from impactsym.testing import reference as R

    n = scene_set.n
    row = np.empty(n)
    which = []
    energy = np.full(n, np.nan)
    for i in range(n):
        got = {k: float(outs[k][i]) for k in OUTPUTS}
        ref = scene_set.refs[i]
        errs = R.relative_errors(got, ref, scene_set.scales[i])
        key = max(errs, key=errs.get)
        row[i] = errs[key]
        which.append(key)
        with mp.workdps(R.DPS):
            if abs(ref["TL"]) >= energy_floor * scene_set.ke0[i]:
                tl = got["TL"]
                energy[i] = (
                    float(abs(mp.mpf(tl) - ref["TL"]) / abs(ref["TL"])) if math.isfinite(tl) else math.inf
                )
    return SetErrors(row, which, energy)


# ------------------------------------------------------------------ timing


def tile(columns: dict, n: int) -> dict:
    """``columns`` repeated to ``n`` rows (contiguous float64)."""
    return {
        k: np.ascontiguousarray(np.resize(np.asarray(v, dtype=np.float64), n)) for k, v in columns.items()
    }


def _cpu_busy_seconds() -> float:
    """CPU seconds the whole machine has spent busy (Linux /proc/stat), or NaN."""
    try:
        with open("/proc/stat") as f:
            fields = [float(x) for x in f.readline().split()[1:]]
    except OSError:
        return math.nan
    idle = fields[3] + (fields[4] if len(fields) > 4 else 0.0)  # idle + iowait
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")


class OtherLoad:
    """Share of the machine's CPUs that *other* processes used while the block ran
    (busy CPU time of the machine minus this process's, over wall time x CPUs)."""

    def __enter__(self):
        self.t0, self.busy0, self.own0 = time.perf_counter(), _cpu_busy_seconds(), os.times()
        return self

    def __exit__(self, *exc):
        wall = time.perf_counter() - self.t0
        own1 = os.times()
        own = (own1.user - self.own0.user) + (own1.system - self.own0.system)
        other = _cpu_busy_seconds() - self.busy0 - own
        self.share = max(0.0, other / (wall * (os.cpu_count() or 1))) if wall > 0 else math.nan
        return False


def time_methods(methods, columns: dict, repeat: int, log=print) -> dict[str, dict]:
    """Median ns per row of each method on ``columns``; timed round-robin."""
    n = len(next(iter(columns.values())))
    runs, warm = {}, {}
    for m in methods:
        runs[m.key] = m.bind(columns)
        t0 = time.perf_counter()
        runs[m.key]()
        warm[m.key] = time.perf_counter() - t0
        log(f"  warm-up {m.label}: {warm[m.key]:.2f} s")
    samples = {m.key: [] for m in methods}
    others = []
    for r in range(repeat):
        for m in methods:
            with OtherLoad() as load:
                t0 = time.perf_counter_ns()
                runs[m.key]()
                samples[m.key].append((time.perf_counter_ns() - t0) / n)
            others.append(load.share)
        log(
            f"  repeat {r + 1}/{repeat} (other processes {np.nanmax(others[-len(methods) :]):.0%} "
            "of the CPUs at most): "
            + ", ".join(f"{m.label} {samples[m.key][-1]:.1f}" for m in methods)
            + " ns/scene"
        )
    out = {k: {"ns": float(np.median(v)), "samples": v, "warmup_s": warm[k]} for k, v in samples.items()}
    out["_other_cpu"] = float(np.nanmean(others)) if others else math.nan
    return out


# ------------------------------------------------------------------ report


def _fmt(x: float, fails: int = 0) -> str:
    if not math.isfinite(x):
        return f"fail ({fails} rows)" if fails else "fail"
    if x == 0:
        return "0"
    return f"{x:.1e}"


def _bits(x: float) -> str:
    """Bits lost relative to the float64 unit roundoff."""
    if not math.isfinite(x):
        return "–"
    return f"{max(0.0, math.log2(max(x, 1e-300) / UNIT_ROUNDOFF)):.0f}"


def markdown(methods, timing, errors, sets, args) -> str:
    """The whole results page."""
    import numba

    from . import sets as S

    d = timing["default"]["ns"]
    lines = [
        "# Run time against error",
        "",
        f"`python -m benchmarks accuracy --n {args.n} --repeat {args.repeat}` — "
        f"rigid model, sliding with a given impulse ratio. Time: median of {args.repeat} runs "
        f"on n = {args.n:,} rows (the realistic set tiled), ns per scene. Error: "
        "|got − reference| / natural scale (`tests/reference.py`, 50-digit mpmath on the "
        "exact float64 inputs), the largest over the 15 outputs of a row; *worst* over rows and "
        "*p99* (99 % of rows are within it). A row whose output is NaN where the reference is "
        "finite fails (infinite error). *bits*: bits lost on the worst row, log2(worst / 2^-53).",
        "",
        f"Sets: **realistic** = `impactsym.testing.scenes.random_realistic({sets['realistic'].n}, "
        f"seed={S.REALISTIC_SEED})`; **stress** = `benchmarks.sets.stress_set()`, "
        f"{sets['stress'].n} constructed rows (families below).",
        "",
        "| method | ns/scene | × default | realistic worst | realistic p99 | stress worst "
        "| stress p99 | bits (stress) | TL self-rel. worst, realistic "
        "| TL self-rel. worst, stress |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for m in methods:
        t = timing[m.key]["ns"]
        er, es = errors[m.key]["realistic"], errors[m.key]["stress"]
        lines.append(
            f"| {m.label} | {t:.1f} | {t / d:.2f} | {_fmt(er.worst(), er.fails)} | "
            f"{_fmt(er.p99())} | {_fmt(es.worst(), es.fails)} | {_fmt(es.p99())} | "
            f"{_bits(es.worst())} | {_fmt(er.energy_worst())} | {_fmt(es.energy_worst())} |"
        )
    lines += [
        "",
        "![run time against error](accuracy.png)",
        "",
        "## Worst error by stress family",
        "",
        "| family | rows | " + " | ".join(m.label for m in methods) + " |",
        "|---|---:|" + "---:|" * len(methods),
    ]
    stress = sets["stress"]
    for fam, _ in S.FAMILIES:
        mask = stress.family == fam
        cells = []
        for m in methods:
            r = errors[m.key]["stress"].row[mask]
            k = int(np.sum(~np.isfinite(r)))
            cells.append(_fmt(float(np.max(r)), k))
        lines.append(f"| {fam} | {int(mask.sum())} | " + " | ".join(cells) + " |")
    lines += ["", "Worst stress row of each method (family, output):", ""]
    for m in methods:
        es = errors[m.key]["stress"]
        i = int(np.argmax(es.row))
        lines.append(
            f"- {m.label}: {_fmt(es.row[i], es.fails)} — {stress.family[i]} row {i}, output `{es.which[i]}`"
        )
    lines += ["", "## Methods", ""]
    for m in methods:
        lines.append(f"- **{m.label}**{'' if not m.opt_in else ' (not offered at run time)'}: {m.note}.")
    lines += ["", "## Stress families", ""]
    lines += [f"- **{fam}**: {text}." for fam, text in S.FAMILIES]
    lines += ["", "## Findings (generated from the numbers above)", ""]
    lines += _findings(methods, timing, errors)
    lines += ["", "Stress families where the default kernel is not the most accurate:", ""]
    lines += _family_findings(methods, errors, stress)
    lines += ["", "## Code measured", "", _code_state()]
    lines += [
        "",
        "## Machine",
        "",
        f"{platform.machine()}, {os.cpu_count()} CPUs, numba {numba.__version__} with "
        f"{numba.get_num_threads()} threads, NumPy {np.__version__}, Python "
        f"{platform.python_version()}. First call ({sets['realistic'].n} rows, includes "
        "the JIT compile; the variants compile from scratch every run, the default "
        "loads numba's cache): "
        + ", ".join(f"{m.label} {timing[m.key].get('first_call_s', math.nan):.2f} s" for m in methods)
        + ". The numba kernels use every thread (prange); `numpy.linalg.solve` and the "
        "lambdified NumPy code run on one. Other processes used "
        f"{timing['_other_cpu']:.0%} of the CPUs during the timed runs (mean)"
        + (": the times are noisy." if timing["_other_cpu"] > 0.1 else "."),
    ]
    return "\n".join(lines) + "\n"


def _code_state() -> str:
    """Which derive source the default kernels and the rendered variants come from."""
    import re

    from derive import emit

    gen = Path(__file__).resolve().parent.parent / "generated" / "planar.py"
    found = re.search(r"derive source sha256 ([0-9a-f]{64})", gen.read_text())
    generated = found.group(1) if found else "?"
    current = emit.source_hash()
    text = (
        f"generated/planar.py header: derive source sha256 `{generated[:16]}…`; the variants "
        f"were rendered from derive/ at `{current[:16]}…`"
    )
    if generated != current:
        return text + " — **generated/ is stale**: run `python -m derive`, then this benchmark."
    return text + " (the same source)."


def _findings(methods, timing, errors) -> list[str]:
    """One line per opt-in method: speed and error relative to the default."""
    d = timing["default"]["ns"]
    out = []
    for m in methods[1:]:
        t = timing[m.key]["ns"] / d
        parts = [f"**{m.label}**: {t:.2f}× the default's time"]
        for s in SET_NAMES:
            mine, base = errors[m.key][s], errors["default"][s]
            if mine.fails:
                parts.append(f"fails {mine.fails} {s} rows")
            elif base.worst() > 0:
                ratio = mine.worst() / base.worst()
                parts.append(
                    f"worst {s} error {ratio:.3g}× the default's "
                    f"({_fmt(mine.worst())} vs {_fmt(base.worst())})"
                )
        ew, bw = errors[m.key]["stress"].energy_worst(), errors["default"]["stress"].energy_worst()
        if math.isfinite(ew) and math.isfinite(bw) and bw > 0:
            parts.append(f"TL self-relative (stress) {ew / bw:.3g}× the default's")
        out.append("- " + "; ".join(parts) + ".")
    better = [
        f"{m.label} on the {s} set ({errors[m.key][s].worst() / errors['default'][s].worst():.2g}×)"
        for m in methods[1:]
        for s in SET_NAMES
        if errors[m.key][s].worst() < errors["default"][s].worst()
    ]
    out.append("- Worst row more accurate than the default's: " + (", ".join(better) or "none") + ".")
    return out


def _family_findings(methods, errors, stress) -> list[str]:
    """Stress families where some method's worst error is < 1/2 of the default's."""
    from . import sets as S

    out = []
    for fam, _ in S.FAMILIES:
        mask = stress.family == fam
        base = float(np.max(errors["default"]["stress"].row[mask]))
        best = min(methods[1:], key=lambda m: float(np.max(errors[m.key]["stress"].row[mask])))
        mine = float(np.max(errors[best.key]["stress"].row[mask]))
        if mine < base / 2:
            i = np.flatnonzero(mask)[int(np.argmax(errors["default"]["stress"].row[mask]))]
            out.append(
                f"- **{fam}**: the default's worst is {_fmt(base)} (row {i}, output "
                f"`{errors['default']['stress'].which[i]}`); {best.label} reaches "
                f"{_fmt(mine)}, {base / max(mine, 1e-300):.2g}× better."
            )
    return out or ["- On every stress family the default is within 2× of the best method."]


def chart(methods, timing, errors, path: Path, n: int) -> None:
    """Log-log chart, one panel per set: x = ns/scene, y = error (worst filled,
    p99 hollow), one colour per method."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FixedLocator, FormatStrFormatter, NullFormatter, NullLocator

    colors = plt.get_cmap("tab10").colors
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.8), sharey=True, constrained_layout=True)
    xs = [timing[m.key]["ns"] for m in methods]
    # label offsets cycle through four corners, in order of run time
    rank = {i: r for r, i in enumerate(sorted(range(len(methods)), key=lambda i: xs[i]))}
    corners = [((7, 7), "left"), ((7, -13), "left"), ((-7, 7), "right"), ((-7, -13), "right")]
    for ax, s in zip(axes, SET_NAMES):
        for i, m in enumerate(methods):
            color = colors[i % len(colors)]
            err = errors[m.key][s]
            w, p = err.worst(), err.p99()
            yw = FAIL_Y if not math.isfinite(w) else max(w, EXACT_Y)
            yp = FAIL_Y if not math.isfinite(p) else max(p, EXACT_Y)
            ax.plot([xs[i], xs[i]], [yp, yw], color=color, lw=1, alpha=0.6)
            ax.scatter(
                [xs[i]],
                [yw],
                s=70,
                color=color,
                zorder=3,
                marker="X" if not math.isfinite(w) else "o",
                label=m.label if s == SET_NAMES[0] else None,
            )
            ax.scatter(
                [xs[i]],
                [yp],
                s=70,
                facecolors="none",
                edgecolors=color,
                zorder=3,
                marker="X" if not math.isfinite(p) else "o",
                linewidths=1.5,
            )
            text = m.label + (f": fail ({err.fails} rows)" if err.fails else "")
            offset, ha = corners[rank[i] % len(corners)]
            ax.annotate(
                text, (xs[i], yw), textcoords="offset points", fontsize=8, color=color, xytext=offset, ha=ha
            )
        for y, text, style in ((UNIT_ROUNDOFF, "2^-53", ":"), (TEST_TOL, "1e-12 (tests)", "--")):
            ax.axhline(y, color="grey", ls=style, lw=1)
            ax.text(0.01, y * 1.8, text, fontsize=7, color="grey", transform=ax.get_yaxis_transform())
        ax.axhline(FAIL_Y, color="red", ls="-", lw=0.5, alpha=0.4)
        ax.text(0.01, FAIL_Y * 1.8, "fail", fontsize=7, color="red", transform=ax.get_yaxis_transform())
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(EXACT_Y / 3, FAIL_Y * 10)
        ax.set_xlim(min(xs) / 1.8, max(xs) * 3)
        ticks = [
            t
            for t in (
                1,
                2,
                3,
                5,
                10,
                20,
                30,
                50,
                100,
                200,
                300,
                500,
                1000,
                2000,
                3000,
                5000,
                10000,
                20000,
                50000,
            )
            if min(xs) / 1.8 <= t <= max(xs) * 3
        ]
        ax.xaxis.set_major_locator(FixedLocator(ticks))
        ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel(f"run time, ns per scene (n = {n:,}, median)")
        ax.set_title(f"{s} set: worst (filled) and p99 (hollow) error")
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("error / natural scale (0 drawn at the bottom)")
    sec = axes[1].secondary_yaxis(
        "right",
        functions=(
            lambda y: np.log2(np.maximum(y, 1e-300)) + 53,
            lambda b: np.exp2(np.clip(b - 53, -1000, 1000)),
        ),
    )
    sec.yaxis.set_major_locator(FixedLocator([0, 10, 20, 30, 40, 50, 60]))
    sec.yaxis.set_major_formatter(FormatStrFormatter("%d"))
    sec.yaxis.set_minor_locator(NullLocator())
    sec.set_ylabel("bits lost: log2(error / 2^-53)")
    axes[0].legend(loc="upper left", fontsize=8, ncol=2, bbox_to_anchor=(0.0, 0.93))
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ------------------------------------------------------------------ entry point

DESCRIPTION = "run time against error of every solution method (Markdown table + PNG)"


def add_arguments(parser) -> None:
    parser.add_argument("--n", type=int, default=1_000_000, help="rows for timing (default 1e6)")
    parser.add_argument("--repeat", type=int, default=5, help="timed runs per method (median)")
    parser.add_argument(
        "--out",
        type=Path,
        default=RESULTS,
        help="folder for accuracy.md and accuracy.png (default benchmarks/results)",
    )


def main(args) -> int:
    from . import sets as S

    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    t_start = time.perf_counter()
    log("references (50-digit) for the realistic and stress sets ...")
    scene_sets = S.load_sets()
    log(f"  realistic {scene_sets['realistic'].n} rows, stress {scene_sets['stress'].n} rows")
    log("rendering and importing variants ...")
    methods = build_methods()
    errors: dict[str, dict[str, SetErrors]] = {}
    first_call = {}
    for m in methods:
        errors[m.key] = {}
        for s in SET_NAMES:
            t0 = time.perf_counter()
            outs = m.bind(scene_sets[s].columns)()
            first_call.setdefault(m.key, time.perf_counter() - t0)
            errors[m.key][s] = set_errors(outs, scene_sets[s])
        log(
            f"  errors {m.label}: realistic {_fmt(errors[m.key]['realistic'].worst())}, "
            f"stress {_fmt(errors[m.key]['stress'].worst(), errors[m.key]['stress'].fails)}"
        )
    log(f"timing n = {args.n} ...")
    timing = time_methods(methods, tile(scene_sets["realistic"].columns, args.n), args.repeat, log)
    for key, seconds in first_call.items():
        timing[key]["first_call_s"] = seconds
    args.out.mkdir(parents=True, exist_ok=True)
    text = markdown(methods, timing, errors, scene_sets, args)
    (args.out / "accuracy.md").write_text(text)
    chart(methods, timing, errors, args.out / "accuracy.png", args.n)
    print(text)
    log(
        f"wrote {args.out / 'accuracy.md'} and {args.out / 'accuracy.png'} "
        f"in {time.perf_counter() - t_start:.0f} s"
    )
    return 0
