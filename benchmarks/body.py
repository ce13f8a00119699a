"""The kernels' own arithmetic: ns per row on one thread, rows in cache.

The performance benchmark measures whole calls against a memory ceiling, where the
memory traffic and the arithmetic overlap and the machine's memory speed moves every
figure. This one takes the memory out: a parallel driver runs on one thread over a few
thousand rows that stay in cache, into outputs allocated once, so what is timed is the
body (the formulas, the row checks, the flags) per row. Rounds interleave what is
compared; the report gives the least and the median over all calls.

Without ``--against``: the cases (a)-(d) of the performance benchmark, each through its
own driver. With ``--against REV``: the rigid body of ``generated/planar_jit.py`` at git
revision REV against the checkout's, both compiled here into the same one-normal
driver (the scenes of case (b)) and checked to give the same bits: a before/after of a
change to the emitted code that machine noise between processes cannot blur (whole
runs on this VM differ by 10-30 %).
"""

from __future__ import annotations

import math
import re
import subprocess
import time
from pathlib import Path

import numba
import numpy as np

from impactsym import _kernels
from impactsym._kernels import runner

from .performance import SEED, approaching_scenes, build_cases

DESCRIPTION = "the kernels' arithmetic per row, one thread, rows in cache (or a before/after)"
ROOT = Path(__file__).resolve().parent.parent
BODY = "_rigid_body"


def add_arguments(parser) -> None:
    parser.add_argument("--rows", type=int, default=8192, help="rows per call (default 8192)")
    parser.add_argument("--rounds", type=int, default=200, help="rounds of 5 calls each (default 200)")
    parser.add_argument("--against", metavar="REV", help="compare the rigid body at git revision REV")


def _case_runner(case, rows: int):
    """A zero-argument call of a case's parallel driver on preallocated outputs."""
    ks = _kernels.kernel_for(*case.kernel)
    inputs = [_kernels.as_input(x) for x in case.inputs()]
    columns = runner._driver_columns(ks, inputs)
    columns = [c if c is None or isinstance(c, np.ndarray) else np.full(rows, c) for c in columns]
    outs = [*runner.allocate(ks, rows).values(), np.empty(rows, np.int32), np.empty(rows, np.int32)]
    driver = ks.driver
    return lambda: driver(*columns, *outs)


def _body_source(text: str) -> str:
    """The source of `BODY` in a generated planar_jit.py, without its decorator."""
    found = re.search(rf"@njit\([^\n]*\)\ndef {BODY}\(.*?(?=\n\n\n)", text, re.S)
    return found.group(0).split("\n", 1)[1]


def _body_runners(sources: dict, rows: int) -> dict:
    """Per label, a zero-argument call of a one-normal driver around that body
    source on the scenes of case (b); every label's outputs must agree bitwise."""
    ks = _kernels.kernel_for("rigid", False, False, "energy")
    scenes = approaching_scenes(rows, SEED + 1, gamma=0.35)
    args = [scenes[k] for k in ks.inputs if k != "gamma"]
    at = ks.inputs.index("gamma")
    nx, ny = math.cos(0.35), math.sin(0.35)
    names = [f"c{k}" for k in range(len(args))]
    row = [f"{c}[i]" for c in names]
    row[at:at] = ["nx", "ny"]
    outs = [f"o{k}" for k in range(len(ks.outputs))] + ["st", "fl"]
    driver = (
        f"def driver({', '.join(names)}, nx, ny, {', '.join(outs)}):\n"
        "    for i in prange(st.shape[0]):\n"
        f"        ({', '.join(o + '[i]' for o in outs)}) = body({', '.join(row)})\n"
    )
    runners, results = {}, {}
    for label, source in sources.items():
        space = {"math": math, "prange": numba.prange}
        exec(source, space)
        space["body"] = numba.njit(error_model="numpy", inline="always")(space[BODY])
        exec(driver, space)
        compiled = numba.njit(parallel=True, error_model="numpy")(space["driver"])
        out = [np.empty(rows) for _ in ks.outputs] + [np.empty(rows, np.int32), np.empty(rows, np.int32)]
        compiled(*args, nx, ny, *out)
        results[label] = out
        runners[label] = lambda f=compiled, out=out: f(*args, nx, ny, *out)
    first = next(iter(results.values()))
    for label, out in results.items():
        if not all(np.array_equal(a, b, equal_nan=True) for a, b in zip(first, out)):
            raise SystemExit(f"{label}: the bodies do not give the same bits; not a like-for-like comparison")
    return runners


def _time(runs: dict, rows: int, rounds: int) -> dict:
    """ns per row of every call, the runs interleaved round by round, on one thread."""
    previous = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        for run in runs.values():
            run()
        times = {label: [] for label in runs}
        for _ in range(rounds):
            for label, run in runs.items():
                for _ in range(5):
                    t0 = time.perf_counter_ns()
                    run()
                    times[label].append((time.perf_counter_ns() - t0) / rows)
    finally:
        numba.set_num_threads(previous)
    return times


def main(args) -> int:
    if args.against:
        old = subprocess.run(
            ["git", "show", f"{args.against}:generated/planar_jit.py"],
            cwd=ROOT,
            check=True,
            capture_output=True,
            text=True,
        ).stdout
        now = (ROOT / "generated" / "planar_jit.py").read_text()
        sources = {args.against: _body_source(old), "checkout": _body_source(now)}
        runs = _body_runners(sources, args.rows)
        command = f"--against {args.against} "
    else:
        cases = [c for c in build_cases(args.rows, lambda *a: None) if c.key in "abcd"]
        runs = {c.label: _case_runner(c, args.rows) for c in cases}
        command = ""
    times = _time(runs, args.rows, args.rounds)
    print(
        f"`python -m benchmarks body {command}--rows {args.rows} --rounds {args.rounds}`: ns per row, one thread"
    )
    print("| what | least | median |\n|---|---:|---:|")
    for label, ns in times.items():
        print(f"| {label} | {min(ns):.1f} | {np.median(ns):.1f} |")
    return 0
