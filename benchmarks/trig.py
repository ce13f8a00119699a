"""ns per angle of derive/trig.py's branch-free ``_sincos`` in a numba ``prange`` loop,
against the same loop calling libm (``math.sin`` + ``math.cos``) and numpy's
``np.sin`` + ``np.cos`` (into preallocated arrays), as ratios from the same run.

``python -m benchmarks trig [--n 1000000] [--repeat 21] [--out benchmarks/results]``

Each loop reads n angles (uniform over [-2π, 2π], the angles scene files give) and
writes sin and cos to two preallocated arrays. A fourth loop that only copies the angle
into both outputs is the memory floor of that traffic ("copy"). Rounds run every
method once in a rotating order; reported are medians over rounds of ns/angle and of
the per-round ratios, at one thread and at numba's default thread count (numpy's
functions are single-threaded at both). Also printed: the packed (SIMD) and scalar
float64 arithmetic instructions of each compiled loop. The machine may be shared: the
share of the CPUs other processes used during the timed rounds is measured and printed.
"""

from __future__ import annotations

import math
import os
import platform
import random
import re
import statistics
import sys
import time
from pathlib import Path

import numba
import numpy as np

from derive import trig

from .performance import Quiet

DESCRIPTION = "vectorised sincos vs libm and numpy: ns per angle in a prange loop"
RESULTS = Path(__file__).resolve().parent / "results"
SEED = 20240611

_namespace: dict = {}
exec(compile(trig.SINCOS_SOURCE, "<derive.trig SINCOS_SOURCE>", "exec"), _namespace)  # noqa: S102
_sincos = numba.njit(inline="always")(_namespace["_sincos"])


@numba.njit(parallel=True)
def loop_sincos(x, s, c):
    for i in numba.prange(x.size):
        s[i], c[i] = _sincos(x[i])


@numba.njit(parallel=True)
def loop_libm(x, s, c):
    for i in numba.prange(x.size):
        s[i] = math.sin(x[i])
        c[i] = math.cos(x[i])


@numba.njit(parallel=True)
def loop_copy(x, s, c):
    for i in numba.prange(x.size):
        s[i] = x[i]
        c[i] = x[i]


def numpy_sincos(x, s, c):
    np.sin(x, out=s)
    np.cos(x, out=c)


METHODS = {  # key: (label, function)
    "sincos": ("`_sincos` (derive/trig.py) in prange", loop_sincos),
    "libm": ("`math.sin` + `math.cos` in prange", loop_libm),
    "numpy": ("`np.sin` + `np.cos` (out=)", numpy_sincos),
    "copy": ("copy x to both outputs in prange (memory floor)", loop_copy),
}
_ARITHMETIC = re.compile(r"\bv(?:add|sub|mul|div|f[n]?m(?:add|sub)\w*)(pd|sd)\b")


def instruction_counts() -> dict[str, tuple[int, int]]:
    """(packed, scalar) float64 arithmetic instructions of each compiled numba loop
    (compiled in this process, so the assembly is available)."""
    out = {}
    for key, (_, fn) in METHODS.items():
        if isinstance(fn, numba.core.registry.CPUDispatcher):
            kinds = [m.group(1) for m in _ARITHMETIC.finditer("\n".join(fn.inspect_asm().values()))]
            out[key] = (kinds.count("pd"), kinds.count("sd"))
    return out


def time_rounds(x, repeat: int, quiet: Quiet, section: str) -> dict[str, list[float]]:
    """ns/angle of every method per round (rotating order); each round waits for, and
    is re-run unless it ran on, a machine the other jobs left (nearly) idle."""
    s, c = np.empty_like(x), np.empty_like(x)
    keys = list(METHODS)
    times = {k: [] for k in keys}

    def one_round(r):
        out = {}
        for k in keys[r % len(keys) :] + keys[: r % len(keys)]:
            t0 = time.perf_counter()
            METHODS[k][1](x, s, c)
            out[k] = (time.perf_counter() - t0) / x.size * 1e9
        return out

    for r in range(repeat):
        for k, ns in quiet.run(section, lambda r=r: one_round(r)).items():
            times[k].append(ns)
    return times


def summarise(times: dict[str, list[float]]) -> dict[str, dict[str, float]]:
    """Median ns/angle and median per-round ratio of every method to ``_sincos``."""
    base = times["sincos"]
    return {
        k: {"ns": statistics.median(v), "x": statistics.median(t / b for t, b in zip(v, base))}
        for k, v in times.items()
    }


def markdown(args, counts, runs, quiet, accuracy) -> str:
    head = (
        f"`python -m benchmarks trig --n {args.n} --repeat {args.repeat}` — "
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, numba "
        f"{numba.__version__}, numpy {np.__version__}, Python {platform.python_version()}. "
        f"n = {args.n:,} angles uniform on [-2π, 2π]; outputs preallocated; median over "
        f"{args.repeat} rounds (methods in rotating order); *× sincos* is the median of the "
        "per-round ratios time / time of `_sincos` (above 1: slower than `_sincos`)."
    )
    acc = (
        f"Accuracy (same run, 50-digit mpmath, {accuracy['points']} points from "
        f"`derive.trig.proof_points`): max error sin {accuracy['sin']:.3f} ulp, cos "
        f"{accuracy['cos']:.3f} ulp, for |x| ≤ SINCOS_LIMIT = {trig.SINCOS_LIMIT:.7g}. "
        "tests/test_sincos.py checks many more points."
    )
    legend = (
        "*packed / scalar*: float64 add/sub/mul/div/fma instructions in the compiled loop "
        "(`vmulpd` etc. are SIMD; the scalar ones are the loop's remainder and set-up). "
        "The libm loop calls `sincos` per element and does no other arithmetic; the copy "
        "loop only moves data."
    )
    lines = [
        "# Vectorised sin/cos: `_sincos` against libm and numpy",
        "",
        head,
        "",
        "**The machine is shared with other jobs (other helpers were running).** " + quiet.summary(),
        "",
        "| threads | method | ns/angle | × sincos | packed / scalar float64 ops |",
        "|---:|---|---:|---:|---:|",
    ]
    for threads, summary in runs.items():
        for k, (label, _) in METHODS.items():
            ops = counts.get(k)
            cell = f"{ops[0]} / {ops[1]}" if ops else "– (numpy)"
            lines.append(f"| {threads} | {label} | {summary[k]['ns']:.2f} | {summary[k]['x']:.2f} | {cell} |")
    lines += ["", acc, "", legend]
    return "\n".join(lines) + "\n"


def add_arguments(parser) -> None:
    parser.add_argument("--n", type=int, default=1_000_000, help="angles per call (default 1e6)")
    parser.add_argument("--repeat", type=int, default=21, help="timed rounds (median; default 21)")
    parser.add_argument("--out", type=Path, default=RESULTS, help="folder for trig.md")
    parser.add_argument(
        "--max-other",
        type=float,
        default=0.10,
        help="wait until other processes use at most this share of the CPUs",
    )
    parser.add_argument(
        "--max-wait",
        type=float,
        default=180.0,
        help="seconds to wait for a quiet machine in total (default 180)",
    )


def main(args) -> int:
    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    print(
        "note: this machine is shared with other jobs right now; each round waits for a quiet "
        "machine (up to --max-wait s in all), the others' CPU share is reported, and the "
        "same-run ratios are the figures to compare"
    )
    x = np.random.default_rng(SEED).uniform(-2 * math.pi, 2 * math.pi, args.n)
    s, c = np.empty_like(x), np.empty_like(x)
    log("compiling ...")
    for _, fn in METHODS.values():
        fn(x, s, c)
    counts = instruction_counts()
    quiet = Quiet(max_other=args.max_other, budget_s=args.max_wait)
    runs = {}
    default_threads = numba.get_num_threads()
    for threads in sorted({1, default_threads}):
        numba.set_num_threads(threads)
        log(f"timing {args.repeat} rounds at {threads} thread(s) ...")
        runs[threads] = summarise(time_rounds(x, args.repeat, quiet, f"{threads} thread(s)"))
    numba.set_num_threads(default_threads)
    points = trig.proof_points(random.Random(SEED))
    err_s, err_c = trig.ulp_errors(_namespace["_sincos"], points)
    text = markdown(args, counts, runs, quiet, {"points": len(points), "sin": err_s, "cos": err_c})
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "trig.md").write_text(text)
    log(f"wrote {args.out / 'trig.md'}")
    return 0
