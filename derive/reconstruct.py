"""Reconstruction: pre-impact speeds from post-impact motion and pre-impact headings.

What a reconstructionist knows: the final velocities and yaw rates (from the
spin-out analysis), the pre-impact headings θ1, θ2 (directions of travel) and
yaw rates (usually 0), masses, inertias, the impact centre and the normal
angle. Unknown: the pre-impact speeds s1, s2. Linear momentum alone gives them:

    m1 s1 h1 + m2 s2 h2 = m1 V1 + m2 V2 = p,  h_i = (cos θi, sin θi)
    s1 = (p × h2) / (m1 (h1 × h2)),   s2 = (h1 × p) / (m2 (h1 × h2)).

Then the impulse P = m1 (V1 - v1), and the coefficients the motion implies:
e = -Gn/gn, μ = Pt/Pn, the moment impulse from each vehicle's angular impulse
equation (they over-determine M: their mean is reported and their difference is
the consistency residual), e_m from moment restitution, the critical ratio for
those e and e_m, the energy loss and its parts, and the direction of the impulse
on each vehicle (the principal direction of force, PDOF).
"""

from __future__ import annotations

import sympy as sp

from . import frame as f
from . import planar
from .frame import (
    I1,
    I2,
    TL,
    W1,
    W2,
    M,
    Pn,
    Pt,
    Px,
    Py,
    TLm,
    TLn,
    TLt,
    V1x,
    V1y,
    V2x,
    V2y,
    e,
    e_m,
    gamma,
    gn,
    gt,
    j1,
    j2,
    k1,
    k2,
    m1,
    m2,
    mu,
    mu_c,
    nx,
    ny,
    r1x,
    r1y,
    r2x,
    r2y,
    v1x,
    v1y,
    v2x,
    v2y,
    w1,
    w2,
    wr,
)
from .kernel import Block, Guard, IsFinite, Kernel, finite_inputs, positive_or_fixed, real
from .planar import drx, dry, r1n, r1t, r2n, r2t

theta1, theta2 = real("theta1 theta2")
h1x, h1y, h2x, h2y, px_tot, py_tot, hcross = real("h1x h1y h2x h2y px_tot py_tot hcross")
s1, s2, M1, M2, M_residual, Gn, Gt, Wr, pdof1, pdof2, dVx, dVy = real(
    "s1 s2 M1 M2 M_residual Gn Gt Wr pdof1 pdof2 dVx dVy"
)

# Headings closer to collinear than this (|sin(θ1 - θ2)|) do not determine the
# speeds (they are amplified by 1/sin): refused.
COLLINEAR = sp.Rational(1, 2**20)
# Below this the speeds are still determined but sensitive to the headings.
SENSITIVE = sp.Rational(1, 10)

INPUTS = (m1, m2, I1, I2, V1x, V1y, W1, V2x, V2y, W2, theta1, theta2, w1, w2, r1x, r1y, r2x, r2y, gamma)
OUTPUTS = (
    s1,
    s2,
    v1x,
    v1y,
    v2x,
    v2y,
    Pn,
    Pt,
    M,
    M_residual,
    e,
    mu,
    e_m,
    mu_c,
    TL,
    TLn,
    TLt,
    TLm,
    pdof1,
    pdof2,
)


def _blocks():
    r1n_, r1t_ = f.to_impact_frame(r1x, r1y)
    r2n_, r2t_ = f.to_impact_frame(r2x, r2y)
    # Relative contact velocities with v2 - v1 (V2 - V1) formed first.
    g = planar.relative_velocity()
    G = tuple(c.xreplace({f.dvx: dVx, f.dvy: dVy, w1: W1, w2: W2}) for c in g)
    pn, pt = f.to_impact_frame(Px, Py)
    jsum = j1 + j2
    # Moment restitution (W2 - W1)(1 - e_m) = e_m M (j1 + j2) solved for e_m;
    # with no moment impulse and no final relative yaw any e_m fits: report 1.
    em_den = Wr + M * jsum
    return (
        (
            Block(
                f.inverse_masses((m1, m2, I1, I2), (k1, k2, j1, j2))
                + f.normal_components()
                + (
                    (h1x, sp.cos(theta1)),
                    (h1y, sp.sin(theta1)),
                    (h2x, sp.cos(theta2)),
                    (h2y, sp.sin(theta2)),
                    (px_tot, m1 * V1x + m2 * V2x),
                    (py_tot, m1 * V1y + m2 * V2y),
                    (drx, r1x - r2x),
                    (dry, r1y - r2y),
                    (wr, w2 - w1),
                    (Wr, W2 - W1),
                    (dVx, V2x - V1x),
                    (dVy, V2y - V1y),
                ),
                equation="frame (conventions.md); headings h_i = (cos theta_i, sin theta_i); "
                "momentum p = m1 V1 + m2 V2",
            ),
            Block(
                ((hcross, h1x * h2y - h1y * h2x), (r1n, r1n_), (r1t, r1t_), (r2n, r2n_), (r2t, r2t_)),
                Guard((sp.StrictGreaterThan(sp.Abs(hcross), COLLINEAR),), "HEADINGS_COLLINEAR"),
                equation="h1 x h2 (collinear headings do not fix the speeds); arms in the impact frame",
            ),
            Block(
                (
                    (s1, (px_tot * h2y - py_tot * h2x) / (m1 * hcross)),
                    (s2, (h1x * py_tot - h1y * px_tot) / (m2 * hcross)),
                ),
                equation="speeds from linear momentum m1 s1 h1 + m2 s2 h2 = p (seed eqs 1, 2; "
                "seed appendix eqs 1, 2), by Cramer's rule",
            ),
            Block(
                (
                    (v1x, s1 * h1x),
                    (v1y, s1 * h1y),
                    (v2x, s2 * h2x),
                    (v2y, s2 * h2y),
                    (f.dvx, s2 * h2x - s1 * h1x),
                    (f.dvy, s2 * h2y - s1 * h1y),
                ),
                equation="initial velocities v_i = s_i h_i",
            ),
            Block(
                (
                    (Px, m1 * (V1x - v1x)),
                    (Py, m1 * (V1y - v1y)),
                    (gn, f.to_impact_frame(*g)[0]),
                    (gt, f.to_impact_frame(*g)[1]),
                    (Gn, f.to_impact_frame(*G)[0]),
                    (Gt, f.to_impact_frame(*G)[1]),
                ),
                f.approach_guard(),
                equation="P = m1 (V1 - v1) (seed eqs 4, 6; seed appendix eqs 1, 2); u2 - u1 at the impact "
                "centre, before and after",
            ),
            Block(
                (
                    (Pn, pn),
                    (Pt, pt),
                    (M1, I1 * (W1 - w1) - (r1x * Py - r1y * Px)),
                    (M2, -I2 * (W2 - w2) - (r2x * Py - r2y * Px)),
                    (e, -Gn / gn),
                    # PDOF: where the impulse on each vehicle comes from (the
                    # opposite of its direction), relative to the heading, CCW, rad.
                    (pdof1, sp.atan2(-Py, -Px) - theta1),
                    (pdof2, sp.atan2(Py, Px) - theta2),
                ),
                Guard((sp.Ne(Pn, 0),), "SINGULAR"),
                equation="M_i from each angular impulse (seed appendix eq 3); e = -Gn/gn (seed eq 3); "
                "PDOF of the impulse",
            ),
            Block(
                ((M, (M1 + M2) / 2), (M_residual, M1 - M2), (mu, Pt / Pn)),
                equation="M = mean of the two angular impulse equations, M_residual their difference; "
                "mu = Pt/Pn (seed eq 5)",
            ),
            Block(
                (
                    (e_m, sp.Piecewise((1, sp.Eq(em_den, 0)), (Wr / em_den, True))),
                    (TLn, Pn * (gn + Gn) / 2),
                    (TLt, Pt * (gt + Gt) / 2),
                    (TLm, M * (wr + Wr) / 2),
                ),
                equation="moment restitution (seed appendix eq 6) solved for e_m; work of Pn, Pt, M "
                "(seed eqs 21-26, conventions.md energy)",
            ),
        )
        + planar.compliance_pieces()
        + planar.critical_ratio_blocks()
        + (Block(((TL, TLn + TLt + TLm),), equation="TL = TLn + TLt + TLm (conventions.md energy)"),)
    )


def _kernel() -> Kernel:
    masses = (m1, m2, I1, I2)
    scalars = (V1x, V1y, W1, V2x, V2y, W2, theta1, theta2, w1, w2, r1x, r1y, r2x, r2y, gamma)
    tolerances, flags = f.physics_flags((TL, TLn, TLt, TLm), ((Pn, gn), (Pt, gt), (M, wr)), mu_used=mu)
    flags = flags + (
        ("E_OUT_OF_RANGE", (sp.StrictLessThan(e, 0), sp.StrictGreaterThan(e, 1))),
        ("NEGATIVE_SPEED", (sp.StrictLessThan(s1, 0), sp.StrictLessThan(s2, 0))),
        ("HEADINGS_ILL_CONDITIONED", (sp.StrictLessThan(sp.Abs(hcross), SENSITIVE),)),
    )
    return Kernel(
        name="reconstruct",
        doc="Pre-impact speeds from post-impact motion and pre-impact headings.",
        inputs=INPUTS,
        checks=(
            finite_inputs(scalars, masses),
            positive_or_fixed(masses),
            # Both vehicles must move: a fixed body's momentum is undefined.
            Guard(tuple(IsFinite(x) for x in masses), "RECONSTRUCT_FIXED"),
        ),
        blocks=_blocks() + (tolerances,),
        outputs=OUTPUTS,
        flags=flags,
    )


KERNELS = (_kernel(),)


# ---------------------------------------------------------------- proofs


def proofs():
    """The speeds conserve linear momentum, the implied coefficients reproduce
    the finals through the forward equations (P, e, μ), and M's residual is the
    disagreement of the two angular impulse equations."""
    knl = KERNELS[0]
    keep = frozenset({nx, ny, h1x, h1y, h2x, h2y, j1, j2})
    got = {s: knl.expanded(s, keep) for s in OUTPUTS + (Px, Py, gn, gt, Gn, Gt)}
    unit_h = {h1y**2: 1 - h1x**2, h2y**2: 1 - h2x**2}

    def zero(expr):
        num = sp.expand(sp.fraction(sp.together(expr))[0])
        num = sp.expand(sp.rem(num, f.UNIT_NORMAL, ny)) if num != 0 else num
        return sp.expand(num.subs(unit_h)) == 0

    momentum = all(
        zero(m1 * (got[a] - V) + m2 * (got[b] - W2_))
        for a, b, V, W2_ in ((v1x, v2x, V1x, V2x), (v1y, v2y, V1y, V2y))
    )
    impulse = zero(got[Px] + m2 * (V2x - got[v2x])) and zero(got[Py] + m2 * (V2y - got[v2y]))
    angular = zero(I1 * (W1 - w1) - (r1x * got[Py] - r1y * got[Px]) - got[M] - got[M_residual] / 2) and zero(
        -I2 * (W2 - w2) - (r2x * got[Py] - r2y * got[Px]) - got[M] + got[M_residual] / 2
    )
    restitution = zero(got[Gn] + got[e] * got[gn])
    ratio = zero(got[Pt] - got[mu] * got[Pn])
    return [
        ("reconstruct: the speeds conserve linear momentum along the headings", momentum),
        ("reconstruct: P = m1 (V1 - v1) = -m2 (V2 - v2)", impulse),
        ("reconstruct: M ± residual/2 satisfy each angular impulse equation", angular),
        ("reconstruct: implied e and mu satisfy restitution and the impulse ratio", restitution and ratio),
    ]
