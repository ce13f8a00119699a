"""The evidence room's one door into generated/: the emitted `evidence` kernels.

Only this module reaches generated/ (through impactsym._kernels, the runtime's
door). `evaluate` runs one per-scene function (plain Python, no numba) and
returns its outputs by name, including the derivatives the emitter published
as the constant 0, plus ``status`` and ``flags``.
"""

from __future__ import annotations

import functools

from .. import _kernels


@functools.cache
def _module():
    return _kernels._generated("evidence")


def evaluate(kernel: str, values: dict) -> dict:
    """Outputs of generated kernel `kernel` (``evidence_linear``,
    ``evidence_energy``, ``evidence_vector``, ``evidence_derived``) at the
    inputs `values` (batch names: m1 ... Px Py M, radians), by name."""
    module = _module()
    row = module.MANIFEST[kernel]
    *outs, status, flags = getattr(module, kernel)(*(float(values[name]) for name in row["columns"]))
    result = dict(row["constants"])
    result.update(zip(row["outputs"], outs))
    result["status"], result["flags"] = int(status), int(flags)
    return result
