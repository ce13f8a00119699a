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

from .. import _kernels
from ._door import LAWS, every_law_column, extra_outputs, kernel

__all__ = [
    "LAWS",
    "DEFAULT_LAW",
    "SLIP_CLASSES",
    "columns_of",
    "solve_one",
    "check_names",
]

DEFAULT_LAW = {"kudlich_slibar": "full", "coulomb": "newton"}  # conventions.md defaults
SLIP_CLASSES = ("continues", "stops", "reverses")


def columns_of(model: str, law: str) -> tuple[str, ...]:
    """The batch input columns of a law."""
    return kernel(model, law).inputs


def solve_one(model: str, law: str, values: Mapping[str, float]) -> dict:
    """One scene through the per-scene function (nothing compiles): `values`
    maps the law's columns to floats. Returns every forward output (``M =
    TLm = 0``, NaN on a failed row), the law's extra output, `status`, `flags`."""
    ks = kernel(model, law)
    out = _kernels.run_one(ks, values, _kernels.OUTPUTS)
    for key in extra_outputs(ks):
        if math.isfinite(out[key]):
            out[key] = int(out[key])
    return out


#: Columns a law batch rejects by name, with the reason (silently ignoring them would
#: hide a mistake: `mu` is not the friction).
_NOT_READ = {
    "mu": "the laws set the impulse ratio; the friction coefficient is the column mu_f",
    "e_m": "a point impulse (M = 0): moment restitution is not used",
}


def check_names(columns: Mapping) -> None:
    """ValueError (one line, naming the column) for a column no law reads
    (mu_f is accepted, and ignored, by the full contact)."""
    known = every_law_column()
    for key in columns:
        if key in _NOT_READ:
            raise ValueError(f"columns: {key!r} is not read by the impact laws ({_NOT_READ[key]})")
        if key not in known:
            raise ValueError(f"columns: unknown column {key!r} (the laws read {' '.join(known)})")
