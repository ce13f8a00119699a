"""Throughput of ``impactsym.solve_batch`` against a memory ceiling and the baselines a
user would write, start-up times, the serial/parallel threshold and a large sweep.

``python -m benchmarks performance [--n 1000000] [--repeat 7] [--sweep | --no-sweep]
[--sweep-points 1e8] [--quick] [--out benchmarks/results]``

1. **Memory ceiling.** For each case, a trivial ``@njit(parallel=True)`` ``prange``
   kernel reads every *array* column the real call is given (scalars are not memory)
   and writes as many freshly allocated float64 arrays as the real call returns, plus an
   int32 status and an int32 flags array (``np.empty`` inside the timed region, as
   ``solve_batch`` allocates). It is timed interleaved with the real call,
   ``impactsym.solve_batch(columns, ...)`` (the public API, dispatch included), and with
   the kernel alone through the runtime (``_kernels.run_batch``: allocation + driver); the
   order rotates each repeat. Reported: the median of the per-repeat ratios
   ceiling time / real time, and ns/scene and Mscenes/s of each (medians).
2. **Baselines.** The 9x9 system of conventions.md (a second solve with the sticking
   equation for mu_c, energies as work; the outputs impactsym gives) per row with
   ``numpy.linalg.solve`` in a Python loop, and batched on (rows, 9, 9) stacks
   (``benchmarks.accuracy._linear_bind``); per-scene time against impactsym's per-scene
   time of case (a), same run.
3. **Start-up and compile waits**, each in a fresh subprocess, least of 5 after one
   untimed warm-up run: ``impactsym solve examples/intersection_si.toml`` wall time;
   ``import impactsym`` (and whether it imports numba) and the first ``solve_batch``
   call on the n rows of case (a) with numba's cache warm, and with an empty cache (a
   temporary NUMBA_CACHE_DIR: the first use on a machine). After that first use, calls
   never made before (three scalar/array mixes of ``solve_batch``, one ``sweep``,
   ``sample`` small and large, ``invert_batch``, ``reconstruct_batch``; ``WAIT_CALLS``):
   the wait of the first run over the least of three later runs in the same process.
4. **Small batches.** The one driver on one thread (numba.set_num_threads(1)) against all
   threads for n = 1, 2, 4, ..., 4096, called directly (preallocated outputs) and through
   ``run_batch``; per n the median of many interleaved calls.
5. **Sweep.** ``impactsym sweep`` of ``--sweep-points`` rows (e x mu grid) writing a
   Parquet file to a temporary folder: wall time, rows/s, peak RSS of the child
   (``os.wait4``). On by default when ``impactsym.sweep`` exists (``--no-sweep``).

Also: the packed and scalar float64 arithmetic instructions of every driver measured
(compiled afresh in a child process), to tell compute-bound scalar code from SIMD code.
The machine is shared: every timed block waits for, and is re-run unless it ran on, a
machine where other processes used at most ``--max-other`` of the CPUs (see ``Quiet``);
their share per section is reported.

Every scene approaches at the impact centre (n.(u2 - u1) < 0) and is solvable, so no row
takes an early exit; the share of status-0 rows is reported.
"""

from __future__ import annotations

import argparse
import compileall
import contextlib
import json
import math
import os
import platform
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import impactsym
from impactsym import _kernels
from impactsym.testing.reference import RIGID_INPUTS

from .accuracy import _cpu_busy_seconds, _linear_bind

DESCRIPTION = "throughput against a memory ceiling and baselines, start-up, serial threshold, sweep"
ROOT = Path(__file__).resolve().parent.parent
RESULTS = Path(__file__).resolve().parent / "results"
SCENE_FILE = "examples/intersection_si.toml"
STARTUP_RUNS = 5
CALLS_PER_ROUND = 5  # section 1: consecutive calls per case, call and round (median)
THRESHOLD_SIZES = tuple(2**k for k in range(13))  # 1 .. 4096
SEED = 20240611


# ------------------------------------------------------------------ scenes


def _approach(c: dict, nx, ny):
    """n.(u2 - u1) at the impact centre (particles: n.(v2 - v1))."""
    w1, w2 = c.get("w1", 0.0), c.get("w2", 0.0)
    u1x, u1y = c["v1x"] - w1 * c.get("r1y", 0.0), c["v1y"] + w1 * c.get("r1x", 0.0)
    u2x, u2y = c["v2x"] - w2 * c.get("r2y", 0.0), c["v2y"] + w2 * c.get("r2x", 0.0)
    return nx * (u2x - u1x) + ny * (u2y - u1y)


def approaching_scenes(
    n: int, seed: int, *, model: str = "rigid", gamma: float | None = None, e_m: float | None = None
) -> dict:
    """``n`` realistic approaching two-car scenes as solve_batch columns (SI).

    Masses 800-3000 kg, yaw inertias 1000-5000 kg m^2, speeds 0-30 m/s in any
    direction, yaw rates within +-0.5 rad/s, lever arms within +-2.5 m per component,
    e in [0, 0.5], e_m in [0.2, 1) (or the scalar ``e_m`` as a column of that value).
    ``gamma=None``: a random angle per row, turned by pi where the row would separate;
    a scalar ``gamma``: the same normal for every row (a scalar column), and the rows
    that would separate have every velocity reversed instead. ``mu`` is a random
    fraction in [0, 1) of the row's critical ratio mu_c (one solve_batch call)."""
    rng = np.random.default_rng(seed)
    c = {}
    for i in (1, 2):
        speed, heading = rng.uniform(0.0, 30.0, n), rng.uniform(-np.pi, np.pi, n)
        c[f"m{i}"] = rng.uniform(800.0, 3000.0, n)
        c[f"v{i}x"], c[f"v{i}y"] = speed * np.cos(heading), speed * np.sin(heading)
        if model == "rigid":
            c[f"I{i}"] = rng.uniform(1000.0, 5000.0, n)
            c[f"w{i}"] = rng.uniform(-0.5, 0.5, n)
            c[f"r{i}x"], c[f"r{i}y"] = rng.uniform(-2.5, 2.5, n), rng.uniform(-2.5, 2.5, n)
    if gamma is None:
        angle = rng.uniform(-np.pi, np.pi, n)
        separating = _approach(c, np.cos(angle), np.sin(angle)) >= 0
        c["gamma"] = np.where(separating, angle - np.copysign(np.pi, angle), angle)
    else:
        separating = _approach(c, math.cos(gamma), math.sin(gamma)) >= 0
        for name in ("v1x", "v1y", "w1", "v2x", "v2y", "w2"):
            if name in c:
                c[name] = np.where(separating, -c[name], c[name])
        c["gamma"] = float(gamma)
    c["e"] = rng.uniform(0.0, 0.5, n)
    if model == "rigid":
        c["e_m"] = rng.uniform(0.2, 1.0, n) if e_m is None else np.full(n, float(e_m))
    mu_c = impactsym.solve_batch({**c, "mu": 0.0}, model=model, outputs=["mu_c"])["mu_c"]
    c["mu"] = rng.uniform(0.0, 1.0, n) * mu_c
    return {k: np.ascontiguousarray(v) if isinstance(v, np.ndarray) else v for k, v in c.items()}


# ------------------------------------------------------------------ memory ceiling

_CEILINGS: dict[tuple[int, int], Callable] = {}


def _ceiling_kernel(n_in: int, n_out: int) -> Callable:
    """A ``prange`` kernel reading ``n_in`` float64 arrays and writing ``n_out`` float64
    arrays plus int32 status and flags: each row sums its inputs and stores the sum plus
    a constant. Written as source and compiled (not cached: numba cannot cache exec'd
    code), one per (n_in, n_out)."""
    key = (n_in, n_out)
    if key not in _CEILINGS:
        import numba

        ins = [f"a{k}" for k in range(n_in)]
        outs = [f"o{k}" for k in range(n_out)]
        lines = [
            f"def ceiling({', '.join(ins + outs)}, status, flags):",
            "    for i in prange(status.shape[0]):",
            f"        s = {' + '.join(f'{a}[i]' for a in ins)}",
        ]
        lines += [f"        {o}[i] = s + {k}.0" for k, o in enumerate(outs)]
        lines += ["        status[i] = 0", "        flags[i] = 0"]
        namespace = {"prange": numba.prange}
        exec(compile("\n".join(lines), f"<ceiling {n_in}x{n_out}>", "exec"), namespace)
        _CEILINGS[key] = numba.njit(parallel=True, error_model="numpy")(namespace["ceiling"])
    return _CEILINGS[key]


def ceiling_call(columns: dict, n_out: int) -> Callable[[], None]:
    """The ceiling of a call on ``columns`` returning ``n_out`` float64 outputs: a
    zero-argument callable that allocates the outputs and runs the trivial kernel."""
    arrays = [v for v in columns.values() if isinstance(v, np.ndarray)]
    n = arrays[0].shape[0]
    kernel = _ceiling_kernel(len(arrays), n_out)

    def run():
        outs = [np.empty(n) for _ in range(n_out)]
        kernel(*arrays, *outs, np.empty(n, dtype=np.int32), np.empty(n, dtype=np.int32))

    return run


# ------------------------------------------------------------------ a shared machine


def _own_cpu() -> float:
    """CPU seconds of this process (every thread) and of its waited-for children."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


class Load:
    """Share of the machine's CPUs that other processes used while the block ran: the
    machine's busy CPU time (/proc/stat) minus this process's and its children's, over
    wall time x CPUs. Both clocks tick at 100 Hz: blocks should last 0.2 s or more."""

    def __enter__(self):
        self.t0, self.busy0, self.own0 = time.perf_counter(), _cpu_busy_seconds(), _own_cpu()
        return self

    def __exit__(self, *exc):
        wall = time.perf_counter() - self.t0
        other = _cpu_busy_seconds() - self.busy0 - (_own_cpu() - self.own0)
        self.share = max(0.0, other / (wall * (os.cpu_count() or 1))) if wall > 0 else math.nan
        return False


@dataclass
class Quiet:
    """Runs timed blocks while other processes leave the CPUs alone. The machine is
    shared: on 2 CPUs one busy neighbour halves a parallel kernel and rounds its time up
    to scheduler slices (~8 ms per call). Before a block, wait (0.25 s windows) until the
    others use at most ``max_other`` of the CPUs; a block during which they used more is
    run again, up to ``tries`` times. Once ``budget_s`` seconds have been spent waiting,
    blocks run as they come. The others' share during each kept block is recorded by
    section."""

    max_other: float = 0.10
    budget_s: float = 180.0
    tries: int = 3
    waited_s: float = 0.0
    rerun: int = 0
    shares: dict = field(default_factory=dict)

    def run(self, section: str, block: Callable):
        """``block()``'s result from its first quiet run (or its last try)."""
        for attempt in range(self.tries):
            self._wait()
            with Load() as load:
                result = block()
            if load.share <= self.max_other or self.waited_s >= self.budget_s:
                break
            self.rerun += attempt + 1 < self.tries
        self.shares.setdefault(section, []).append(load.share)
        return result

    def _wait(self) -> None:
        while self.waited_s < self.budget_s:
            t0 = time.perf_counter()
            with Load() as load:
                time.sleep(0.25)
            if load.share <= self.max_other:
                return
            self.waited_s += time.perf_counter() - t0

    def summary(self) -> str:
        """One sentence: the others' share by section, re-runs, time waited."""
        parts = [f"section {k} {np.mean(v):.0%} (max {np.max(v):.0%})" for k, v in self.shares.items()]
        noisy = any(np.mean(v) > self.max_other for v in self.shares.values())
        return (
            "Other processes' share of the CPUs during the timed blocks, mean: "
            + ", ".join(parts)
            + f". Blocks re-run because others used more than "
            f"{self.max_other:.0%}: {self.rerun}; waited {self.waited_s:.0f} s for a quiet "
            f"machine (budget {self.budget_s:.0f} s)"
            + (": **the machine was busy, the times are noisy**." if noisy else ".")
        )


# ------------------------------------------------------------------ 1. throughput


@dataclass
class Case:
    """One solve_batch call to measure: columns and keyword arguments, the kernel the
    runtime picks for it (family, critical, e_m = 1, tier), the ceiling target."""

    key: str
    label: str
    columns: dict
    kwargs: dict
    kernel: tuple
    target: float | None
    arrays: int = 0
    returned: int = 0
    times: dict = field(default_factory=dict)
    faults: dict = field(default_factory=dict)

    def real(self) -> Callable[[], dict]:
        return lambda: impactsym.solve_batch(self.columns, **self.kwargs)

    def inputs(self) -> list:
        """The kernel's inputs in its order (critical: mu is a placeholder 0)."""
        ks = _kernels.kernel_for(*self.kernel)
        unread = ("mu",) if self.kernel[1] else ()
        return [0.0 if k in unread else self.columns[k] for k in ks.inputs]

    def kernel_only(self) -> Callable[[], tuple]:
        """The kernel through the runtime: run_batch (allocation + driver), no solve_batch layer."""
        ks, inputs = _kernels.kernel_for(*self.kernel), self.inputs()
        n = self.columns["m1"].shape[0]
        return lambda: _kernels.run_batch(ks, inputs, n)

    def driver(self):
        """The driver run_batch calls for these columns (the kernel's one driver)."""
        return _kernels.kernel_for(*self.kernel).driver

    def median_ns(self, what: str) -> float:
        return float(np.median(self.times[what]))

    def ceiling_ratio(self) -> float:
        """Median over repeats of ceiling time / real time."""
        return float(np.median(np.array(self.times["ceiling"]) / np.array(self.times["real"])))

    def spread(self) -> float:
        """Slowest over fastest real call: how much the rounds disagree."""
        return max(self.times["real"]) / min(self.times["real"])


def per_round(x: Case, y: Case, what: str, combine: Callable[[float, float], float]) -> float:
    """Median over rounds of ``combine(x's time, y's time)`` for the same call in the same
    round: robust to rounds where the whole machine ran slower."""
    return float(np.median([combine(p, q) for p, q in zip(x.times[what], y.times[what])]))


def speedup(a: Case, e: Case) -> float:
    """Velocities tier speed-up: real time of (a) over (e), per round."""
    return per_round(a, e, "real", lambda p, q: p / q)


def build_cases(n: int, log) -> list[Case]:
    """The cases of section 1 on ``n`` fresh scenes each (a)-(e) and critical."""
    log("  scenes: general ...")
    general = approaching_scenes(n, SEED)
    log("  scenes: constant normal, e_m = 1, particle ...")
    constant = approaching_scenes(n, SEED + 1, gamma=0.35)
    em1 = approaching_scenes(n, SEED + 2, e_m=1.0)
    particle = approaching_scenes(n, SEED + 3, model="particle")
    critical = {k: v for k, v in general.items() if k != "mu"} | {"mu": "critical"}
    rigid, velocities = ("rigid", False, False, "energy"), ("rigid", False, False, "velocities")
    cases = [
        Case("a", "(a) rigid, per-row angle, all outputs", general, {}, rigid, 0.50),
        Case("b", "(b) rigid, constant normal (gamma scalar), all outputs", constant, {}, rigid, 0.70),
        Case(
            "c",
            "(c) rigid, e_m = 1 on every row, all outputs",
            em1,
            {},
            ("rigid", False, True, "energy"),
            0.60,
        ),
        Case(
            "d",
            "(d) particle, all outputs",
            particle,
            {"model": "particle"},
            ("particle", False, False, "energy"),
            0.60,
        ),
        Case(
            "e",
            "(e) rigid, per-row angle, velocities tier",
            general,
            {"outputs": "velocities"},
            velocities,
            None,
        ),
        Case(
            "crit", "rigid, mu = critical, all outputs", critical, {}, ("rigid", True, False, "energy"), None
        ),
    ]
    for case in cases:
        case.arrays = sum(isinstance(v, np.ndarray) for v in case.columns.values())
        case.returned = len(_kernels.requested_outputs(case.kwargs.get("outputs"))[0])
    return cases


def _minor_faults() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def _time_round(cases: list[Case], runs: dict, r: int) -> dict:
    """One round: every case's ceiling, kernel-only and real call back to back, in an
    order rotated by ``r``, each ``CALLS_PER_ROUND`` times in a row; (median ns/scene,
    median minor page faults) by case and call. One call of 2e5 rows lasts a few
    milliseconds, so one sample per round measured thread wake-ups and the cache state
    the previous call left as much as the call itself."""
    order = ["ceiling", "kernel", "real"]
    samples = {}
    for case in cases:
        n = case.columns["m1"].shape[0]
        for what in order[r % 3 :] + order[: r % 3]:
            ns, faults = [], []
            for _ in range(CALLS_PER_ROUND):
                before = _minor_faults()
                t0 = time.perf_counter_ns()
                runs[case.key][what]()
                ns.append((time.perf_counter_ns() - t0) / n)
                faults.append(_minor_faults() - before)
            samples[case.key, what] = float(np.median(ns)), float(np.median(faults))
    return samples


def time_cases(cases: list[Case], repeat: int, quiet: Quiet, log) -> dict:
    """Time ceiling, kernel-only and real call of every case over ``repeat`` rounds
    (each a quiet-gated block), counting each call's minor page faults (fresh outputs
    may or may not land on fresh pages: that depends on whether glibc returned the last
    call's memory to the system). Returns the share of status-0 rows by case."""
    runs = {}
    ok = {}
    for case in cases:
        runs[case.key] = {
            "ceiling": ceiling_call(case.columns, case.returned),
            "kernel": case.kernel_only(),
            "real": case.real(),
        }
        for run in runs[case.key].values():
            run()  # warm-up: JIT compile of the ceiling, numba cache load, page faults
        ok[case.key] = float(np.mean(runs[case.key]["real"]()["status"] == 0))
        case.times = {what: [] for what in runs[case.key]}
        case.faults = {what: [] for what in runs[case.key]}
    for r in range(repeat):
        samples = quiet.run("1", lambda r=r: _time_round(cases, runs, r))
        by_key = {c.key: c for c in cases}
        for (key, what), (ns, faults) in samples.items():
            by_key[key].times[what].append(ns)
            by_key[key].faults[what].append(faults)
        log(
            f"  round {r + 1}/{repeat} (others {quiet.shares['1'][-1]:.0%}): "
            + ", ".join(f"{c.key} {c.times['real'][-1]:.1f}/{c.times['ceiling'][-1]:.1f}" for c in cases)
            + " ns/scene (real/ceiling)"
        )
    return ok


_ARITHMETIC = r"\bv(?:add|sub|mul|div|sqrt|f[n]?m(?:add|sub)\w*)"


def _arithmetic(dispatcher) -> dict:
    """Packed and scalar float64 arithmetic instructions in a dispatcher's compiled code."""
    asm = "\n".join(dispatcher.inspect_asm().values())
    return {
        "packed": len(re.findall(_ARITHMETIC + r"pd\b", asm)),
        "scalar": len(re.findall(_ARITHMETIC + r"sd\b", asm)),
    }


def print_simd_counts(rows: int = 256) -> None:
    """Print (JSON) the float64 arithmetic of each case's parallel driver and of the
    ceiling kernel of case (a). Meant for a child process with an empty NUMBA_CACHE_DIR:
    numba shows no assembly for code loaded from its cache."""
    counts = {}
    for case in build_cases(rows, lambda msg: None):
        case.real()()
        counts[case.key] = _arithmetic(case.driver())
        if case.key == "a":
            ceiling_call(case.columns, case.returned)()
            counts["ceiling"] = _arithmetic(_ceiling_kernel(case.arrays, case.returned))
    print(json.dumps(counts))


def simd_counts() -> dict:
    """print_simd_counts run in a child process that compiles every driver afresh."""
    with tempfile.TemporaryDirectory(prefix="impactsym_numba_") as cache:
        child = subprocess.run(
            [
                sys.executable,
                "-c",
                "from benchmarks.performance import print_simd_counts; print_simd_counts()",
            ],
            cwd=ROOT,
            env={**os.environ, "NUMBA_CACHE_DIR": cache},
            check=True,
            capture_output=True,
            text=True,
        )
    return json.loads(child.stdout.splitlines()[-1])


# ------------------------------------------------------------------ 2. baselines


def _row_system(c: dict, i: int) -> tuple:
    """The 15 outputs of row ``i`` the way a user would write it: the 9x9 system of
    conventions.md in (V1x V1y W1 V2x V2y W2 Px Py M) assembled from Python floats and
    solved by numpy.linalg.solve; a second solve with the sticking equation for mu_c."""
    m1, m2, I1, I2, v1x, v1y, w1, v2x, v2y, w2, r1x, r1y, r2x, r2y, gamma, e, mu, em = (
        float(c[k][i]) for k in RIGID_INPUTS
    )
    k1, k2, j1, j2 = 1.0 / m1, 1.0 / m2, 1.0 / I1, 1.0 / I2
    nx, ny = math.cos(gamma), math.sin(gamma)
    tx, ty = -ny, nx
    u1x, u1y, u2x, u2y = v1x - w1 * r1y, v1y + w1 * r1x, v2x - w2 * r2y, v2y + w2 * r2x
    gn, gt = nx * (u2x - u1x) + ny * (u2y - u1y), tx * (u2x - u1x) + ty * (u2y - u1y)
    A = np.eye(9)
    A[6, 6] = A[7, 7] = A[8, 8] = 0.0
    A[0, 6] = A[1, 7] = -k1
    A[2, 6:9] = j1 * r1y, -j1 * r1x, -j1
    A[3, 6] = A[4, 7] = k2
    A[5, 6:9] = -j2 * r2y, j2 * r2x, j2
    A[6, 0:6] = -nx, -ny, -(r1x * ny - r1y * nx), nx, ny, r2x * ny - r2y * nx
    A[8, 2], A[8, 5], A[8, 8] = -(1.0 - em), 1.0 - em, -em * (j1 + j2)
    b = np.array([v1x, v1y, w1, v2x, v2y, w2, -e * gn, 0.0, 0.0])
    A[7, 6:8] = tx - mu * nx, ty - mu * ny
    V1x, V1y, W1, V2x, V2y, W2, Px, Py, M = np.linalg.solve(A, b).tolist()
    A[7, 6:8] = 0.0
    A[7, 0:6] = -tx, -ty, -(r1x * ty - r1y * tx), tx, ty, r2x * ty - r2y * tx
    xc = np.linalg.solve(A, b)
    Pn, Pt = nx * Px + ny * Py, tx * Px + ty * Py
    mu_c = float((tx * xc[6] + ty * xc[7]) / (nx * xc[6] + ny * xc[7]))
    U1x, U1y, U2x, U2y = V1x - W1 * r1y, V1y + W1 * r1x, V2x - W2 * r2y, V2y + W2 * r2x
    TLn = Pn * (gn + nx * (U2x - U1x) + ny * (U2y - U1y)) / 2
    TLt = Pt * (gt + tx * (U2x - U1x) + ty * (U2y - U1y)) / 2
    TLm = M * ((w2 - w1) + (W2 - W1)) / 2
    return V1x, V1y, W1, V2x, V2y, W2, Pn, Pt, M, mu, mu_c, TLn + TLt + TLm, TLn, TLt, TLm


def time_python_loop(columns: dict, rows: int, repeat: int, quiet: Quiet) -> tuple[float, float]:
    """(median over ``repeat`` passes, one quiet-gated block, of ns per row of the per-row
    loop over the first ``rows`` rows; its largest deviation from solve_batch on those
    rows relative to the row's largest speed)."""

    def passes():
        samples = []
        for _ in range(repeat):
            t0 = time.perf_counter_ns()
            got = [_row_system(columns, i) for i in range(rows)]
            samples.append((time.perf_counter_ns() - t0) / rows)
        return samples, got

    samples, got = quiet.run("2", passes)
    ref = impactsym.solve_batch({k: v[:rows] for k, v in columns.items()}, outputs="velocities")
    speeds = np.array([[g[0], g[1], g[3], g[4]] for g in got])
    want = np.column_stack([ref[k] for k in ("V1x", "V1y", "V2x", "V2y")])
    scale = np.max(np.abs(want), axis=1)
    return float(np.median(samples)), float(np.max(np.abs(speeds - want).max(axis=1) / scale))


def time_stacked(columns: dict, rows: int, repeat: int, quiet: Quiet) -> float:
    """Median ns per row of the batched numpy.linalg.solve baseline on the first ``rows``
    rows (``accuracy._linear_bind``: stacks of up to 65536 9x9 systems, outputs
    preallocated), each call a quiet-gated block."""
    run = _linear_bind({k: v[:rows] for k, v in columns.items()})
    run()

    def once():
        t0 = time.perf_counter_ns()
        run()
        return (time.perf_counter_ns() - t0) / rows

    return float(np.median([quiet.run("2", once) for _ in range(repeat)]))


# ------------------------------------------------------------------ 3. start-up

_FIRST_CALL = """\
import json, sys, time
t0 = time.perf_counter()
import impactsym
t1 = time.perf_counter()
numba_on_import = "numba" in sys.modules
import numpy as np
with np.load(sys.argv[1]) as data:
    columns = {k: data[k] for k in data.files}
t2 = time.perf_counter()
impactsym.solve_batch(columns)
t3 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "call_s": t3 - t2, "numba_on_import": numba_on_import}))
"""

# A call measured in a fresh process: its first run (loading or compiling the drivers it
# needs, or running in Python before they load) and three later runs (the least of them:
# steady state); the difference is what the user waits for.
_WAIT = """\
import json, sys, time
from benchmarks.performance import wait_call
call = wait_call(sys.argv[1], sys.argv[2])
times = []
for _ in range(4):
    t0 = time.perf_counter()
    call()
    times.append(time.perf_counter() - t0)
# steady: the least of the later calls
print(json.dumps({"first_s": times[0], "steady_s": min(times[1:])}))
"""

# Calls never made before on this machine's cache, after the package's first use (one
# solve_batch on case (a): every column an array, an angle per row). Three scalar/array
# mixes of solve_batch, then one call of each other batch API.
WAIT_CALLS = {
    "mix: masses and inertias scalar": "solve_batch, m1 m2 I1 I2 scalars, the rest arrays",
    "mix: e, mu, e_m scalar": "solve_batch, e mu e_m scalars, the rest arrays",
    "mix: one normal, arms scalar": "solve_batch, gamma r1x r1y r2x r2y scalars, the rest arrays",
    "sweep": f"impactsym.sweep('{SCENE_FILE}', e=30 values, mu=30 values)",
    "sample": f"impactsym.sample('{SCENE_FILE}', e uniform, mu uniform, n=5000)",
    "sweep, 90,000 points": f"impactsym.sweep('{SCENE_FILE}', e=300 values, mu=300 values)",
    "sample, 100,000 draws": f"impactsym.sample('{SCENE_FILE}', e uniform, mu uniform, n=100000)",
    "invert_batch": "impactsym.invert_batch on 10,000 solved rows",
    "reconstruct_batch": "impactsym.reconstruct_batch on 10,000 solved rows",
}


def wait_call(kind: str, path: str) -> Callable[[], object]:
    """The zero-argument call of WAIT_CALLS ``kind`` on the case-(a) columns in ``path``
    (an .npz); inputs are built outside the call."""
    with np.load(path) as data:
        c = {k: data[k] for k in data.files}
    scalars = {
        "mix: masses and inertias scalar": ("m1", "m2", "I1", "I2"),
        "mix: e, mu, e_m scalar": ("e", "mu", "e_m"),
        "mix: one normal, arms scalar": ("gamma", "r1x", "r1y", "r2x", "r2y"),
    }
    if kind in scalars:
        mixed = {k: float(v[0]) if k in scalars[kind] else v for k, v in c.items()}
        return lambda: impactsym.solve_batch(mixed)
    if kind.startswith("sweep"):
        k = 300 if "," in kind else 30
        grid = {"e": np.linspace(0.0, 0.4, k), "mu": np.linspace(0.0, 0.6, k)}
        return lambda: impactsym.sweep(SCENE_FILE, **grid)
    if kind.startswith("sample"):
        dists = {"e": ("uniform", 0.0, 0.4), "mu": ("uniform", 0.0, 0.3)}
        return lambda: impactsym.sample(SCENE_FILE, dists, 100_000 if "," in kind else 5000, seed=1)
    rows = {k: v[:10_000] for k, v in c.items()}
    out = impactsym.solve_batch(rows)
    finals = {k: out[k] for k in ("V1x", "V1y", "W1", "V2x", "V2y", "W2")}
    if kind == "invert_batch":
        columns = {
            **{
                k: rows[k]
                for k in ("m1", "m2", "I1", "I2", "r1x", "r1y", "r2x", "r2y", "gamma", "e", "mu", "e_m")
            },
            **finals,
        }
        return lambda: impactsym.invert_batch(columns)
    if kind == "reconstruct_batch":
        columns = {
            **{k: rows[k] for k in ("m1", "m2", "I1", "I2", "w1", "w2", "r1x", "r1y", "r2x", "r2y", "gamma")},
            **finals,
            "theta1": np.arctan2(rows["v1y"], rows["v1x"]),
            "theta2": np.arctan2(rows["v2y"], rows["v2x"]),
        }
        return lambda: impactsym.reconstruct_batch(columns)
    raise ValueError(f"unknown wait call {kind!r}")


def time_compile_waits(columns: dict, quiet: Quiet, runs: int = STARTUP_RUNS) -> dict:
    """Per WAIT_CALLS kind, in fresh processes: the wait of the very first run (the call
    never made before; compiles if a driver it needs is not cached) and the least wait
    over ``runs`` runs. Before them, one solve_batch on ``columns`` in its own process:
    the package's first use. Also the first use with an empty numba cache (a temporary
    NUMBA_CACHE_DIR), least of ``runs``."""
    out = {"calls": {}, "runs": runs}
    with tempfile.TemporaryDirectory(prefix="impactsym_perf_") as tmp:
        path = Path(tmp) / "columns.npz"
        np.savez(path, **columns)

        def child(script, *argv, env=None):
            done = subprocess.run(
                [sys.executable, "-c", script, *argv],
                cwd=ROOT,
                check=True,
                capture_output=True,
                text=True,
                env=env,
            )
            return json.loads(done.stdout.splitlines()[-1])

        # The package's first use (warm cache for case (a)), then `impactsym compile` of
        # every other driver, timed; the waits below are measured after it.
        quiet_env = dict(os.environ)
        child(_FIRST_CALL, str(path), env=quiet_env)
        t0 = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "impactsym", "compile", "--quiet"], cwd=ROOT, check=True, env=quiet_env
        )
        out["warmup_s"] = time.perf_counter() - t0
        for kind in WAIT_CALLS:
            samples = [
                quiet.run("3", lambda k=kind: child(_WAIT, k, str(path), env=quiet_env)) for _ in range(runs)
            ]
            waits = [s["first_s"] - s["steady_s"] for s in samples]
            out["calls"][kind] = {
                "first_wait_s": waits[0],
                "min_wait_s": min(waits),
                "steady_s": min(s["steady_s"] for s in samples),
            }
        cold = []
        for _ in range(runs):
            with tempfile.TemporaryDirectory(prefix="impactsym_numba_") as cache:
                env = {**quiet_env, "NUMBA_CACHE_DIR": cache}
                cold.append(quiet.run("3", lambda e=env: child(_FIRST_CALL, str(path), env=e)))
        out["cold_first_call_s"] = min(s["call_s"] for s in cold)
    return out


def _stale_bytecode(path: Path) -> bool:
    """Whether ``path`` has no .pyc that Python would accept (magic, source mtime, size)."""
    import importlib.util

    pyc = Path(importlib.util.cache_from_source(str(path)))
    try:
        head = pyc.read_bytes()[:16]
    except OSError:
        return True
    stat = path.stat()
    return (
        head[:4] != importlib.util.MAGIC_NUMBER
        or int.from_bytes(head[8:12], "little") != int(stat.st_mtime) & 0xFFFFFFFF
        or int.from_bytes(head[12:16], "little") != stat.st_size & 0xFFFFFFFF
    )


def write_bytecode() -> tuple[str, float]:
    """Write the .pyc of impactsym/ and generated/ that are missing or stale, as pip does
    when it installs the wheel (and as the first import does on a machine that writes
    bytecode; this one may not: PYTHONDONTWRITEBYTECODE). Returns ``bytecode_note()``
    from before, so the report says what a process without them would have paid."""
    note = bytecode_note()
    for folder in ("impactsym", "generated"):
        compileall.compile_dir(str(ROOT / folder), quiet=1)
    return note


def bytecode_note() -> tuple[str, float]:
    """(a sentence on whether generated/'s bytecode is cached, the seconds a fresh process
    spends compiling the source of the modules that have none)."""
    stale = [p for p in sorted((ROOT / "generated").glob("*.py")) if _stale_bytecode(p)]
    if not stale:
        return "generated/'s bytecode was cached (.pyc up to date) before the section.", 0.0
    t0 = time.perf_counter()
    for path in stale:
        compile(path.read_text(), str(path), "exec")
    seconds = time.perf_counter() - t0
    why = " (PYTHONDONTWRITEBYTECODE is set here)" if sys.dont_write_bytecode else ""
    return (
        f"{len(stale)} of generated/'s modules had no up-to-date .pyc{why}: a fresh "
        f"process would compile their source, {seconds:.2f} s of each start-up; the "
        "section wrote them first (`compileall`), as pip does when it installs the wheel, "
        "so the times above do not include that.",
        seconds,
    )


def _impactsym_script() -> str:
    """The venv's ``impactsym`` console script (next to this Python)."""
    found = Path(sys.executable).parent / "impactsym"
    return str(found) if found.exists() else shutil.which("impactsym") or "impactsym"


def time_cli_solve(quiet: Quiet, runs: int = STARTUP_RUNS) -> float:
    """Least wall time of ``impactsym solve SCENE_FILE`` over ``runs`` fresh processes,
    each run a quiet-gated block (one untimed run first)."""
    cmd = [_impactsym_script(), "solve", SCENE_FILE]

    def once():
        t0 = time.perf_counter()
        subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        return time.perf_counter() - t0

    once()
    return min(quiet.run("3", once) for _ in range(runs))


def time_first_call(columns: dict, quiet: Quiet, runs: int = STARTUP_RUNS) -> dict:
    """Least times of ``import impactsym`` and of the first solve_batch call on ``columns``
    (and whether the import alone brought numba in), each run in a fresh process (columns loaded from an .npz, untimed) as a quiet-gated
    block; one untimed run first warms numba's cache."""
    with tempfile.TemporaryDirectory(prefix="impactsym_perf_") as tmp:
        path = Path(tmp) / "columns.npz"
        np.savez(path, **columns)
        cmd = [sys.executable, "-c", _FIRST_CALL, str(path)]

        def once():
            return json.loads(
                subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, text=True).stdout
            )

        once()
        samples = [quiet.run("3", once) for _ in range(runs)]
    out = {key: min(s[key] for s in samples) for key in ("import_s", "call_s")}
    out["numba_on_import"] = any(s["numba_on_import"] for s in samples)
    return out


# ------------------------------------------------------------------ 4. serial threshold


def _median_call_ns(calls: dict, repeat: int) -> dict:
    """Median ns of each zero-argument callable, called ``repeat`` times interleaved."""
    samples = {k: [] for k in calls}
    for _ in range(repeat):
        for key, call in calls.items():
            t0 = time.perf_counter_ns()
            call()
            samples[key].append(time.perf_counter_ns() - t0)
    return {k: float(np.median(v)) for k, v in samples.items()}


def _threshold_calls(columns: dict, n: int) -> dict:
    """The one rigid driver (a prange loop) on ``n`` rows, on one thread ("serial":
    numba.set_num_threads(1) around the call, the cost a serial twin would have) and on
    all ("parallel"): called directly with preallocated outputs, and through run_batch."""
    import numba

    from impactsym._kernels import runner

    ks = _kernels.kernel_for("rigid", False)
    inputs = [np.ascontiguousarray(columns[k][:n]) for k in ks.inputs]
    driven = runner._driver_columns(ks, inputs)
    outs = [*runner.allocate(ks, n).values(), np.empty(n, dtype=np.int32), np.empty(n, dtype=np.int32)]
    threads = numba.get_num_threads()

    def one_thread(call):
        def run():
            numba.set_num_threads(1)
            try:
                call()
            finally:
                numba.set_num_threads(threads)

        return run

    return {
        "serial": one_thread(lambda: ks.driver(*driven, *outs)),
        "parallel": lambda: ks.driver(*driven, *outs),
        "run_batch serial": one_thread(lambda: _kernels.run_batch(ks, inputs, n)),
        "run_batch parallel": lambda: _kernels.run_batch(ks, inputs, n),
    }


def time_threshold(columns: dict, repeat: int) -> dict:
    """Median ns per call of each way, by n in THRESHOLD_SIZES. Short: run it as one
    quiet-gated block."""
    table = {}
    for n in THRESHOLD_SIZES:
        calls = _threshold_calls(columns, n)
        for call in calls.values():
            call()
        table[n] = _median_call_ns(calls, repeat)
    return table


def crossover(table: dict, serial: str, parallel: str) -> int | None:
    """The smallest n from which the parallel way is faster at every larger n measured."""
    found = None
    for n in sorted(table, reverse=True):
        if table[n][parallel] >= table[n][serial]:
            break
        found = n
    return found


# ------------------------------------------------------------------ 5. sweep


def run_sweep(points: int) -> dict:
    """``impactsym sweep SCENE_FILE --vary e=0:0.4:K --vary mu=0:0.6:K -o TMP.parquet
    --no-progress`` with K = round(sqrt(points)), in a child process: wall time, rows/s,
    peak RSS (``os.wait4``'s ru_maxrss of that child alone), file size; the file is
    deleted afterwards."""
    k = max(1, round(math.sqrt(points)))
    with tempfile.TemporaryDirectory(prefix="impactsym_sweep_", dir="/tmp") as tmp:
        out = Path(tmp) / "sweep.parquet"
        cmd = [
            _impactsym_script(),
            "sweep",
            SCENE_FILE,
            "--vary",
            f"e=0:0.4:{k}",
            "--vary",
            f"mu=0:0.6:{k}",
            "-o",
            str(out),
            "--no-progress",
        ]
        with open(Path(tmp) / "stderr.txt", "w+") as err:
            t0 = time.perf_counter()
            child = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=err)
            _, status, usage = os.wait4(child.pid, 0)
            wall = time.perf_counter() - t0
            err.seek(0)
            stderr = err.read().strip()
        code = os.waitstatus_to_exitcode(status)
        size = out.stat().st_size if out.exists() else 0
    shown = ["impactsym"] + cmd[1:]
    shown[shown.index("-o") + 1] = "TMPDIR/sweep.parquet"
    return {
        "command": " ".join(shown),
        "rows": k * k,
        "wall_s": wall,
        "rows_per_s": k * k / wall,
        "exit_code": code,
        "peak_rss_gb": usage.ru_maxrss / 2**20,
        "file_gb": size / 1e9,
        "stderr": stderr[-2000:],
    }


# ------------------------------------------------------------------ targets and report


@dataclass
class Target:
    """A goal: ``value`` must be >= ``goal`` (``at_least``) or <= it."""

    what: str
    value: float
    goal: float
    at_least: bool
    unit: str
    reason: str = ""

    @property
    def met(self) -> bool:
        return self.value >= self.goal if self.at_least else self.value <= self.goal

    def line(self) -> str:
        sign = "≥" if self.at_least else "≤"
        head = f"{self.what}: {self._fmt(self.value)} (target {sign} {self._fmt(self.goal)})"
        if self.met:
            return f"- **met** — {head}"
        short = self._fmt(abs(self.value - self.goal)).replace("%", "points")
        factor = self.goal / self.value if self.at_least else self.value / self.goal
        return f"- **missed** — {head}: by {short} ({factor:.2f}× off)" + (
            f"; likely: {self.reason}" if self.reason else ""
        )

    def _fmt(self, x: float) -> str:
        if self.unit == "%":
            return f"{100 * x:.0f} %"
        if self.unit == "×":
            return f"{x:,.1f}×"
        return f"{x:.2f} {self.unit}"


def _angle_note(cases: dict) -> str:
    """What a per-row angle costs: rigid kernel (a) against (b), the same kernel with one
    normal for the batch (median over rounds of the per-round difference)."""
    cost = per_round(cases["a"], cases["b"], "kernel", lambda p, q: p - q)
    return (
        f"a per-row angle costs reading it and the vectorised sincos (derive/trig.py) on "
        f"every row: {cost:.1f} ns/scene in the rigid kernel (per-round median; medians "
        f"(a) {cases['a'].median_ns('kernel'):.1f} against (b), one normal, "
        f"{cases['b'].median_ns('kernel'):.1f})"
    )


def _ceiling_reason(case: Case, simd: dict, angle: str) -> str:
    """Why a case misses its ceiling target: the kernel itself (whether its loop is SIMD
    code, a per-row angle), the solve_batch layer around it, or neither (noise)."""
    real, kernel, ceiling = (case.median_ns(w) for w in ("real", "kernel", "ceiling"))
    reasons = []
    if ceiling / kernel < case.target:
        ops = simd.get(case.key)
        reasons.append(
            f"the kernel alone (run_batch) reaches only {ceiling / kernel:.0%} of the "
            "ceiling"
            + (
                f"; its loop is scalar code ({ops['packed']} packed / "
                f"{ops['scalar']} scalar float64 arithmetic instructions): "
                "compute-bound, not memory-bound"
                if ops and ops["packed"] == 0
                else ""
            )
        )
        if isinstance(case.columns["gamma"], np.ndarray):
            reasons.append(angle)
    if (real - kernel) / real >= 0.1:
        reasons.append(
            f"solve_batch around the kernel adds {real - kernel:.1f} ns/scene "
            f"({(real - kernel) / real:.0%}: validation, e_m check, filler arrays "
            "for outputs the kernel does not compute)"
        )
    return "; ".join(reasons) or (
        f"noise (kernel alone at {ceiling / kernel:.0%} of the "
        f"ceiling, solve_batch layer {(real - kernel) / real:.0%})"
    )


def targets(cases: dict, simd: dict, base: dict, start: dict, sweep: dict | None) -> list[Target]:
    """Every target of the brief with its measured value."""
    angle = _angle_note(cases)
    out = [
        Target(
            f"{c.label}: ceiling / real",
            c.ceiling_ratio(),
            c.target,
            True,
            "%",
            _ceiling_reason(c, simd, angle),
        )
        for c in cases.values()
        if c.target is not None
    ]
    a, e = cases["a"], cases["e"]
    out.append(
        Target(
            "(e) velocities tier speed-up over all outputs",
            speedup(a, e),
            1.5,
            True,
            "×",
            f"the tier saves memory traffic (the all-outputs ceiling is "
            f"{a.median_ns('ceiling') / e.median_ns('ceiling'):.2f}× the velocities "
            "one) but the velocities need the whole impulse solution: kernel alone "
            f"{a.median_ns('kernel'):.1f} → {e.median_ns('kernel'):.1f} ns/scene, "
            f"{e.ceiling_ratio():.0%} of its own ceiling; {angle}",
        )
    )
    out.append(
        Target(
            "Python loop of numpy.linalg.solve, per row vs impactsym (a)",
            base["loop_ns"] / a.median_ns("real"),
            1000,
            True,
            "×",
            f"the loop costs {base['loop_ns'] / 1e3:.1f} µs per row (two 9x9 solves); "
            f"1000× would need impactsym at {base['loop_ns'] / 1000:.1f} ns/scene, "
            f"it runs at {a.median_ns('real'):.1f}; {angle}",
        )
    )
    out.append(
        Target(
            "batched numpy.linalg.solve, per row vs impactsym (a)",
            base["stack_ns"] / a.median_ns("real"),
            20,
            True,
            "×",
            f"impactsym runs at {a.median_ns('real'):.1f} ns/scene; {angle}",
        )
    )
    out.append(
        Target(
            "`import impactsym`",
            start["import_s"],
            0.5,
            False,
            "s",
            "numba imported by `import impactsym`"
            if start["numba_on_import"]
            else "numba is not imported; the time is numpy and impactsym's own modules",
        )
    )
    for kind, wait in start.get("waits", {}).get("calls", {}).items():
        out.append(
            Target(
                f"compile wait of a call never made before after first use, {kind}",
                wait["first_wait_s"],
                1.0,
                False,
                "s",
                "a driver it needs (another kernel, or the other form of the same "
                "kernel) was not compiled by the first use; it compiles once per "
                "machine",
            )
        )
    out.append(
        Target(
            "`impactsym solve` wall time",
            start["cli_s"],
            0.6,
            False,
            "s",
            f"`import impactsym` alone takes {start['import_s']:.2f} s",
        )
    )
    n = a.columns["m1"].shape[0]
    out.append(
        Target(
            f"first solve_batch call ({n:,} rows), fresh process",
            start["call_s"],
            1.0,
            False,
            "s",
            "the steady-state call takes "
            f"{a.median_ns('real') * n / 1e9:.2f} s; the rest is loading the cached "
            "kernels and first-touch page faults",
        )
    )
    if sweep and sweep["exit_code"] == 0:
        out.append(
            Target(
                f"sweep of {sweep['rows']:,} rows, peak RSS",
                sweep["peak_rss_gb"],
                1.5,
                False,
                "GB",
                "chunks or the writer's buffers held in memory",
            )
        )
    return out


def _git(*args: str) -> str:
    """Output of a read-only git command in the repository ("" if git fails)."""
    done = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True)
    return done.stdout.strip() if done.returncode == 0 else ""


def code_state() -> str:
    """The code measured: commit, derive source hash of generated/planar.py, and
    uncommitted changes under impactsym/ and generated/ (others edit them meanwhile)."""
    found = re.search(r"derive source sha256 ([0-9a-f]{64})", (ROOT / "generated" / "planar.py").read_text())
    dirty = _git("status", "--porcelain", "--", "impactsym", "generated").splitlines()
    return (
        f"Code: commit `{_git('rev-parse', '--short', 'HEAD') or '?'}`, generated/planar.py "
        f"from derive source `{found.group(1)[:12] if found else '?'}…`; "
        + (
            f"uncommitted: {', '.join(line[3:] for line in dirty)}."
            if dirty
            else "no uncommitted changes under impactsym/ or generated/."
        )
    )


def _machine() -> str:
    import numba

    cpu = "?"
    with contextlib.suppress(OSError, StopIteration):
        cpu = next(
            line.split(":", 1)[1].strip()
            for line in Path("/proc/cpuinfo").read_text().splitlines()
            if line.startswith("model name")
        )
    return (
        f"{platform.machine()} {cpu}, {os.cpu_count()} CPUs, numba {numba.__version__} "
        f"({numba.get_num_threads()} threads, threading layer "
        f"{numba.threading_layer()}, SVML {'on' if numba.config.USING_SVML else 'off'}), "
        f"NumPy {np.__version__}, "
        f"Python {platform.python_version()}"
    )


def markdown(
    args,
    code: str,
    cases: dict,
    ok: dict,
    quiet: Quiet,
    simd: dict,
    base: dict,
    start: dict,
    thresh: dict,
    sweep: dict | None,
    sweep_note: str,
    goals: list[Target],
    elapsed: float,
) -> str:
    """The results page."""
    n = args.n
    lines = [
        "# Throughput, start-up, serial threshold",
        "",
        f"`{command(args)}` — n = {n:,} scenes, {args.repeat} repeats, took {elapsed:.0f} s.",
        "",
        f"Machine: {_machine()}.",
        "",
        code,
        "",
        quiet.summary(),
        "",
        "## 1. Against a memory ceiling (same run, interleaved)",
        "",
        "Ceiling: a trivial `prange` kernel reading every array column the call is given and "
        "writing as many fresh float64 arrays as the call returns plus int32 status and flags. "
        "*kernel*: the generated driver through `_kernels.run_batch` (allocation + driver); "
        "*real*: `impactsym.solve_batch`. Each round calls each of them "
        f"{CALLS_PER_ROUND} times in a row, in an order rotated per round, and keeps the "
        "median; times are the medians over rounds in ns/scene; *ceiling / real* is "
        "the median of the per-round ratios. *faults*: median minor page faults per call, "
        "real / ceiling (fresh outputs on fresh pages cost far more than the memory traffic). "
        "*SIMD*: packed / scalar float64 arithmetic instructions in the compiled parallel "
        "driver (compiled afresh in a child process). *spread*: slowest over fastest real "
        "call across rounds.",
        "",
        "| case | arrays in / out | real ns | real Mscenes/s | kernel ns | ceiling ns "
        "| ceiling / real | target | status 0 | faults | SIMD | spread |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for c in cases.values():
        real = c.median_ns("real")
        target = f"≥ {c.target:.0%}" if c.target else "–"
        lines.append(
            f"| {c.label} | {c.arrays} / {c.returned}+2 | {real:.1f} | {1e3 / real:.1f} "
            f"| {c.median_ns('kernel'):.1f} | {c.median_ns('ceiling'):.1f} "
            f"| {c.ceiling_ratio():.0%} | {target} | {ok[c.key]:.4%} "
            f"| {np.median(c.faults['real']):.0f} / {np.median(c.faults['ceiling']):.0f} "
            f"| {_simd_cell(simd.get(c.key))} | {c.spread():.2f} |"
        )
    a, e = cases["a"], cases["e"]
    lines += [
        "",
        f"Velocities tier speed-up over all outputs (a / e, real, median of the "
        f"per-round ratios): **{speedup(a, e):.2f}×**; ceilings "
        f"{a.median_ns('ceiling') / e.median_ns('ceiling'):.2f}×. The ceiling kernel "
        f"itself compiles to {_simd_cell(simd.get('ceiling'))} packed / scalar "
        "instructions.",
        "",
        "## 2. Against baselines a user would write",
        "",
        "The 9x9 system of conventions.md and a second solve (sticking) for mu_c, "
        "energies as work: the outputs impactsym returns (without dV1, dV2).",
        "",
        "| method | rows timed | ns/scene | × impactsym (a) |",
        "|---|---:|---:|---:|",
        f"| impactsym.solve_batch, case (a) | {n:,} | {a.median_ns('real'):.1f} | 1 |",
        f"| Python loop, numpy.linalg.solve per row | {base['loop_rows']:,} "
        f"| {base['loop_ns']:,.0f} | {base['loop_ns'] / a.median_ns('real'):,.0f} |",
        f"| numpy.linalg.solve on (rows, 9, 9) stacks (chunks of 65536) "
        f"| {base['stack_rows']:,} | {base['stack_ns']:,.0f} "
        f"| {base['stack_ns'] / a.median_ns('real'):,.1f} |",
        "",
        f"The loop's velocities agree with solve_batch to {base['loop_agreement']:.1e} of "
        "the row's largest speed. NumPy's solve runs on one core, impactsym on "
        f"{os.cpu_count()}.",
        "",
        f"## 3. Start-up (fresh processes, least of {start['waits']['runs']})",
        "",
        "| what | seconds | target |",
        "|---|---:|---:|",
        f"| `impactsym solve {SCENE_FILE}` (wall) | {start['cli_s']:.2f} | ≤ 0.6 |",
        f"| `import impactsym` | {start['import_s']:.2f} | – |",
        f"| first `solve_batch` call, {n:,} rows, case (a), numba cache warm | {start['call_s']:.2f} | ≤ 1 |",
        f"| first `solve_batch` call, {n:,} rows, case (a), empty numba cache "
        f"(first use on a machine) | {start['waits']['cold_first_call_s']:.2f} | – |",
        "",
        f"`import impactsym` imports numba: {start['numba_on_import']}.",
        "",
        start["bytecode_note"],
        "",
        "### Compile waits after first use (fresh processes)",
        "",
        "The package's first use: one `solve_batch` on case (a) (every column an array, "
        "an angle per row) in its own process, then `impactsym compile` of every other "
        f"batch driver ({start['waits']['warmup_s']:.0f} s; it loads what is cached "
        "already). Then each call below, never made before, "
        f"in {start['waits']['runs']} fresh processes: wait = first run − the least of three "
        "later runs of the call in the process (loading the drivers it needs). *first*: the "
        "very first process; *min*: least over the processes.",
        "",
        "| call | what | first wait s | min wait s | steady s | target |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for kind, wait in start["waits"]["calls"].items():
        lines.append(
            f"| {kind} | {WAIT_CALLS[kind]} | {wait['first_wait_s']:.2f} "
            f"| {wait['min_wait_s']:.2f} | {wait['steady_s']:.3f} | ≤ 1 |"
        )
    lines += [
        "",
        "## 4. Small batches: one thread or all (rigid, all outputs; median µs per call)",
        "",
        "*serial*: the driver with numba.set_num_threads(1) around the call; *parallel*: "
        "on all threads, as the runtime runs every batch.",
        "",
        "| n | serial | parallel | run_batch serial | run_batch parallel |",
        "|---:|---:|---:|---:|---:|",
    ]
    for size, row in thresh["table"].items():
        lines.append(
            f"| {size} | "
            + " | ".join(
                f"{row[k] / 1e3:.2f}"
                for k in ("serial", "parallel", "run_batch serial", "run_batch parallel")
            )
            + " |"
        )
    lines += ["", thresh["verdict"], "", "## 5. Sweep", "", sweep_note, ""]
    if sweep:
        lines += [
            f"`{sweep['command']}`: exit code {sweep['exit_code']}, {sweep['rows']:,} "
            f"rows in {sweep['wall_s']:.1f} s = {sweep['rows_per_s'] / 1e6:.2f} M rows/s, "
            f"peak RSS {sweep['peak_rss_gb']:.2f} GB, Parquet {sweep['file_gb']:.2f} GB "
            "(deleted). "
            f"solve_batch alone runs case (a) at {1e3 / a.median_ns('real'):.1f} M rows/s: "
            "the sweep's time goes mostly to building and writing the table "
            f"({sweep['file_gb'] / sweep['wall_s'] * 1e3:.0f} MB/s of Parquet). The rest "
            "of the machine (other processes, kernel threads writing the file back) kept "
            f"{sweep['other_cpu_share']:.0%} of the CPUs busy meanwhile.",
            "",
        ]
        if sweep["exit_code"] != 0:
            lines += ["```", sweep["stderr"], "```", ""]
    lines += ["## Targets", ""] + [g.line() for g in goals]
    return "\n".join(lines) + "\n"


def _simd_cell(ops: dict | None) -> str:
    return "?" if not ops else f"{ops['packed']} / {ops['scalar']}"


def threshold_verdict(table: dict, tolerance: float = 0.05) -> str:
    """What the measurement says about run_batch's SERIAL_BELOW: the crossover, and the
    most the current value costs over the faster way at any measured n (it is supported
    when that is within ``tolerance``)."""
    direct = crossover(table, "serial", "parallel")
    runtime = crossover(table, "run_batch serial", "run_batch parallel")
    current = 0  # the runtime runs every batch on all threads
    cost, worst = max(
        (
            row["run_batch serial" if n < current else "run_batch parallel"]
            / min(row["run_batch serial"], row["run_batch parallel"])
            - 1,
            n,
        )
        for n, row in table.items()
    )
    first = table[min(table)]
    launch = first["parallel"] - first["serial"]
    overhead = first["run_batch serial"] - first["serial"]

    def says(found):
        return "none (serial is faster up to the largest n)" if found is None else f"n = {found}"

    text = (
        f"Crossover (smallest n from which parallel is faster at every larger n measured; "
        f"n doubles, so it is known to a factor 2): direct {says(direct)}, through run_batch "
        f"{says(runtime)}. All threads at every n (no serial twin) "
        + (
            f"costs at most {cost:.1%} over the faster way at any measured n (n = {worst}): "
            if cost > 0
            else "picks the faster way at every measured n: "
        )
    )
    suggested = runtime if runtime is not None else f"more than {max(table)}"
    if cost <= tolerance:
        text += f"the measurement supports it (within {tolerance:.0%}; the crossover suggests {suggested})."
    else:
        text += f"the measurement suggests {suggested}."
    return text + (
        f" At n = {min(table)} a launch on all threads costs {launch / 1e3:.1f} µs "
        f"more than on one (parallel − serial) and run_batch's own work {overhead / 1e3:.1f} µs "
        "(allocation, argument handling)."
    )


def command(args) -> str:
    parts = [
        f"--n {args.n}",
        f"--repeat {args.repeat}",
        f"--max-other {args.max_other}",
        f"--max-wait {args.max_wait:g}",
    ]
    if args.sweep is not None:
        parts.append("--sweep" if args.sweep else "--no-sweep")
    parts.append(f"--sweep-points {args.sweep_points}")
    if args.quick:
        parts.append("--quick")
    return "python -m benchmarks performance " + " ".join(parts)


# ------------------------------------------------------------------ entry point


def add_arguments(parser) -> None:
    parser.add_argument(
        "--n",
        type=lambda s: int(float(s)),
        default=1_000_000,
        help="scenes per call in section 1 (default 1e6)",
    )
    parser.add_argument("--repeat", type=int, default=7, help="timed rounds (median; default 7)")
    parser.add_argument(
        "--loop-rows", type=int, default=2000, help="rows of the Python-loop baseline (default 2000)"
    )
    parser.add_argument(
        "--stack-rows",
        type=lambda s: int(float(s)),
        default=200_000,
        help="rows of the batched numpy.linalg.solve baseline (default 2e5)",
    )
    parser.add_argument(
        "--threshold-repeat",
        type=int,
        default=301,
        help="calls per n and way in the serial-threshold section (default 301)",
    )
    parser.add_argument(
        "--sweep",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="run the impactsym sweep section (default: on)",
    )
    parser.add_argument(
        "--sweep-points",
        type=lambda s: int(float(s)),
        default=100_000_000,
        help="rows of the sweep (default 1e8)",
    )
    parser.add_argument(
        "--max-other",
        type=float,
        default=0.10,
        help="re-run a timed block when other processes used more than this share of the CPUs (default 0.10)",
    )
    parser.add_argument(
        "--max-wait",
        type=float,
        default=180.0,
        help="seconds to wait in all for a quiet machine (default 180)",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="a short run: n <= 2e5, 3 repeats, small baselines, 2 start-up "
        "runs, no sweep (a few minutes; for checking, not for the record)",
    )
    parser.add_argument(
        "--out", type=Path, default=RESULTS, help="folder for performance.md and performance.json"
    )


def _sweep_section(args, log) -> tuple[dict | None, str]:
    """Run the sweep section unless `--no-sweep`; (its numbers or None, a note)."""
    if not args.sweep:
        return None, "Not run (`--no-sweep`)."
    log(f"5. sweep of {args.sweep_points:,} rows ...")
    with Load() as load:
        sweep = run_sweep(args.sweep_points)
    sweep["other_cpu_share"] = load.share
    note = (
        f"The grid e = 0…0.4 × mu = 0…0.6 around `{SCENE_FILE}` through the CLI, "
        "Parquet to /tmp; peak RSS of the child process."
    )
    return sweep, note


def main(args) -> int:
    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    if args.quick:
        args.n, args.repeat, args.loop_rows = min(args.n, 200_000), min(args.repeat, 3), 200
        args.stack_rows, args.threshold_repeat, args.sweep = 20_000, 31, False
    t_start = time.perf_counter()
    code = code_state()
    quiet = Quiet(max_other=args.max_other, budget_s=args.max_wait)
    log(f"1. scenes and memory ceiling, n = {args.n:,} ...")
    cases = {c.key: c for c in build_cases(args.n, log)}
    ok = time_cases(list(cases.values()), args.repeat, quiet, log)
    log("   SIMD check (compiles every driver afresh in a child process) ...")
    simd = simd_counts()
    log("2. baselines ...")
    general = cases["a"].columns
    stack_rows = min(args.stack_rows, args.n)
    loop_ns, agreement = time_python_loop(general, args.loop_rows, args.repeat, quiet)
    base = {
        "loop_rows": args.loop_rows,
        "loop_ns": loop_ns,
        "loop_agreement": agreement,
        "stack_rows": stack_rows,
        "stack_ns": time_stacked(general, stack_rows, min(args.repeat, 3), quiet),
    }
    log("3. start-up and compile waits ...")
    runs = 2 if args.quick else STARTUP_RUNS
    bytecode = write_bytecode()
    start = {
        "cli_s": time_cli_solve(quiet, runs),
        **time_first_call(general, quiet, runs),
        "waits": time_compile_waits(general, quiet, runs),
    }
    start["bytecode_note"], start["source_compile_s"] = bytecode
    log("4. serial threshold ...")
    table = quiet.run("4", lambda: time_threshold(general, args.threshold_repeat))
    thresh = {"table": table, "verdict": threshold_verdict(table)}
    sweep, sweep_note = _sweep_section(args, log)
    goals = targets(cases, simd, base, start, sweep)
    elapsed = time.perf_counter() - t_start
    if code_state() != code:
        code += " **The code changed during the run** (now: " + code_state() + ")"
    text = markdown(
        args, code, cases, ok, quiet, simd, base, start, thresh, sweep, sweep_note, goals, elapsed
    )
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "performance.md").write_text(text)
    record = {
        "command": command(args),
        "machine": _machine(),
        "code": code,
        "elapsed_s": elapsed,
        "other_cpu_share_by_section": quiet.shares,
        "blocks_rerun": quiet.rerun,
        "waited_s": quiet.waited_s,
        "cases": {
            k: {
                "label": c.label,
                "arrays_in": c.arrays,
                "outputs": c.returned,
                "status0_share": ok[k],
                "ceiling_ratio": c.ceiling_ratio(),
                "target": c.target,
                "ns_per_scene": c.times,
                "minor_faults_per_call": c.faults,
                "simd": simd.get(k),
            }
            for k, c in cases.items()
        },
        "ceiling_simd": simd.get("ceiling"),
        "baselines": base,
        "startup": start,
        "serial_threshold": {
            "table_ns": {str(k): v for k, v in table.items()},
            "verdict": thresh["verdict"],
        },
        "sweep": sweep,
        "sweep_note": sweep_note,
        "targets": [{"what": g.what, "value": g.value, "goal": g.goal, "met": g.met} for g in goals],
    }
    (args.out / "performance.json").write_text(json.dumps(record, indent=1))
    print(text)
    log(f"wrote {args.out / 'performance.md'} and performance.json in {elapsed:.0f} s")
    return 0
