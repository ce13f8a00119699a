"""Brach's general planar rigid-body impact model (seed appendix, conventions.md).

Six equations for six unknown final velocities (V1x, V1y, W1, V2x, V2y, W2):
linear and angular impulse-momentum for each body, restitution e at the impact
centre, the impulse ratio μ = Pt/Pn (or no sliding at separation, μ = μ_c), and
moment restitution (W2 - W1)(1 - e_m) = e_m·M·(1/I1 + 1/I2).

The derivation works in impulse space. The momentum equations give the change
of the relative velocity at the impact centre and of the relative yaw rate as a
linear map of (Pn, Pt, M): a symmetric compliance matrix C. Moment restitution
gives M in terms of (Pn, Pt); eliminating it leaves an effective 2x2 compliance
K and a coupling h to the initial relative yaw rate. Restitution plus the
impulse ratio (or sticking) then fix (Pn, Pt). Every quantity is a named,
rounded-once intermediate; energy loss is the work of the impulse components.
"""

from __future__ import annotations

import sympy as sp

from . import frame as f
from . import particle, specialise
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
    dgn,
    dV1,
    dV2,
    dvx,
    dvy,
    e,
    e_m,
    gamma,
    gn,
    gt,
    gx,
    gy,
    j1,
    j2,
    k1,
    k2,
    m1,
    m2,
    mu,
    mu_c,
    mu_used,
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

INPUTS = (m1, m2, I1, I2, v1x, v1y, w1, v2x, v2y, w2, r1x, r1y, r2x, r2y, gamma, e, mu, e_m)
OUTPUTS = (V1x, V1y, W1, V2x, V2y, W2, Pn, Pt, M, mu_used, mu_c, dV1, dV2, TL, TLn, TLt, TLm)

r1n, r1t, r2n, r2t = real("r1n r1t r2n r2t")
Cnn, Cnt, Ctt, Cnm, Ctm, Cmm = real("Cnn Cnt Ctt Cnm Ctm Cmm")
Knn, Knt, Ktt, hn, ht, am = real("Knn Knt Ktt hn ht am")
drx, dry, drn, drt, r12, kk, jbar, wa, wb, wc = real("drx dry drn drt r12 kk jbar wa wb wc")
bn, bt, D, Dc, s, c1, c2, cd = real("bn bt D Dc s c1 c2 cd")


def _perp(rn, rt):
    """z × r in impact-frame components: the velocity of a point at r per unit yaw rate."""
    return sp.Matrix([-rt, rn])


def _cross(rn, rt, an, at):
    """Scalar cross product r × a (frame invariant: n × t = 1)."""
    return rn * at - rt * an


def relative_velocity():
    """u2 - u1 in the scene frame from u_i = v_i + w_i (-r_iy, r_ix), written
    with v2 - v1 formed first (dvx, dvy), so equal large speeds cancel exactly."""
    u1 = sp.Matrix([v1x - w1 * r1y, v1y + w1 * r1x])
    u2 = sp.Matrix([v2x - w2 * r2y, v2y + w2 * r2x])
    g = (u2 - u1).xreplace({v2x: dvx + v1x, v2y: dvy + v1y})
    return sp.expand(g[0]), sp.expand(g[1])


def compliance():
    """The symmetric matrix C with (Δgn, Δgt, Δwr) = -C (Pn, Pt, M), derived from
    the linear and angular impulse-momentum equations of both bodies."""
    P = sp.Matrix([Pn, Pt])
    dU1 = k1 * P + j1 * (_cross(r1n, r1t, Pn, Pt) + M) * _perp(r1n, r1t)
    dU2 = -k2 * P - j2 * (_cross(r2n, r2t, Pn, Pt) + M) * _perp(r2n, r2t)
    dg = dU2 - dU1
    dwr = -j2 * (_cross(r2n, r2t, Pn, Pt) + M) - j1 * (_cross(r1n, r1t, Pn, Pt) + M)
    return -sp.Matrix([dg[0], dg[1], dwr]).jacobian([Pn, Pt, M]).applyfunc(sp.expand)


def moment_impulse():
    """M solved from moment restitution, (Wr)(1 - e_m) = e_m·M·Cmm, Wr = wr + Δwr."""
    wr_final = wr - (Cnm * Pn + Ctm * Pt + Cmm * M)
    return sp.solve(sp.Eq(wr_final * (1 - e_m), e_m * M * Cmm), M)[0]


def _frame_blocks():
    """Inverse masses, the normal, relative motion at the impact centre, and the
    pieces of the effective compliance."""
    r1n_, r1t_ = f.to_impact_frame(r1x, r1y)
    r2n_, r2t_ = f.to_impact_frame(r2x, r2y)
    drn_, drt_ = f.to_impact_frame(drx, dry)
    gx_, gy_ = relative_velocity()
    gn_, gt_ = f.to_impact_frame(gx, gy)
    C = compliance()
    return (
        Block(
            f.inverse_masses((m1, m2, I1, I2), (k1, k2, j1, j2))
            + f.normal_components()
            + (
                (dvx, v2x - v1x),
                (dvy, v2y - v1y),
                (wr, w2 - w1),
                (drx, r1x - r2x),
                (dry, r1y - r2y),
                (r12, r1x * r2y - r1y * r2x),
            ),
            Guard((sp.StrictGreaterThan(k1 + k2, 0), sp.StrictGreaterThan(j1 + j2, 0)), "SINGULAR"),
            equation="conventions.md frame: k = 1/m, j = 1/I, n = (cos gamma, sin gamma)",
        ),
        Block(
            (
                (r1n, r1n_),
                (r1t, r1t_),
                (r2n, r2n_),
                (r2t, r2t_),
                (gx, gx_),
                (gy, gy_),
                (drn, drn_),
                (drt, drt_),
                (kk, k1 + k2),
                (jbar, j1 * j2 / (j1 + j2)),
            ),
            equation="arms in the impact frame; u2 - u1 at the impact centre, u_i = v_i + w_i z x r_i",
        ),
        Block(
            (
                (gn, gn_),
                (gt, gt_),
                (Cnm, C[0, 2]),
                (Ctm, C[1, 2]),
                # 1 - e_m kept as one factor: e_m = 1 gives exactly no moment impulse.
                (am, (1 - e_m) / C[2, 2]),
                (wa, e_m * j1),
                (wb, e_m * j2),
                (wc, (1 - e_m) * jbar),
            ),
            f.approach_guard(),
            equation="compliance C from impulse-momentum (seed appendix eqs 1-3); "
            "moment restitution (seed appendix eq 6)",
        ),
    )


def effective_compliance():
    """K and h of Δ(gn, gt) = -K (Pn, Pt) - h once M is eliminated.

    Eliminating M gives K = C₂ - am·c cᵀ (C₂ the translational 2x2 block, c the
    moment column, am = (1 - e_m)/(j1 + j2)). Written that way it cancels badly
    when a yaw inertia is small (j large). The same matrix, exactly, is
        K = kk·I + e_m (j1 s1 s1ᵀ + j2 s2 s2ᵀ) + (1 - e_m)·jbar·(s1 - s2)(s1 - s2)ᵀ
    with s_i = z × r_i and jbar = j1 j2/(j1 + j2): a sum of non-negative terms for
    0 ≤ e_m ≤ 1 (derive proves the two forms equal)."""
    return {
        Knn: kk + wa * r1t**2 + wb * r2t**2 + wc * drt**2,
        Knt: -(wa * r1n * r1t + wb * r2n * r2t + wc * drn * drt),
        Ktt: kk + wa * r1n**2 + wb * r2n**2 + wc * drn**2,
        hn: am * Cnm * wr,
        ht: am * Ctm * wr,
    }


def effective_determinant():
    """det K by the Cauchy–Binet formula for kk·I + Σ w_i a_i a_iᵀ:
    kk² + kk Σ w_i |a_i|² + Σ_{i<k} w_i w_k (a_i × a_k)², where every cross
    product of s1, s2, s1 - s2 has the magnitude |r1 × r2|. No cancellation for
    0 ≤ e_m ≤ 1, unlike Knn·Ktt - Knt²."""
    arms = wa * (r1x**2 + r1y**2) + wb * (r2x**2 + r2y**2) + wc * (drx**2 + dry**2)
    return kk**2 + kk * arms + r12**2 * (wa * wb + wa * wc + wb * wc)


def compliance_pieces():
    """Assignments of the pieces K needs, from (drx, dry) and r_n, r_t already
    assigned: kk, jbar, the weights, the moment coupling am (for inverse and
    reconstruction kernels, which assemble their own frames)."""
    drn_, drt_ = f.to_impact_frame(drx, dry)
    C = compliance()
    return (
        Block(
            ((drn, drn_), (drt, drt_), (kk, k1 + k2), (jbar, j1 * j2 / (j1 + j2))),
            equation="arms r1 - r2 in the impact frame; kk = 1/m1 + 1/m2, jbar = j1 j2/(j1 + j2)",
        ),
        Block(
            (
                (am, (1 - e_m) / C[2, 2]),
                (wa, e_m * j1),
                (wb, e_m * j2),
                (wc, (1 - e_m) * jbar),
                (Cnm, C[0, 2]),
                (Ctm, C[1, 2]),
            ),
            equation="compliance C from impulse-momentum (seed appendix eqs 1-3); "
            "moment restitution (seed appendix eq 6)",
        ),
    )


def critical_ratio_blocks():
    """μ_c of a scene whose initial relative motion (gn, gt, wr) and e, e_m are
    known: the effective compliance, then the sticking ratio (Pt/Pn with zero
    final slip), with its denominator guarded."""
    return (
        Block(tuple(effective_compliance().items()), equation="effective compliance K (M eliminated)"),
        Block(
            ((bn, (1 + e) * gn - hn), (bt, gt - ht)),
            equation="K (Pn, Pt) = (bn, bt): restitution (seed eq 3) and no sliding at separation (seed eq 8)",
        ),
        Block(
            ((Dc, Ktt * bn - Knt * bt),),
            Guard((sp.Ne(Dc, 0),), "SINGULAR"),
            equation="Pn of the sticking solution (Cramer's rule, det K cancels)",
        ),
        Block(
            ((mu_c, (Knn * bt - Knt * bn) / Dc),),
            equation="mu_c = Pt/Pn of the sticking solution, the seed's mu_max (eq 18) generalised",
        ),
    )


def _impulse_blocks(sticking: bool):
    """Restitution plus impulse ratio (sliding) or zero final slip (sticking)."""
    keff = effective_compliance()
    # Restitution: Δgn = -(1 + e)·gn =: dgn; K (Pn, Pt) = (bn, bt) with
    # bn = -(dgn + hn) and, for sticking (Δgt = -gt), bt = gt - ht.
    pn_c, pt_c = (Ktt * bn - Knt * bt), (Knn * bt - Knt * bn)
    if sticking:
        denom, pn, pt = (D, effective_determinant()), pn_c / D, pt_c / D
    else:
        denom, pn, pt = (D, Knn + mu * Knt), bn / D, mu * bn / D
    return (
        Block(
            tuple(keff.items()) + ((dgn, -(1 + e) * gn),),
            equation="effective compliance K (M eliminated); restitution (seed eq 3, seed appendix eq 4)",
        ),
        Block(((bn, -(dgn + hn)), (bt, gt - ht)), equation="K (Pn, Pt) = (bn, bt)"),
        Block(
            (denom, (Dc, pn_c)),
            Guard((sp.Ne(D, 0), sp.Ne(Dc, 0)), "SINGULAR"),
            equation=(
                "no sliding at separation (seed eq 8)"
                if sticking
                else "impulse ratio Pt = mu Pn (seed eq 5, seed appendix eq 5)"
            ),
        ),
        # μ_c: the ratio Pt/Pn of the sticking solution (det K cancels).
        Block(
            ((mu_c, pt_c / Dc), (Pn, pn), (Pt, pt)),
            equation="impulses; mu_c, the seed's mu_max (eq 18) generalised",
        ),
    )


def lever_products_sticking():
    """c1 = r1 × P, c2 = r2 × P and cd = (r1 - r2) × P of the sticking impulse
    P = K⁻¹ b, by Cramer's rule: c = (bt·(K ρ)_n - bn·(K ρ)_t) / det K for
    ρ = (r_n, r_t) of r1, r2 and r1 - r2.

    With a small yaw inertia (large j_i) sticking makes P nearly parallel to
    r_i (or to r1 - r2 when both are small), so the cross product from (Pn, Pt)
    would be a small difference of large products, then multiplied by the
    large j. In K ρ the large terms drop out exactly (s_i · ρ_i = 0 and
    (s1 - s2)·(ρ1 - ρ2) = 0); the dot products left are ±(r1 × r2) = ±r12."""
    k_rho1 = (kk * r1n + r12 * (wb * r2t - wc * drt), kk * r1t + r12 * (wc * drn - wb * r2n))
    k_rho2 = (kk * r2n - r12 * (wa * r1t + wc * drt), kk * r2t + r12 * (wa * r1n + wc * drn))
    k_rhod = (kk * drn + r12 * (wa * r1t + wb * r2t), kk * drt - r12 * (wa * r1n + wb * r2n))
    return tuple((bt * kn - bn * kt) / D for kn, kt in (k_rho1, k_rho2, k_rhod))


def yaw_changes():
    """W1 - w1 = j1 (c1 + M) and W2 - w2 = -j2 (c2 + M) with M = am·s written
    out as a blend of the two limits of moment restitution:
        W1 - w1 =  e_m·j1·c1 + (1 - e_m)·(jbar·cd + wr·j1/(j1 + j2)),
        W2 - w2 = -e_m·j2·c2 + (1 - e_m)·(jbar·cd - wr·j2/(j1 + j2)).
    e_m = 1 gives exactly j1·c1 (no moment); e_m = 0 the common final yaw rate,
    where c1 + M would cancel (M ≈ -c1) and only jbar·cd, with cd = (r1 - r2) × P
    formed directly, survives large inertial weights."""
    jsum = compliance()[2, 2]
    common = 1 - e_m
    return (
        e_m * j1 * c1 + common * (jbar * cd + wr * j1 / jsum),
        -e_m * j2 * c2 + common * (jbar * cd - wr * j2 / jsum),
    )


def _final_blocks(sticking: bool):
    """Finals from the impulses, and energy loss as the work of each component."""
    px, py = f.to_scene_frame(Pn, Pt)
    gt_final = 0 if sticking else gt - (Knt * Pn + Ktt * Pt) - ht
    levers = (
        lever_products_sticking()
        if sticking
        else (_cross(r1n, r1t, Pn, Pt), _cross(r2n, r2t, Pn, Pt), _cross(drn, drt, Pn, Pt))
    )
    dw1, dw2 = yaw_changes()
    return (
        Block(
            (
                (Px, px),
                (Py, py),
                (c1, levers[0]),
                (c2, levers[1]),
                (cd, levers[2]),
                *f.delta_v_magnitudes(),
                (mu_used, mu_c if sticking else mu),
                # (gn + Gn) with Gn = -e·gn factors to (1 - e)·gn (see particle).
                (TLn, Pn * sp.factor(gn - e * gn) / 2),
                (TLt, Pt * (gt + gt_final) / 2),
            ),
            equation="P in the scene frame; dV = |P|/m; work of Pn, Pt (seed eqs 21-26)",
        ),
        Block(
            (
                # Relative yaw rate at separation if there were no moment impulse.
                (s, wr - (j1 * c1 + j2 * c2)),
                (V1x, v1x + k1 * Px),
                (V1y, v1y + k1 * Py),
                (V2x, v2x - k2 * Px),
                (V2y, v2y - k2 * Py),
                (W1, w1 + dw1),
                (W2, w2 + dw2),
            ),
            equation="final velocities from impulse-momentum (seed appendix eqs 1-3)",
        ),
        Block(
            (
                (M, am * s),
                # W2 - W1 = e_m·s at separation.
                (TLm, am * s * (wr + e_m * s) / 2),
            ),
            equation="moment impulse (seed appendix eq 6) and its work",
        ),
        Block(((TL, TLn + TLt + TLm),), equation="TL = TLn + TLt + TLm (conventions.md energy)"),
    )


def kernel(sticking: bool) -> Kernel:
    """The rigid-body kernel, impulse ratio given (sliding) or μ = μ_c (sticking)."""
    name = "rigid_critical" if sticking else "rigid"
    doc = "General planar rigid-body impact (Brach), " + (
        "no sliding at separation (mu = mu_c)." if sticking else "impulse ratio mu given."
    )
    scalars = (v1x, v1y, w1, v2x, v2y, w2, r1x, r1y, r2x, r2y, gamma, e, e_m)
    tolerances, flags = f.physics_flags((TL, TLn, TLt, TLm), ((Pn, gn), (Pt, gt), (M, wr)), restitution=e)
    return Kernel(
        name=name,
        doc=doc,
        inputs=INPUTS,
        checks=(
            finite_inputs(scalars + (() if sticking else (mu,)), (m1, m2, I1, I2)),
            positive_or_fixed((m1, m2, I1, I2)),
            # A fixed body has infinite mass AND inertia, or neither.
            Guard((sp.Eq(IsFinite(m1), IsFinite(I1)), sp.Eq(IsFinite(m2), IsFinite(I2))), "BAD_MASS"),
        ),
        blocks=_frame_blocks() + _impulse_blocks(sticking) + _final_blocks(sticking) + (tolerances,),
        outputs=OUTPUTS,
        flags=flags,
        family="rigid",
        variant=(("critical", True),) if sticking else (),
    )


KERNELS = (kernel(sticking=False), kernel(sticking=True))


def emitted_kernels() -> tuple[Kernel, ...]:
    """What generated/planar.py holds: each kernel in normal form, for every
    output tier, general and with e_m = 1 (no moment impulse)."""
    out = []
    for base in KERNELS:
        general = specialise.normal_form(base)
        no_moment = specialise.fix_inputs(
            general, f"{base.name}_em1", {e_m: 1}, "Moment restitution e_m = 1: no moment impulse."
        )
        out += specialise.tiers(general) + specialise.tiers(no_moment)
    return tuple(out)


EMITTED = emitted_kernels()


def ke_difference_kernel() -> Kernel:
    """The sliding kernel with TL as the naive kinetic-energy difference
    T_before - T_after (finite masses only). Not emitted to generated/: it
    exists so benchmarks/ can measure what the work form saves."""
    base = kernel(sticking=False)

    def energy(vx, vy, w, m, inertia):
        return m * (vx**2 + vy**2) / 2 + inertia * w**2 / 2

    naive = (
        energy(v1x, v1y, w1, m1, I1)
        + energy(v2x, v2y, w2, m2, I2)
        - energy(V1x, V1y, W1, m1, I1)
        - energy(V2x, V2y, W2, m2, I2)
    )
    blocks = tuple(Block(((TL, naive),)) if block.assigns[0][0] == TL else block for block in base.blocks)
    return Kernel(
        name="rigid_ke_difference",
        doc=base.doc + " TL as a kinetic-energy difference.",
        inputs=base.inputs,
        checks=base.checks,
        blocks=blocks,
        outputs=base.outputs,
        flags=base.flags,
    )


# ---------------------------------------------------------------- proofs

KEEP = frozenset({k1, k2, j1, j2, nx, ny})


def _cross_products(knl: Kernel) -> dict:
    """c_i → r_i × P in terms of (Pn, Pt): the lever products as the sliding
    kernel computes them (for the sticking kernel: lemma `_cramer_levers`)."""
    rn = {x: knl.expanded(x, KEEP) for x in (r1n, r1t, r2n, r2t, drn, drt)}
    return {
        c1: _cross(rn[r1n], rn[r1t], Pn, Pt),
        c2: _cross(rn[r2n], rn[r2t], Pn, Pt),
        cd: _cross(rn[drn], rn[drt], Pn, Pt),
    }


def _expanded(knl: Kernel, sym, atoms=frozenset()):
    """`sym` expanded down to KEEP ∪ atoms ∪ {c1, c2, cd}, then c = r × P."""
    return knl.expanded(sym, KEEP | atoms | {c1, c2, cd}).xreplace(_cross_products(knl))


def _zero(expr) -> bool:
    return f.reduce_unit_normal(expr) == 0


def six_equation_residuals(got, sticking: bool):
    """Residuals of the six equations (conventions.md) in the scene frame.

    `got` maps finals (and P, M) to expressions; initials not in `got` stay
    symbols (the forward problem), or are expressions too (the inverse)."""
    px, py = got[Px], got[Py]
    v1x_, v1y_, w1_, v2x_, v2y_, w2_ = (got.get(s, s) for s in (v1x, v1y, w1, v2x, v2y, w2))
    u1 = (v1x_ - w1_ * r1y, v1y_ + w1_ * r1x)
    u2 = (v2x_ - w2_ * r2y, v2y_ + w2_ * r2x)
    U1 = (got[V1x] - got[W1] * r1y, got[V1y] + got[W1] * r1x)
    U2 = (got[V2x] - got[W2] * r2y, got[V2y] + got[W2] * r2x)
    n, t = (nx, ny), (-ny, nx)

    def dot(a, b):
        return a[0] * b[0] + a[1] * b[1]

    rel = (U2[0] - U1[0], U2[1] - U1[1])
    res = [
        got[V1x] - v1x_ - k1 * px,
        got[V1y] - v1y_ - k1 * py,
        got[V2x] - v2x_ + k2 * px,
        got[V2y] - v2y_ + k2 * py,
        got[W1] - w1_ - j1 * (r1x * py - r1y * px + got[M]),
        got[W2] - w2_ + j2 * (r2x * py - r2y * px + got[M]),
        dot(n, rel) + e * dot(n, (u2[0] - u1[0], u2[1] - u1[1])),
        (got[W2] - got[W1]) * (1 - e_m) - e_m * got[M] * (j1 + j2),
        dot(t, rel) if sticking else dot(t, (px, py)) - mu * dot(n, (px, py)),
    ]
    return res, rel


def _small_atoms(sticking: bool):
    """Atoms for the impulse-level identities, and the lemma that replaces the
    sticking kernel's det K (Cauchy–Binet form, proven separately)."""
    atoms = frozenset({Knn, Knt, Ktt, hn, ht, gn, gt})
    if sticking:
        return atoms | {D}, {D: Knn * Ktt - Knt**2}
    return atoms, {}


def _six_equations_hold(knl: Kernel, sticking: bool) -> bool:
    """The six equations, in three exact steps:
    1. with (Pn, Pt) free and the kernel's M(Pn, Pt), momentum, angular impulse
       and moment restitution hold identically, and the final relative velocity
       at the impact centre is (gn, gt) - K (Pn, Pt) - h (K, h expanded);
    2. the kernel's (Pn, Pt), as functions of K, h, gn, gt, e, μ, satisfy
       restitution and the impulse ratio (or zero final slip);
    3. so the scene-frame restitution and ratio residuals vanish."""
    free = {sym: _expanded(knl, sym, {Pn, Pt}) for sym in knl.outputs + (Px, Py)}
    res, rel = six_equation_residuals(free, sticking)
    Gn, Gt = f.to_impact_frame(*rel)
    keff = {sym: knl.expanded(sym, KEEP) for sym in (Knn, Knt, Ktt, hn, ht, gn, gt)}
    step1 = (
        all(_zero(r) for r in res[:6] + res[7:8])
        and _zero(Gn - (keff[gn] - keff[Knn] * Pn - keff[Knt] * Pt - keff[hn]))
        and _zero(Gt - (keff[gt] - keff[Knt] * Pn - keff[Ktt] * Pt - keff[ht]))
    )
    small, lemma = _small_atoms(sticking)
    pn, pt = (knl.expanded(x, small).xreplace(lemma) for x in (Pn, Pt))
    restitution = (gn - Knn * pn - Knt * pt - hn) + e * gn
    second = (gt - Knt * pn - Ktt * pt - ht) if sticking else pt - mu * pn
    step2 = sp.simplify(restitution) == 0 and sp.simplify(second) == 0
    pn_back, pt_back = f.to_impact_frame(free[Px], free[Py])
    step3 = _zero(pn_back - Pn) and _zero(pt_back - Pt)
    return step1 and step2 and step3


def _derivation_checks():
    """C is symmetric; the structured K, h equal SymPy's elimination of M."""
    C = compliance()
    out = [("rigid: compliance C is symmetric (reciprocity)", C == C.T)]
    m_sol = moment_impulse()
    C_syms = {Cnn: C[0, 0], Cnt: C[0, 1], Ctt: C[1, 1], Cnm: C[0, 2], Ctm: C[1, 2], Cmm: C[2, 2]}
    dg = -sp.Matrix([[Cnn, Cnt, Cnm], [Cnt, Ctt, Ctm]]) * sp.Matrix([Pn, Pt, m_sol])
    pieces = {
        am: (1 - e_m) / Cmm,
        wa: e_m * j1,
        wb: e_m * j2,
        kk: k1 + k2,
        wc: (1 - e_m) * j1 * j2 / (j1 + j2),
        drn: r1n - r2n,
        drt: r1t - r2t,
    }
    keff = {k: v.xreplace(pieces) for k, v in effective_compliance().items()}
    structured = -sp.Matrix([[keff[Knn], keff[Knt]], [keff[Knt], keff[Ktt]]]) * sp.Matrix(
        [Pn, Pt]
    ) - sp.Matrix([keff[hn], keff[ht]])
    out.append(
        (
            "rigid: eliminating M (moment restitution) gives the effective K and h",
            all(_zero((dg[i] - structured[i]).xreplace(C_syms)) for i in range(2)),
        )
    )
    stick = KERNELS[1]
    out.append(
        (
            "rigid: the Cauchy-Binet form of det K equals Knn Ktt - Knt^2",
            _zero(stick.expanded(D, KEEP) - stick.expanded(Knn * Ktt - Knt**2, KEEP)),
        )
    )
    return out


def _kernel_checks(knl: Kernel, sticking: bool, sliding: Kernel | None = None):
    """Proofs for one kernel. The six equations are checked on the closed forms
    expanded down to the inputs. The energy claims are checked as lemmas with
    (Pn, Pt) or (Pn, Pt, M) kept as free symbols, where the difference must be
    an identity or a multiple of a residual already proven zero; that keeps
    every check exact and fast."""
    tag = knl.name
    out = [(f"{tag}: the closed forms satisfy the six equations", _six_equations_hold(knl, sticking))]
    out.append(
        (
            f"{tag}: dV1, dV2 are |V1 - v1|, |V2 - v2|",
            f.delta_v_magnitudes_hold(lambda x: _expanded(knl, x, frozenset({Pn, Pt}))),
        )
    )
    g0 = tuple(c.xreplace({dvx: v2x - v1x, dvy: v2y - v1y}) for c in relative_velocity())
    gn0, gt0 = f.to_impact_frame(*g0)
    wr0 = w2 - w1
    # Lemma: for ANY impulse (Pn, Pt, M), the kinetic energy lost is the work of
    # the components on the mean relative velocity (conventions.md, Energy).
    px, py = (knl.expanded(x, KEEP | {Pn, Pt}) for x in (Px, Py))
    lever = _cross_products(knl)
    free = {
        V1x: v1x + k1 * px,
        V1y: v1y + k1 * py,
        V2x: v2x - k2 * px,
        V2y: v2y - k2 * py,
        W1: w1 + j1 * (lever[c1] + M),
        W2: w2 - j2 * (lever[c2] + M),
    }
    _, rel = six_equation_residuals({**free, Px: px, Py: py, M: M}, sticking)
    Gn, Gt = f.to_impact_frame(*rel)
    ke = [
        (vx**2 + vy**2) / (2 * k) + w**2 / (2 * j)
        for vx, vy, w, k, j in ((v1x, v1y, w1, k1, j1), (v2x, v2y, w2, k2, j2))
    ]
    KE = [
        (free[a] ** 2 + free[b] ** 2) / (2 * k) + free[c] ** 2 / (2 * j)
        for a, b, c, k, j in ((V1x, V1y, W1, k1, j1), (V2x, V2y, W2, k2, j2))
    ]
    work = Pn * (gn0 + Gn) / 2 + Pt * (gt0 + Gt) / 2 + M * (wr0 + free[W2] - free[W1]) / 2
    out.append(
        (f"{tag}: kinetic energy lost = work of Pn, Pt, M (any impulse)", _zero(sum(ke) - sum(KE) - work))
    )
    # The kernel's parts, with (Pn, Pt) free and M the kernel's M(Pn, Pt).
    at = frozenset({Pn, Pt})
    m_k = _expanded(knl, M, at)
    Gn_k, Gt_k, Wr_k = (x.xreplace({M: m_k}) for x in (Gn, Gt, free[W2] - free[W1]))
    restitution = Gn_k + e * gn0
    slip = Gt_k if sticking else 0
    out.append(
        (
            f"{tag}: TLn, TLt, TLm are those works given restitution"
            + (" and zero final slip" if sticking else ""),
            _zero(_expanded(knl, TLn, at) - Pn * (gn0 + Gn_k) / 2 + Pn * restitution / 2)
            and _zero(_expanded(knl, TLt, at) - Pt * (gt0 + Gt_k) / 2 + Pt * slip / 2)
            and _zero(_expanded(knl, TLm, at) - m_k * (wr0 + Wr_k) / 2)
            and knl.expanded(TL, frozenset({TLn, TLt, TLm})) == TLn + TLt + TLm,
        )
    )
    if sticking:
        out.append(
            (
                f"{tag}: Cramer's c1, c2, cd equal r1, r2, r1 - r2 x P of the sticking impulse",
                _cramer_levers(knl),
            )
        )
        out.append(
            (f"{tag}: equals the sliding kernel at mu = mu_c", _sticking_is_sliding_at_critical(knl, sliding))
        )
    else:
        out.append(
            (
                f"{tag}: mu = mu_c makes the final tangential relative velocity vanish",
                _critical_ratio_ends_slip(knl, Gt_k),
            )
        )
        got = {sym: knl.expanded(sym, KEEP) for sym in (V1x, V1y, V2x, V2y)}
        out.append(
            (f"{tag}: zero lever arms reduce to the particle model, eqs 10-13", _reduces_to_particle(got))
        )
    return out


def _cramer_levers(stick: Kernel) -> bool:
    """Lemma: the sticking kernel's c_i (Cramer's rule, r12 and Cauchy–Binet
    det K) equal r_i × P of its (Pn, Pt), as identities in the impact-frame
    lever arms, kk, the weights and (bn, bt)."""
    atoms = frozenset({r1n, r1t, r2n, r2t, kk, wa, wb, wc, bn, bt, drn, drt, r12, D})
    frame = {drn: r1n - r2n, drt: r1t - r2t, r12: r1n * r2t - r1t * r2n}
    keff = {k: v.xreplace(frame) for k, v in effective_compliance().items()}
    det = keff[Knn] * keff[Ktt] - keff[Knt] ** 2
    sub = {**frame, D: det}

    def at_atoms(sym):
        return stick.expanded(sym, atoms).xreplace(keff).xreplace(sub)

    pn, pt = at_atoms(Pn), at_atoms(Pt)
    return all(
        sp.simplify(at_atoms(c) - _cross(rn, rt, pn, pt)) == 0
        for c, rn, rt in ((c1, r1n, r1t), (c2, r2n, r2t), (cd, r1n - r2n, r1t - r2t))
    )


def _sticking_is_sliding_at_critical(stick: Kernel, slide: Kernel) -> bool:
    """Same finals as functions of (Pn, Pt), and the same (Pn, Pt) at μ = μ_c
    (an identity in K, bn, bt)."""
    at = frozenset({Pn, Pt})
    same_finals = all(
        sp.expand(_expanded(stick, o, at) - _expanded(slide, o, at)) == 0
        for o in (V1x, V1y, W1, V2x, V2y, W2, M)
    )
    stick_atoms, lemma = _small_atoms(True)
    slide_atoms = _small_atoms(False)[0] | {bn, bt}
    crit = {mu: slide.expanded(mu_c, slide_atoms)}
    same_impulse = all(
        sp.simplify(
            stick.expanded(o, stick_atoms | {bn, bt}).xreplace(lemma)
            - slide.expanded(o, slide_atoms).xreplace(crit)
        )
        == 0
        for o in (Pn, Pt)
    )
    return same_finals and same_impulse


def _critical_ratio_ends_slip(knl: Kernel, gt_final) -> bool:
    """Gt = bt - (Knt Pn + Ktt Pt) for any (Pn, Pt) (lemma, expanded), and with
    the kernel's Pn, Pt at μ = μ_c that is zero (identity in K, bn, bt)."""
    small = frozenset({Knn, Knt, Ktt, bn, bt})
    lemma = _zero(gt_final - knl.expanded(bt - (Knt * Pn + Ktt * Pt), KEEP | {Pn, Pt}))
    at_small = knl.expanded(bt - (Knt * Pn + Ktt * Pt), small)
    return lemma and sp.simplify(at_small.xreplace({mu: knl.expanded(mu_c, small)})) == 0


def _reduces_to_particle(got) -> bool:
    """With r1 = r2 = 0 the translational results are the seed's eqs 10–13."""
    zero_arms = {r1x: 0, r1y: 0, r2x: 0, r2y: 0}
    printed = particle.seed_printed_solution(sticking=False)
    vals = particle._seed_frame_values()
    for (sx, sy), (sn, st) in (
        ((V1x, V1y), (particle.V1n, particle.V1t)),
        ((V2x, V2y), (particle.V2n, particle.V2t)),
    ):
        fn, ft = f.to_impact_frame(got[sx].xreplace(zero_arms), got[sy].xreplace(zero_arms))
        if not (_zero(fn - printed[sn].xreplace(vals)) and _zero(ft - printed[st].xreplace(vals))):
            return False
    return True


def _specialised_checks():
    """The emitted kernels with e_m = 1 have M ≡ 0 and TLm ≡ 0 and otherwise
    the general kernel's outputs at e_m = 1 (expanded to the inverse masses
    and the normal); every tier's outputs are the full kernel's."""
    out = []
    by_name = {k.name: k for k in EMITTED}
    for base in KERNELS:
        general = by_name[base.name]
        no_moment = by_name[f"{base.name}_em1"]
        same = all(
            _zero(no_moment.expanded(o, KEEP) - general.expanded(o, KEEP).xreplace({e_m: 1}))
            for o in no_moment.outputs
        )
        out.append(
            (
                f"{no_moment.name}: M = TLm = 0 and the other outputs are {base.name}'s at e_m = 1",
                dict(no_moment.constants) == {"M": 0.0, "TLm": 0.0} and same,
            )
        )
        for full in (general, no_moment):
            out.append(
                (
                    f"{full.name}: every output tier computes the full kernel's formulas",
                    all(_same_formulas(by_name[f"{full.name}_{tier}"], full) for tier in specialise.TIERS),
                )
            )
    return out


def _same_formulas(part: Kernel, full: Kernel) -> bool:
    """Each output of `part`, expanded to the inputs, is `full`'s."""
    return all(part.expanded(o) == full.expanded(o) for o in part.outputs)


def proofs():
    """(claim, passed) pairs for the rigid-body kernels."""
    out = _derivation_checks()
    sliding, sticking = KERNELS
    out += _kernel_checks(sliding, False)
    out += _kernel_checks(sticking, True, sliding)
    return out + _specialised_checks()
