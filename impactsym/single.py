"""Solve one scene: validate, run the generated kernel, wrap the outcome."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from generated.codes import STATUS_NOT_APPROACHING

from . import _kernels
from .codes import describe_status
from .result import Result
from .scene import Scene, SceneError, load_scene

__all__ = ["solve", "status_reason"]

_HINTS = {
    STATUS_NOT_APPROACHING: "check impact.normal_angle and the vehicles' velocities and yaw rates",
}


def solve(scene: Scene | Mapping | str | Path) -> Result:
    """Solve the impact of a scene (a :class:`Scene`, a mapping or a file path).

    Returns a :class:`Result` in the scene's units.  Raises :class:`SceneError`
    for an invalid scene or one the kernel cannot solve (not approaching,
    singular), and :class:`OSError` for a file that cannot be read.
    """
    scene = load_scene(scene)
    model, critical, values = scene.to_inputs()
    out = _kernels.solve_one(model, critical, values)
    if out["status"] != 0:
        raise SceneError(status_reason(out["status"]))
    return Result.from_kernel(scene, out)


def status_reason(status: int) -> str:
    """A one-line explanation of a non-zero kernel status, with a hint where one helps."""
    reason = f"cannot solve the scene: {describe_status(status)}"
    hint = _HINTS.get(status)
    return f"{reason}; {hint}" if hint else reason
