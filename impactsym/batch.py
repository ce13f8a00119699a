"""`solve_batch`: many scenes at once through the generated numba drivers.

Columns follow conventions.md (struct of arrays, float64, angles in radians).
A bad row never stops the batch: it gets a non-zero `status` and NaN outputs.
A bad *column* (missing, wrong length, not numeric) is a whole-batch error.
"""

from __future__ import annotations

import numpy as np

from . import _kernels


def _is_dataframe(obj) -> bool:
    return type(obj).__module__.startswith("pandas") and hasattr(obj, "columns")


def _as_column(columns, name: str, n: int | None) -> np.ndarray:
    """One input column as a contiguous float64 array; a scalar is broadcast."""
    if name not in columns:
        raise ValueError(f"{name}: missing column")
    try:
        arr = np.asarray(columns[name], dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: not a numeric column ({exc})") from None
    if arr.ndim > 1:
        raise ValueError(f"{name}: must be one-dimensional, got shape {arr.shape}")
    if arr.ndim == 1 and n is not None and arr.shape[0] != n:
        raise ValueError(f"{name}: length {arr.shape[0]} differs from the other columns ({n})")
    return arr


def _row_count(columns, names) -> int:
    """The common length of the array columns (1 if all are scalars)."""
    lengths = {np.ndim(columns[k]) and len(columns[k]) for k in names if k in columns}
    lengths.discard(0)
    return max(lengths) if lengths else 1


def _critical_mode(columns) -> bool:
    """True when `mu` is the string "critical" (the sticking kernels)."""
    mu = columns["mu"] if "mu" in columns else None
    return isinstance(mu, str) and mu == "critical"


def run_columns(ks: _kernels.KernelSet, columns, outputs, placeholders=()):
    """Validate `columns` for kernel `ks`, run it, and return `outputs` plus
    `status` and `flags` as the same kind of mapping (dict or DataFrame).
    Inputs named in `placeholders` are not read (the kernel ignores them)."""
    names = [k for k in ks.inputs if k not in placeholders]
    n = _row_count(columns, names)
    inputs = [np.zeros(n) if name in placeholders else
              np.ascontiguousarray(np.broadcast_to(_as_column(columns, name, n), (n,)))
              for name in ks.inputs]
    outs, status, flags = _kernels.run_batch(ks, inputs)
    result = {name: outs[name] if name in outs else _filler(status, n) for name in outputs}
    result["status"], result["flags"] = status, flags
    if _is_dataframe(columns):
        import pandas as pd

        return pd.DataFrame(result, index=columns.index)
    return result


def solve_batch(columns, model: str = "rigid", outputs=None, engine: str = "local"):
    """Solve one scene per row with the generated kernels.

    `columns` maps input names to equal-length float64 arrays (a dict or a
    pandas DataFrame): ``m1 m2 I1 I2 v1x v1y w1 v2x v2y w2 r1x r1y r2x r2y gamma
    e mu e_m`` for the rigid model, ``m1 m2 v1x v1y v2x v2y gamma e mu`` for
    particles. Units are consistent SI (kg, m, kg·m², m/s, rad/s) or US (slug,
    ft, slug·ft², ft/s, rad/s); `gamma` (the normal angle Γ) is in radians. A
    fixed body is ``m = I = inf``. ``mu="critical"`` uses the critical impulse
    ratio (no sliding at separation) for every row; a scalar is broadcast.

    `model` is any model name a scene may give: a preset of the seed's models
    fills the coefficients it fixes, which the columns must leave out
    (``"limpert"`` and ``"impac"``: e = 0, μ = μ_c, e_m = 1; ``"macmillan"``:
    e_m = 1); ``"impac_sideswipe"`` takes a ``slip`` column in place of ``e mu
    e_m``; ``"brach"`` is ``"rigid"``.

    `outputs` selects what is computed and returned: ``"velocities"`` (``V1x
    V1y W1 V2x V2y W2``), ``"impulses"`` (those plus ``Pn Pt M mu mu_c dV1
    dV2``; ``dV1``, ``dV2`` are the delta-V magnitudes), ``"energy"`` or
    ``"all"`` or None (those plus ``TL TLn TLt TLm``), or a list of those
    names. ``status`` and ``flags`` are always returned, and the physics flags
    are always computed, whatever the tier. ``engine="dask"`` runs the same
    kernels over chunks on the active ``dask.distributed`` client (the
    ``dask`` extra); the result is identical.

    Returns the same kind of mapping with the requested outputs (float64) and
    ``status`` and ``flags`` (int32): see `impactsym.codes` for their meanings.
    """
    names, _tier = _kernels.requested_outputs(outputs)
    if engine == "dask":
        from .dask_engine import solve_batch_dask

        return solve_batch_dask(columns, model=model, outputs=outputs)
    if engine != "local":
        raise ValueError(f"engine: unknown engine {engine!r} (use local or dask)")
    family, fixed = _kernels.preset(model)
    merged = _with_fixed(columns, fixed, model) if fixed else columns
    critical = _critical_mode(merged)
    ks = _kernels.kernel_for(family, critical)
    result = run_columns(ks, merged, names, ("mu",) if critical else ())
    if merged is not columns and _is_dataframe(columns):
        import pandas as pd

        return pd.DataFrame(result, index=columns.index)
    return result


def _with_fixed(columns, fixed: dict, model: str) -> dict:
    """The columns plus the coefficients a preset fixes; a column for one of
    those is an error (it would be silently replaced)."""
    for name, value in fixed.items():
        if name in columns:
            raise ValueError(f"{name}: the {model} model fixes {name} = {value}; "
                             "leave the column out")
    return {**{name: columns[name] for name in columns}, **fixed}


def _filler(status: np.ndarray, n: int) -> np.ndarray:
    """Zeros for a quantity the model does not have (particles: yaw, moment),
    NaN on the rows that were not solved."""
    out = np.zeros(n)
    out[status != 0] = np.nan
    return out
