"""Specialised kernels: the same formulas with what a batch does not need taken out.

Three mechanical transforms of a derived :class:`Kernel`; none writes a formula
of its own, so a specialised kernel computes exactly what the kernel it comes
from computes, minus what it drops:

* :func:`normal_form`: the contact normal enters as its components (nx, ny)
  instead of the angle Γ. A batch with one Γ for every row then costs one
  cos/sin, not one per row; the emitter also writes drivers that take Γ and
  form (nx, ny) per row.
* :func:`fix_inputs`: inputs fixed to numbers (e_m = 1), propagated forward.
  An assignment that becomes a number is folded into later ones; an output
  that becomes a number is published as a constant, not computed (e_m = 1:
  M = 0 and TLm = 0, so the moment impulse disappears from the kernel).
* :func:`prune`: only some outputs. Assignments that neither those outputs, nor
  a guard (the row's status), nor a physics flag need are dropped. Flags are
  always kept: a batch that asks for final velocities only still learns that a
  row created energy.
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from .frame import gamma, nx, ny
from .kernel import Guard, IsFinite, Kernel, NotNaN

# Output tiers of the forward kernels: each adds to the one before.
# A tier is emitted as a kernel of its own only where it saves arithmetic:
# the velocities tier (benchmarks/results/performance.md). "impulses" names the
# outputs up to dV2 for solve_batch, served by the full kernel: pruned, it
# kept every operation of the full one (the energies are differences of the
# velocities it computes anyway).
TIER_VELOCITIES = ("V1x", "V1y", "W1", "V2x", "V2y", "W2")
TIER_IMPULSES = TIER_VELOCITIES + ("Pn", "Pt", "M", "mu", "mu_c", "dV1", "dV2")
TIERS = {"velocities": TIER_VELOCITIES}
# Every output tier solve_batch accepts, by the outputs it returns (the last,
# "energy", is every output of the full kernel); emitted into the registry.
REQUEST_TIERS = {"velocities": TIER_VELOCITIES, "impulses": TIER_IMPULSES}


def normal_form(kernel: Kernel) -> Kernel:
    """`kernel` with inputs (nx, ny) in place of Γ and the assignments
    nx = cos Γ, ny = sin Γ removed; the input check asks both to be finite."""
    defs = kernel.definitions()
    if defs.get(nx) != sp.cos(gamma) or defs.get(ny) != sp.sin(gamma):
        raise ValueError(f"{kernel.name}: the normal is not (cos gamma, sin gamma)")
    at = kernel.inputs.index(gamma)
    inputs = kernel.inputs[:at] + (nx, ny) + kernel.inputs[at + 1 :]
    checks = tuple(_replace_angle_check(g) for g in kernel.checks)
    blocks = tuple(
        replace(b, assigns=tuple((s, x) for s, x in b.assigns if s not in (nx, ny))) for b in kernel.blocks
    )
    return replace(kernel, inputs=inputs, checks=checks, blocks=blocks, angle=gamma)


def _replace_angle_check(guard: Guard) -> Guard:
    """IsFinite(Γ) becomes IsFinite(nx), IsFinite(ny) (cos of a non-finite
    angle is NaN, so the row status is the same)."""
    conditions = []
    for cond in guard.conditions:
        conditions += [IsFinite(nx), IsFinite(ny)] if cond == IsFinite(gamma) else [cond]
    return Guard(tuple(conditions), guard.status)


def fix_inputs(kernel: Kernel, name: str, values: dict, doc: str) -> Kernel:
    """`kernel` with the inputs of `values` fixed to those numbers.

    Assignments are substituted in order; one that evaluates to a number is
    carried forward as that number. Conditions that become True are dropped
    (one that became False would make every row fail: an error here). Outputs
    that become numbers move to `constants`."""
    known = {sym: sp.sympify(v) for sym, v in values.items()}
    blocks = []
    for block in kernel.blocks:
        assigns = []
        for sym, expr in block.assigns:
            value = expr.xreplace(known)
            if value.is_Number:
                known[sym] = value
            else:
                assigns.append((sym, value))
        blocks.append(replace(block, assigns=tuple(assigns), guard=_fixed_guard(block.guard, known)))
    outputs = tuple(s for s in kernel.outputs if s not in known)
    constants = kernel.constants + tuple(
        (kernel.public_name(s), float(known[s])) for s in kernel.outputs if s in known
    )
    flags = tuple(
        (flag, tuple(c for c in (x.xreplace(known) for x in conds) if c is not sp.false))
        for flag, conds in kernel.flags
    )
    fixed = replace(
        kernel,
        name=name,
        doc=f"{kernel.doc} {doc}",
        inputs=tuple(s for s in kernel.inputs if s not in values),
        checks=tuple(g for g in (_fixed_guard(g, known) for g in kernel.checks) if g),
        blocks=tuple(blocks),
        outputs=outputs,
        constants=constants,
        finite=tuple(s for s in kernel.finite_checked() if s not in known),
        flags=tuple((flag, conds) for flag, conds in flags if conds),
        family=kernel.family_name(),
        variant=kernel.variant + tuple((str(sym), float(v)) for sym, v in values.items()),
    )
    return prune(fixed, name, fixed.output_names() + tuple(n for n, _ in constants))


def _fixed_guard(guard: Guard | None, known: dict) -> Guard | None:
    """A guard with known values substituted; None when every condition holds."""
    if guard is None:
        return None
    kept = []
    for cond in guard.conditions:
        value = _evaluate(cond.xreplace(known))
        if value is sp.false:
            raise ValueError(f"fixing inputs makes every row fail the guard {cond}")
        if value is not sp.true:
            kept.append(value)
    return Guard(tuple(kept), guard.status) if kept else None


def _evaluate(cond):
    """A condition on numbers only, decided: IsFinite/NotNaN of a number."""
    if isinstance(cond, (IsFinite, NotNaN)) and cond.args[0].is_Number:
        return sp.true if cond.args[0].is_finite else sp.false
    return cond


def prune(kernel: Kernel, name: str, outputs: tuple[str, ...], doc: str = "", tier: str = "") -> Kernel:
    """`kernel` computing only the outputs named in `outputs` (public names),
    plus whatever its guards and flags need; `doc` is added to its docstring,
    `tier` (when given) to its registry variant."""
    keep = tuple(s for s in kernel.outputs if kernel.public_name(s) in outputs)
    needed = set(keep)
    for guard in kernel.checks:
        needed |= _symbols(guard.conditions)
    for _, conds in kernel.flags:
        needed |= _symbols(conds)
    blocks = []
    for block in reversed(kernel.blocks):
        if block.guard is not None:
            needed |= _symbols(block.guard.conditions)
        assigns = tuple((s, x) for s, x in block.assigns if s in needed)
        for _, expr in assigns:
            needed |= expr.free_symbols
        if assigns or block.guard is not None:
            blocks.append(replace(block, assigns=assigns))
    computed = {s for b in blocks for s, _ in b.assigns}
    return replace(
        kernel,
        name=name,
        doc=f"{kernel.doc} {doc}".rstrip(),
        blocks=tuple(reversed(blocks)),
        outputs=keep,
        constants=tuple((n, v) for n, v in kernel.constants if n in outputs),
        integers=tuple(s for s in kernel.integers if s in keep),
        finite=tuple(s for s in kernel.finite_checked() if s in computed),
        family=kernel.family_name(),
        variant=kernel.variant + ((("tier", tier),) if tier else ()),
    )


def _symbols(conditions) -> set:
    out = set()
    for cond in conditions:
        out |= cond.free_symbols
    return out


def tiers(kernel: Kernel) -> tuple[Kernel, ...]:
    """The pruned kernels of every tier below "all", then `kernel` itself."""
    return tuple(
        prune(kernel, f"{kernel.name}_{tier}", names, f"Outputs: {tier} only.", tier)
        for tier, names in TIERS.items()
    ) + (kernel,)
