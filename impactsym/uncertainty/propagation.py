"""Uncertainty of a scene's answers: Monte Carlo, first-order propagation, budget, Sobol.

Every uncertain leaf of a scene (``{"normal": [mean, sd]}``, ``{"uniform":
[low, high]}``, ``{"triangular": [low, mode, high]}``, in scene units, angles
in degrees) is an input; every number of the command's JSON object is an
output (``vehicles[0].speed``, ``energy_loss.total``, ``restitution``; integer
codes such as ``flags`` and ``pdof_clock`` are not outputs).

Monte Carlo. Draws are standard-normal scores from `impactsym.sweep`'s
reproducible block streams (block b of `sweep.BLOCK` rows from
``PCG64(SeedSequence(seed, spawn_key=(b,)))``, so draw i is the same whatever
the number of draws and the chunk size), correlated by the Cholesky factor of
the inputs' correlation matrix (a Gaussian copula) and mapped to each input's
distribution by its inverse CDF. Chunks of `sweep.CHUNK_SIZE` draws run
through the batch kernels; memory is bounded by the chunk (plus at most
`KEEP` accepted draws kept for the caller). A draw is rejected, and counted by
reason, when a leaf is outside its domain (a negative weight), the kernel
cannot solve it (its status), or the result is physically impossible (each
physics flag: energy created, tensile impulse, μ beyond critical, and for a
reconstruction an implied e outside [0, 1] or a negative speed; a draw can
count under several flags). Statistics are over the accepted draws.

Linear method. ``sd_linear`` is the first-order standard deviation
``sqrt(gᵀ Σ g)`` with g the gradient of the output with respect to the
uncertain leaves at the nominal scene and Σ their covariance (sd_i sd_j ρ_ij,
ρ the correlation given for the normal scores; exact for normal inputs). The
gradient chains three derivatives: the leaf → column map of the scene by a
fourth-order central difference (Richardson extrapolation of two central
differences; that map is smooth and cheap, and the scene reader takes real
arrays only, so complex step is not available there), the kernel's exact
derivatives (``impactsym._kernels.JACOBIAN``, derived and proven in
derive/jacobian.py), and the JSON output map (differences, magnitudes,
degrees) by complex step, exact to rounding. The budget gives each input's
share ``g_i (Σ g)_i / (gᵀ Σ g)``: shares sum to 1; with correlated inputs a
share can be negative.

Sobol indices (``sobol=True``, the ``uncertainty`` extra: SALib) are first
order and total, from Saltelli's scheme on independent inputs (correlations
are not used there); rejected draws take the mean accepted output, and the
fraction so replaced is reported.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .. import _kernels
from .._kernels import CODES as _codes
from ..batch.sweeps import BLOCK, CHUNK_SIZE, SamplePlan
from .commands import COMMANDS, COMPLEX_STEP, RECONSTRUCT, Command, command_for
from .inputs import Input, cholesky, correlation_matrix
from .result import KEEP, MIN_INTERVAL_DRAWS, Stats, Uncertainty

STATUS_NAMES = {getattr(_codes, n): n[len("STATUS_") :] for n in dir(_codes) if n.startswith("STATUS_")}
FLAG_NAMES = {n[len("FLAG_") :]: getattr(_codes, n) for n in dir(_codes) if n.startswith("FLAG_")}

__all__ = [
    "BLOCK",
    "COMMANDS",
    "KEEP",
    "RECONSTRUCT",
    "Command",
    "Input",
    "Source",
    "Uncertainty",
    "command_for",
    "propagate",
    "uncertainty",
]

#: Threads drawing the blocks of a chunk.
DRAW_THREADS = min(4, os.cpu_count() or 1)
# Monte Carlo sd and sd_linear further apart than this (either way) get a note
# (linearity_notes): well past the Monte Carlo sd's own error (under 8 % with
# MIN_INTERVAL_DRAWS accepted draws) and the roughness expected of a first-order
# method that still ranks the inputs.
LINEAR_FACTOR = 1.5

#: Flags that make a draw physically impossible (ill-conditioned headings only warn).
REJECTING_FLAGS = (
    "ENERGY_CREATED",
    "TENSILE_IMPULSE",
    "MU_BEYOND_CRITICAL",
    "E_OUT_OF_RANGE",
    "NEGATIVE_SPEED",
)


# --------------------------------------------------------------------------- a source of columns


@dataclass(frozen=True)
class Source:
    """What the engine needs of a scene: the command, the uncertain inputs and
    their correlations, and `columns(overrides)` → (kernel columns, per-row
    reason: "" or why the row's leaves are out of their domain), overrides
    mapping input paths to arrays in scene units."""

    command: Command
    inputs: tuple[Input, ...]
    columns: Callable
    correlations: tuple = ()
    nominal_json: Callable | None = None


# --------------------------------------------------------------------------- propagation


def propagate(
    source: Source,
    draws: int = 10_000,
    seed: int | None = None,
    sobol: bool = False,
    chunk_size: int = CHUNK_SIZE,
) -> Uncertainty:
    """Monte Carlo and first-order propagation of `source`'s uncertain inputs
    (see the module docstring). `draws` Monte Carlo draws from `seed`
    (None: fresh entropy, reported as `Uncertainty.seed`)."""
    if not isinstance(draws, int) or isinstance(draws, bool) or draws < 2:
        raise ValueError(f"draws: must be an integer >= 2, got {draws!r}")
    if not source.inputs:
        raise ValueError(
            "the scene has no uncertain inputs: give a leaf as "
            '{"normal": [mean, sd]}, {"uniform": [low, high]} or '
            '{"triangular": [low, mode, high]}'
        )
    command = source.command
    nominal = _nominal(source)
    corr = correlation_matrix(source.inputs, source.correlations)
    factor = cholesky(corr)
    entropy = np.random.SeedSequence(seed).entropy
    plan = SamplePlan(
        model="",
        units="",
        outputs=None,
        constants={},
        names=tuple(x.path for x in source.inputs),
        kernels=(),
        dists=(("normal", (0.0, 1.0)),) * len(source.inputs),
        entropy=entropy,
        rows=draws,
    )
    stats, accepted, rejected, kept = _monte_carlo(source, plan, factor, nominal, chunk_size)
    linear = linear_method(source, nominal)
    outputs, budget = {}, {}
    for path, s in stats.items():
        p5, p50, p95 = s.percentiles()
        sd_lin, shares = linear.get(path, (math.nan, {}))
        outputs[path] = {
            "nominal": nominal["outputs"][path],
            "mean": s.mean,
            "sd": s.sd,
            "p5": p5,
            "p50": p50,
            "p95": p95,
            "sd_linear": sd_lin,
        }
        budget[path] = shares
    result = Uncertainty(
        command.name,
        draws,
        accepted,
        rejected,
        tuple(x.path for x in source.inputs),
        outputs,
        budget,
        kept,
        _notes(nominal["flags"], accepted, draws, rejected) + linearity_notes(outputs, accepted, draws),
        seed=int(entropy) if seed is None else seed,
    )
    if sobol:
        result.sobol = sobol_indices(source, draws, seed, stats)
    return result


def linear_method(source: Source, nominal: dict | None = None) -> dict:
    """{output path: (sd_linear, budget)}: the first-order method at the
    nominal scene (`nominal`, as `_nominal` gives it, when already known)
    from the exact derivatives, with the inputs' correlations."""
    gradient = _gradients(source, _nominal(source) if nominal is None else nominal)
    sd = np.array([x.sd for x in source.inputs])
    cov = correlation_matrix(source.inputs, source.correlations) * np.outer(sd, sd)
    return {path: _linear(g, cov, source.inputs) for path, g in gradient.items()}


def _monte_carlo(source: Source, plan: SamplePlan, factor: np.ndarray, nominal: dict, chunk_size: int):
    """The draws of `plan`, chunk by chunk: (Stats per output, accepted
    count, rejected counts by reason, accepted draws kept for the caller)."""
    stats = {path: Stats(value) for path, value in nominal["outputs"].items()}
    rejected: dict[str, int] = {}
    accepted, kept, kept_rows = 0, [], 0
    draws = plan.rows
    step = max(BLOCK, (chunk_size // BLOCK) * BLOCK)
    correlated = not np.array_equal(factor, np.eye(len(source.inputs)))
    with ThreadPoolExecutor(DRAW_THREADS) as pool:
        for start in range(0, draws, step):
            stop = min(start + step, draws)
            scores = _scores(plan, start, stop, pool)
            if correlated:  # (the identity factor would give the same numbers)
                scores = factor @ scores
            overrides = {x.path: x.from_scores(z, in_place=True) for x, z in zip(source.inputs, scores)}
            ok, values = _run_chunk(source, overrides, rejected)
            rows = np.flatnonzero(ok)
            accepted += rows.size
            # The accepted values, selected once: Stats keeps them (no copy) and
            # so does the caller's table of draws while it has room.
            chosen = {p: np.asarray(v, dtype=np.float64).take(rows) for p, v in values.items()}
            for path, s in stats.items():
                s.add(chosen[path], owned=True)
            if kept_rows < KEEP:
                kept_rows += rows.size
                kept.append({**{p: v.take(rows) for p, v in overrides.items()}, **chosen})
    return stats, accepted, rejected, kept


def _scores(plan: SamplePlan, start: int, stop: int, pool: ThreadPoolExecutor) -> np.ndarray:
    """Normal scores of draws start..stop-1 (start a multiple of BLOCK), one
    row per input: each block from its own stream, blocks drawn on `pool`'s
    threads (numpy releases the GIL while it fills an array; every block
    writes its own columns, so the numbers do not depend on the threads)."""
    out = np.empty((len(plan.dists), stop - start))

    def block(a: int) -> None:
        b = min(a + BLOCK, stop)
        plan.draws_into(a, b, out[:, a - start : b - start])

    list(pool.map(block, range(start, stop, BLOCK)))
    return out


def _run_chunk(source: Source, overrides: dict, rejected: dict):
    """Solve one chunk: (accepted mask, output path → values)."""
    columns, reason = source.columns(overrides)
    outs, status, flags = source.command.run(columns)
    n = status.shape[0]
    values = {
        path: np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
        for path, v in source.command.outputs(columns, outs).items()
    }
    reason = np.asarray(reason)
    bad_leaf = np.broadcast_to(reason != "", (n,))
    ok = ~bad_leaf
    if not ok.all():
        reason = np.broadcast_to(reason, (n,))
        for text in np.unique(reason[bad_leaf]).tolist():
            _count(rejected, text, int(np.count_nonzero(reason == text)))
    for code in np.unique(status[ok & (status != 0)]).tolist():
        _count(rejected, STATUS_NAMES[int(code)].lower(), int(np.count_nonzero(ok & (status == code))))
    ok &= status == 0
    for name in REJECTING_FLAGS:
        bit = FLAG_NAMES[name]
        hit = ok & ((flags & bit) != 0)
        if hit.any():
            _count(rejected, name.lower(), int(np.count_nonzero(hit)))
    for name in REJECTING_FLAGS:
        ok &= (flags & FLAG_NAMES[name]) == 0
    return ok, values


def _count(table: dict, key: str, n: int) -> None:
    table[key] = table.get(key, 0) + n


def _nominal(source: Source) -> dict:
    """The nominal scene: columns, kernel outputs, JSON outputs and flags."""
    overrides = {x.path: np.array([x.nominal]) for x in source.inputs}
    columns, reason = source.columns(overrides)
    outs, status, flags = source.command.run(columns)
    if int(np.asarray(status)[0]) != 0 or np.asarray(reason)[0] != "":
        raise ValueError(
            "the nominal scene cannot be solved: "
            + (str(np.asarray(reason)[0]) or STATUS_NAMES[int(status[0])].lower())
        )
    values = source.command.outputs(columns, outs)
    return {
        "columns": _row(columns, 0),
        "outputs": {p: float(np.ravel(v)[0]) for p, v in values.items()},
        "flags": int(flags[0]),
    }


def _row(columns: Mapping, i: int) -> dict:
    """Row i of columns as scalars (strings such as mu = "critical" kept;
    CRASH3's per-vehicle crush tables row by row too)."""

    def at(v):
        return v if isinstance(v, str) or np.ndim(v) == 0 else float(np.asarray(v)[i])

    return {
        k: ([None if t is None else {a: at(b) for a, b in t.items()} for t in v] if k == "crush" else at(v))
        for k, v in columns.items()
    }


def _flat(columns: Mapping) -> dict:
    """Columns with CRASH3's crush tables flattened to ``crush<i>.<name>``."""
    out = {k: v for k, v in columns.items() if k != "crush"}
    for i, table in enumerate(columns.get("crush") or (), start=1):
        out.update({f"crush{i}.{k}": v for k, v in (table or {}).items()})
    return out


def _notes(flags: int, accepted: int, draws: int, rejected: dict) -> list[str]:
    """Whether a flag raised at the nominal values is robust or measurement noise."""
    notes = []
    share = accepted / draws
    for name in REJECTING_FLAGS:
        if flags & FLAG_NAMES[name]:
            what = name.lower().replace("_", " ")
            verdict = (
                "the flag is measurement noise"
                if share >= 0.5
                else "the flag is robust: most draws are impossible too"
            )
            notes.append(f"{what} at the nominal values; {share:.0%} of draws are physical ({verdict})")
    if accepted == 0:
        notes.append("no draw is physical: the statistics are undefined")
    elif accepted < MIN_INTERVAL_DRAWS:
        notes.append(
            f"only {accepted} accepted draws: the 90 % interval (p5, p95) needs at least "
            f"{MIN_INTERVAL_DRAWS}; take more draws"
        )
    return notes


def linearity_notes(outputs: dict, accepted: int, draws: int) -> list[str]:
    """A note when the Monte Carlo sd and sd_linear of some outputs differ by
    more than LINEAR_FACTOR either way (and there are MIN_INTERVAL_DRAWS
    accepted draws, the sd's own error then under 8 %): the linear method's sd
    and its budget shares, which are linear, do not describe those outputs."""
    if accepted < MIN_INTERVAL_DRAWS:
        return []
    off = {}
    for path, o in outputs.items():
        sd, linear = o["sd"], o["sd_linear"]
        if math.isfinite(sd) and math.isfinite(linear) and sd > 0.0 and linear > 0.0:
            ratio = max(sd / linear, linear / sd)
            if ratio > LINEAR_FACTOR:
                off[path] = ratio
    if not off:
        return []
    worst = max(off, key=off.get)
    rejected = f", or {1.0 - accepted / draws:.0%} of the draws rejected" if accepted < draws else ""
    return [
        f"the linear method does not hold for {len(off)} of {len(outputs)} outputs: their Monte Carlo sd "
        f"and sd_linear differ by more than {LINEAR_FACTOR:g} times (most: {worst}, sd "
        f"{outputs[worst]['sd']:.4g} against sd_linear {outputs[worst]['sd_linear']:.4g}; a model curved "
        f"over the inputs' range{rejected}); their budget shares, first-order too, do not say which input "
        "drives them; the Monte Carlo intervals are the answer"
    ]


# --------------------------------------------------------------------------- linear method


def _gradients(source: Source, nominal: dict) -> dict:
    """Output path → gradient (one entry per input) at the nominal scene;
    empty when the command has no Jacobian kernel."""
    command = source.command
    base = nominal["columns"]
    if command.gradients is not None:
        return command.gradients(base, _column_derivatives(source, base))
    ks, extra = command.jacobian_kernel(base)
    if ks is None:
        return {}
    values = {**base, **extra}
    values = {k: v for k, v in values.items() if not isinstance(v, str)}
    values.setdefault("mu", 0.0)
    row = _kernels.run_one(ks, values, ks.outputs + tuple(ks.constants))
    if row["status"] != 0:
        return {}
    names = [k for k in ks.inputs]
    value_outputs = [o for o in ks.outputs if not o.startswith("d_")]
    grads = {}
    dcols = _column_derivatives(source, base)
    for j, dc in enumerate(dcols):
        # Tangent of every column, then of every kernel output (exact Jacobian),
        # then the JSON map by complex step.
        h = COMPLEX_STEP
        cols = {k: complex(v, h * dc.get(k, 0.0)) for k, v in base.items() if not isinstance(v, str)}
        outs = {}
        for o in value_outputs:
            tangent = sum(row.get(f"d_{o}__d_{x}", 0.0) * dc.get(x, 0.0) for x in names)
            outs[o] = complex(row[o], h * tangent)
        for o in _kernels.OUTPUTS:
            outs.setdefault(o, complex(ks.constants.get(o, 0.0), 0.0))
        for path, y in command.outputs(cols, outs).items():
            grads.setdefault(path, np.zeros(len(source.inputs)))[j] = np.imag(y) / h
    return grads


def _column_derivatives(source: Source, base: dict) -> list[dict]:
    """Per input, d column / d input at the nominal scene: Richardson
    extrapolation of central differences with steps h and h/2 (error O(h⁴)),
    h = 1e-3 of the input's sd, all in one call of the column map."""
    x0 = np.array([x.nominal for x in source.inputs])
    k = len(x0)
    h = np.array([1e-3 * x.sd if x.sd > 0 else 1e-6 * max(abs(x.nominal), 1.0) for x in source.inputs])
    offsets = np.array([1.0, -1.0, 0.5, -0.5])
    grid = np.repeat(x0[:, None], 4 * k, axis=1)
    for j in range(k):
        grid[j, 4 * j : 4 * j + 4] += offsets * h[j]
    columns, _reason = source.columns({x.path: grid[i] for i, x in enumerate(source.inputs)})
    out = []
    for j in range(k):
        dc = {}
        for name, col in _flat(columns).items():
            if isinstance(col, str) or np.ndim(col) == 0:
                continue
            f = np.asarray(col, dtype=np.float64)[4 * j : 4 * j + 4]
            d_h = (f[0] - f[1]) / (2 * h[j])
            d_half = (f[2] - f[3]) / h[j]
            d = (4 * d_half - d_h) / 3
            if d != 0.0 and math.isfinite(d):
                dc[name] = d
        out.append(dc)
    return out


def _linear(gradient, cov: np.ndarray, inputs) -> tuple[float, dict]:
    """(sd_linear, budget shares) of one output."""
    if gradient is None:
        return math.nan, {}
    g = np.asarray(gradient)
    spread = cov @ g
    var = float(g @ spread)
    if not var > 0:
        return (0.0 if var == 0 else math.nan), {}
    return math.sqrt(var), {x.path: float(g[i] * spread[i] / var) for i, x in enumerate(inputs)}


# --------------------------------------------------------------------------- Sobol


def sobol_indices(source: Source, draws: int, seed, stats: dict) -> dict:
    """First-order and total Sobol indices per output (SALib, Saltelli's
    scheme, independent inputs), from about `draws` model runs."""
    try:
        from SALib.analyze import sobol as analyze
        from SALib.sample import sobol as sample
    except ImportError:
        raise ImportError("sobol=True needs SALib: pip install 'impactsym[uncertainty]'") from None
    k = len(source.inputs)
    base = 1 << max(6, int(math.log2(max(draws // (k + 2), 64))))
    problem = {"num_vars": k, "names": [x.path for x in source.inputs], "bounds": [[0.0, 1.0]] * k}
    unit = sample.sample(problem, base, calc_second_order=False, seed=seed)
    unit = np.clip(unit, 1e-12, 1 - 1e-12)
    overrides = {x.path: x.from_unit(unit[:, i]) for i, x in enumerate(source.inputs)}
    ok, values = _run_chunk(source, overrides, {})
    result = {}
    for path in stats:
        y = np.asarray(values[path], dtype=np.float64).copy()
        if not ok.any() or np.ptp(y[ok]) == 0:
            continue
        y[~ok] = y[ok].mean()
        si = analyze.analyze(problem, y, calc_second_order=False, seed=seed)
        result[path] = {
            "S1": dict(zip(problem["names"], map(float, si["S1"]))),
            "ST": dict(zip(problem["names"], map(float, si["ST"]))),
            "replaced": float(1 - ok.mean()),
        }
    return result


# --------------------------------------------------------------------------- scenes


def uncertainty(
    scene,
    command: str = "solve",
    draws: int = 10_000,
    seed: int | None = None,
    sobol: bool = False,
    restitution: float | None = None,
    energy: str | None = None,
    correction: str | None = None,
) -> Uncertainty:
    """Uncertainty of ``command``'s answers for a scene whose leaves carry
    distributions (see the module docstring and conventions.md, Uncertainty).
    ``restitution``, ``energy`` ("dissipated" | "absorbed") and
    ``correction`` ("crash3" | "woolley"): CRASH3's options (crash3 only),
    overriding the scene's ``"crash3"`` object as in `impactsym.crash3`."""
    return propagate(
        scene_source(scene, command, restitution, energy, correction), draws=draws, seed=seed, sobol=sobol
    )


def scene_source(
    scene,
    command: str,
    restitution: float | None = None,
    energy: str | None = None,
    correction: str | None = None,
) -> Source:
    """The Source of a scene (path, mapping or Scene) for a command; for
    crash3 with the scene's CRASH3 options overridden by those given."""
    from ..crash3 import crash3_options
    from ..laws.scene import is_law_scene, law_columns, load_law_scene
    from ..scene import load_scene, scene_columns, scene_data

    kind = {"solve": "forward", "invert": "inverse", "reconstruct": "reconstruct", "crash3": "crash3"}.get(
        command
    )
    if kind is None:
        raise ValueError(f"command: unknown command {command!r} (use one of {', '.join(COMMANDS)})")
    options = {}
    if command == "crash3":
        opts = crash3_options(scene_data(scene), restitution, energy, correction)
        options = {"restitution": opts.restitution, "energy": opts.energy, "correction": opts.correction}
    model, law = None, None
    if command == "solve" and is_law_scene(scene):  # impactsym.laws: its rigid reading + the law
        law = load_law_scene(scene)
        parsed, model = law.scene, f"{law.model}:{law.law}"
    else:
        parsed = load_scene(scene, kind=kind)
    uncertain = parsed.uncertain if law is None else law.uncertain
    inputs = tuple(Input(path, kind_, tuple(params)) for path, kind_, params in uncertain)

    def columns(overrides):
        if law is None:
            sc = scene_columns(parsed, overrides)
            return sc.columns, sc.reason
        return law_columns(law, overrides)

    return Source(
        command_for(command, model or parsed.model, parsed.units, **options),
        inputs,
        columns,
        tuple(getattr(parsed, "correlations", ())),
    )
