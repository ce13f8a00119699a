"""`solve_batch`: many scenes at once through the generated numba drivers.

Columns follow conventions.md (struct of arrays, float64, angles in RADIANS:
a heading or normal angle given in degrees by mistake gives a wrong result and
no flag). A column may also be a scalar: the same value for every row, passed
to the kernel as a scalar (never broadcast), so a constant angle costs one
cos/sin. A bad row never stops the batch: it gets a non-zero `status` and NaN
outputs. A bad *column* is a whole-batch one-line ValueError naming it, as
strict as a scene file: missing, of another length, unknown (with the nearest
name, ``restitusion: unknown column; did you mean "e" (restitution)?``), not
read by the model (``I1`` for particles), or not numbers (bool, text, None, a
structured array). A forward or inverse row whose given restitution e is
outside [0, 1] is solved (as a scene is) and the kernel marks it with the
flag `codes.FLAG_E_OUT_OF_RANGE`.

Dispatch is per whole array, never per row in Python: the rows of a batch are
grouped by (model, critical impulse ratio), each group runs the most
specialised kernel that serves it (e_m = 1 for every row of the group: the
kernel without a moment impulse; only the requested output tier), and the
results come back in the original row order.
"""

from __future__ import annotations

import numpy as np

from .. import _kernels
from .._util import CHUNK_SIZE, is_dataframe, row_count, spans
from ..laws.dispatch import check_names, extra_outputs, is_law_model, law_kernel
from ..scene import CRITICAL
from .columns import as_column, check_columns, require_mapping
from .dask_engine import map_chunks


def run_columns(ks: _kernels.KernelSet, columns, outputs, model: str, everywhere: tuple[str, ...] = ()):
    """Validate `columns` for kernel `ks` (`check_columns`: `model` names it
    in messages, ``"the particle model"``; `everywhere` are the columns of
    its other models), run it,
    and return `outputs` plus `status` and `flags` as the same kind of
    mapping (dict or DataFrame)."""
    check_columns(columns, ks.inputs, model, everywhere)
    return _like(columns, _run(ks, columns, outputs, ()))


def _run(ks: _kernels.KernelSet, columns, outputs, placeholders) -> dict:
    """Normalise each column the kernel reads (once), run it, assemble `outputs`."""
    names = [k for k in ks.inputs if k not in placeholders]
    n = row_count(columns, names)
    inputs = [0.0 if name in placeholders else as_column(columns, name) for name in ks.inputs]
    outs, status, flags = _kernels.run(ks, inputs, n)
    return _collect(outs, status, flags, outputs)


def _collect(outs, status, flags, outputs) -> dict:
    """The requested outputs of a kernel run (its driver writes every output
    of the model's tier: computed, or a constant such as e_m = 1's M = 0 and
    particles' W1 = 0, NaN on a failed row), then status and flags."""
    result = {name: outs[name] for name in outputs}
    result["status"], result["flags"] = status, flags
    return result


def _like(columns, result: dict):
    """`result` as a DataFrame with the columns' index when they were one."""
    if is_dataframe(columns):
        import pandas as pd

        return pd.DataFrame(result, index=columns.index)
    return result


def solve_batch(columns, model="rigid", outputs=None, engine: str = "local"):
    """Solve one scene per row with the generated kernels.

    `columns` maps input names to equal-length float64 arrays or scalars (a
    dict or a pandas DataFrame): ``m1 m2 I1 I2 v1x v1y w1 v2x v2y w2 r1x r1y
    r2x r2y gamma e mu e_m`` for the rigid model, ``m1 m2 v1x v1y v2x v2y gamma
    e mu`` for particles. Units are consistent SI (kg, m, kg·m², m/s, rad/s)
    or US (slug, ft, slug·ft², ft/s, rad/s); `gamma` (the normal angle Γ) is in
    RADIANS: an angle in degrees by mistake gives a wrong speed and no flag.
    Columns are checked as a scene file is (module docstring): an unknown
    column, one the model does not read, or one that is not numbers (bool,
    text, None) is a one-line ValueError naming it; no rows give an empty
    result with every requested column. A row whose restitution e is outside
    [0, 1] is solved and flagged (FLAG_E_OUT_OF_RANGE). A fixed body is ``m = I = inf``. A scalar is the same value for
    every row. ``mu="critical"`` uses the critical impulse ratio (no sliding
    at separation); `mu` may also be an array mixing numbers and "critical".

    `model` is any model name a scene may give, or an array of them (one per
    row): a preset of the seed's models fills the coefficients it fixes
    (``"limpert"`` and ``"impac"``: e = 0, μ = μ_c, e_m = 1; ``"macmillan"``:
    e_m = 1); with one model for the batch the columns must leave those out,
    in a mixed batch their values on the preset's rows must be the fixed
    value or NaN. ``"impac_sideswipe"`` takes a ``slip`` column in place of
    ``e mu e_m``; ``"brach"`` is ``"rigid"``. Mixed batches are grouped, each
    group solved by its kernel, and returned in the original row order.

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
    names, tier = _kernels.requested_outputs(outputs)
    require_mapping(columns)
    if is_law_model(model):  # "kudlich_slibar[:contact]", "coulomb[:law]": impactsym.laws
        return _like(columns, _solve_law(columns, model, names))
    if engine == "dask":
        return solve_batch_dask(columns, model=model, outputs=outputs)
    if engine != "local":
        raise ValueError(f"engine: unknown engine {engine!r} (use local or dask)")
    models, critical = _row_models(columns, model)
    _check_forward_columns(columns, models)
    if isinstance(models, str) and not isinstance(critical, np.ndarray):
        return _like(columns, _solve_group(columns, models, critical, names, tier, mixed=False))
    return _like(columns, _solve_mixed(columns, models, critical, names, tier))


def solve_batch_dask(columns, model="rigid", outputs=None, chunk_size: int = CHUNK_SIZE):
    """`solve_batch` over chunks of ``chunk_size`` rows as dask tasks
    (`dask_engine.map_chunks`): the same arguments (``model`` a name or one
    per row) and the same result (a dict, or a DataFrame with the input's
    index) as the local engine. Each chunk is sent to the cluster ahead of
    its task, not embedded in the task graph."""
    data = {name: columns[name].to_numpy() if is_dataframe(columns) else columns[name] for name in columns}
    n = row_count({**data, "model": model})
    chunks = ((_rows(data, *span), _rows({"model": model}, *span)["model"]) for span in spans(n, chunk_size))
    parts = list(map_chunks(_solve_chunk, outputs, chunks, scatter_items=True))
    return _like(columns, {name: np.concatenate([part[name] for part in parts]) for name in parts[0]})


def _solve_chunk(outputs, chunk: tuple) -> dict:
    """A dask task: `solve_batch` with the local engine on one chunk, (columns, model)."""
    columns, model = chunk
    return solve_batch(columns, model=model, outputs=outputs, engine="local")


def _rows(columns: dict, start: int, stop: int) -> dict:
    """Rows start..stop-1 of every array column; scalars stay scalars."""
    return {name: column if np.ndim(column) == 0 else column[start:stop] for name, column in columns.items()}


def _check_forward_columns(columns, models) -> None:
    """Every column is read by the batch's model (or, in a mixed batch, by one
    of its models): `check_columns` with the forward kernels' inputs."""
    names = [models] if isinstance(models, str) else sorted(set(models.tolist()))
    everywhere = _kernels.every_forward_column()
    known = tuple(dict.fromkeys(c for name in names for c in _kernels.forward_columns(name))) or everywhere
    label = f"the {names[0]} model" if len(names) == 1 else f"the models {', '.join(names)}"
    check_columns(columns, known, label, everywhere)


def _row_models(columns, model):
    """(model name or per-row array of names, critical flag or per-row bool array)."""
    if not isinstance(model, str):
        model = np.asarray(model, dtype=object)
        if model.ndim != 1:
            raise ValueError("model: a model name or a one-dimensional array of them")
        uniq = set(model.tolist())
        if len(uniq) == 1:
            model = uniq.pop()
    mu = columns.get("mu")
    if isinstance(mu, str):
        if mu != CRITICAL:
            raise ValueError(f"mu: a number or {CRITICAL!r}, got {mu!r}")
        return model, True
    if mu is None or np.ndim(mu) == 0 or np.asarray(mu).dtype != object:
        return model, False
    arr = np.asarray(mu, dtype=object)
    crit = np.array([isinstance(v, str) for v in arr.tolist()])
    bad = {v for v in arr[crit].tolist() if v != CRITICAL}
    if bad:
        raise ValueError(f"mu: a number or {CRITICAL!r}, got {sorted(bad)[0]!r}")
    return model, bool(crit[0]) if crit.all() or not crit.any() else crit


def _solve_group(columns, model: str, critical: bool, names, tier: str, mixed: bool) -> dict:
    """Rows that share a model and impulse-ratio mode: plan → run → assemble."""
    critical = critical or _is_critical(columns.get("mu"))
    plan = _kernels.plan(model, critical, _no_moment(columns), tier)
    if plan.fixed:
        columns = _with_fixed(columns, plan.fixed, model, mixed)
    return _run(plan.kernel, columns, names, plan.placeholders)


def _solve_law(columns, model: str, names) -> dict:
    """Rows of an impact law (impactsym.laws): its registry kernel, run as a
    forward group is, with the law's extra output (``sliding``, ``slip_class``:
    int64, -1 on a failed row)."""
    ks = law_kernel(model)
    check_names(columns)
    return _run(ks, columns, names + extra_outputs(ks), ())


def _is_critical(mu) -> bool:
    return isinstance(mu, str) and mu == CRITICAL


def _no_moment(columns) -> bool:
    """True when e_m = 1 on every row: the kernel without a moment impulse
    serves the whole group (a group with any other e_m runs the general one)."""
    if "e_m" not in columns or isinstance(columns["e_m"], str):
        return False
    em = np.asarray(columns["e_m"])
    if em.dtype.kind not in "fiu":
        return False
    # The first row decides most batches without a pass over the column; then
    # two reductions without temporaries (a NaN makes min and max NaN: not 1).
    return bool(em.flat[0] == 1.0 and em.min() == 1.0 and em.max() == 1.0) if em.size else True


def _solve_mixed(columns, models, critical, names, tier: str) -> dict:
    """Group rows by (model, critical), solve each group, scatter back in order."""
    n = row_count(columns)
    model_rows = np.broadcast_to(np.asarray(models, dtype=object), (n,))
    crit_rows = np.broadcast_to(np.asarray(critical, dtype=bool), (n,))
    keys = np.array([f"{m}\0{int(c)}" for m, c in zip(model_rows.tolist(), crit_rows.tolist())])
    result = {name: np.empty(n) for name in names}
    result["status"] = np.empty(n, dtype=np.int32)
    result["flags"] = np.empty(n, dtype=np.int32)
    for key in np.unique(keys):
        rows = np.flatnonzero(keys == key)
        model, crit = key.split("\0")
        part = {k: _take(columns[k], rows, k) for k in columns}
        if crit == "1":
            part["mu"] = CRITICAL
        solved = _solve_group(part, model, crit == "1", names, tier, mixed=True)
        for name, values in solved.items():
            result[name][rows] = values
    return result


def _take(column, rows: np.ndarray, name: str):
    """The group's rows of a column; a scalar stays a scalar."""
    if isinstance(column, str) or np.ndim(column) == 0:
        return column
    arr = np.asarray(column)
    if arr.dtype == object and name == "mu":
        arr = arr[rows]
        return np.array([np.nan if isinstance(v, str) else v for v in arr.tolist()], dtype=float)
    return arr[rows]


def _with_fixed(columns, fixed: dict, model: str, mixed: bool) -> dict:
    """The columns plus the coefficients a preset fixes. With one model for the
    batch a column for one of those is an error (it would be silently
    replaced); in a mixed batch its values on these rows must be the fixed
    value or NaN."""
    for name, value in fixed.items():
        if name not in columns:
            continue
        if not mixed or not _matches(columns[name], value):
            raise ValueError(
                f"{name}: the {model} model fixes {name} = {value}; "
                "leave the column out" + (" or give that value or NaN" if mixed else "")
            )
    return {**{name: columns[name] for name in columns}, **fixed}


def _matches(column, value) -> bool:
    """Every entry of the column is `value` or NaN ("critical" for μ = μ_c)."""
    if isinstance(value, str):
        return (
            isinstance(column, str)
            and column == value
            or (np.ndim(column) > 0 and bool(np.all(np.isnan(np.asarray(column, dtype=float)))))
        )
    arr = np.asarray(column, dtype=float)
    return bool(np.all((arr == value) | np.isnan(arr)))
