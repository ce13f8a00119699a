"""Batch columns: checked as strictly as a scene file, then normalised once.

A column is a float (a scalar column, the same for every row) or a writable
C-contiguous 1-D float64 array, as the kernels' runner takes it; `as_column`
is the one place a column is checked and converted.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping

import numpy as np

from .. import _kernels
from .._util import is_dataframe
from ..scene.casefile import unknown_key

#: Scene-file words for batch columns: a near miss of one suggests its column.
_SCENE_WORDS = {
    "restitution": "e",
    "impulse_ratio": "mu",
    "moment_restitution": "e_m",
    "normal_angle": "gamma",
    "mass": "m1",
    "yaw_inertia": "I1",
    "yaw_rate": "w1",
}


def check_columns(columns, known: tuple[str, ...], model: str, everywhere: tuple[str, ...] = ()) -> None:
    """ValueError unless ``columns`` is a mapping (or DataFrame) of columns
    that the kernel reads (``known``): a name in ``everywhere`` (read by other
    models) is "given but not used by ``model``" (``"the particle model"``), any other is unknown, with
    the nearest known name, as an unknown key of a scene file is."""
    require_mapping(columns)
    for name in columns:
        if name in known:
            continue
        if name in everywhere:
            raise ValueError(f"{name}: given but not used by {model} (its columns: {' '.join(known)})")
        raise ValueError(f"{name}: {unknown_key(str(name), known, 'column', _SCENE_WORDS)}")


def require_mapping(columns) -> None:
    """ValueError unless ``columns`` is a mapping or a DataFrame of columns."""
    if not (isinstance(columns, Mapping) or is_dataframe(columns)):
        raise ValueError(_not_a_mapping(columns))


def _not_a_mapping(columns) -> str:
    """Why ``columns`` is not a batch, and what to pass instead."""
    if isinstance(columns, np.ndarray) and columns.dtype.names:
        return (
            "columns: a structured array; pass a dict of its fields, "
            "{name: a[name] for name in a.dtype.names}, or a pandas DataFrame"
        )
    if isinstance(columns, (list, tuple)):
        return (
            "columns: a list (one scene per item?); pass a dict of columns "
            "(name -> array) or pandas.DataFrame(rows)"
        )
    return f"columns: must be a dict of columns (name -> array) or a DataFrame, got {type(columns).__name__}"


_ALL_NUMBERS = object()  # no bad element found (None itself is a bad one)


def _check_numbers(arr: np.ndarray, name: str) -> None:
    """ValueError unless ``arr`` holds real numbers: a scene file refuses
    true/false, text and null for a number, and so does a batch (NumPy would
    read True as 1.0 and "0.3" as 0.3)."""
    kind = arr.dtype.kind
    if arr.dtype.names:
        raise ValueError(
            f"{name}: a structured array, not a numeric column "
            f"(fields {', '.join(arr.dtype.names)}; pass one field)"
        )
    if kind in "fiu":
        return
    if kind == "O":
        not_numbers = (
            v for v in arr.flat if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real)
        )
        bad = next(not_numbers, _ALL_NUMBERS)
        if bad is _ALL_NUMBERS:
            return
        shown = repr(bad) if len(repr(bad)) <= 40 else repr(bad)[:37] + "..."
        raise ValueError(f"{name}: must be numbers, got {shown} ({type(bad).__name__})")
    what = {"b": "true/false (bool)", "U": "text", "S": "bytes"}.get(kind, f"dtype {arr.dtype}")
    raise ValueError(
        f"{name}: must be numbers, got {what}; a batch, like a scene file, "
        "reads numbers only (no units, no booleans)"
    )


def as_column(columns, name: str):
    """One input column as the runner takes it: a float (a scalar column) or
    a writable C-contiguous 1-D float64 array (its length already checked by
    `row_count`)."""
    if name not in columns:
        raise ValueError(f"{name}: missing column")
    try:
        arr = np.asarray(columns[name])
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: not a numeric column ({exc})") from None
    _check_numbers(arr, name)
    if arr.ndim > 1:
        raise ValueError(f"{name}: must be one-dimensional, got shape {arr.shape}")
    return _kernels.as_input(arr)
