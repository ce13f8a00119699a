"""Exact first derivatives of the closed forms: Jacobian kernels for uncertainty.

A Jacobian kernel is its value kernel with derivative blocks added: after each
block of assignments ``s = f(a, b, ...)`` comes a block of
``d_s__d_x = ∂f/∂a · d_a__d_x + ∂f/∂b · d_b__d_x + ...`` for every input x
(forward-mode chain rule through the named intermediates). The derivative of
an intermediate is itself a named symbol, so the value kernel's structure (the
approach velocity formed once, 1 - e kept as one factor, the Cauchy–Binet
determinant) carries over to the derivatives and the value blocks are shared
exactly: the same formulas, the same guards, the same status. A derivative
that is identically zero is not computed: it is published as a constant 0.

Outputs: the value kernel's outputs, then ``d_<output>__d_<input>`` for every
output and input (public names: ``d_mu__d_e``, ``d_TL__d_v1x``). Angles are in
radians as in the batch columns.

The impact laws (derive/kudlich_slibar.py, derive/coulomb.py) switch between
closed forms (sliding or full contact; the Coulomb process's slip phases and
where compression and the impact end). Their derivatives are those of the
branch the scene takes: a slip direction sgn(gt) is constant on each side of
gt = 0, so its DiracDelta is taken as 0; min/max of two phase lengths give a
Heaviside (1/2 exactly at the switch, the mean of the one-sided derivatives).
Exactly on a switch the output is continuous but not differentiable.

The proofs evaluate each Jacobian kernel's formulas at random rational points
with 50-digit arithmetic and compare every derivative output with SymPy's own
derivative of the value kernel's output, expanded down to the inputs (the
closed form as a single expression, differentiated by ``sympy.diff``).
"""

from __future__ import annotations

import random
from dataclasses import replace

import sympy as sp

from . import coulomb, crash3, inverse, kudlich_slibar, particle, planar, reconstruct
from .kernel import Block, Kernel, real

DIGITS = 50
# Agreement demanded of the 50-digit evaluations (relative to the larger of
# |derivative| and 1e-12 of the output's scale): 35 digits.
PROOF_TOLERANCE = sp.Float("1e-35", DIGITS)


def derivative_name(output: str, wrt: str) -> str:
    """The output column of ∂output/∂wrt (public names: ``d_TL__d_v1x``)."""
    return f"d_{output}__d_{wrt}"


def _tangent_symbol(sym: sp.Symbol, wrt: sp.Symbol) -> sp.Symbol:
    return real(derivative_name(Kernel.public_name(sym), wrt.name))


def jacobian_kernel(
    base: Kernel, name: str | None = None, wrt: tuple | None = None, family: str = "jacobian"
) -> Kernel:
    """`base` plus the exact derivatives of its outputs with respect to its inputs
    (or to the inputs `wrt` only), in the registry's `family` (the Jacobians of
    the value kernels by default; a family whose kernels carry their own
    derivatives, such as the evidence fit's, names itself).

    Blocks that only feed the physics flags (the flag tolerances, sums of
    absolute values) get no derivative blocks: no output depends on them."""
    wrt = tuple(base.inputs) if wrt is None else tuple(wrt)
    tangents = {x: {x: sp.Integer(1)} for x in wrt}
    needed = _needed_by_outputs(base)
    blocks = []
    for block in base.blocks:
        blocks.append(block)
        derived = []
        for sym, expr in block.assigns:
            if sym not in needed:
                continue
            row = _chain_rule(expr, tangents)
            tangents[sym] = {}
            for x, value in row.items():
                dsym = _tangent_symbol(sym, x)
                derived.append((dsym, value))
                tangents[sym][x] = dsym
        if derived:
            label = f"d/d(inputs) of: {block.equation}" if block.equation else ""
            blocks.append(Block(tuple(derived), equation=label))
    outputs, zeros = [], []
    for out in base.outputs:
        for x in wrt:
            dsym = tangents.get(out, {}).get(x)
            if dsym is None:
                zeros.append((derivative_name(base.public_name(out), x.name), 0.0))
            else:
                outputs.append(dsym)
    return replace(
        base,
        name=name or f"{base.name}_jacobian",
        doc=f"{base.doc} With exact first derivatives d_<output>__d_<input>.",
        blocks=tuple(blocks),
        outputs=tuple(base.outputs) + tuple(outputs),
        constants=tuple(base.constants) + tuple(zeros),
        family=family,
        variant=(("of", base.name),),
    )


def _needed_by_outputs(base: Kernel) -> set:
    """Assigned symbols some output depends on (the derivatives of the rest,
    the flag tolerances, are never used)."""
    defs = base.definitions()
    needed, stack = set(), list(base.outputs)
    while stack:
        sym = stack.pop()
        if sym in needed or sym not in defs:
            continue
        needed.add(sym)
        stack.extend(defs[sym].free_symbols)
    return needed


def branch_taken(derivative: sp.Expr) -> sp.Expr:
    """A derivative on the branch a scene takes: the DiracDelta of a sign
    switch (sgn of the slip, of an impulse) is 0 off the switch."""
    return derivative.replace(sp.DiracDelta, lambda *args: sp.S.Zero)


def _chain_rule(expr: sp.Expr, tangents: dict) -> dict:
    """{x: d expr/d x} through the symbols of `expr` that carry a tangent;
    derivatives that are identically zero are left out."""
    row = {}
    for s in sorted(expr.free_symbols & tangents.keys(), key=lambda q: q.name):
        partial = branch_taken(sp.diff(expr, s))
        if partial == 0:
            continue
        for x, ds in tangents[s].items():
            row[x] = row.get(x, 0) + partial * ds
    return {x: v for x, v in row.items() if v != 0}


# The kernels with derivatives: forward (given and critical μ), inverse,
# reconstruction, CRASH3 energy (both oblique corrections: E and E_woolley are
# outputs of the same kernel), delta-V (energy dissipated or absorbed) and the
# impact laws (Kudlich–Slibar's contacts, the Coulomb process's three ends).
# Base (angle) form, every input.
BASES = (
    planar.KERNELS
    + particle.KERNELS
    + inverse.KERNELS
    + reconstruct.KERNELS
    + tuple(k for k in crash3.KERNELS if k.name.startswith("crash3_energy"))
    + tuple(
        k
        for k in crash3.KERNELS
        if k.name
        in ("crash3_delta_v", "crash3_moment_arm", "crash3_radius_of_gyration", "crash3_delta_v_absorbed")
    )
    + kudlich_slibar.KERNELS
    + coulomb.KERNELS
)
# Kernels that switch between closed forms: proved on the branch each point takes.
SWITCHING = frozenset(k.name for k in kudlich_slibar.KERNELS + coulomb.KERNELS)

KERNELS = tuple(jacobian_kernel(k) for k in BASES)


# ---------------------------------------------------------------- proofs

# Ranges of the random rational proof points, by input name (anything else:
# a number in [-3, 3]). Chosen so the guards pass for most draws; a draw that
# fails a guard is redrawn.
RANGES = {
    "m1": (1, 3),
    "m2": (1, 3),
    "I1": (1, 3),
    "I2": (1, 3),
    "mass": (1, 3),
    "inertia": (1, 3),
    "e": (sp.Rational(1, 10), sp.Rational(9, 10)),
    "e_m": (sp.Rational(1, 10), sp.Rational(9, 10)),
    "mu": (sp.Rational(-1, 2), sp.Rational(1, 2)),
    "mu_f": (0, sp.Rational(6, 5)),
    "gamma": (-1, 1),
    "alpha": (sp.Rational(-7, 10), sp.Rational(7, 10)),
    "alpha1": (-1, 1),
    "alpha2": (-1, 1),
    "A": (1, 3),
    "B": (1, 3),
    "width": (1, 3),
    "rg1": (1, 3),
    "rg2": (1, 3),
    "E": (1, 3),
    "theta1": (0, 1),
    "theta2": (2, 3),
}


def _random_point(knl: Kernel, rng: random.Random) -> dict:
    point = {}
    for x in knl.inputs:
        lo, hi = RANGES.get(x.name, (-3, 3))
        if x.name.startswith("C") and x.name[1:].isdigit():
            lo, hi = 0, 1
        point[x] = sp.Rational(lo) + (sp.Rational(hi) - sp.Rational(lo)) * sp.Rational(
            rng.randint(1, 999), 1000
        )
    return point


def _evaluate(knl: Kernel, point: dict) -> dict | None:
    """Every assignment of `knl` at `point` with DIGITS-digit arithmetic, or
    None when a guard fails there."""
    values = dict(point)
    for block in knl.blocks:
        for sym, expr in block.assigns:
            values[sym] = sp.N(expr.xreplace(values), DIGITS)
        if block.guard is not None and not all(bool(c.xreplace(values)) for c in block.guard.conditions):
            return None
    return values


def _sympy_gradients(base: Kernel):
    """Per output of `base`, a function of the inputs (mpmath numbers)
    returning SymPy's derivatives of the output, expanded down to the inputs,
    with respect to every input (`sympy.diff`, then lambdified for mpmath)."""
    funcs = {}
    for out in base.outputs:
        formula = base.expanded(out)
        grads = [branch_taken(sp.diff(formula, x)) for x in base.inputs]
        funcs[out] = sp.lambdify(base.inputs, grads, modules="mpmath", cse=True)
    return funcs


def _taken(expr: sp.Expr, values: dict) -> sp.Expr:
    """`expr` on the branch taken at `values` (50-digit values of the inputs
    and of every assigned symbol): Piecewise, Min, Max, sgn and |x| resolved."""

    def num(a):
        return sp.N(a.xreplace(values), DIGITS)

    def piecewise(*args):
        return next(branch for branch, cond in args if cond == sp.true or bool(cond.xreplace(values)))

    expr = expr.replace(sp.Piecewise, piecewise)
    expr = expr.replace(sp.Min, lambda *a: min(a, key=num)).replace(sp.Max, lambda *a: max(a, key=num))
    expr = expr.replace(sp.sign, lambda a: sp.sign(num(a)))
    return expr.replace(sp.Abs, lambda a: a if num(a) >= 0 else -a)


def _taken_gradients(base: Kernel, values: dict):
    """Per output, SymPy's derivatives of the output on the branch taken at
    `values`, expanded down to the inputs (a switching kernel's expanded
    Piecewise is too large to differentiate whole)."""
    defs = base.definitions()
    taken = {sym: _taken(expr, values) for sym, expr in defs.items()}
    funcs = {}
    for out in base.outputs:
        formula = out
        for sym in reversed(list(defs)):
            formula = formula.xreplace({sym: taken[sym]})
        grads = [branch_taken(sp.diff(formula, x)) for x in base.inputs]
        funcs[out] = sp.lambdify(base.inputs, grads, modules="mpmath", cse=True)
    return funcs


def _agrees(knl: Kernel, base: Kernel, rng: random.Random, points: int) -> bool:
    """At `points` random points, each derivative output equals SymPy's
    derivative of the base kernel's expanded output (for a switching kernel:
    of the branch the point takes)."""
    import mpmath

    checked = 0
    switching = base.name in SWITCHING
    gradients = None if switching else _sympy_gradients(base)
    for _attempt in range(50 * points):
        point = _random_point(knl, rng)
        values = _evaluate(knl, point)
        if values is None:
            continue
        if switching:
            gradients = _taken_gradients(base, values)
        with mpmath.workdps(DIGITS):
            args = [mpmath.mpf(point[x].p) / point[x].q for x in base.inputs]
            for out in base.outputs:
                scale = abs(values[out]) + 1
                for x, want in zip(base.inputs, gradients[out](*args)):
                    want = sp.Float(want, DIGITS)
                    got = values.get(_tangent_symbol(out, x), sp.Integer(0))
                    if abs(got - want) > PROOF_TOLERANCE * max(abs(want), scale):
                        return False
        checked += 1
        if checked == points:
            return True
    return False


def _cap_agrees(knl: Kernel, base: Kernel, rng: random.Random) -> bool:
    """The EDCRASH cap in a CRASH3 energy Jacobian (alpha_c = min(|α|, 45°)).
    Beyond the cap (45° < |α| < 90°, random points) every derivative with
    respect to α is exactly 0: the corrected energies no longer depend on α.
    Exactly at |α| = 45° the derivative is a kink's: the kernel returns the
    mean of the one-sided derivatives (SymPy's Heaviside(0) = 1/2), i.e. half
    of SymPy's derivative of the uncapped forms E_crush/cos²α and
    E_crush/cos α there, with the sign of α."""
    alpha = crash3.alpha
    corrected = {
        real("E"): base.expanded(real("E_crush")) / sp.cos(alpha) ** 2,
        real("E_woolley"): base.expanded(real("E_crush")) / sp.cos(alpha),
    }
    for _attempt in range(100):
        point = _random_point(knl, rng)
        beyond = dict(point)
        beyond[alpha] = sp.Rational(rng.choice((-1, 1))) * (
            sp.Rational(4, 5) + sp.Rational(rng.randint(1, 999), 1000) * sp.Rational(7, 10)
        )
        at_cap = [{**point, alpha: sign * sp.pi / 4} for sign in (1, -1)]
        values = [_evaluate(knl, p) for p in (beyond, *at_cap)]
        if any(v is None for v in values):
            continue
        ok = all(values[0].get(_tangent_symbol(out, alpha), 0) == 0 for out in base.outputs)
        for p, v in zip(at_cap, values[1:]):
            for out, formula in corrected.items():
                one_sided = sp.diff(formula, alpha).xreplace(p)
                want = sp.N(one_sided, DIGITS) / 2
                got = v[_tangent_symbol(out, alpha)]
                ok &= abs(got - want) <= PROOF_TOLERANCE * max(abs(want), 1)
        return bool(ok)
    return False


def _points(base: Kernel) -> int:
    """Proof points: more for a switching kernel (each point proves one branch)."""
    return 4 if base.name in SWITCHING else 2


def proofs():
    """(claim, passed): every Jacobian kernel's derivative outputs equal
    SymPy's derivatives of its value kernel's outputs at random points; the
    CRASH3 energy derivatives beyond and at the EDCRASH cap."""
    rng = random.Random(20261123)
    capped = [
        (
            (
                f"{knl.name}: d_E__d_alpha and d_E_woolley__d_alpha are 0 beyond the 45 deg cap "
                "and, at +-45 deg exactly, half the uncapped one-sided derivative (the mean of "
                "the two one-sided derivatives)"
            ),
            _cap_agrees(knl, base, rng),
        )
        for knl, base in zip(KERNELS, BASES)
        if base.name.startswith("crash3_energy")
    ]
    return capped + [
        (
            (
                f"{knl.name}: every d_output__d_input equals sympy.diff of the expanded "
                f"{base.name} output{' (the branch taken)' if base.name in SWITCHING else ''} at "
                f"{_points(base)} random rational points ({DIGITS} digits)"
            ),
            _agrees(knl, base, rng, points=_points(base)),
        )
        for knl, base in zip(KERNELS, BASES)
    ]
