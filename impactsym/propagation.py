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
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from generated import codes as _codes

from . import _kernels
from .batch import solve_batch
from .inverse import invert_batch
from .reconstruct import reconstruct_batch
from .sweep import BLOCK, CHUNK_SIZE, SamplePlan

STATUS_NAMES = {getattr(_codes, n): n[len("STATUS_"):] for n in dir(_codes) if n.startswith("STATUS_")}
FLAG_NAMES = {n[len("FLAG_"):]: getattr(_codes, n) for n in dir(_codes) if n.startswith("FLAG_")}

__all__ = ["COMMANDS", "KEEP", "Input", "Uncertainty", "propagate", "uncertainty"]

COMMANDS = ("solve", "invert", "reconstruct", "crash3")
#: Accepted draws kept for the caller (`Uncertainty.draws`); statistics use every draw.
KEEP = 1 << 20
#: Bins of the streaming histograms that give percentiles beyond KEEP accepted draws.
HISTOGRAM_BINS = 1 << 16
PERCENTILES = (5.0, 50.0, 95.0)
#: Flags that make a draw physically impossible (ill-conditioned headings only warn).
REJECTING_FLAGS = ("ENERGY_CREATED", "TENSILE_IMPULSE", "MU_BEYOND_CRITICAL",
                   "E_OUT_OF_RANGE", "NEGATIVE_SPEED")
COMPLEX_STEP = 1e-30
DEGREES = 180.0 / math.pi


# --------------------------------------------------------------------------- inputs

@dataclass(frozen=True)
class Input:
    """An uncertain leaf: its path, distribution kind and parameters (scene units)."""

    path: str
    kind: str
    params: tuple[float, ...]

    @property
    def nominal(self) -> float:
        """Mean (normal), midpoint (uniform) or mode (triangular)."""
        p = self.params
        return {"normal": p[0], "uniform": (p[0] + p[1]) / 2}.get(self.kind, p[1])

    @property
    def sd(self) -> float:
        """The distribution's standard deviation."""
        p = self.params
        if self.kind == "normal":
            return p[1]
        if self.kind == "uniform":
            return (p[1] - p[0]) / math.sqrt(12.0)
        a, c, b = p
        return math.sqrt((a * a + b * b + c * c - a * b - a * c - b * c) / 18.0)

    def from_scores(self, z: np.ndarray) -> np.ndarray:
        """Values with normal scores `z` (inverse CDF of Φ(z))."""
        if self.kind == "normal":
            return self.params[0] + self.params[1] * z
        return self.from_unit(_normal_cdf(z))

    def from_unit(self, u: np.ndarray) -> np.ndarray:
        """Values at probabilities `u` (inverse CDF)."""
        p = self.params
        if self.kind == "normal":
            return p[0] + p[1] * _normal_ppf(u)
        if self.kind == "uniform":
            return p[0] + (p[1] - p[0]) * u
        a, c, b = p
        left = (c - a) / (b - a)
        return np.where(u < left, a + np.sqrt(u * (b - a) * (c - a)),
                        b - np.sqrt((1.0 - u) * (b - a) * (b - c)))


def _normal_cdf(z):
    from scipy.special import ndtr

    return ndtr(z)


def _normal_ppf(u):
    from scipy.special import ndtri

    return ndtri(u)


def correlation_matrix(inputs: tuple[Input, ...], correlations) -> np.ndarray:
    """The inputs' correlation matrix from ``(path_a, path_b, rho)`` pairs."""
    index = {x.path: i for i, x in enumerate(inputs)}
    corr = np.eye(len(inputs))
    for a, b, rho in correlations:
        corr[index[a], index[b]] = corr[index[b], index[a]] = rho
    return corr


def _cholesky(corr: np.ndarray) -> np.ndarray:
    """A factor L with L Lᵀ = corr (positive semi-definite: by eigenvalues)."""
    try:
        return np.linalg.cholesky(corr)
    except np.linalg.LinAlgError:
        values, vectors = np.linalg.eigh(corr)
        return vectors * np.sqrt(np.clip(values, 0.0, None))


# --------------------------------------------------------------------------- commands: columns -> outputs

def _hypot(x, y):
    """|(x, y)|, valid for the complex step (np.hypot is real only)."""
    return np.sqrt(x * x + y * y)


def _clockwise_deg(rad):
    """A counter-clockwise angle [rad] as degrees clockwise in (-180, 180];
    the wrap acts on the real part only, so the complex step passes through."""
    deg = rad * (-180.0 / math.pi)
    real = (np.real(deg) + 180.0) % 360.0 - 180.0
    return real + 1j * np.imag(deg) if np.iscomplexobj(deg) else real


def _forward_outputs(c: Mapping, o: Mapping, yaw: bool) -> dict:
    out = {}
    for i in (1, 2):
        v = f"vehicles[{i - 1}]"
        out[f"{v}.velocity[0]"], out[f"{v}.velocity[1]"] = o[f"V{i}x"], o[f"V{i}y"]
        if yaw:
            out[f"{v}.yaw_rate"] = o[f"W{i}"]
        out[f"{v}.delta_v[0]"] = o[f"V{i}x"] - c[f"v{i}x"]
        out[f"{v}.delta_v[1]"] = o[f"V{i}y"] - c[f"v{i}y"]
        out[f"{v}.delta_v_magnitude"] = o[f"dV{i}"]
    return {**out, **_impulse_energy(o, yaw), "impulse_ratio": o["mu"],
            "critical_impulse_ratio": o["mu_c"]}


def _impulse_energy(o: Mapping, yaw: bool) -> dict:
    out = {"impulse.normal": o["Pn"], "impulse.tangential": o["Pt"]}
    if yaw:
        out["impulse.moment"] = o["M"]
    out.update({"energy_loss.total": o["TL"], "energy_loss.normal": o["TLn"],
                "energy_loss.tangential": o["TLt"]})
    if yaw:
        out["energy_loss.moment"] = o["TLm"]
    return out


def _inverse_outputs(c: Mapping, o: Mapping, yaw: bool) -> dict:
    out = {}
    for i in (1, 2):
        v = f"vehicles[{i - 1}]"
        out[f"{v}.velocity[0]"], out[f"{v}.velocity[1]"] = o[f"v{i}x"], o[f"v{i}y"]
        if yaw:
            out[f"{v}.yaw_rate"] = o[f"w{i}"]
        dx, dy = c[f"V{i}x"] - o[f"v{i}x"], c[f"V{i}y"] - o[f"v{i}y"]
        out[f"{v}.delta_v[0]"], out[f"{v}.delta_v[1]"] = dx, dy
        out[f"{v}.delta_v_magnitude"] = _hypot(dx, dy)
    return {**out, **_impulse_energy(o, yaw), "impulse_ratio": c["mu"],
            "critical_impulse_ratio": o["mu_c"]}


def _reconstruct_outputs(c: Mapping, o: Mapping, yaw: bool = True) -> dict:
    out = {}
    for i in (1, 2):
        v = f"vehicles[{i - 1}]"
        out[f"{v}.speed"] = o[f"s{i}"]
        out[f"{v}.velocity[0]"], out[f"{v}.velocity[1]"] = o[f"v{i}x"], o[f"v{i}y"]
        dx, dy = c[f"V{i}x"] - o[f"v{i}x"], c[f"V{i}y"] - o[f"v{i}y"]
        out[f"{v}.delta_v[0]"], out[f"{v}.delta_v[1]"] = dx, dy
        out[f"{v}.delta_v_magnitude"] = _hypot(dx, dy)
        out[f"{v}.pdof_deg"] = _clockwise_deg(o[f"pdof{i}"])
    return {**out, **_impulse_energy(o, True), "moment_residual": o["M_residual"],
            "restitution": o["e"], "impulse_ratio": o["mu"], "moment_restitution": o["e_m"],
            "critical_impulse_ratio": o["mu_c"]}


@dataclass(frozen=True)
class Command:
    """How one command turns kernel columns into its JSON numbers.

    `run(columns)` → (kernel outputs, status, flags) through the batch kernels;
    `jacobian(columns)` → the exact Jacobian kernel's row at one scene (kernel
    inputs → value and derivative outputs), or None where there is none;
    `outputs(columns, kernel outputs)` → JSON path → values (complex-safe)."""

    name: str
    run: Callable
    jacobian_kernel: Callable
    outputs: Callable
    gradients: Callable | None = None


def _forward_command(model: str) -> Command:
    family, fixed = _kernels.preset(model)
    yaw = family != "particle"

    def kernel(columns):
        if family not in ("rigid", "particle"):
            return None, {}
        critical = fixed.get("mu") == "critical" or columns.get("mu") == "critical"
        extra = {k: v for k, v in fixed.items() if k != "mu"}
        return _kernels.JACOBIAN[family + ("_critical" if critical else "")], extra

    return Command("solve", lambda c: _split(solve_batch(c, model=model)), kernel,
                   lambda c, o: _forward_outputs(c, o, yaw))


def _inverse_command(family: str) -> Command:
    yaw = family != "particle"
    return Command("invert", lambda c: _split(invert_batch(c, model=family)),
                   lambda c: (_kernels.JACOBIAN[f"{family}_inverse"], {}),
                   lambda c, o: _inverse_outputs(c, o, yaw))


RECONSTRUCT = Command("reconstruct", lambda c: _split(reconstruct_batch(c)),
                      lambda c: (_kernels.JACOBIAN["reconstruct"], {}), _reconstruct_outputs)


def _split(result: Mapping):
    outs = {k: v for k, v in result.items() if k not in ("status", "flags")}
    return outs, np.asarray(result["status"]), np.asarray(result["flags"])


# --------------------------------------------------------------------------- CRASH3: a chain of kernels

def _crash3_stages(c: Mapping, units: str, e: float, tangents: list | None = None):
    """CRASH3 over columns `c` (scene_columns' crash3 form): per vehicle the
    crush-energy kernel, radius of gyration and moment arm, then the delta-V
    kernel on the total energy. With `tangents` (per input, d column) the
    exact Jacobian kernels of each stage carry them through too (one scene).
    Returns (values by name, status, per-input tangents by name)."""
    from .crash3 import ENERGY_FACTOR

    factor = ENERGY_FACTOR[units]
    n = max([np.size(v) for k, v in c.items() if k != "crush"] + [
        np.size(v) for crush in c["crush"] if crush for v in crush.values()])
    vals, status = {}, np.zeros(n, dtype=np.int32)
    tan = [dict(t) for t in tangents] if tangents is not None else None

    def stage(name: str, ks, inputs: dict, prefix: str = ""):
        args = [inputs[k] for k in ks.inputs]
        if tan is None:
            outs, st, _fl = _kernels.run_batch(ks, args, n)
        else:
            jk = _kernels.JACOBIAN[name]
            row = _kernels.run_one(jk, {k: float(np.ravel(v)[0]) for k, v in inputs.items()},
                                   jk.outputs)
            st = np.array([row["status"]])
            outs = {o: np.array([row[o]]) for o in ks.outputs}
            for t in tan:
                for o in ks.outputs:
                    t[prefix + o] = sum(row.get(f"d_{o}__d_{x}", 0.0) * t.get(inputs_key[x], 0.0)
                                        for x in ks.inputs)
        np.copyto(status, st, where=status == 0)
        return outs

    for i, crush in enumerate(c["crush"], start=1):
        if crush is None:
            vals.update({f"E{i}": 0.0, f"E_crush{i}": 0.0, f"rg{i}": math.inf, f"h{i}": 0.0,
                         f"alpha{i}": 0.0, f"m{i}": math.inf})
            continue
        depths = sum(1 for k in crush if k.startswith("C") and k[1:].isdigit())
        inputs_key = {k: f"crush{i}.{k}" for k in crush}
        out = stage(f"crash3_energy_{depths}", _kernels.CRASH3_ENERGY[depths], crush, f"energy{i}.")
        vals[f"E_crush{i}"], vals[f"E{i}"] = out["E_crush"] * factor, out["E"] * factor
        vals[f"alpha{i}"], vals[f"m{i}"] = crush["alpha"], c[f"m{i}"]
        if tan is not None:
            for t in tan:
                t[f"E{i}"] = t[f"energy{i}.E"] * factor
                t[f"E_crush{i}"] = t[f"energy{i}.E_crush"] * factor
                t[f"alpha{i}"], t[f"m{i}"] = t.get(f"crush{i}.alpha", 0.0), t.get(f"m{i}", 0.0)
        if "radius_of_gyration" in crush:
            vals[f"rg{i}"] = crush["radius_of_gyration"]
            _alias(tan, f"rg{i}", f"crush{i}.radius_of_gyration")
        elif np.all(np.isfinite(c[f"I{i}"])):
            inputs_key = {"mass": f"m{i}", "inertia": f"I{i}"}
            vals[f"rg{i}"] = stage("crash3_radius_of_gyration", _kernels.CRASH3_RADIUS_OF_GYRATION,
                                   {"mass": c[f"m{i}"], "inertia": c[f"I{i}"]}, f"rg{i}.")["rg"]
            _alias(tan, f"rg{i}", f"rg{i}.rg")
        else:
            vals[f"rg{i}"] = math.inf
        if "moment_arm" in crush:
            vals[f"h{i}"] = crush["moment_arm"]
            _alias(tan, f"h{i}", f"crush{i}.moment_arm")
        else:
            theta = c["gamma"] + crush["alpha"]
            if tan is not None:
                for t in tan:
                    t[f"theta{i}"] = t.get("gamma", 0.0) + t.get(f"crush{i}.alpha", 0.0)
            inputs_key = {"rx": f"r{i}x", "ry": f"r{i}y", "theta": f"theta{i}"}
            vals[f"h{i}"] = stage("crash3_moment_arm", _kernels.CRASH3_MOMENT_ARM,
                                  {"rx": c[f"r{i}x"], "ry": c[f"r{i}y"], "theta": theta}, f"h{i}.")["h"]
            _alias(tan, f"h{i}", f"h{i}.h")
    vals["E"] = vals["E1"] + vals["E2"]
    if tan is not None:
        for t in tan:
            t["E"] = t.get("E1", 0.0) + t.get("E2", 0.0)
    inputs_key = {k: k for k in ("m1", "m2", "rg1", "rg2", "h1", "h2", "E", "e", "gamma",
                                 "alpha1", "alpha2")}
    dv_inputs = {k: vals[k] if k in vals else c[k] for k in inputs_key if k != "e"}
    dv_inputs["e"] = e
    vals.update(stage("crash3_delta_v", _kernels.CRASH3_DELTA_V, dv_inputs, "dv."))
    if tan is not None:
        for t in tan:
            for o in _kernels.CRASH3_DELTA_V.outputs:
                t[o] = t[f"dv.{o}"]
    return vals, status, tan


def _alias(tangents, name: str, source: str) -> None:
    if tangents is not None:
        for t in tangents:
            t[name] = t.get(source, 0.0)


def _crash3_outputs(c: Mapping, v: Mapping) -> dict:
    out = {}
    for i in (1, 2):
        p = f"vehicles[{i - 1}]"
        out.update({f"{p}.crush_energy": v[f"E{i}"], f"{p}.crush_energy_uncorrected": v[f"E_crush{i}"],
                    f"{p}.effective_mass_factor": v[f"mass_factor{i}"], f"{p}.moment_arm": v[f"h{i}"],
                    f"{p}.delta_v[0]": v[f"dV{i}x"], f"{p}.delta_v[1]": v[f"dV{i}y"],
                    f"{p}.delta_v_magnitude": v[f"dV{i}"], f"{p}.pdof": v[f"alpha{i}"] * DEGREES})
        if f"dV{i}_eff" in v:  # EDCRASH's effective-mass delta-V, where the kernel has it
            out[f"{p}.delta_v_effective_mass"] = v[f"dV{i}_eff"]
    out["energy_total"], out["impulse"] = v["E"], v["P"]
    return out


def _crash3_command(units: str, e: float) -> Command:
    """CRASH3 as a chain of kernels; its gradients chain their exact Jacobians."""
    def run(c):
        vals, status, _ = _crash3_stages(c, units, e)
        return vals, status, np.zeros_like(status)

    def gradients(base: dict, dcols: list) -> dict:
        vals, status, tan = _crash3_stages(base, units, e, dcols)
        if status[0] != 0:
            return {}
        values = _crash3_outputs(base, {k: np.ravel(x)[0] if np.ndim(x) else x for k, x in vals.items()})
        grads = {path: np.zeros(len(dcols)) for path in values}
        for j, t in enumerate(tan):
            h = COMPLEX_STEP
            cplx = {k: complex(np.ravel(x)[0] if np.ndim(x) else x, h * t.get(k, 0.0))
                    for k, x in vals.items()}
            for path, y in _crash3_outputs(base, cplx).items():
                grads[path][j] = np.imag(y) / h
        return grads

    return Command("crash3", run, lambda c: (None, {}), _crash3_outputs, gradients)


def command_for(command: str, model: str = "rigid", units: str = "SI",
                restitution: float = 0.0) -> Command:
    """The Command of ``solve`` (any model), ``invert`` (rigid, particle),
    ``reconstruct`` or ``crash3`` (scene units and CRASH3's restitution)."""
    if command == "crash3":
        return _crash3_command(units, restitution)
    if command == "solve":
        return _forward_command(model)
    if command == "invert":
        return _inverse_command(_kernels.preset(model)[0])
    if command == "reconstruct":
        return RECONSTRUCT
    raise ValueError(f"command: unknown command {command!r} (use one of {', '.join(COMMANDS)})")


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


# --------------------------------------------------------------------------- streaming statistics

class _Stats:
    """Count, mean, sd (sums shifted by the nominal value) and percentiles of
    one output over accepted draws: exact from the values kept in memory up to
    `KEEP` draws, beyond that from a `HISTOGRAM_BINS`-bin histogram whose
    range is set by the first KEEP values and more (widened by half their span
    each side; values outside it are counted and bounded by the running min
    and max)."""

    def __init__(self, shift: float):
        self.shift = shift if math.isfinite(shift) else 0.0
        self.n, self.s1, self.s2 = 0, 0.0, 0.0
        self.kept: list[np.ndarray] = []
        self.kept_n = 0
        self.edges = self.hist = None
        self.low_count = self.high_count = 0
        self.lo, self.hi = math.inf, -math.inf

    def add(self, x: np.ndarray) -> None:
        if x.size == 0:
            return
        d = x - self.shift
        self.n += x.size
        self.s1 += float(d.sum())
        self.s2 += float((d * d).sum())
        self.lo, self.hi = min(self.lo, float(x.min())), max(self.hi, float(x.max()))
        if self.hist is None and self.n <= KEEP:
            self.kept.append(x.copy())
            self.kept_n = self.n
            return
        if self.hist is None:  # past KEEP: the histogram starts from the values kept
            first = np.concatenate(self.kept + [x])
            span = max(float(first.max() - first.min()), abs(self.shift) * 1e-12, 1e-300)
            self.edges = (float(first.min()) - span / 2, float(first.max()) + span / 2)
            self.hist = np.zeros(HISTOGRAM_BINS, dtype=np.int64)
            self.kept, x = [], first
        a, b = self.edges
        pos = (x - a) * (HISTOGRAM_BINS / (b - a))
        inside = (pos >= 0) & (pos < HISTOGRAM_BINS)
        self.low_count += int(np.count_nonzero(pos < 0))
        self.high_count += int(np.count_nonzero(pos >= HISTOGRAM_BINS))
        self.hist += np.bincount(pos[inside].astype(np.intp), minlength=HISTOGRAM_BINS)

    @property
    def mean(self) -> float:
        return self.shift + self.s1 / self.n if self.n else math.nan

    @property
    def sd(self) -> float:
        if self.n < 2:
            return math.nan
        var = (self.s2 - self.s1 * self.s1 / self.n) / (self.n - 1)
        return math.sqrt(max(var, 0.0))

    def percentiles(self, q=PERCENTILES) -> list[float]:
        if self.n == 0:
            return [math.nan] * len(q)
        if self.hist is None:
            return [float(v) for v in np.percentile(np.concatenate(self.kept), q)]
        return [self._from_histogram(p) for p in q]

    def _from_histogram(self, p: float) -> float:
        rank = p / 100.0 * (self.n - 1)
        if rank < self.low_count:
            return self.lo
        cum = np.cumsum(self.hist) + self.low_count
        k = int(np.searchsorted(cum, rank, side="right"))
        if k >= HISTOGRAM_BINS:
            return self.hi
        a, b = self.edges
        width = (b - a) / HISTOGRAM_BINS
        before = cum[k - 1] if k else self.low_count
        frac = (rank - before + 0.5) / max(self.hist[k], 1)
        return float(a + (k + min(max(frac, 0.0), 1.0)) * width)


# --------------------------------------------------------------------------- the result

@dataclass
class Uncertainty:
    """The uncertainty of a command's answers (scene units).

    `summary`: DataFrame, one row per output: nominal, mean, sd, p5, p50, p95,
    sd_linear and the three largest budget shares. `budget`: output → input →
    share of the linearised variance. `draws`: DataFrame of (at most `KEEP`)
    accepted draws, inputs then outputs. `rejected`: reason → count. `notes`:
    what the flags at the nominal values mean given the draws. `sobol`: output
    → {"S1": {input: index}, "ST": {...}} or None."""

    command: str
    n_draws: int
    accepted: int
    rejected: dict
    inputs: tuple[str, ...]
    outputs: dict
    budget: dict
    kept: list = field(repr=False)
    notes: list = field(default_factory=list)
    sobol: dict | None = None
    seed: int | None = None
    _draws: Any = field(default=None, repr=False)

    @property
    def draws(self):
        """The accepted draws (at most `KEEP`) as a DataFrame, built on first use."""
        if self._draws is None:
            self._draws = _frame(self.kept)
        return self._draws

    @property
    def summary(self):
        import pandas as pd

        rows = {}
        for path, o in self.outputs.items():
            top = sorted(self.budget.get(path, {}).items(), key=lambda kv: -abs(kv[1]))[:3]
            rows[path] = {**{k: o[k] for k in ("nominal", "mean", "sd", "p5", "p50", "p95",
                                              "sd_linear")},
                          "budget": ", ".join(f"{name} {share:.0%}" for name, share in top)}
        return pd.DataFrame.from_dict(rows, orient="index")

    def to_json_dict(self) -> dict:
        """The ``"uncertainty"`` object of conventions.md (non-finite → null)."""
        def num(x):
            return float(x) if x is not None and math.isfinite(x) else None

        outputs = {path: {**{k: num(o[k]) for k in ("nominal", "mean", "sd", "p5", "p50", "p95",
                                                   "sd_linear")},
                          "budget": {k: num(v) for k, v in self.budget.get(path, {}).items()}}
                   for path, o in self.outputs.items()}
        out = {"draws": self.n_draws, "accepted": self.accepted, "rejected": dict(self.rejected),
               "inputs": list(self.inputs), "outputs": outputs}
        if self.notes:
            out["notes"] = list(self.notes)
        if self.sobol is not None:
            out["sobol"] = self.sobol
        return out

    def table(self, units: str | None = None) -> str:
        """Nominal, mean, 90 % interval and the three largest budget shares per output."""
        lines = [f"uncertainty ({self.command}): {self.n_draws} draws, {self.accepted} accepted"
                 + (f", seed {self.seed}" if self.seed is not None else "")]
        if self.rejected:
            lines.append("rejected: " + ", ".join(f"{k} {v}" for k, v in self.rejected.items()))
        lines += [f"note: {n}" for n in self.notes]
        width = max(len(p) for p in self.outputs) + 2
        lines += ["", (f"{'output':<{width}}{'nominal':>12}{'mean':>12}{'90 % interval':>26}"
                       "  largest budget shares")]
        for path, o in self.outputs.items():
            top = sorted(self.budget.get(path, {}).items(), key=lambda kv: -abs(kv[1]))[:3]
            interval = f"[{_cell(o['p5'])}, {_cell(o['p95'])}]"
            lines.append(f"{path:<{width}}{_cell(o['nominal']):>12}{_cell(o['mean']):>12}"
                         f"{interval:>26}  " + ", ".join(f"{n} {s:.0%}" for n, s in top))
        return "\n".join(lines)


def _cell(x) -> str:
    return "n/a" if x is None or not math.isfinite(x) else f"{x:.5g}"


# --------------------------------------------------------------------------- propagation

def propagate(source: Source, draws: int = 10_000, seed: int | None = None, sobol: bool = False,
              chunk_size: int = CHUNK_SIZE) -> Uncertainty:
    """Monte Carlo and first-order propagation of `source`'s uncertain inputs
    (see the module docstring). `draws` Monte Carlo draws from `seed`
    (None: fresh entropy, reported as `Uncertainty.seed`)."""
    if not isinstance(draws, int) or isinstance(draws, bool) or draws < 2:
        raise ValueError(f"draws: must be an integer >= 2, got {draws!r}")
    if not source.inputs:
        raise ValueError("the scene has no uncertain inputs: give a leaf as "
                         '{"normal": [mean, sd]}, {"uniform": [low, high]} or '
                         '{"triangular": [low, mode, high]}')
    command = source.command
    nominal = _nominal(source)
    corr = correlation_matrix(source.inputs, source.correlations)
    factor = _cholesky(corr)
    entropy = np.random.SeedSequence(seed).entropy
    plan = SamplePlan(model="", units="", outputs=None, constants={},
                      names=tuple(x.path for x in source.inputs), kernels=(),
                      dists=(("normal", (0.0, 1.0)),) * len(source.inputs),
                      entropy=entropy, rows=draws)
    stats = {path: _Stats(value) for path, value in nominal["outputs"].items()}
    rejected: dict[str, int] = {}
    accepted, kept, kept_rows = 0, [], 0
    step = max(BLOCK, (chunk_size // BLOCK) * BLOCK)
    for start in range(0, draws, step):
        stop = min(start + step, draws)
        scores = factor @ np.vstack(plan.draws(start, stop))
        overrides = {x.path: x.from_scores(z) for x, z in zip(source.inputs, scores)}
        ok, values = _run_chunk(source, overrides, rejected)
        accepted += int(ok.sum())
        for path, s in stats.items():
            s.add(np.asarray(values[path], dtype=np.float64)[ok])
        if kept_rows < KEEP:
            kept_rows += int(ok.sum())
            kept.append({**{p: v[ok] for p, v in overrides.items()},
                         **{p: np.broadcast_to(v, ok.shape)[ok] for p, v in values.items()}})
    gradient = _gradients(source, nominal)
    cov = corr * np.outer([x.sd for x in source.inputs], [x.sd for x in source.inputs])
    outputs, budget = {}, {}
    for path, s in stats.items():
        p5, p50, p95 = s.percentiles()
        sd_lin, shares = _linear(gradient.get(path), cov, source.inputs)
        outputs[path] = {"nominal": nominal["outputs"][path], "mean": s.mean, "sd": s.sd,
                         "p5": p5, "p50": p50, "p95": p95, "sd_linear": sd_lin}
        budget[path] = shares
    result = Uncertainty(command.name, draws, accepted, rejected,
                         tuple(x.path for x in source.inputs), outputs, budget,
                         kept, _notes(nominal["flags"], accepted, draws, rejected),
                         seed=int(entropy) if seed is None else seed)
    if sobol:
        result.sobol = sobol_indices(source, draws, seed, stats)
    return result


def _run_chunk(source: Source, overrides: dict, rejected: dict):
    """Solve one chunk: (accepted mask, output path → values)."""
    columns, reason = source.columns(overrides)
    outs, status, flags = source.command.run(columns)
    n = status.shape[0]
    values = {path: np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
              for path, v in source.command.outputs(columns, outs).items()}
    ok = np.ones(n, dtype=bool)
    reason = np.broadcast_to(np.asarray(reason, dtype=object), (n,))
    bad_leaf = reason != ""
    for text in np.unique(reason[bad_leaf]).tolist():
        _count(rejected, text, int(np.count_nonzero(reason == text)))
    ok &= ~bad_leaf
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
        raise ValueError("the nominal scene cannot be solved: "
                         + (str(np.asarray(reason)[0]) or STATUS_NAMES[int(status[0])].lower()))
    values = source.command.outputs(columns, outs)
    return {"columns": _row(columns, 0), "outputs": {p: float(np.ravel(v)[0]) for p, v in values.items()},
            "flags": int(flags[0])}


def _row(columns: Mapping, i: int) -> dict:
    """Row i of columns as scalars (strings such as mu = "critical" kept;
    CRASH3's per-vehicle crush tables row by row too)."""
    def at(v):
        return v if isinstance(v, str) or np.ndim(v) == 0 else float(np.asarray(v)[i])

    return {k: ([None if t is None else {a: at(b) for a, b in t.items()} for t in v]
                if k == "crush" else at(v)) for k, v in columns.items()}


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
            verdict = ("the flag is measurement noise" if share >= 0.5 else
                       "the flag is robust: most draws are impossible too")
            notes.append(f"{what} at the nominal values; {share:.0%} of draws are physical "
                         f"({verdict})")
    if accepted == 0:
        notes.append("no draw is physical: the statistics are undefined")
    return notes


def _frame(kept: list):
    import pandas as pd

    if not kept:
        return pd.DataFrame()
    columns = {k: np.concatenate([part[k] for part in kept])[:KEEP] for k in kept[0]}
    return pd.DataFrame(columns)


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
    h = np.array([1e-3 * x.sd if x.sd > 0 else 1e-6 * max(abs(x.nominal), 1.0)
                  for x in source.inputs])
    offsets = np.array([1.0, -1.0, 0.5, -0.5])
    grid = np.repeat(x0[:, None], 4 * k, axis=1)
    for j in range(k):
        grid[j, 4 * j:4 * j + 4] += offsets * h[j]
    columns, _reason = source.columns({x.path: grid[i] for i, x in enumerate(source.inputs)})
    out = []
    for j in range(k):
        dc = {}
        for name, col in _flat(columns).items():
            if isinstance(col, str) or np.ndim(col) == 0:
                continue
            f = np.asarray(col, dtype=np.float64)[4 * j:4 * j + 4]
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
        result[path] = {"S1": dict(zip(problem["names"], map(float, si["S1"]))),
                        "ST": dict(zip(problem["names"], map(float, si["ST"]))),
                        "replaced": float(1 - ok.mean())}
    return result


# --------------------------------------------------------------------------- scenes

def uncertainty(scene, command: str = "solve", draws: int = 10_000, seed: int | None = None,
                sobol: bool = False, restitution: float = 0.0, energy: str | None = None,
                correction: str | None = None) -> Uncertainty:
    """Uncertainty of ``command``'s answers for a scene whose leaves carry
    distributions (see the module docstring and conventions.md, Uncertainty).
    ``restitution``, ``energy``, ``correction``: CRASH3's options (crash3
    only; the uncertainty of CRASH3 supports its default energy treatment,
    dissipated, and the 1 + tan²α correction)."""
    if energy not in (None, "dissipated") or correction not in (None, "crash3"):
        raise ValueError("--uncertainty of crash3 supports energy 'dissipated' and correction "
                         f"'crash3' only, got energy {energy!r}, correction {correction!r}")
    return propagate(scene_source(scene, command, restitution), draws=draws, seed=seed,
                     sobol=sobol)


def scene_source(scene, command: str, restitution: float = 0.0) -> Source:
    """The Source of a scene (path, mapping or Scene) for a command."""
    from .scene import load_scene, scene_columns

    kind = {"solve": "forward", "invert": "inverse", "reconstruct": "reconstruct",
            "crash3": "crash3"}.get(command)
    if kind is None:
        raise ValueError(f"command: unknown command {command!r} (use one of {', '.join(COMMANDS)})")
    parsed = load_scene(scene, kind=kind)
    inputs = tuple(Input(path, kind_, tuple(params)) for path, kind_, params in parsed.uncertain)

    def columns(overrides):
        sc = scene_columns(parsed, overrides)
        return sc.columns, sc.reason

    return Source(command_for(command, parsed.model, parsed.units, restitution), inputs, columns,
                  tuple(getattr(parsed, "correlations", ())))
