"""Checks of single scene-file fields: each returns the value (converted) or
raises :class:`SceneError` with one line naming the field path. Shared by the
scene reader and the modules that read their own tables (CRASH3, compare)."""

from __future__ import annotations

import math
import numbers
import sys
from collections.abc import Mapping
from typing import Any

if sys.version_info >= (3, 11):
    pass
else:
    pass

from ..errors import SceneError, show_value


def require_key(data: Mapping, key: str, path: str) -> Any:
    """``data[key]``, or a ``missing`` error naming ``path.key``."""
    if key not in data:
        raise SceneError("missing", f"{path}.{key}" if path else key)
    return data[key]


def as_mapping(value: Any, path: str) -> Mapping:
    """``value`` if it is an object/table."""
    if not isinstance(value, Mapping):
        raise SceneError(f"must be an object (a table of keys), got {show_value(value)}", path)
    return value


def as_choice(value: Any, path: str, allowed: tuple[str, ...], what: str) -> str:
    """``value`` if it is one of the ``allowed`` strings (exact spelling)."""
    if not isinstance(value, str) or value not in allowed:
        options = " or ".join(f'"{option}"' for option in allowed)
        raise SceneError(f"unknown {what} {show_value(value)} (use {options})", path)
    return value


def as_flag(value: Any, path: str) -> bool:
    """``value`` if it is a bool."""
    if not isinstance(value, bool):
        raise SceneError(f"must be true or false, got {show_value(value)}", path)
    return value


def as_name(value: Any, path: str) -> str:
    """``value`` if it is a non-empty string."""
    if not isinstance(value, str) or not value.strip():
        raise SceneError(f"must be a non-empty string, got {show_value(value)}", path)
    return value


def finite_float(value: Any) -> float | None:
    """``value`` as a finite float when it is a bare real number (not a bool),
    else None (an integer too large for a float counts as infinite)."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        try:
            number = float(value)
        except OverflowError:
            return None
        if math.isfinite(number):
            return number
    return None


def as_number(value: Any, path: str) -> float:
    """``value`` as a finite float (a bare number; for tables other modules read)."""
    number = finite_float(value)
    if number is None:
        raise SceneError(f"must be a finite number, got {show_value(value)}", path)
    return number


def as_positive(value: Any, path: str) -> float:
    """``value`` as a positive finite float (masses, inertias, sizes)."""
    try:
        number = as_number(value, path)
    except SceneError:
        number = math.nan
    if number > 0.0:
        return number
    raise SceneError(f"must be a positive finite number, got {show_value(value)}", path)
