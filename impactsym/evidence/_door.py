"""The evidence room's one door into generated/: the emitted `evidence` kernels.

The room reaches generated/ only here, and only through the runtime's door
(impactsym._kernels.registry). `evaluate` runs one per-scene function (plain
Python, no numba) and returns its outputs by name, including the derivatives
the emitter published as the constant 0, plus ``status`` and ``flags``.
"""

from __future__ import annotations

from .._kernels import registry


def evaluate(kernel: str, values: dict) -> dict:
    """Outputs of generated kernel `kernel` (``evidence_linear``,
    ``evidence_energy``, ``evidence_vector``, ``evidence_derived``) at the
    inputs `values` (batch names: m1 ... Px Py M, radians), by name."""
    ks = registry.kernel(kernel)
    *outs, status, flags = ks.scene(*(float(values[name]) for name in ks.arguments))
    result = dict(ks.constants)
    result.update(zip(ks.outputs, outs))
    result["status"], result["flags"] = int(status), int(flags)
    return result
