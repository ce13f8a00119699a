"""Batch kernels of the impact laws against the memory ceiling and Brach's rigid kernel.

``python -m benchmarks laws [--n 200000] [--repeat 7] [--first-use] [--body-first-use]``

Rows: ``impactsym.testing.laws.realistic`` (approaching passenger-car scenes with
friction 0-1.2). Timed interleaved, the order rotating each repeat: the memory
ceiling of each call (``benchmarks.performance.ceiling_call``: a trivial ``prange``
kernel reading the same input arrays and writing as many outputs), Brach's rigid
kernel (``impactsym.solve_batch(model="rigid")`` at e_m = 1 and mu = the friction
with the sign opposing the slip), and every law through ``impactsym.solve_batch``.
Reported per call: ns/row (median), ceiling time / call time (median of the per-repeat
ratios), call time / rigid time and the call's time beyond its driver (the driver through
the runner alone, timed in the same round: the runtime's own work, ns/row); then the bodies on one thread (each kernel's driver
through the door's runner with numba at one thread, least of 7) against Brach's
point-impulse kernel ``rigid_em1``. ``--first-use``: the first ``solve_batch`` of a law
(200,000 rows) in a fresh process with an empty numba cache: wall and CPU seconds.
``--body-first-use``: the same for each law's body alone (its generated ``_<kernel>_body``
in a one-loop ``prange`` driver: no per-row angle loop, no sincos; the batch driver
around it is generated/'s template), against Brach's ``rigid_em1`` body.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

DESCRIPTION = "impact-law batch kernels against the memory ceiling and the rigid kernel"
LAWS = ("kudlich_slibar", "kudlich_slibar:sliding", "coulomb", "coulomb:poisson", "coulomb:energetic")


def add_arguments(parser) -> None:
    parser.add_argument("--n", type=int, default=200_000)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--first-use", action="store_true")
    parser.add_argument("--body-first-use", action="store_true")


def _rows(n: int) -> dict:
    from impactsym.testing import laws

    c = laws.realistic(int(n * 1.3) + 100, 2026)
    return {k: np.ascontiguousarray(v[:n]) for k, v in c.items()}


def main(args) -> int:
    import impactsym
    from impactsym import _kernels
    from impactsym.laws.dispatch import extra_outputs, law_kernel

    from .performance import ceiling_call

    c = _rows(args.n)
    n = len(c["e"])
    rigid = {k: v for k, v in c.items() if k != "mu_f"}
    gt_sign = np.sign(impactsym.laws.coulomb_batch({k: v[:n] for k, v in c.items()}, "newton")["Pt"])
    rigid.update(mu=np.ascontiguousarray(gt_sign * c["mu_f"]), e_m=np.ones(n))
    calls = {"rigid (Brach)": lambda: impactsym.solve_batch(rigid, model="rigid")}
    # The ceiling writes as many 8-byte columns as the call returns besides status
    # and flags (its own two int32 columns): Brach's outputs, a law's and its class.
    # Until session 10 it wrote two more (19 and 20: status and flags counted twice),
    # a ceiling two columns slower (benchmarks/results/laws.md).
    ceilings = {"rigid (Brach)": ceiling_call(rigid, len(_kernels.OUTPUTS))}
    drivers = {"rigid (Brach)": _driver_call(_kernels.kernel_for("rigid", False, True), rigid)}
    for law in LAWS:
        cols = c if law != "kudlich_slibar" else {k: v for k, v in c.items() if k != "mu_f"}
        calls[law] = lambda cols=cols, law=law: impactsym.solve_batch(cols, model=law)
        ceilings[law] = ceiling_call(cols, len(_kernels.OUTPUTS) + len(extra_outputs(law_kernel(law))))
        drivers[law] = _driver_call(law_kernel(law), cols)
    for fn in [*calls.values(), *ceilings.values(), *drivers.values()]:
        fn()  # compile / warm
    times = {name: [] for name in calls}
    ceil = {name: [] for name in calls}
    driven = {name: [] for name in calls}
    names = list(calls)
    for r in range(args.repeat):
        for name in names[r % len(names) :] + names[: r % len(names)]:
            t0 = time.perf_counter()
            ceilings[name]()
            t1 = time.perf_counter()
            calls[name]()
            t2 = time.perf_counter()
            drivers[name]()
            t3 = time.perf_counter()
            ceil[name].append(t1 - t0)
            times[name].append(t2 - t1)
            driven[name].append(t3 - t2)
    base = statistics.median(times["rigid (Brach)"])
    print(f"rows {n}, repeats {args.repeat}, cpus {os.cpu_count()} (shared machine)")
    print(f"{'call':<26}{'ns/row':>10}{'ceiling/call':>14}{'call/rigid':>12}{'beyond driver':>15}")
    report = {}
    for name in names:
        t = statistics.median(times[name])
        ratio = statistics.median(a / b for a, b in zip(ceil[name], times[name]))
        beyond = 1e9 * statistics.median(a - b for a, b in zip(times[name], driven[name])) / n
        report[name] = {
            "ns_per_row": 1e9 * t / n,
            "ceiling_over_call": ratio,
            "over_rigid": t / base,
            "beyond_driver_ns_per_row": beyond,
        }
        print(f"{name:<26}{1e9 * t / n:>10.1f}{ratio:>14.2f}{t / base:>12.2f}{beyond:>15.2f}")
    report["serial_ns_per_row"] = _serial(c)
    if args.first_use:
        report["first_use_s"] = _first_use()
    if args.body_first_use:
        report["body_first_use_s"] = _body_first_use()
    print(json.dumps(report, indent=1))
    return 0


def _driver_call(ks, cols: dict):
    """The kernel's driver through the runner alone (`_kernels.run` on normalised
    columns): what a `solve_batch` call costs beyond it is the runtime's own work."""
    from impactsym import _kernels

    inputs = [_kernels.as_input(cols[name]) for name in ks.inputs]
    n = len(cols["e"])
    return lambda: _kernels.run(ks, inputs, n)


def _serial(c: dict) -> dict:
    """The kernels' bodies on one thread: each law's driver (the registry's kernel,
    through the door's runner, numba set to one thread), least of 7, against
    Brach's point-impulse kernel (rigid_em1)."""
    import numba

    from impactsym._kernels import registry
    from impactsym.laws._door import LAWS, kernel

    n = len(c["e"])

    def least(run):
        run()
        times = []
        for _ in range(7):
            t0 = time.perf_counter()
            run()
            times.append(time.perf_counter() - t0)
        return 1e9 * min(times) / n

    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        out = {"rigid_em1": least(_driver_call(registry.kernel("rigid_em1"), dict(c, mu=c["mu_f"], e_m=1.0)))}
        for model, laws in LAWS.items():
            for law in laws:
                ks = kernel(model, law)
                out[ks.name] = least(_driver_call(ks, c))
    finally:
        numba.set_num_threads(threads)
    print("one thread (ns/row, x rigid_em1):")
    for name, value in out.items():
        print(f"  {name:<20}{value:>8.1f}{value / out['rigid_em1']:>8.2f}")
    return out


def _first_use() -> dict:
    """The first solve_batch of a law (200,000 rows) in a fresh process with an empty
    numba cache: wall and CPU seconds of the call (the driver compiles on demand)."""
    code = (
        "import time, impactsym; from impactsym.testing import laws; c = laws.realistic(ROWS, 1); "
        "c = {k: v[:200000] for k, v in c.items()}; "
        "t, p = time.perf_counter(), time.process_time(); impactsym.solve_batch(c, model=MODEL); "
        "print(time.perf_counter() - t, time.process_time() - p)"
    )
    out = {}
    for model in ("kudlich_slibar:sliding", "coulomb:energetic"):
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, NUMBA_CACHE_DIR=cache)
            proc = subprocess.run(
                [sys.executable, "-c", code.replace("MODEL", repr(model)).replace("ROWS", "270000")],
                capture_output=True,
                text=True,
                env=env,
                timeout=600,
            )
        key = f"{model}, 200000 rows"
        if proc.returncode == 0:
            wall, cpu = map(float, proc.stdout.strip().splitlines()[-1].split())
            out[key] = {"wall_s": wall, "cpu_s": cpu, "load": os.getloadavg()[0]}
        else:
            out[key] = proc.stderr
        print(f"first use {key}: {out[key]}")
    return out


# A one-loop prange driver around one generated body, compiled in a fresh process.
_BODY_CODE = """
import importlib, inspect, os, sys, time
import numpy as np
from impactsym.testing import laws
module, name = sys.argv[1], sys.argv[2]
body = getattr(importlib.import_module(module), f"_{name}_body").py_func
args = list(inspect.signature(body).parameters)
src = inspect.getsource(body)
n_out = src[src.rindex("return ("):].count(",") + 1
c = laws.realistic(270000, 1)
c = {k: np.ascontiguousarray(v[:200000]) for k, v in c.items()}
c.update(nx=np.cos(c["gamma"]), ny=np.sin(c["gamma"]), mu=c["mu_f"], e_m=np.ones(200000))
outs = ", ".join(f"o{q}" for q in range(n_out))
loop = (
    "import math\\nfrom numba import njit, prange\\n\\n" + src + "\\n\\n"
    "@njit(cache=True, error_model='numpy', parallel=True)\\n"
    f"def loop({', '.join('c_' + a for a in args)}, {outs}):\\n"
    "    for i in prange(o0.shape[0]):\\n"
    f"        ({', '.join(f'o{q}[i]' for q in range(n_out))}) = "
    f"_{name}_body({', '.join(f'c_{a}[i]' for a in args)})\\n"
)
path = os.path.join(os.environ["NUMBA_CACHE_DIR"], f"body_{name}.py")
with open(path, "w") as fh:
    fh.write(loop)
sys.path.insert(0, os.environ["NUMBA_CACHE_DIR"])
driver = importlib.import_module(f"body_{name}").loop
arrays = [np.empty(200000) for _ in range(n_out - 2)] + [np.empty(200000, np.int32) for _ in range(2)]
t, p = time.perf_counter(), time.process_time()
driver(*[c[a] for a in args], *arrays)
print(time.perf_counter() - t, time.process_time() - p)
"""


def _body_first_use() -> dict:
    """Each law's body alone, and Brach's rigid_em1 body: compile and 200,000 rows
    in a fresh process with an empty numba cache (wall and CPU seconds)."""
    from impactsym.laws._door import LAWS, kernel

    names = [("generated.planar_jit", "rigid_em1")]
    names += [
        (f"generated.{model}_jit", kernel(model, law).name) for model, laws in LAWS.items() for law in laws
    ]
    out = {}
    for module, name in names:
        with tempfile.TemporaryDirectory() as cache:
            proc = subprocess.run(
                [sys.executable, "-c", _BODY_CODE, module, name],
                capture_output=True,
                text=True,
                env=dict(os.environ, NUMBA_CACHE_DIR=cache),
                timeout=600,
            )
        if proc.returncode == 0:
            wall, cpu = map(float, proc.stdout.strip().splitlines()[-1].split())
            out[name] = {"wall_s": wall, "cpu_s": cpu, "load": os.getloadavg()[0]}
        else:
            out[name] = proc.stderr
        print(f"first use of the body alone, {name}: {out[name]}")
    return out
