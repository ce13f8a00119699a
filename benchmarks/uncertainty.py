"""Uncertainty: Monte Carlo end to end, Jacobian kernels, memory of a long stream.

Three measurements, each as a ratio to a baseline of the same run (the
machine is shared; absolute times are noisy, ratios less so):

1. ``propagate`` of a reconstruction with eight uncertain inputs, N draws end
   to end (draws, copula, kernels, rejection, statistics, linear budget),
   after a first call has compiled everything; baseline: ``reconstruct_batch``
   alone on N rows of fixed columns.
2. A Jacobian kernel per scene against its value kernel: the plain-Python
   per-scene functions (what the linear method runs) for reconstruct, rigid
   and particle, and the numba parallel drivers for the particle kernel (the
   rigid and reconstruct Jacobian drivers, 250-300 outputs of straight-line
   code, take numba more than five minutes to compile: not measured).
3. Peak resident memory of a child process streaming ``--stream`` draws,
   against a child streaming 2^18 draws (one chunk).
4. ``reconstruct --uncertainty`` through the run-out (rest poses given),
   ``--runout-draws`` draws end to end (reading, nominal fits, linearisation,
   Monte Carlo with every draw's run-outs fitted, statistics, linear method)
   after a first call of 200 draws, for an all-locked scene (tests/runout_rest.py)
   and the mixed-wheel example examples/runout/chain_reconstruct_uncertain.json;
   with the run-outs it took per draw and, as the baseline of the same run,
   the run-outs per second of ``runout_batch`` on those scenes' nominal rows.

    python -m benchmarks uncertainty [--draws 1000000] [--stream 100000000]
        [--runout-draws 100000] [--parts end_to_end,jacobian,stream,runout]
"""

from __future__ import annotations

import math
import subprocess
import sys
import time

import numpy as np

DESCRIPTION = "uncertainty: 1e6-draw reconstruction, Jacobian vs value kernels, streaming memory"

FORWARD = {
    "m1": 1500.0,
    "m2": 1200.0,
    "I1": 2500.0,
    "I2": 2000.0,
    "v1x": 20.0,
    "v1y": 0.0,
    "w1": 0.1,
    "v2x": 0.0,
    "v2y": 15.0,
    "w2": 0.0,
    "r1x": 2.0,
    "r1y": 0.3,
    "r2x": -0.5,
    "r2y": -2.0,
    "gamma": 0.3,
    "e": 0.2,
    "mu": -0.4,
    "e_m": 0.8,
}


def _reconstruction_scene() -> dict:
    """Reconstruction columns whose finals are FORWARD's solved finals (a
    physical scene: draws around it are mostly accepted)."""
    from impactsym import solve_batch

    fwd = solve_batch({k: np.array([v]) for k, v in FORWARD.items()})
    scene = {k: FORWARD[k] for k in ("m1", "m2", "I1", "I2", "w1", "w2", "r1x", "r1y", "r2x", "r2y", "gamma")}
    scene.update({k: float(fwd[k][0]) for k in ("V1x", "V1y", "W1", "V2x", "V2y", "W2")})
    return {**scene, "theta1": 0.0, "theta2": math.pi / 2}


SCENE = _reconstruction_scene()
UNCERTAIN = {
    "V1x": 0.3,
    "V1y": 0.3,
    "V2x": 0.3,
    "V2y": 0.3,
    "m1": 30.0,
    "m2": 30.0,
    "theta1": 0.02,
    "theta2": 0.02,
}


def source():
    """A column-level reconstruction with eight normal inputs (named by column)."""
    from impactsym.uncertainty import propagation as U

    inputs = tuple(U.Input(k, "normal", (SCENE[k], sd)) for k, sd in UNCERTAIN.items())

    def columns(overrides):
        n = len(next(iter(overrides.values())))
        return {**SCENE, **overrides}, np.full(n, "")

    return U.Source(U.RECONSTRUCT, inputs, columns)


def _best(func, repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return min(times)


def end_to_end(draws: int) -> dict:
    from impactsym import reconstruct_batch
    from impactsym.uncertainty import propagation as U

    src = source()
    U.propagate(src, draws=1 << 16, seed=1)  # compile and warm up
    rng = np.random.default_rng(0)
    cols = {**SCENE, **{k: SCENE[k] + sd * rng.standard_normal(draws) for k, sd in UNCERTAIN.items()}}
    reconstruct_batch(cols)
    t_mc = _best(lambda: U.propagate(src, draws=draws, seed=2), repeat=2)
    t_kernel = _best(lambda: reconstruct_batch(cols), repeat=3)
    accepted = U.propagate(src, draws=draws, seed=2).accepted
    return {
        "draws": draws,
        "accepted": accepted,
        "propagate_s": t_mc,
        "reconstruct_batch_s": t_kernel,
        "ratio": t_mc / t_kernel,
    }


REPS = 200


def jacobian_vs_value() -> dict:
    """Per scene: the plain-Python per-scene function (what the linear method
    runs, once per scene) of each Jacobian kernel against its value kernel's.
    (Jacobian kernels have no batch drivers: derive/__main__.py says why.)"""
    from impactsym import _kernels

    out = {}
    point, reps = FORWARD, REPS
    for name, value_ks, values in (
        ("reconstruct", _kernels.RECONSTRUCT, SCENE),
        ("rigid", _kernels.kernel_for("rigid", False), point),
        ("particle", _kernels.kernel_for("particle", False), point),
    ):
        jac = _kernels.JACOBIAN[name]
        t_jac = (
            _best(lambda jac=jac, v=values: [_kernels.run_one(jac, v, jac.outputs) for _ in range(REPS)])
            / reps
        )
        t_val = (
            _best(lambda ks=value_ks, v=values: [_kernels.run_one(ks, v, ks.outputs) for _ in range(REPS)])
            / reps
        )
        out[f"{name} per scene (plain Python)"] = {
            "jacobian_us": 1e6 * t_jac,
            "value_us": 1e6 * t_val,
            "ratio": t_jac / t_val,
            "jacobian_outputs": len(jac.outputs),
        }
    return out


CHILD = """
import resource, sys, time
from benchmarks.uncertainty import source
from impactsym.uncertainty import propagation as U
start = time.perf_counter()
r = U.propagate(source(), draws={draws}, seed=3)
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, time.perf_counter() - start,
      r.accepted)
"""


def stream_memory(draws: int) -> dict:
    """Peak RSS [MB] of a child streaming `draws` draws, and of one with one chunk."""
    out = {}
    for label, n in (("one_chunk", 1 << 18), ("stream", draws)):
        text = subprocess.run(
            [sys.executable, "-c", CHILD.format(draws=n)], check=True, capture_output=True, text=True
        ).stdout.split()
        out[label] = {
            "draws": n,
            "peak_rss_mb": float(text[0]),
            "seconds": float(text[1]),
            "accepted": int(text[2]),
        }
    out["ratio"] = out["stream"]["peak_rss_mb"] / out["one_chunk"]["peak_rss_mb"]
    return out


def through_runout(draws: int, scene, label: str) -> dict:
    """Part 4 for one scene (a path or mapping)."""
    from impactsym.runout.batch import columns, runout_batch
    from impactsym.runout.scene import row_values
    from impactsym.runout.uncertain import chained_uncertainty

    chained, _ = chained_uncertainty(scene, draws=200, seed=1)  # compile and warm up
    start = time.perf_counter()
    chained, u = chained_uncertainty(scene, draws=draws, seed=2)
    elapsed = time.perf_counter() - start
    rows = np.vstack(
        [row_values(v, columns(), *p) for v, p in zip(chained.runout.vehicles, chained.p)] * 10_000
    )
    table = {c: rows[:, i] for i, c in enumerate(columns())}
    runout_batch(table)
    batch = _best(lambda: runout_batch(table), repeat=3)
    work = chained.work
    return {
        "scene": label,
        "draws": draws,
        "accepted": u.accepted,
        "seconds": round(elapsed, 2),
        "runouts": work["runouts"],
        "runouts_per_draw": round(work["runouts"] / draws, 2),
        "exact_newton_rows": work["exact_rows"],
        "batch_runouts_per_s": round(rows.shape[0] / batch),
        "seconds_in_runouts_at_that_rate": round(work["runouts"] * batch / rows.shape[0], 2),
    }


PARTS = ("end_to_end", "jacobian", "stream", "runout")


def add_arguments(parser) -> None:
    parser.add_argument("--draws", type=int, default=1_000_000, help="end-to-end draws")
    parser.add_argument("--stream", type=int, default=100_000_000, help="draws of the memory test")
    parser.add_argument(
        "--runout-draws",
        type=int,
        default=100_000,
        help="draws of reconstruct --uncertainty through run-outs",
    )
    parser.add_argument(
        "--runout-scenes", default="locked,mixed", help="run-out part: locked, mixed or both (default)"
    )
    parser.add_argument(
        "--parts", default=",".join(PARTS), help=f"comma-separated parts to run (default {','.join(PARTS)})"
    )


def main(args) -> int:
    parts = args.parts.split(",")
    if "end_to_end" in parts:
        print("end to end:", end_to_end(args.draws), flush=True)
    if "jacobian" in parts:
        print("jacobian vs value:", jacobian_vs_value(), flush=True)
    if "stream" in parts:
        print("streaming memory:", stream_memory(args.stream), flush=True)
    if "runout" in parts:
        from tests.runout_rest import rest_scene

        scenes = {
            "locked": lambda: rest_scene(wheels="locked", sd_position=0.1, sd_heading=2.0, sd_friction=0.05),
            "mixed": lambda: "examples/runout/chain_reconstruct_uncertain.json",
        }
        for name in args.runout_scenes.split(","):
            result = through_runout(args.runout_draws, scenes[name](), name)
            print("through the run-out:", result, flush=True)
    return 0
