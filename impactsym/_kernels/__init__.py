"""The runtime's one door into generated/: which kernel serves which scene.

Three modules: `registry` (the only importer of generated/: the emitted kernel
table, and each kernel's per-scene function and numba driver on first use),
`runner` (columns in, outputs out) and `compile` (`impactsym compile`). This
module names what the rest of the runtime asks for, all read from the
registry: the forward model families and their outputs, the output tiers,
the presets, status codes and flags, and the kernels of each job.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from .compile import compile_all
from .registry import (
    CODES,
    COEFFICIENT_INPUTS,
    FAMILY_OUTPUTS,
    PRESETS,
    TIERS_GIVEN,
    KernelSet,
    generated,
    generated_digest,
    members,
    select,
)
from .runner import as_input, run, run_batch, run_one

__all__ = [
    "CODES",
    "COEFFICIENT_INPUTS",
    "FAMILY_OUTPUTS",
    "PRESETS",
    "KernelSet",
    "as_input",
    "compile_all",
    "generated",
    "generated_digest",
    "inverse_kernel_for",
    "kernel_for",
    "plan",
    "preset",
    "requested_outputs",
    "run",
    "run_batch",
    "run_one",
    "solve_one",
]

STATUS_NOT_APPROACHING = CODES.STATUS_NOT_APPROACHING
STATUS_OVERFLOW = CODES.STATUS_OVERFLOW
STATUS_PDOF_BEYOND_LIMIT = CODES.STATUS_PDOF_BEYOND_LIMIT
FLAG_PDOF_CAPPED = CODES.FLAG_PDOF_CAPPED

#: The forward kernel families, in the order the presets first name them.
MODELS = tuple(dict.fromkeys(row["kernel"] for row in PRESETS.values()))
#: Every output of a forward solve (the union over the families).
OUTPUTS = tuple(dict.fromkeys(name for family in MODELS for name in FAMILY_OUTPUTS[family]))
#: Output tiers of solve_batch(outputs=...): each adds to the one before.
TIERS = {**TIERS_GIVEN, "energy": OUTPUTS}

INVERSE = members("inverse", "model")
INVERSE_MODELS = tuple(INVERSE)
INVERSE_OUTPUTS = FAMILY_OUTPUTS["inverse"]
DELTA_V = select("delta_v_from_energy")
RECONSTRUCT = select("reconstruct")
KINETIC_ENERGY = select("kinetic_energy")
CRASH3_ENERGY = members("crash3_energy", "points")
CRASH3_DELTA_V = select("crash3_delta_v")
CRASH3_DELTA_V_ABSORBED = select("crash3_delta_v_absorbed")
CRASH3_MOMENT_ARM = select("crash3_moment_arm")
CRASH3_RADIUS_OF_GYRATION = select("crash3_radius_of_gyration")
CRASH3_IMPLIED_PDOF = select("crash3_implied_pdof")
#: Exact first derivatives (derive/jacobian.py), by value-kernel name: the
#: value outputs plus d_<output>__d_<input> (angles in radians, inputs as the
#: batch columns). Evaluated per scene: they have no driver.
JACOBIAN = members("jacobian", "of")


def requested_outputs(outputs) -> tuple[tuple[str, ...], str]:
    """(names to return, smallest tier that has them) for solve_batch's
    `outputs`: None or "all" (every output), a tier name, or a list of names."""
    if outputs is None or outputs == "all":
        return OUTPUTS, "energy"
    if isinstance(outputs, str):
        if outputs not in TIERS:
            raise ValueError(
                f"outputs: unknown tier {outputs!r} (use one of "
                f"{', '.join(TIERS)}, all, or a list of output names)"
            )
        return TIERS[outputs], outputs
    names = tuple(outputs)
    unknown = [name for name in names if name not in OUTPUTS]
    if unknown or not names:
        raise ValueError(
            f"outputs: unknown output {', '.join(unknown) or '(none given)'} "
            f"(outputs are {' '.join(OUTPUTS)})"
        )
    tier = next(t for t, have in TIERS.items() if set(names) <= set(have))
    return names, tier


def _check_model(model: str, models: tuple[str, ...] = MODELS) -> None:
    if model not in models:
        raise ValueError(f"model: unknown model {model!r} (use one of {', '.join(models)})")


def preset(model: str) -> tuple[str, dict]:
    """The kernel family of a model name of the registry's PRESETS and the
    coefficients it fixes, by kernel input name (``limpert`` → ``("rigid",
    {"e": 0.0, "mu": "critical", "e_m": 1.0})``); ValueError if unknown."""
    _check_model(model, tuple(PRESETS))
    row = PRESETS[model]
    return row["kernel"], {COEFFICIENT_INPUTS[k]: v for k, v in row["fixed"].items()}


def kernel_for(model: str, critical: bool, no_moment: bool = False, tier: str = "energy") -> KernelSet:
    """The forward kernel of a family for an impulse-ratio mode, e_m = 1 on
    every row and an output tier: the most specialised one the registry has
    (a family or tier without a specialised kernel gets the full one).
    ValueError if the family is unknown."""
    _check_model(model)
    variant = {"critical": True} if critical else {}
    if no_moment:
        variant["e_m"] = 1.0
    if tier != "energy":
        variant["tier"] = tier
    return select(model, **variant)


@cache
def forward_columns(model: str) -> tuple[str, ...]:
    """The batch columns the forward kernels of a model name read (its
    family's general kernel: a preset's fixed coefficients among them)."""
    return kernel_for(preset(model)[0], False).inputs


def every_forward_column() -> tuple[str, ...]:
    """The columns any forward model reads."""
    return tuple(dict.fromkeys(c for family in MODELS for c in forward_columns(family)))


@dataclass(frozen=True)
class Plan:
    """What one forward batch group runs: `kernel`, the coefficients its
    preset `fixed` (kernel input → value, ``"critical"`` for mu), and the
    kernel inputs no column gives (`placeholders`: mu when mu = mu_c)."""

    kernel: KernelSet
    fixed: dict
    placeholders: tuple[str, ...]


@cache
def plan(model: str, critical: bool, e_m_one: bool, tier: str) -> Plan:
    """The plan of a group of rows of one model name: critical impulse ratio
    (asked, or fixed by the preset), e_m = 1 on every row (`e_m_one`, or fixed
    by the preset) and an output tier choose the most specialised kernel."""
    family, fixed = preset(model)
    critical = critical or fixed.get("mu") == "critical"
    no_moment = e_m_one or fixed.get("e_m") == 1.0
    return Plan(kernel_for(family, critical, no_moment, tier), fixed, ("mu",) if critical else ())


def inverse_kernel_for(model: str) -> KernelSet:
    """The inverse kernel (pre-impact from post-impact) of a model."""
    _check_model(model, INVERSE_MODELS)
    return INVERSE[model]


def solve_one(model: str, critical: bool, values: dict) -> dict:
    """Solve one scene without compiling: `values` maps input names to floats
    (gamma in radians; `mu` is ignored and may be absent when `critical`).
    Returns every name of `OUTPUTS` plus int `status` and `flags`."""
    values = {"mu": 0.0, **values} if critical else values
    return run_one(kernel_for(model, critical), values, OUTPUTS)
