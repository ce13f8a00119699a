"""The error a bad scene raises, and how a scene value is shown in its message."""

from __future__ import annotations

import json
from typing import Any

import numpy as np

__all__ = ["SceneError", "show_value"]


class SceneError(ValueError):
    """A scene that cannot be solved; the message is one line.

    ``field`` is the path of the offending entry (``"vehicles[1].mass"``) or
    ``None`` when the problem is not tied to one field (a malformed file, a
    scene the kernel rejects).
    """

    def __init__(self, message: str, field: str | None = None):
        self.field = field
        text = f"{field}: {message}" if field else message
        super().__init__(" ".join(text.split()))


def show_value(value: Any) -> str:
    """A short, one-line rendering of a scene value for error messages."""
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape}"
    if isinstance(value, str):
        text = repr(value)
    else:
        try:
            text = json.dumps(value)
        except (TypeError, ValueError):
            text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
