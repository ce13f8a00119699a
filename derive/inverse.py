"""The inverse problem: pre-impact velocities from post-impact ones in one step
(seed ref. [21]), for the rigid-body and the particle model.

The six equations are linear in the initial and the final velocities together,
so the finals and the coefficients fix the impulse directly. Moment restitution
gives M from the final relative yaw rate Wr:  M = (1 - e_m)·Wr / (e_m·(j1 + j2)).
Restitution gives the initial normal approach from the final one: gn = -Gn/e.
The normal relative velocity changes by gn - Gn = Cnn·Pn + Cnt·Pt + Cnm·M, with
Pt = μ·Pn, which fixes Pn. Then v_i = V_i ∓ k_i·P and w_i = W_i ∓ j_i·(r_i × P + M).

Here e and e_m sit in denominators (the seed: "e appears in the denominator"):
e = 0 erases the normal approach speed and e_m = 0 the initial relative yaw
rate. Values below INVERSE_MIN are refused with a status that names the missing
information, never divided by.
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
from .kernel import Block, Guard, Kernel, finite_inputs, positive_or_fixed, real
from .planar import Cnm, Ctm, c1, c2, drx, dry, kk, r1n, r1t, r2n, r2t

# Below this, e or |e_m| leaves the answer dominated by the error of the finals
# (it is amplified by 1/e): refused, not divided by.
INVERSE_MIN = sp.Rational(1, 2**20)

dVx, dVy, Gx, Gy, Gn, Gt, Wr = real("dVx dVy Gx Gy Gn Gt Wr")
Cnn, Cnt, Ctt, Jsum, Dn, dgn_inv = real("Cnn Cnt Ctt Jsum Dn dgn_inv")

RIGID_INPUTS = (m1, m2, I1, I2, V1x, V1y, W1, V2x, V2y, W2, r1x, r1y, r2x, r2y, gamma, e, mu, e_m)
RIGID_OUTPUTS = (v1x, v1y, w1, v2x, v2y, w2, Pn, Pt, M, mu_c, TL, TLn, TLt, TLm)
PARTICLE_INPUTS = (m1, m2, V1x, V1y, V2x, V2y, gamma, e, mu)
PARTICLE_OUTPUTS = (v1x, v1y, v2x, v2y, Pn, Pt, mu_c, TL, TLn, TLt)


def _coefficient_guards(rigid: bool):
    guards = [Guard((sp.GreaterThan(e, INVERSE_MIN),), "INVERSE_E_TOO_SMALL")]
    if rigid:
        guards.append(Guard((sp.GreaterThan(sp.Abs(e_m), INVERSE_MIN),), "INVERSE_EM_TOO_SMALL"))
    return tuple(guards)


def _separating_guard() -> Guard:
    """The finals must separate at the impact centre (Gn > 0) for e > 0."""
    return Guard((sp.StrictGreaterThan(Gn, 0),), "NOT_APPROACHING")


def _rigid_blocks():
    r1n_, r1t_ = f.to_impact_frame(r1x, r1y)
    r2n_, r2t_ = f.to_impact_frame(r2x, r2y)
    G = planar.relative_velocity()
    final_rel = tuple(c.xreplace({f.dvx: dVx, f.dvy: dVy, w1: W1, w2: W2}) for c in G)
    Gn_, Gt_ = f.to_impact_frame(Gx, Gy)
    C = planar.compliance()
    px, py = f.to_scene_frame(Pn, Pt)
    # Restitution gives the initial normal approach; the initial relative
    # motion is the final one plus C·(Pn, Pt, M).
    gn_ = -Gn / e
    return (
        (
            Block(
                f.inverse_masses((m1, m2, I1, I2), (k1, k2, j1, j2))
                + f.normal_components()
                + ((dVx, V2x - V1x), (dVy, V2y - V1y), (Wr, W2 - W1), (drx, r1x - r2x), (dry, r1y - r2y)),
                Guard((sp.StrictGreaterThan(k1 + k2, 0), sp.StrictGreaterThan(j1 + j2, 0)), "SINGULAR"),
                equation="conventions.md frame: k = 1/m, j = 1/I, n = (cos gamma, sin gamma); "
                "V2 - V1, W2 - W1",
            ),
            Block(
                (
                    (r1n, r1n_),
                    (r1t, r1t_),
                    (r2n, r2n_),
                    (r2t, r2t_),
                    (Gx, final_rel[0]),
                    (Gy, final_rel[1]),
                    (Jsum, C[2, 2]),
                ),
                equation="arms in the impact frame; U2 - U1 at the impact centre at separation, "
                "U_i = V_i + W_i z x r_i",
            ),
        )
        + planar.compliance_pieces()
        + (
            Block(
                (
                    (Gn, Gn_),
                    (Gt, Gt_),
                    (Cnn, C[0, 0]),
                    (Cnt, C[0, 1]),
                    (Ctt, C[1, 1]),
                    # Moment restitution solved for M: e_m in the denominator.
                    (M, (1 - e_m) * Wr / (e_m * Jsum)),
                ),
                _separating_guard(),
                equation="compliance C (seed appendix eqs 1-3); M from moment restitution "
                "(seed appendix eq 6) solved for M",
            ),
            Block(
                ((Dn, Cnn + mu * Cnt), (dgn_inv, (1 + e) * Gn / e)),
                Guard((sp.Ne(Dn, 0),), "SINGULAR"),
                equation="restitution (seed eq 3) solved for the approach: gn - Gn = -(1 + e) Gn/e, "
                "e in the denominator",
            ),
            Block(
                ((Pn, -(dgn_inv + Cnm * M) / Dn),),
                equation="Pn from gn - Gn = Cnn Pn + Cnt Pt + Cnm M with Pt = mu Pn (seed eq 5, seed appendix eq 5)",
            ),
            Block(((Pt, mu * Pn),), equation="impulse ratio Pt = mu Pn (seed eq 5, seed appendix eq 5)"),
            Block(
                (
                    (Px, px),
                    (Py, py),
                    (c1, r1n * Pt - r1t * Pn),
                    (c2, r2n * Pt - r2t * Pn),
                    (gn, gn_),
                    (gt, Gt + Cnt * Pn + Ctt * Pt + Ctm * M),
                    (wr, Wr + Cnm * Pn + Ctm * Pt + Jsum * M),
                ),
                equation="P in the scene frame; initial relative motion (gn, gt, wr) = final + C (Pn, Pt, M)",
            ),
            Block(
                (
                    (v1x, V1x - k1 * Px),
                    (v1y, V1y - k1 * Py),
                    (v2x, V2x + k2 * Px),
                    (v2y, V2y + k2 * Py),
                    (w1, W1 - j1 * (c1 + M)),
                    (w2, W2 + j2 * (c2 + M)),
                    # (gn + Gn) = Gn (e - 1)/e: one factor, as in the forward kernels.
                    (TLn, Pn * sp.factor(gn_ + Gn) / 2),
                    (TLt, Pt * (gt + Gt) / 2),
                    (TLm, M * (wr + Wr) / 2),
                ),
                equation="initial velocities (seed appendix eqs 1-3); work of Pn, Pt, M "
                "(seed eqs 21-26, conventions.md energy)",
            ),
            Block(((TL, TLn + TLt + TLm),), equation="TL = TLn + TLt + TLm (conventions.md energy)"),
            # μ_c of the recovered scene: the forward kernel's sticking ratio.
        )
        + planar.critical_ratio_blocks()
    )


def _particle_blocks():
    gn_ = -Gn / e
    px, py = f.to_scene_frame(Pn, Pt)
    return (
        Block(
            f.inverse_masses((m1, m2), (k1, k2))
            + f.normal_components()
            + ((dVx, V2x - V1x), (dVy, V2y - V1y)),
            Guard((sp.StrictGreaterThan(k1 + k2, 0),), "SINGULAR"),
            equation="conventions.md frame: k = 1/m, n = (cos gamma, sin gamma); final relative velocity V2 - V1",
        ),
        Block(
            ((Gn, dVx * nx + dVy * ny), (Gt, dVy * nx - dVx * ny), (kk, k1 + k2)),
            _separating_guard(),
            equation="separation in the impact frame (seed Fig. 1); kk = 1/m1 + 1/m2",
        ),
        Block(
            ((Pn, -(1 + e) * Gn / (e * kk)),),
            equation="Pn from restitution (seed eq 3) and eq 4 solved for the approach: e in the denominator",
        ),
        Block(((Pt, mu * Pn),), equation="impulse ratio Pt = mu Pn (seed eq 5)"),
        # gn = -Gn/e < 0, unless it underflows (e huge): mu_c divides by it.
        Block(
            ((Px, px), (Py, py), (gn, gn_), (gt, Gt + kk * Pt)),
            Guard((sp.StrictLessThan(gn, 0),), "NOT_APPROACHING"),
            equation="P in the scene frame; initial approach gn = -Gn/e (seed eq 3), gt = Gt + kk Pt (seed eq 6)",
        ),
        Block(
            (
                (v1x, V1x - k1 * Px),
                (v1y, V1y - k1 * Py),
                (v2x, V2x + k2 * Px),
                (v2y, V2y + k2 * Py),
                (TLn, Pn * sp.factor(gn_ + Gn) / 2),
                (TLt, Pt * (gt + Gt) / 2),
                (mu_c, gt / ((1 + e) * gn)),
            ),
            equation="initial velocities (seed eqs 4, 6); work of Pn, Pt (seed eqs 21-26); mu_max (seed eq 18)",
        ),
        Block(((TL, TLn + TLt),), equation="TL = TLn + TLt (conventions.md energy)"),
    )


def _kernel(rigid: bool) -> Kernel:
    if rigid:
        name, inputs, outputs, blocks = "rigid_inverse", RIGID_INPUTS, RIGID_OUTPUTS, _rigid_blocks()
        scalars = (V1x, V1y, W1, V2x, V2y, W2, r1x, r1y, r2x, r2y, gamma, e, mu, e_m)
        masses = (m1, m2, I1, I2)
        energy, work = (TL, TLn, TLt, TLm), ((Pn, gn), (Pt, gt), (M, wr))
    else:
        name, inputs, outputs, blocks = (
            "particle_inverse",
            PARTICLE_INPUTS,
            PARTICLE_OUTPUTS,
            _particle_blocks(),
        )
        scalars = (V1x, V1y, V2x, V2y, gamma, e, mu)
        masses = (m1, m2)
        energy, work = (TL, TLn, TLt), ((Pn, gn), (Pt, gt))
    tolerances, flags = f.physics_flags(energy, work, mu_used=mu, restitution=e)
    return Kernel(
        name=name,
        doc=(
            "Pre-impact velocities from post-impact ones, "
            + ("rigid bodies (Brach)." if rigid else "particles.")
        ),
        inputs=inputs,
        checks=(finite_inputs(scalars, masses), positive_or_fixed(masses)) + _coefficient_guards(rigid),
        blocks=blocks + (tolerances,),
        outputs=outputs,
        flags=flags,
        # particles neither turn nor take a moment: the rigid outputs they lack
        constants=() if rigid else (("w1", 0.0), ("w2", 0.0), ("M", 0.0), ("TLm", 0.0)),
        family="inverse",
        variant=(("model", "rigid" if rigid else "particle"),),
    )


KERNELS = (_kernel(rigid=True), _kernel(rigid=False))


# ---------------------------------------------------------------- proofs


def _zero(expr) -> bool:
    return f.reduce_unit_normal(expr) == 0


def proofs():
    """The recovered initials and the given finals satisfy the six equations;
    the energy parts are the work of the impulse components."""
    out = []
    rigid, particle = KERNELS
    keep = planar.KEEP
    got = {s: rigid.expanded(s, keep) for s in RIGID_OUTPUTS + (Px, Py)}
    got.update({s: s for s in (V1x, V1y, W1, V2x, V2y, W2)})
    res, rel = planar.six_equation_residuals(got, sticking=False)
    out.append(
        (
            "rigid_inverse: recovered initials and given finals satisfy the six equations",
            all(_zero(r) for r in res),
        )
    )
    # The kernel's gn, gt, wr are the initial relative motion of the recovered
    # initials (expanded); given that and restitution (proven above), the
    # energy parts are the work of the impulse components (identities in atoms).
    u = [
        (got[v1x] - got[w1] * r1y, got[v1y] + got[w1] * r1x),
        (got[v2x] - got[w2] * r2y, got[v2y] + got[w2] * r2x),
    ]
    gn0, gt0 = f.to_impact_frame(u[1][0] - u[0][0], u[1][1] - u[0][1])
    kinematic = (
        _zero(rigid.expanded(gn, keep) - gn0)
        and _zero(rigid.expanded(gt, keep) - gt0)
        and _zero(rigid.expanded(wr, keep) - (got[w2] - got[w1]))
    )
    atoms = frozenset({Pn, Pt, M, gn, gt, wr, Gn, Gt, Wr})
    parts = (
        sp.simplify(rigid.expanded(TLn, atoms) - Pn * (gn + Gn) / 2 + Pn * (gn + Gn / e) / 2) == 0
        and sp.expand(rigid.expanded(TLt, atoms) - Pt * (gt + Gt) / 2) == 0
        and sp.expand(rigid.expanded(TLm, atoms) - M * (wr + Wr) / 2) == 0
    )
    out.append(("rigid_inverse: TLn, TLt, TLm are the work of Pn, Pt, M", kinematic and parts))
    pkeep = frozenset({k1, k2, nx, ny})
    pgot = {s: particle.expanded(s, pkeep) for s in PARTICLE_OUTPUTS + (Px, Py)}
    pgot.update({W1: 0, W2: 0, M: 0, w1: 0, w2: 0})
    pgot.update({s: s for s in (V1x, V1y, V2x, V2y)})
    zero_arms = {r1x: 0, r1y: 0, r2x: 0, r2y: 0}
    pres, _ = planar.six_equation_residuals(pgot, sticking=False)
    out.append(
        (
            "particle_inverse: recovered initials and given finals satisfy eqs 1-7",
            all(_zero(r.xreplace(zero_arms)) for i, r in enumerate(pres) if i not in (4, 5, 7)),
        )
    )
    return out
