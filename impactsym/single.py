"""Solve one scene: validate, run the generated kernel, wrap the outcome."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Union

from . import _kernels
from .codes import STATUS_MESSAGES
from .result import Result
from .scene import Scene, SceneError, load_scene

__all__ = ["solve"]

STATUS_NOT_APPROACHING = 3
STATUS_SINGULAR = 4

_REASONS = {
    STATUS_NOT_APPROACHING: (
        "vehicles are not approaching at the impact centre (check normal_angle: n must point "
        "from vehicle 1 toward vehicle 2, and the velocities)"
    ),
}


def solve(scene: Union[Scene, Mapping, str, Path]) -> Result:
    """Solve the impact of a scene (a :class:`Scene`, a mapping or a file path).

    Returns a :class:`Result` in the scene's units.  Raises :class:`SceneError`
    for an invalid scene or one the kernel cannot solve (not approaching,
    singular), and :class:`OSError` for a file that cannot be read.
    """
    scene = load_scene(scene)
    model, critical, values = scene.to_inputs()
    out = _kernels.solve_one(model, critical, values)
    status = int(out["status"])
    if status != 0:
        raise SceneError(status_reason(status))
    return Result.from_kernel(scene, out)


def status_reason(status: int) -> str:
    """A one-line explanation of a non-zero kernel status."""
    if status in _REASONS:
        return _REASONS[status]
    message = STATUS_MESSAGES.get(status, f"unknown kernel status {status}")
    if status == STATUS_SINGULAR:
        message += " (the impulse equations have no unique solution for these masses and inertias)"
    return f"cannot solve the scene: {message}"
