"""Which emitted kernel solves which law, and running it on one scene or on columns.

Batch columns (SI or US, one consistent set; angles in radians), as
conventions.md's batch API: ``m1 m2 I1 I2 v1x v1y w1 v2x v2y w2 r1x r1y r2x
r2y gamma e``, and ``mu_f`` (friction coefficient at the impact centre) for
Kudlich–Slibar's sliding contact and the Coulomb process. ``e`` is the law's
restitution (K–S: Poisson's ε). Outputs: ``V1x V1y W1 V2x V2y W2 Pn Pt M mu
mu_c dV1 dV2 TL TLn TLt TLm status flags`` (``M = TLm = 0``: a point impulse;
``mu`` the realised Pt/Pn; ``mu_c`` Brach's critical ratio at e), plus
``sliding`` (K–S: 1 where the sliding contact applied) or ``slip_class``
(Coulomb: 0 continues, 1 stops, 2 reverses).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ._door import generated_module

#: (model, law) -> (generated module, kernel name). K–S laws are its contacts.
KERNELS = {
    ("kudlich_slibar", "full"): ("kudlich_slibar", "ks_full"),
    ("kudlich_slibar", "sliding"): ("kudlich_slibar", "ks_sliding"),
    ("coulomb", "newton"): ("coulomb", "coulomb_newton"),
    ("coulomb", "poisson"): ("coulomb", "coulomb_poisson"),
    ("coulomb", "energetic"): ("coulomb", "coulomb_energetic"),
}
LAWS = {"kudlich_slibar": ("full", "sliding"), "coulomb": ("newton", "poisson", "energetic")}
DEFAULT_LAW = {"kudlich_slibar": "full", "coulomb": "newton"}
SLIP_CLASSES = ("continues", "stops", "reverses")
#: Kernel output names the runtime renames.
_RENAME = {"slide": "sliding"}
_INTEGER = ("status", "flags", "sliding", "slip_class")
#: Rows below which a batch runs the serial driver, not the parallel one.
SERIAL_BELOW = 64
#: A process's first PYTHON_BUDGET rows of a law's batches run through its per-scene
#: function (plain Python, ~20 us a row, the same bits as the drivers: tested) while its
#: numba drivers are not loaded: compiling them on a machine with an empty cache takes
#: 7-17 s (measured, shared 2-core machine), so a first small batch (a sweep of a few
#: hundred points) does not wait for it. Once used up, the drivers load.
PYTHON_BUDGET = 10_000
_python_rows: dict[str, int] = {}  # rows run in Python per generated module
_loaded: set[str] = set()  # generated modules whose drivers were called


def _entry(model: str, law: str) -> tuple:
    """(plain module, kernel name) of a law; ValueError for an unknown one."""
    if model not in LAWS:
        raise ValueError(f"model: unknown impact law model {model!r} (use {', '.join(LAWS)})")
    if law not in LAWS[model]:
        raise ValueError(f"{model}: unknown law {law!r} (use {', '.join(LAWS[model])})")
    module, name = KERNELS[(model, law)]
    return module, name


def columns_of(model: str, law: str) -> tuple[str, ...]:
    """The batch input columns of a law."""
    module, name = _entry(model, law)
    return tuple(generated_module(module).MANIFEST[name]["columns"])


def _outputs(module: str, name: str) -> tuple[str, ...]:
    return tuple(_RENAME.get(o, o) for o in generated_module(module).MANIFEST[name]["outputs"])


def _finish(out: dict) -> dict:
    """Add the point impulse's M = TLm = 0 (NaN on a failed row)."""
    failed = out["status"] != 0
    zero = np.where(failed, np.nan, 0.0) if isinstance(failed, np.ndarray) else (math.nan if failed else 0.0)
    out["M"], out["TLm"] = zero, zero
    return out


def solve_one(model: str, law: str, values: Mapping[str, float]) -> dict:
    """One scene through the per-scene function (nothing compiles): `values`
    maps the law's columns to floats. Returns every output, `status`, `flags`."""
    module, name = _entry(model, law)
    plain = generated_module(module)
    args = dict(values)
    args["nx"], args["ny"] = plain.unit_normal(float(values["gamma"]))
    row = getattr(plain, name)(*(float(args[a]) for a in plain.MANIFEST[name]["arguments"]))
    out = dict(zip(_outputs(module, name) + ("status", "flags"), row))
    for key in _INTEGER:
        if key in out and math.isfinite(out[key]):
            out[key] = int(out[key])
    return _finish(out)


#: Columns a law batch rejects by name, with the reason (silently ignoring them would
#: hide a mistake: `mu` is not the friction).
_NOT_READ = {
    "mu": "the laws set the impulse ratio; the friction coefficient is the column mu_f",
    "e_m": "a point impulse (M = 0): moment restitution is not used",
}
#: Every column some law reads (mu_f is accepted, and ignored, by the full contact).
_KNOWN = [
    "m1",
    "m2",
    "I1",
    "I2",
    "v1x",
    "v1y",
    "w1",
    "v2x",
    "v2y",
    "w2",
    "r1x",
    "r1y",
    "r2x",
    "r2y",
    "gamma",
    "e",
    "mu_f",
]


def _check_names(columns: Mapping) -> None:
    """ValueError (one line, naming the column) for a column no law reads."""
    for key in columns:
        if key in _NOT_READ:
            raise ValueError(f"columns: {key!r} is not read by the impact laws ({_NOT_READ[key]})")
        if key not in _KNOWN:
            raise ValueError(f"columns: unknown column {key!r} (the laws read {' '.join(_KNOWN)})")


def _column(columns: Mapping, key: str):
    """One input column as a float64 array (a scalar is broadcast later)."""
    if key not in columns:
        raise ValueError(f"columns: missing input column {key!r}")
    raw = np.asarray(columns[key])
    if raw.dtype.kind not in "fiu":
        raise ValueError(f"columns: {key!r} must be numbers, got {raw.dtype} values")
    value = raw.astype(np.float64, copy=False)
    if value.ndim > 1:
        raise ValueError(f"columns: {key!r} must be a 1-D array or a scalar")
    return value


def run_batch(model: str, law: str, columns: Mapping) -> dict:
    """Every row of `columns` through the law's kernel. Equal-length arrays or
    scalars; returns a dict of arrays (outputs, `status`, `flags`)."""
    module, name = _entry(model, law)
    _check_names(columns)
    names = columns_of(model, law)
    values = {key: _column(columns, key) for key in names}
    lengths = {v.shape[0] for v in values.values() if v.ndim == 1}
    if len(lengths) > 1:
        raise ValueError(f"columns: arrays of different lengths {sorted(lengths)}")
    n = lengths.pop() if lengths else 1
    values = {k: np.ascontiguousarray(np.broadcast_to(v, (n,))) for k, v in values.items()}
    outputs = _outputs(module, name)
    if module not in _loaded and _python_rows.get(module, 0) + n <= PYTHON_BUDGET:
        _python_rows[module] = _python_rows.get(module, 0) + n
        rows = [solve_one(model, law, {k: v[i] for k, v in values.items()}) for i in range(n)]
        out = {key: np.array([r[key] for r in rows], dtype=np.float64) for key in outputs + ("M", "TLm")}
        out["status"] = np.array([r["status"] for r in rows], dtype=np.int64)
        out["flags"] = np.array([r["flags"] for r in rows], dtype=np.int64)
    else:
        jit = generated_module(module, jit=True)
        outs = [np.empty(n) for _ in outputs] + [np.empty(n, dtype=np.float64), np.empty(n)]
        _loaded.add(module)
        driver = getattr(jit, f"{name}_batch" + ("_serial" if n < SERIAL_BELOW else ""))
        driver(*(values[k] for k in names), *outs)
        out = dict(zip(outputs, outs[: len(outputs)]))
        out["status"] = outs[-2].astype(np.int64)
        out["flags"] = outs[-1].astype(np.int64)
        _finish(out)
    for key in ("sliding", "slip_class"):
        if key in out:
            column = out[key]
            out[key] = np.where(np.isfinite(column), column, -1).astype(np.int64)
    return out
