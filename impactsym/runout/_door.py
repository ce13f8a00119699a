"""The run-out room's one way into generated/: through impactsym._kernels.

`plain()` is generated/runout.py (constants, columns, status texts; no numba),
`jit()` generated/runout_jit.py (numba, imported on first use). Only this
module names them; re-point it when the kernel door changes.
"""

from __future__ import annotations

from .. import _kernels


def plain():
    """generated/runout.py."""
    return _kernels._generated("runout")


def jit():
    """generated/runout_jit.py (imports numba; compiles on first call of a driver)."""
    return _kernels._jit_module("runout")
