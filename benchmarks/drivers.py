"""Whole drivers before and after: this checkout's batch drivers against a git revision's.

The drivers of ``generated/planar_jit.py`` and ``generated/particle_jit.py`` at revision
REV are written to a temporary folder, imported beside the checkout's, given the same
columns (cases (a)-(e) of the performance benchmark: an angle per row, one normal,
e_m = 1, particles, the velocities tier) and checked to give the same bits; then calls
of the two alternate, round by round, on all threads. The figure is the median of the
per-round ratios new / old: a change of the emitted drivers (their loops, not the
memory around them) that machine noise between processes cannot blur. Rows per call
are few enough (default 20,000) that a call mostly runs within one scheduler slice
on a busy machine.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

DESCRIPTION = "this checkout's batch drivers against a git revision's, same process, interleaved"
ROOT = Path(__file__).resolve().parent.parent
RIGID = ("m1", "m2", "I1", "I2", "v1x", "v1y", "w1", "v2x", "v2y", "w2", "r1x", "r1y", "r2x", "r2y")
PARTICLE = ("m1", "m2", "v1x", "v1y", "v2x", "v2y")
# case: (module, old driver, new driver, columns before the normal, after it, outputs, one normal)
CASES = {
    "(a) rigid, per-row angle": (
        "planar",
        "rigid_batch",
        "rigid_batch",
        RIGID,
        ("e", "mu", "e_m"),
        17,
        False,
    ),
    "(b) rigid, one normal": (
        "planar",
        "rigid_batch_normal",
        "rigid_batch",
        RIGID,
        ("e", "mu", "e_m"),
        17,
        True,
    ),
    "(c) rigid, e_m = 1": ("planar", "rigid_em1_batch", "rigid_em1_batch", RIGID, ("e", "mu"), 15, False),
    "(d) particle": ("particle", "particle_batch", "particle_batch", PARTICLE, ("e", "mu"), 13, False),
    "(e) rigid, velocities tier": (
        "planar",
        "rigid_velocities_batch",
        "rigid_velocities_batch",
        RIGID,
        ("e", "mu", "e_m"),
        6,
        False,
    ),
}


def add_arguments(parser) -> None:
    parser.add_argument("--against", default="9d057a6", help="git revision (default 9d057a6)")
    parser.add_argument("--rows", type=int, default=20_000, help="rows per call (default 20000)")
    parser.add_argument("--rounds", type=int, default=200, help="rounds (default 200)")


def _old_module(rev: str, model: str, folder: Path):
    """generated/<model>_jit.py at ``rev``, imported under another name."""
    text = subprocess.run(
        ["git", "show", f"{rev}:generated/{model}_jit.py"],
        cwd=ROOT,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    name = f"_impactsym_old_{model}_jit"
    path = folder / f"{name}.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # numba's cache re-imports the module by name
    spec.loader.exec_module(module)
    return module


def _columns(n: int) -> dict:
    rng = np.random.default_rng(1)
    ranges = {
        "m1": (900, 2500), "m2": (900, 2500), "I1": (1000, 4000), "I2": (1000, 4000),
        "v1x": (5, 30), "v1y": (-2, 2), "w1": (-0.5, 0.5), "v2x": (-5, 5), "v2y": (5, 25),
        "w2": (-0.5, 0.5), "r1x": (1, 2.5), "r1y": (-1, 1), "r2x": (-1, 1), "r2y": (-2.5, -1),
        "gamma": (-0.5, 0.5), "e": (0, 0.5), "mu": (0, 0.3), "e_m": (0, 1),
    }  # fmt: skip
    return {k: rng.uniform(a, b, n) for k, (a, b) in ranges.items()}


def _calls(old_modules: dict, n: int) -> dict:
    """Per case (old call, new call, same bits)."""
    from impactsym._kernels import registry

    c = _columns(n)
    none = np.empty(0)
    normal = [np.array([np.cos(0.3)]), np.array([np.sin(0.3)])]
    out = {}
    for label, (model, old_name, new_name, head, tail, k, one) in CASES.items():
        new = getattr(registry._module(f"{model}_jit"), new_name)
        old = getattr(old_modules[model], old_name)
        cols, rest = [c[x] for x in head], [c[x] for x in tail]
        a_old = cols + (normal if one else [c["gamma"]]) + rest
        a_new = cols + ([none, *normal] if one else [c["gamma"], none, none]) + rest
        o_old = [np.empty(n) for _ in range(k)] + [np.empty(n, np.int32), np.empty(n, np.int32)]
        o_new = [np.empty(n) for _ in range(k)] + [np.empty(n, np.int32), np.empty(n, np.int32)]
        old(*a_old, *o_old)
        new(*a_new, *o_new)
        same = all(np.array_equal(x, y, equal_nan=True) for x, y in zip(o_old, o_new))
        out[label] = (
            lambda f=old, a=a_old, o=o_old: f(*a, *o),
            lambda f=new, a=a_new, o=o_new: f(*a, *o),
            same,
        )
    return out


def main(args) -> int:
    with tempfile.TemporaryDirectory(prefix="impactsym_drivers_") as tmp:
        old = {model: _old_module(args.against, model, Path(tmp)) for model in ("planar", "particle")}
        calls = _calls(old, args.rows)
        times = {label: ([], []) for label in calls}
        for r in range(args.rounds):
            for label, (f_old, f_new, _) in calls.items():
                pair = ((f_old, 0), (f_new, 1)) if r % 2 else ((f_new, 1), (f_old, 0))
                for f, k in pair:
                    t0 = time.perf_counter_ns()
                    f()
                    times[label][k].append((time.perf_counter_ns() - t0) / args.rows)
    print(
        f"`python -m benchmarks drivers --against {args.against} --rows {args.rows} --rounds {args.rounds}`"
        f" (load average {os.getloadavg()[0]:.1f}): ns per row on all threads, medians"
    )
    print(
        f"| case | {args.against} | checkout | checkout / {args.against} | same bits |\n|---|---:|---:|---:|---|"
    )
    for label, (t_old, t_new) in times.items():
        ratio = float(np.median(np.array(t_new) / np.array(t_old)))
        print(
            f"| {label} | {np.median(t_old):.1f} | {np.median(t_new):.1f} | {ratio:.3f} | {calls[label][2]} |"
        )
    return 0
