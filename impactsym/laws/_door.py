"""The laws room's one way into generated/: every kernel module it uses comes from here.

It goes through the runtime's door (`impactsym._kernels`), so generated/ is
still imported in one place only; when that door becomes a registry, this is
the one function to re-point.
"""

from __future__ import annotations

from .. import _kernels

#: The derive modules of the laws (generated/<name>.py and <name>_jit.py).
MODULES = ("kudlich_slibar", "coulomb")


def generated_module(name: str, jit: bool = False):
    """generated/<name>.py (plain Python, per scene) or, with `jit`,
    generated/<name>_jit.py (numba batch drivers)."""
    if name not in MODULES:
        raise ValueError(f"not a laws module: {name!r}")
    return _kernels._generated(f"{name}_jit" if jit else name)
