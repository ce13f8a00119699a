"""The run-out room's one way into generated/: through the kernel door's registry.

`plain()` is generated/runout.py (constants, columns, status texts; no numba),
`jit()` generated/runout_jit.py (numba, imported on first use). Only this
module names them.
"""

from __future__ import annotations

from .._kernels import registry


def plain():
    """generated/runout.py."""
    return registry.module("runout")


def jit():
    """generated/runout_jit.py (imports numba; compiles on first call of a driver)."""
    return registry.module("runout_jit")
