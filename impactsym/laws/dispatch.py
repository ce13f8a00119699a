"""The hook `impactsym.solve_batch` (and through it sweep and sample) calls for a law model.

Model names: ``"kudlich_slibar"`` (full contact), ``"kudlich_slibar:sliding"``,
``"coulomb"`` (Newton), ``"coulomb:poisson"``, ``"coulomb:energetic"`` (also
``"kudlich_slibar:full"``, ``"coulomb:newton"``). Imports only the laws'
kernel table, so `impactsym.batch` can call it without an import cycle.
"""

from __future__ import annotations

import numpy as np

from .kernels import DEFAULT_LAW, LAWS, run_batch

_EXTRA = ("sliding", "slip_class")


def split(model) -> tuple[str, str] | None:
    """(model, law) of a law model name, or None for any other model."""
    if not isinstance(model, str):
        return None
    name, _, law = model.partition(":")
    if name not in LAWS:
        return None
    law = law or DEFAULT_LAW[name]
    if law not in LAWS[name]:
        raise ValueError(f"model: unknown law {law!r} of {name} (use {', '.join(LAWS[name])})")
    return name, law


def is_law_model(model) -> bool:
    return split(model) is not None


def solve_law_batch(columns, model: str, names: tuple[str, ...]) -> dict:
    """The law's batch with the requested output `names` (the law's extra column,
    ``sliding`` or ``slip_class``, always), ``status`` and ``flags`` (int32)."""
    name, law = split(model)
    out = run_batch(name, law, columns)
    keep = {key: out[key] for key in names if key in out}
    keep.update({key: out[key] for key in _EXTRA if key in out})
    keep["status"] = out["status"].astype(np.int32)
    keep["flags"] = out["flags"].astype(np.int32)
    return keep
