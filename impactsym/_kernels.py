"""The runtime's door to generated/: which kernel serves which scene.

A single scene runs the kernel's plain-Python twin (`.py_func`): the same
generated code, with no JIT compile. Batches run the numba drivers: the serial
twin below `SERIAL_BELOW` rows (a `prange` launch costs more than it saves),
the parallel one above.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import generated

if getattr(generated, "IMPACTSYM_GENERATED", None) != "impactsym":
    raise ImportError(
        f"the module 'generated' at {getattr(generated, '__file__', '?')} is not "
        "impactsym's generated kernels (another package named 'generated' shadows it)"
    )

import numpy as np  # noqa: E402

from generated import (  # noqa: E402
    crash3, delta_v, inverse, jacobian, particle, planar, presets, reconstruct, report,
)
from generated.presets import COEFFICIENT_INPUTS, PRESETS  # noqa: E402

SERIAL_BELOW = 64

OUTPUTS = ("V1x", "V1y", "W1", "V2x", "V2y", "W2", "Pn", "Pt", "M",
           "mu", "mu_c", "dV1", "dV2", "TL", "TLn", "TLt", "TLm")


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


@dataclass(frozen=True)
class KernelSet:
    """One generated kernel: per-scene function, batch drivers, names.

    `inputs` are the batch columns, `outputs` the computed outputs and
    `constants` the outputs the kernel fixes to a number (e_m = 1: M = 0).
    A kernel in normal form (`arguments` not None) takes the normal's
    components (nx, ny) in place of `gamma`: `unit_normal` forms them, and
    `batch_normal`/`serial_normal` are its drivers that take them as given."""

    scene: Callable
    batch: Callable
    serial: Callable
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    constants: dict = field(default_factory=dict)
    arguments: tuple[str, ...] | None = None
    batch_normal: Callable | None = None
    serial_normal: Callable | None = None
    unit_normal: Callable | None = None


def _kernel_set(module, name: str) -> KernelSet:
    upper = name.upper()
    arguments = getattr(module, f"{upper}_ARGUMENTS", None)
    normal = arguments is not None
    return KernelSet(
        scene=getattr(module, name),
        batch=getattr(module, f"{name}_batch"),
        serial=getattr(module, f"{name}_batch_serial"),
        inputs=getattr(module, f"{upper}_INPUTS"),
        outputs=getattr(module, f"{upper}_OUTPUTS"),
        constants=getattr(module, f"{upper}_CONSTANTS", {}),
        arguments=arguments,
        batch_normal=getattr(module, f"{name}_batch_normal") if normal else None,
        serial_normal=getattr(module, f"{name}_batch_normal_serial") if normal else None,
        unit_normal=module.unit_normal if normal else None,
    )


def _forward_name(family: str, critical: bool, no_moment: bool, tier: str) -> str:
    """Generated kernel name: rigid[_critical][_em1][_velocities|_impulses]."""
    return (family + ("_critical" if critical else "") + ("_em1" if no_moment else "")
            + ("" if tier == "energy" else f"_{tier}"))


def _forward_kernels() -> dict:
    """(family, critical, e_m = 1, tier) → KernelSet for every forward kernel."""
    table = {}
    for module, family, moment in ((planar, "rigid", (False, True)), (particle, "particle", (False,))):
        for critical in (False, True):
            for no_moment in moment:
                for tier in TIERS:
                    name = _forward_name(family, critical, no_moment, tier)
                    table[(family, critical, no_moment, tier)] = _kernel_set(module, name)
    table[("impac_sideswipe", False, False, "energy")] = _kernel_set(presets, "impac_sideswipe")
    return table


KERNELS = _forward_kernels()

DELTA_V = _kernel_set(delta_v, "delta_v_from_energy")

INVERSE = {
    "rigid": _kernel_set(inverse, "rigid_inverse"),
    "particle": _kernel_set(inverse, "particle_inverse"),
}
RECONSTRUCT = _kernel_set(reconstruct, "reconstruct")

INVERSE_OUTPUTS = ("v1x", "v1y", "w1", "v2x", "v2y", "w2", "Pn", "Pt", "M",
                   "mu_c", "TL", "TLn", "TLt", "TLm")

# Kernel families; the model names a scene may give, and the family each
# selects with its fixed coefficients, are generated.presets.PRESETS.
MODELS = ("rigid", "particle", "impac_sideswipe")
INVERSE_MODELS = ("rigid", "particle")

CRASH3_ENERGY = {n: _kernel_set(crash3, f"crash3_energy_{n}") for n in (2, 4, 6)}
CRASH3_DELTA_V = _kernel_set(crash3, "crash3_delta_v")
CRASH3_DELTA_V_ABSORBED = _kernel_set(crash3, "crash3_delta_v_absorbed")
CRASH3_MOMENT_ARM = _kernel_set(crash3, "crash3_moment_arm")
CRASH3_RADIUS_OF_GYRATION = _kernel_set(crash3, "crash3_radius_of_gyration")
CRASH3_IMPLIED_PDOF = _kernel_set(crash3, "crash3_implied_pdof")
KINETIC_ENERGY = _kernel_set(report, "kinetic_energy")

# Exact first derivatives (derive/jacobian.py), by value-kernel name: the value
# outputs plus d_<output>__d_<input> (angles in radians, inputs as the batch
# columns, gamma rather than the normal's components).
JACOBIAN = {name: _kernel_set(jacobian, f"{name}_jacobian") for name in (
    "rigid", "rigid_critical", "particle", "particle_critical", "rigid_inverse",
    "particle_inverse", "reconstruct", "crash3_energy_2", "crash3_energy_4", "crash3_energy_6",
    "crash3_delta_v", "crash3_moment_arm", "crash3_radius_of_gyration")}


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


def kernel_for(model: str, critical: bool, no_moment: bool = False,
               tier: str = "energy") -> KernelSet:
    """The forward kernel of a kernel family for an impulse-ratio mode, e_m = 1
    (rigid only: no moment impulse) and an output tier; a family without a
    specialised kernel gets its full one. ValueError if the family is unknown."""
    _check_model(model)
    key = (model, bool(critical), bool(no_moment) and model == "rigid", tier)
    return KERNELS.get(key) or KERNELS[(model, bool(critical), False, "energy")]


def inverse_kernel_for(model: str) -> KernelSet:
    """The inverse kernel (pre-impact from post-impact) of a model."""
    _check_model(model, INVERSE_MODELS)
    return INVERSE[model]


def _as_input(value):
    """A batch input as the drivers take it: a float scalar (the same for every
    row) or a C-contiguous float64 array (one value per row)."""
    if np.ndim(value) == 0:
        return float(value)
    return np.ascontiguousarray(value, dtype=np.float64)


def run_batch(ks: KernelSet, inputs: list, n: int | None = None) -> tuple[dict, np.ndarray, np.ndarray]:
    """Run a kernel's batch driver over `inputs` (in `ks.inputs` order; each a
    float64 array of the batch length or a scalar for every row) and return
    (computed outputs by name, status, flags) in freshly allocated arrays.

    A kernel in normal form with one angle for every row gets the normal's
    components once, not per row. Below `SERIAL_BELOW` rows the serial twin
    runs (a parallel launch costs more than it saves)."""
    inputs = [_as_input(x) for x in inputs]
    if n is None:
        n = max((x.shape[0] for x in inputs if isinstance(x, np.ndarray)), default=1)
    outs = {name: np.empty(n) for name in ks.outputs}
    status = np.empty(n, dtype=np.int32)
    flags = np.empty(n, dtype=np.int32)
    serial = n < SERIAL_BELOW
    driver = ks.serial if serial else ks.batch
    if ks.arguments is not None:
        at = ks.inputs.index("gamma")
        if not isinstance(inputs[at], np.ndarray):
            inputs[at:at + 1] = ks.unit_normal.py_func(inputs[at])
            driver = ks.serial_normal if serial else ks.batch_normal
    driver(*inputs, *outs.values(), status, flags)
    return outs, status, flags


def run_one(ks: KernelSet, values: dict, outputs: tuple[str, ...]) -> dict:
    """Run one scene through a kernel's plain-Python twin (no compile).

    Returns every name of `outputs` (0.0 for a quantity the kernel's model does
    not have, NaN on a failed row) plus int `status` and `flags`."""
    args = [float(values[name]) for name in ks.inputs]
    if ks.arguments is not None:
        at = ks.inputs.index("gamma")
        args[at:at + 1] = ks.unit_normal.py_func(args[at])
    *outs, status, flags = ks.scene.py_func(*args)
    result = dict(zip(ks.outputs, outs))
    for name in outputs:
        if name not in result:
            value = ks.constants.get(name, 0.0)
            result[name] = value if status == 0 else math.nan
    result["status"], result["flags"] = int(status), int(flags)
    return result


def solve_one(model: str, critical: bool, values: dict) -> dict:
    """Solve one scene without compiling: `values` maps input names to floats
    (gamma in radians; `mu` is ignored and may be absent when `critical`).
    Returns every name of `OUTPUTS` plus int `status` and `flags`."""
    values = {"mu": 0.0, **values} if critical else values
    return run_one(kernel_for(model, critical), values, OUTPUTS)
