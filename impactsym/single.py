"""Solve one scene: validate, run the generated kernel, wrap the outcome."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

from . import _kernels, laws
from ._kernels import STATUS_NOT_APPROACHING, STATUS_OVERFLOW
from .codes import describe_status
from .result import Result
from .scene import Scene, SceneError, load_scene

__all__ = ["SAFE_MAGNITUDE", "overflow_error", "solve", "status_reason", "turned_round_note"]

#: Magnitudes (scene units) within which the closed forms stay finite: they
#: multiply and divide at most a few inputs, and (1e100)^3 = 1e300 < 1.8e308.
#: An input outside is named when a solve overflows or underflows.
SAFE_MAGNITUDE = (1e-100, 1e100)

_HINTS = {
    STATUS_NOT_APPROACHING: "check impact.normal_angle and the vehicles' velocities and yaw rates",
}


def solve(scene: Scene | Mapping | str | Path) -> Result:
    """Solve the impact of a scene (a :class:`Scene`, a mapping or a file path).

    Returns a :class:`Result` in the scene's units.  Raises :class:`SceneError`
    for an invalid scene or one the kernel cannot solve (not approaching,
    singular), and :class:`OSError` for a file that cannot be read.
    """
    if laws.is_law_scene(scene):  # "kudlich_slibar" or "coulomb": impactsym.laws
        return laws.solve_law(scene)
    scene = load_scene(scene)
    model, critical, values = scene.to_inputs()
    out = _kernels.solve_one(model, critical, values)
    if out["status"] != 0:
        raise overflow_error(scene, out["status"]) or SceneError(
            status_reason(out["status"]) + turned_round_note(scene, out["status"])
        )
    return Result.from_kernel(scene, out)


def turned_round_note(scene: Scene, status: int) -> str:
    """For a scene refused as not approaching after its normal was turned
    round (conventions: n·(r1 - r2) > 0 is used), why it was turned and what
    that means; "" otherwise."""
    leaf = scene.leaves.get("impact.normal_angle")
    if status != STATUS_NOT_APPROACHING or leaf is None or leaf.nominal == scene.impact.normal_angle:
        return ""
    return (
        f"; impact.normal_angle = {leaf.nominal:g} deg was turned round to "
        f"{scene.impact.normal_angle:g} deg because the impact points put the centres of gravity "
        "on the other sides (vehicle 2's behind vehicle 1's along the normal as given), and with "
        "the turned normal the vehicles separate; check the impact points (vectors from each "
        "centre of gravity to the impact centre) as well as the angle"
    )


def overflow_error(scene: Scene, status: int) -> SceneError | None:
    """For a solve that overflowed (status 5), a SceneError naming the input
    whose magnitude is furthest outside :data:`SAFE_MAGNITUDE` (a velocity of
    1e308, a subnormal mass of 1e-320); None for another status or when every
    non-zero input is within it."""
    if status != STATUS_OVERFLOW:
        return None
    low, high = (math.log10(bound) for bound in SAFE_MAGNITUDE)
    worst, beyond = None, 0.0
    for path, leaf in scene.leaves.items():
        size = abs(leaf.nominal)
        if size == 0.0 or not math.isfinite(size):
            continue
        excess = max(math.log10(size) - high, low - math.log10(size))
        if excess > beyond:
            worst, beyond = path, excess
    if worst is None:
        return None
    value = scene.leaves[worst].nominal
    size = "large" if abs(value) > 1.0 else "small"
    return SceneError(
        f"{value:g} is too {size}: the results of the impact are not finite (overflow); "
        f"keep every input between {SAFE_MAGNITUDE[0]:g} and {SAFE_MAGNITUDE[1]:g} "
        "in magnitude (scene units)",
        worst,
    )


def status_reason(status: int) -> str:
    """A one-line explanation of a non-zero kernel status, with a hint where one helps."""
    reason = f"cannot solve the scene: {describe_status(status)}"
    hint = _HINTS.get(status)
    return f"{reason}; {hint}" if hint else reason
