"""Quantities of the model-comparison report: the kinetic energy of the pair before impact.

The seed reports energy loss "as a percent of initial system energy" (Tables 1
and 6): the reference is the kinetic energy of both vehicles, translational
plus yaw, T = m1 |v1|²/2 + I1 w1²/2 + m2 |v2|²/2 + I2 w2²/2. A fixed body
(m = I = inf) is at rest and contributes nothing; the kernel says so with a
branch instead of forming inf·0. Particles pass I = w = 0 (an inertia may be 0
here, a mass may not).
"""

from __future__ import annotations

import sympy as sp

from .frame import I1, I2, m1, m2, v1x, v1y, v2x, v2y, w1, w2
from .kernel import Block, Guard, Kernel, finite_inputs, positive_or_fixed, real

T, T1, T2 = real("T T1 T2")


def _body_energy(m, inertia, vx, vy, w):
    """m |v|²/2 + I w²/2, or 0 for a fixed body (m = inf). The finiteness test
    is on an assumption-free copy of m: SymPy folds m < oo to True for the
    positive model symbol."""
    moving = sp.StrictLessThan(sp.Symbol(m.name), sp.oo)
    return sp.Piecewise((m * (vx**2 + vy**2) / 2 + inertia * w**2 / 2, moving), (0, True))


KERNELS = (
    Kernel(
        name="kinetic_energy",
        doc="Kinetic energy of the pair, translational plus yaw; a fixed body contributes 0.",
        inputs=(m1, m2, I1, I2, v1x, v1y, w1, v2x, v2y, w2),
        checks=(
            finite_inputs((v1x, v1y, w1, v2x, v2y, w2), (m1, m2, I1, I2)),
            positive_or_fixed((m1, m2)),
            Guard(tuple(sp.GreaterThan(sp.Symbol(i.name), 0) for i in (I1, I2)), "BAD_MASS"),
        ),
        blocks=(
            Block(
                ((T1, _body_energy(m1, I1, v1x, v1y, w1)), (T2, _body_energy(m2, I2, v2x, v2y, w2))),
                equation="kinetic energy of each vehicle, m |v|^2/2 (seed eq 16) plus yaw I w^2/2",
            ),
            Block(
                ((T, T1 + T2),),
                equation="initial system energy, the reference of energy loss percentages (seed Tables 1, 6)",
            ),
        ),
        outputs=(T, T1, T2),
    ),
)


def proofs():
    """The moving branch is each body's kinetic energy; a fixed body's is 0."""
    knl = KERNELS[0]
    moving = {sp.Symbol(m1.name): m1, sp.Symbol(m2.name): m2}
    total = knl.expanded(T).xreplace(moving)
    expected = (m1 * (v1x**2 + v1y**2) + I1 * w1**2 + m2 * (v2x**2 + v2y**2) + I2 * w2**2) / 2
    fixed = knl.expanded(T1).xreplace({sp.Symbol(m1.name): sp.oo})
    return [
        (
            "kinetic_energy: T = sum of m |v|^2/2 + I w^2/2 for moving bodies",
            sp.simplify(total - expected) == 0,
        ),
        ("kinetic_energy: a fixed body (m = inf) contributes 0", fixed == 0),
    ]
