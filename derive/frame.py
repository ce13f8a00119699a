"""Symbols, frame and shared kinematics of conventions.md, used by every model.

Scene frame (x, y); impact frame at the impact centre: normal n = (cos Γ, sin Γ)
from vehicle 1 toward vehicle 2, tangent t = (-sin Γ, cos Γ). Lower case is
initial, upper case final (seed). P is the impulse on vehicle 1, Pn = P·n,
Pt = P·t; vehicle 2 receives -P. Masses enter as inverses k = 1/m, j = 1/I so a
fixed body (m = I = inf) is exactly k = j = 0, never a large number.
"""

from __future__ import annotations

import sympy as sp

from .kernel import Block, Guard, real

# Inputs (batch column names of conventions.md).
m1, m2, I1, I2 = sp.symbols("m1 m2 I1 I2", positive=True)
v1x, v1y, w1, v2x, v2y, w2 = real("v1x v1y w1 v2x v2y w2")
r1x, r1y, r2x, r2y = real("r1x r1y r2x r2y")
gamma, e, mu, e_m = real("gamma e mu e_m")

# Inverse masses and inertias; components of the normal.
k1, k2, j1, j2 = sp.symbols("k1 k2 j1 j2", nonnegative=True)
nx, ny = real("nx ny")

# Outputs, with the seed's names.
V1x, V1y, W1, V2x, V2y, W2 = real("V1x V1y W1 V2x V2y W2")
Pn, Pt, M, Px, Py = real("Pn Pt M Px Py")
mu_c, TL, TLn, TLt, TLm = real("mu_c TL TLn TLt TLm")
mu_used = sp.Symbol("mu_used", real=True)
dV1, dV2 = real("dV1 dV2")
# Flag tolerances are sums of absolute values: non-negative, so a part that is
# identically 0 (TLm with e_m = 1) gives a flag condition SymPy decides False.
tol_energy, tol_mu = sp.symbols("tol_energy tol_mu", nonnegative=True)

# Relative motion at the impact centre: g = u2 - u1 (u: contact-point velocity),
# gn = n·g (< 0 when approaching), gt = t·g, wr = w2 - w1.
dvx, dvy, gx, gy, gn, gt, wr = real("dvx dvy gx gy gn gt wr")
# Required changes of the relative velocity components (restitution; sticking).
dgn, dgt = real("dgn dgt")

UNIT_NORMAL = nx**2 + ny**2 - 1


def inverse_masses(masses, inverses):
    """Assignments k = 1/m: exact zero for a fixed body (m = inf)."""
    return tuple((k, 1 / m) for m, k in zip(masses, inverses))


def normal_components():
    """Assignments nx = cos Γ, ny = sin Γ."""
    return ((nx, sp.cos(gamma)), (ny, sp.sin(gamma)))


def delta_v_magnitudes():
    """Assignments dV_i = |V_i - v_i| = |P|/m_i from the impulse components: no
    difference of final and initial velocities, exactly 0 for a fixed body."""
    impulse = sp.sqrt(Pn**2 + Pt**2)
    return ((dV1, k1 * impulse), (dV2, k2 * impulse))


def delta_v_magnitudes_hold(expand) -> bool:
    """Proof helper: dV_i² = |V_i - v_i|² for the expressions `expand(sym)` gives
    (a kernel's formulas with Pn, Pt kept free), modulo nx² + ny² = 1."""
    pairs = ((dV1, V1x, V1y, v1x, v1y), (dV2, V2x, V2y, v2x, v2y))
    return all(
        reduce_unit_normal(expand(dv) ** 2 - (expand(vx) - ix) ** 2 - (expand(vy) - iy) ** 2) == 0
        for dv, vx, vy, ix, iy in pairs
    )


def to_impact_frame(ax, ay):
    """(n, t) components of a scene-frame vector (ax, ay)."""
    return ax * nx + ay * ny, ay * nx - ax * ny


def to_scene_frame(an, at):
    """(x, y) components of an impact-frame vector (an, at)."""
    return an * nx - at * ny, an * ny + at * nx


def approach_guard() -> Guard:
    """The vehicles must approach at the impact centre: n·(u2 - u1) < 0."""
    return Guard((sp.StrictLessThan(gn, 0),), "NOT_APPROACHING")


# A flag is raised only when a quantity is beyond its bound by more than its
# own rounding error (16 units in the last place of the terms it is made of):
# a result that is exactly on the bound (μ = μ_max in the seed's Table 2, or
# T_L = 0 at e = 1) must not be flagged because of the last bit.
ROUNDING = sp.Rational(1, 2**48)


def physics_flags(energy_parts, work_terms, mu_used=mu_used, restitution=None):
    """The block of flag tolerances and the conditions for the flag bits of
    conventions.md on a solved row.

    Energy created: TL or any of its parts below -ROUNDING·E, where E is the
    sum of |work terms| (|Pn·gn| + |Pt·gt| (+ |M·wr|)) the parts are built from.
    Tensile normal impulse: Pn ≥ 0 (a compressive impulse on vehicle 1 points
    along -n). μ beyond critical: μ not between 0 and μ_c (either sign), by
    more than ROUNDING·(1 + |μ_c|) (an absolute floor for bounds near 0). With `restitution` (a kernel that takes e):
    e outside [0, 1], which the equations solve but no collision has (e < 0
    leaves the vehicles moving into each other, e > 1 creates energy).
    """
    tolerances = Block(
        (
            (tol_energy, ROUNDING * sum(sp.Abs(a * b) for a, b in work_terms)),
            # μ and μ_c are ratios of an impulse to Pn: each is rounded on the
            # scale of the impulses, so absolutely by about ROUNDING·(1 + |μ_c|)
            # however small the ratio (μ = -3e-16 beside μ_c = -1.75e-16 is 0).
            (tol_mu, ROUNDING * (1 + sp.Abs(mu_c))),
        ),
        equation="tolerances of the physics flags (conventions.md)",
    )
    return tolerances, (
        ("ENERGY_CREATED", tuple(sp.StrictLessThan(part, -tol_energy) for part in energy_parts)),
        ("TENSILE_IMPULSE", (sp.GreaterThan(Pn, 0),)),
        (
            "MU_BEYOND_CRITICAL",
            (
                sp.StrictLessThan(mu_used, sp.Min(0, mu_c) - tol_mu),
                sp.StrictGreaterThan(mu_used, sp.Max(0, mu_c) + tol_mu),
            ),
        ),
    ) + (
        (("E_OUT_OF_RANGE", (sp.StrictLessThan(restitution, 0), sp.StrictGreaterThan(restitution, 1))),)
        if restitution is not None
        else ()
    )


def reduce_unit_normal(expr: sp.Expr) -> sp.Expr:
    """Numerator of `expr` reduced modulo nx² + ny² = 1 (zero iff `expr` is zero
    for every unit normal, given a non-vanishing denominator)."""
    num, _ = sp.fraction(sp.together(expr))
    num = sp.expand(num)
    if num == 0:
        return num
    return sp.expand(sp.rem(num, UNIT_NORMAL, ny))
