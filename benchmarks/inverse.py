"""How the inverse solution's error grows as e → 0 (the seed: "e appears in the
denominator"). Forward-solve realistic scenes at a given e, invert the float64
finals, and measure how far the recovered initials are from the true ones, in
units of the scene's speed scale (largest initial or final speed). "Physical
rows" are those whose forward result has no flag: in the rest, restitution with
friction creates energy (Kane and Levinson's paradox), in the worst case sending
a vehicle off at 80 times its approach speed.

    python -m benchmarks inverse
"""

from __future__ import annotations

import numpy as np

import impactsym
from impactsym.testing import scenes

DESCRIPTION = "round-trip error of the inverse solution as e -> 0"
RESTITUTIONS = (0.5, 0.1, 0.05, 0.01, 1e-3, 1e-4, 1e-5, 1e-6)
INITIALS = ("v1x", "v1y", "w1", "v2x", "v2y", "w2")
FINALS = ("V1x", "V1y", "W1", "V2x", "V2y", "W2")


def round_trip_errors(e: float, n: int = 2000, seed: int = 3):
    """Per-row worst error of invert(forward(x)) against x, speed-scale units,
    and whether the forward result of the row is physical (no flag)."""
    c = scenes.random_realistic(n, seed=seed)
    c["e"] = np.full(n, e)
    c["e_m"] = np.ones(n)
    fwd = impactsym.solve_batch(c)
    finals = {k: v for k, v in c.items() if k not in INITIALS}
    finals.update({k: fwd[k] for k in FINALS})
    inv = impactsym.invert_batch(finals)
    scale = np.max(
        [
            np.hypot(c["v1x"], c["v1y"]),
            np.hypot(c["v2x"], c["v2y"]),
            np.hypot(fwd["V1x"], fwd["V1y"]),
            np.hypot(fwd["V2x"], fwd["V2y"]),
        ],
        axis=0,
    )
    ok = (fwd["status"] == 0) & (inv["status"] == 0)
    errors = np.max([np.abs(inv[k] - c[k]) / scale for k in INITIALS if k[0] == "v"], axis=0)
    return errors[ok], fwd["flags"][ok] == 0


def add_arguments(parser) -> None:
    """No options: the restitution values and the scene set are fixed."""


def main(args=None) -> int:
    """Print the error growth table (Markdown)."""
    print("| e | median error | 99th percentile | worst | worst, physical rows |")
    print("|---|---|---|---|---|")
    for e in RESTITUTIONS:
        err, physical = round_trip_errors(e)
        print(
            f"| {e:g} | {np.median(err):.1e} | {np.percentile(err, 99):.1e} "
            f"| {err.max():.1e} | {err[physical].max():.1e} ({physical.sum()} rows) |"
        )
    return 0
