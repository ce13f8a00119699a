"""What `impactsym.solve_batch` (and through it sweep and sample) asks of the laws room.

Model names: ``"kudlich_slibar"`` (full contact), ``"kudlich_slibar:sliding"``,
``"coulomb"`` (Newton), ``"coulomb:poisson"``, ``"coulomb:energetic"`` (also
``"kudlich_slibar:full"``, ``"coulomb:newton"``). The batch room runs the
kernel given here through the door's runner, as it runs a forward group.
Imports only the laws' kernel table, so `impactsym.batch` can call it
without an import cycle.
"""

from __future__ import annotations

from .._kernels import KernelSet
from ._door import extra_outputs, kernel
from .kernels import DEFAULT_LAW, LAWS, check_names

__all__ = ["split", "is_law_model", "law_kernel", "extra_outputs", "check_names"]


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


def law_kernel(model: str) -> KernelSet:
    """The registry kernel of a law model name."""
    return kernel(*split(model))
