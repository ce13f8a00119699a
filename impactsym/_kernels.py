"""The runtime's door to generated/: which kernel serves which scene.

A single scene runs the kernel's plain-Python twin (`.py_func`): the same
generated code, with no JIT compile. Batches run the numba drivers: the serial
twin below `SERIAL_BELOW` rows (a `prange` launch costs more than it saves),
the parallel one above.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import generated

if getattr(generated, "IMPACTSYM_GENERATED", None) != "impactsym":
    raise ImportError(
        f"the module 'generated' at {getattr(generated, '__file__', '?')} is not "
        "impactsym's generated kernels (another package named 'generated' shadows it)"
    )

import numpy as np  # noqa: E402

from generated import (  # noqa: E402
    crash3, delta_v, inverse, particle, planar, presets, reconstruct, report,
)
from generated.presets import COEFFICIENT_INPUTS, PRESETS  # noqa: E402

SERIAL_BELOW = 64

OUTPUTS = ("V1x", "V1y", "W1", "V2x", "V2y", "W2", "Pn", "Pt", "M",
           "mu", "mu_c", "dV1", "dV2", "TL", "TLn", "TLt", "TLm")


@dataclass(frozen=True)
class KernelSet:
    """One generated kernel: per-scene function, batch drivers, names."""

    scene: Callable
    batch: Callable
    serial: Callable
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]


def _kernel_set(module, name: str) -> KernelSet:
    upper = name.upper()
    return KernelSet(
        scene=getattr(module, name),
        batch=getattr(module, f"{name}_batch"),
        serial=getattr(module, f"{name}_batch_serial"),
        inputs=getattr(module, f"{upper}_INPUTS"),
        outputs=getattr(module, f"{upper}_OUTPUTS"),
    )


KERNELS = {
    ("rigid", False): _kernel_set(planar, "rigid"),
    ("rigid", True): _kernel_set(planar, "rigid_critical"),
    ("particle", False): _kernel_set(particle, "particle"),
    ("particle", True): _kernel_set(particle, "particle_critical"),
    ("impac_sideswipe", False): _kernel_set(presets, "impac_sideswipe"),
}

DELTA_V = _kernel_set(delta_v, "delta_v_from_energy")

INVERSE = {
    "rigid": _kernel_set(inverse, "rigid_inverse"),
    "particle": _kernel_set(inverse, "particle_inverse"),
}
RECONSTRUCT = _kernel_set(reconstruct, "reconstruct")

# Output tiers of solve_batch(outputs=...): each adds to the one before.
TIERS = {
    "velocities": OUTPUTS[:6],
    "impulses": OUTPUTS[:13],
    "energy": OUTPUTS,
}


def requested_outputs(outputs) -> tuple[tuple[str, ...], str]:
    """(names to return, smallest tier that has them) for solve_batch's
    `outputs`: None or "all" (every output), a tier name, or a list of names."""
    if outputs is None or outputs == "all":
        return OUTPUTS, "energy"
    if isinstance(outputs, str):
        if outputs not in TIERS:
            raise ValueError(f"outputs: unknown tier {outputs!r} (use one of "
                             f"{', '.join(TIERS)}, all, or a list of output names)")
        return TIERS[outputs], outputs
    names = tuple(outputs)
    unknown = [name for name in names if name not in OUTPUTS]
    if unknown or not names:
        raise ValueError(f"outputs: unknown output {', '.join(unknown) or '(none given)'} "
                         f"(outputs are {' '.join(OUTPUTS)})")
    tier = next(t for t, have in TIERS.items() if set(names) <= set(have))
    return names, tier


INVERSE_OUTPUTS = ("v1x", "v1y", "w1", "v2x", "v2y", "w2", "Pn", "Pt", "M",
                   "mu_c", "TL", "TLn", "TLt", "TLm")

# Kernel families; the model names a scene may give, and the family each
# selects with its fixed coefficients, are generated.presets.PRESETS.
MODELS = ("rigid", "particle", "impac_sideswipe")
INVERSE_MODELS = ("rigid", "particle")

CRASH3_ENERGY = {n: _kernel_set(crash3, f"crash3_energy_{n}") for n in (2, 4, 6)}
CRASH3_DELTA_V = _kernel_set(crash3, "crash3_delta_v")
CRASH3_MOMENT_ARM = _kernel_set(crash3, "crash3_moment_arm")
CRASH3_RADIUS_OF_GYRATION = _kernel_set(crash3, "crash3_radius_of_gyration")
CRASH3_IMPLIED_PDOF = _kernel_set(crash3, "crash3_implied_pdof")
KINETIC_ENERGY = _kernel_set(report, "kinetic_energy")


def _check_model(model: str, models: tuple[str, ...] = MODELS) -> None:
    if model not in models:
        raise ValueError(f"model: unknown model {model!r} (use one of {', '.join(models)})")


def preset(model: str) -> tuple[str, dict]:
    """The kernel family of a model name of generated.presets.PRESETS and the
    coefficients it fixes, by kernel input name (``limpert`` → ``("rigid",
    {"e": 0.0, "mu": "critical", "e_m": 1.0})``); ValueError if unknown."""
    _check_model(model, tuple(PRESETS))
    row = PRESETS[model]
    return row["kernel"], {COEFFICIENT_INPUTS[k]: v for k, v in row["fixed"].items()}


def kernel_for(model: str, critical: bool) -> KernelSet:
    """The forward kernel for a model name and impulse-ratio mode; ValueError if unknown."""
    _check_model(model)
    return KERNELS[(model, bool(critical))]


def inverse_kernel_for(model: str) -> KernelSet:
    """The inverse kernel (pre-impact from post-impact) of a model."""
    _check_model(model, INVERSE_MODELS)
    return INVERSE[model]


def run_batch(ks: KernelSet, inputs: list[np.ndarray]) -> tuple[dict, np.ndarray, np.ndarray]:
    """Run a kernel's batch driver over contiguous float64 input arrays of equal
    length; returns (outputs by name, status, flags) in freshly allocated arrays."""
    n = inputs[0].shape[0]
    outs = {name: np.empty(n) for name in ks.outputs}
    status = np.empty(n, dtype=np.int32)
    flags = np.empty(n, dtype=np.int32)
    driver = ks.serial if n < SERIAL_BELOW else ks.batch
    driver(*inputs, *outs.values(), status, flags)
    return outs, status, flags


def run_one(ks: KernelSet, values: dict, outputs: tuple[str, ...]) -> dict:
    """Run one scene through a kernel's plain-Python twin (no compile).

    Returns every name of `outputs` (0.0 for a quantity the kernel's model does
    not have, NaN on a failed row) plus int `status` and `flags`."""
    *outs, status, flags = ks.scene.py_func(*[float(values[name]) for name in ks.inputs])
    result = dict(zip(ks.outputs, outs))
    for name in outputs:
        if name not in result:
            result[name] = 0.0 if status == 0 else math.nan
    result["status"], result["flags"] = int(status), int(flags)
    return result


def solve_one(model: str, critical: bool, values: dict) -> dict:
    """Solve one scene without compiling: `values` maps input names to floats
    (gamma in radians; `mu` is ignored and may be absent when `critical`).
    Returns every name of `OUTPUTS` plus int `status` and `flags`."""
    values = {"mu": 0.0, **values} if critical else values
    return run_one(kernel_for(model, critical), values, OUTPUTS)
