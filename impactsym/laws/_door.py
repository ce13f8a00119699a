"""The laws room's one way to its kernels: the registry of `impactsym._kernels`.

derive/kudlich_slibar.py and derive/coulomb.py emit the families
``kudlich_slibar`` (variant key ``contact``) and ``coulomb`` (variant key
``restitution_law``); every law, its columns and its outputs are read from
their registry rows here, so nothing in this room names a kernel or copies
an output list.
"""

from __future__ import annotations

from functools import cache

from .. import _kernels
from .._kernels import registry

#: The registry variant key that names a law in each law family.
LAW_KEY = {"kudlich_slibar": "contact", "coulomb": "restitution_law"}
#: model -> {law: its kernel}, in registry order (K–S: its contacts).
_KERNELS = {model: registry.members(model, key) for model, key in LAW_KEY.items()}
#: model -> its laws, in registry order.
LAWS = {model: tuple(kernels) for model, kernels in _KERNELS.items()}


def kernel(model: str, law: str) -> _kernels.KernelSet:
    """The registry's kernel of a law; ValueError (one line) for an unknown one."""
    if model not in LAWS:
        raise ValueError(f"model: unknown impact law model {model!r} (use {', '.join(LAWS)})")
    if law not in LAWS[model]:
        raise ValueError(f"{model}: unknown law {law!r} (use {', '.join(LAWS[model])})")
    return _KERNELS[model][law]


def extra_outputs(ks: _kernels.KernelSet) -> tuple[str, ...]:
    """The outputs a law adds to the forward ones (``sliding``, ``slip_class``)."""
    return tuple(name for name in ks.outputs if name not in _kernels.OUTPUTS)


@cache
def every_law_column() -> tuple[str, ...]:
    """The batch columns any law reads."""
    return tuple(dict.fromkeys(c for model in LAWS for law in LAWS[model] for c in kernel(model, law).inputs))
