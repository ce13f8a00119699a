"""Kudlich–Slibar impulse model (Steffan & Moser, SAE 960886, eqs 47–56, planar): PC-Crash's law.

A point impulse (M = 0) at the impact centre. With g = u2 - u1 the relative
velocity there (conventions.md) and P the impulse on vehicle 1, the
impulse-momentum equations give g_final = g - W P with the symmetric compliance

    W = [[c2, -c3], [-c3, c1]]   in (n, t) components,
    c1 = 1/m1 + 1/m2 + r1n²/I1 + r2n²/I2   (tangential),
    c2 = 1/m1 + 1/m2 + r1t²/I1 + r2t²/I2   (normal),
    c3 = r1n r1t/I1 + r2n r2t/I2           (coupling),

(the paper's c1, c2, c3 read in impactsym's frame; W is planar.py's effective
compliance K at e_m = 1, so Knn = c2, Knt = -c3, Ktt = c1). The restitution ε is
Poisson's: the impulse is (1 + ε) times the impulse to the end of compression.

* Full impact: both components of g vanish at the end of compression,
  Pc = W⁻¹ g, P = (1 + ε) W⁻¹ g, final relative velocity -ε g (the slip reverses
  by design), energy loss ½(1 - ε²) gᵀW⁻¹g.
* Sliding contact (friction μ in the contact plane): when the full impact needs
  |Pt| > μ|Pn|, the impulse keeps |Pt| = μ|Pn| with Pt of the sign of the initial
  slip gt (friction on vehicle 1 drags it along the slip of vehicle 2; with no
  initial slip, the sign the full impact needs); compression ends when the
  normal relative velocity is 0, Pn = (1 + ε) gn/(Knn + μs Knt) with μs = Pt/Pn.
  A denominator ≤ 0 means compression never ends: status NO_END_OF_COMPRESSION.

Energy parts are the works of Pn and Pt along the impulse path, a straight line
for this law: TLn = Pn (gn + Gn)/2, TLt = Pt (gt + Gt)/2.
"""

from __future__ import annotations

import sympy as sp

from . import frame as f
from . import planar, specialise
from .frame import (
    I1,
    I2,
    TL,
    W1,
    W2,
    Pn,
    Pt,
    Px,
    Py,
    TLn,
    TLt,
    V1x,
    V1y,
    V2x,
    V2y,
    dV1,
    dV2,
    dvx,
    dvy,
    e,
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
)
from .kernel import Block, Guard, IsFinite, Kernel, finite_inputs, positive_or_fixed, real
from .planar import Knn, Knt, Ktt, kk, r1n, r1t, r2n, r2t, r12

# Friction coefficient in the contact plane (an input; `mu` is the realised ratio).
mu_f = real("mu_f")
# Kudlich–Slibar's compliance coefficients, det W, the full impact's Pn, Pt
# numerators (Cramer), and the sliding law's pieces.
ks_c1, ks_c2, ks_c3, detW = real("ks_c1 ks_c2 ks_c3 detW")
pn_full, pt_full, slide, sgn_t, mu_s, Ds, Gn, Gt, Dcb = real(
    "pn_full pt_full sliding sgn_t mu_s Ds Gn Gt Dcb"
)
c1, c2 = real("c1 c2")

INPUTS_FULL = (m1, m2, I1, I2, v1x, v1y, w1, v2x, v2y, w2, r1x, r1y, r2x, r2y, gamma, e)
INPUTS_SLIDING = INPUTS_FULL + (mu_f,)
OUTPUTS = (V1x, V1y, W1, V2x, V2y, W2, Pn, Pt, mu_used, mu_c, dV1, dV2, TL, TLn, TLt, slide)
# A point impulse: no moment, no work of one (the laws' kernels publish them as constants).
POINT_IMPULSE = (("M", 0.0), ("TLm", 0.0))


def compliance_coefficients():
    """(c1, c2, c3) of the paper from the arms in the impact frame."""
    return (
        kk + j1 * r1n**2 + j2 * r2n**2,
        kk + j1 * r1t**2 + j2 * r2t**2,
        j1 * r1n * r1t + j2 * r2n * r2t,
    )


def point_frame_blocks():
    """Inverse masses, normal, relative velocity at the impact centre and the
    point-impulse compliance W (planar.py's K at e_m = 1), with det W in the
    Cauchy–Binet form kk² + kk (j1|r1|² + j2|r2|²) + j1 j2 (r1 × r2)² (a sum of
    non-negative terms: no cancellation). Shared by the Coulomb process."""
    r1n_, r1t_ = f.to_impact_frame(r1x, r1y)
    r2n_, r2t_ = f.to_impact_frame(r2x, r2y)
    gx_, gy_ = planar.relative_velocity()
    gn_, gt_ = f.to_impact_frame(gx, gy)
    c1_, c2_, c3_ = compliance_coefficients()
    arms = j1 * (r1x**2 + r1y**2) + j2 * (r2x**2 + r2y**2)
    return (
        Block(
            f.inverse_masses((m1, m2, I1, I2), (k1, k2, j1, j2))
            + f.normal_components()
            + ((dvx, v2x - v1x), (dvy, v2y - v1y), (r12, r1x * r2y - r1y * r2x)),
            Guard((sp.StrictGreaterThan(k1 + k2, 0),), "SINGULAR"),
            equation="conventions.md frame: k = 1/m, j = 1/I, n = (cos gamma, sin gamma)",
        ),
        Block(
            ((r1n, r1n_), (r1t, r1t_), (r2n, r2n_), (r2t, r2t_), (gx, gx_), (gy, gy_), (kk, k1 + k2)),
            equation="arms in the impact frame; u2 - u1 at the impact centre, u_i = v_i + w_i z x r_i",
        ),
        Block(
            (
                (gn, gn_),
                (gt, gt_),
                (ks_c1, c1_),
                (ks_c2, c2_),
                (ks_c3, c3_),
                (detW, kk**2 + kk * arms + j1 * j2 * r12**2),
            ),
            f.approach_guard(),
            equation="compliance W = [[c2, -c3], [-c3, c1]] from impulse-momentum "
            "(six equations 1, 2, M = 0; SAE 960886 eqs 47-50)",
        ),
        Block(
            ((Knn, ks_c2), (Knt, -ks_c3), (Ktt, ks_c1)),
            equation="W as planar.py's effective compliance K at e_m = 1",
        ),
    )


def brach_critical_blocks():
    """Brach's μ_c at the scene's e (point impulse): the sticking ratio, NaN
    when the sticking impulse has Pn = 0 (reported, not a failed row)."""
    bn_, bt_ = (1 + e) * gn, gt
    return (
        Block(((Dcb, Ktt * bn_ - Knt * bt_),), equation="Pn of Brach's sticking impulse (Cramer)"),
        Block(
            ((mu_c, sp.Piecewise(((Knn * bt_ - Knt * bn_) / Dcb, sp.Ne(Dcb, 0)), (sp.nan, True))),),
            equation="mu_c: Brach's critical ratio at the scene's e (seed eq 18 generalised)",
        ),
    )


def _impulse_blocks(sliding: bool):
    """The full impact by Cramer's rule on W Pc = g; with `sliding`, the
    friction-bounded impulse where the full one exceeds μ|Pn|."""
    pn_f, pt_f = (1 + e) * (Ktt * gn - Knt * gt) / detW, (1 + e) * (Knn * gt - Knt * gn) / detW
    full = (
        Block(
            ((pn_full, pn_f), (pt_full, pt_f)),
            equation="full impact: P = (1 + eps) W^-1 g, both components of g vanish at the end "
            "of compression (SAE 960886 eqs 51-53)",
        ),
    )
    if not sliding:
        return full + (
            Block(((Pn, pn_full), (Pt, pt_full), (slide, sp.S.Zero)), equation="impulses of the full impact"),
        )
    # sign of the friction on vehicle 1: the initial slip's, or the full impact's with no slip.
    sign_ = sp.Piecewise((sp.sign(gt), sp.Ne(gt, 0)), (sp.sign(pt_full), True))
    return full + (
        Block(
            (
                (slide, sp.Piecewise((1, sp.StrictGreaterThan(sp.Abs(pt_full), -mu_f * pn_full)), (0, True))),
                (sgn_t, sign_),
            ),
            equation="sliding when the full impact needs |Pt| > mu |Pn| (SAE 960886 eq 54)",
        ),
        Block(
            (
                (mu_s, -mu_f * sgn_t),
                (Ds, sp.Piecewise((Knn - mu_f * sgn_t * Knt, sp.Eq(slide, 1)), (1, True))),
            ),
            Guard((sp.StrictGreaterThan(Ds, 0),), "NO_END_OF_COMPRESSION"),
            equation="sliding: Pt = mu_s Pn with |mu_s| = mu opposing the slip; compression ends "
            "when Knn + mu_s Knt > 0 (SAE 960886 eqs 55-56)",
        ),
        Block(
            (
                (Pn, sp.Piecewise(((1 + e) * gn / Ds, sp.Eq(slide, 1)), (pn_full, True))),
                (Pt, sp.Piecewise(((1 + e) * mu_s * gn / Ds, sp.Eq(slide, 1)), (pt_full, True))),
            ),
            equation="impulses: sliding (Poisson restitution, Pn = (1 + eps) Pn_c) or full",
        ),
    )


def full_levers():
    """r1 x P and r2 x P of the full impact P = (1 + ε) W⁻¹ g by Cramer's rule,
    c = (1 + ε)(gt (W ρ)_n - gn (W ρ)_t)/det W for ρ = (r_n, r_t): in W ρ the
    large terms of a small yaw inertia drop out exactly (as planar.py's
    sticking levers; the impulse is then nearly along the arm and r x P from
    (Pn, Pt) would cancel)."""
    w_rho1 = (kk * r1n + r12 * j2 * r2t, kk * r1t - r12 * j2 * r2n)
    w_rho2 = (kk * r2n - r12 * j1 * r1t, kk * r2t + r12 * j1 * r1n)
    return tuple((1 + e) * (gt * wn - gn * wt) / detW for wn, wt in (w_rho1, w_rho2))


def _final_blocks(sliding: bool):
    """Finals, the realised ratio, and the works of Pn and Pt along the straight path."""
    gt_final = -e * gt
    lever = full_levers()
    if sliding:
        gt_final = sp.Piecewise((gt - (Knt * Pn + Ktt * Pt), sp.Eq(slide, 1)), (gt_final, True))
        cross = (planar._cross(r1n, r1t, Pn, Pt), planar._cross(r2n, r2t, Pn, Pt))
        lever = tuple(sp.Piecewise((x, sp.Eq(slide, 1)), (y, True)) for x, y in zip(cross, lever))
    px, py = f.to_scene_frame(Pn, Pt)
    return (
        Block(
            (
                (Px, px),
                (Py, py),
                *f.delta_v_magnitudes(),
                (mu_used, sp.Piecewise((Pt / Pn, sp.Ne(Pn, 0)), (sp.nan, True))),
                # -eps gn exactly (proved: restitution), not g - W P, which cancels.
                (Gn, -e * gn),
                (Gt, gt_final),
                (c1, lever[0]),
                (c2, lever[1]),
            ),
            equation="P in the scene frame; dV = |P|/m; realised ratio Pt/Pn; final relative velocity "
            "g - W P (-eps g in the full impact, proved)",
        ),
        Block(
            (
                (V1x, v1x + k1 * Px),
                (V1y, v1y + k1 * Py),
                (V2x, v2x - k2 * Px),
                (V2y, v2y - k2 * Py),
                (W1, w1 + j1 * c1),
                (W2, w2 - j2 * c2),
                (TLn, Pn * (gn + Gn) / 2),
                (TLt, Pt * (gt + Gt) / 2),
            ),
            equation="final velocities (six equations 1, 2, M = 0); works of Pn, Pt on the straight "
            "impulse path (conventions.md energy)",
        ),
        Block(((TL, TLn + TLt),), equation="TL = TLn + TLt"),
    )


def kernel(sliding: bool) -> Kernel:
    """The Kudlich–Slibar kernel: full contact, or sliding contact with friction mu_f."""
    name = "ks_sliding" if sliding else "ks_full"
    doc = "Kudlich-Slibar impulse model (SAE 960886), " + (
        "sliding contact: full impact unless it needs |Pt| > mu_f |Pn|." if sliding else "full impact."
    )
    inputs = INPUTS_SLIDING if sliding else INPUTS_FULL
    scalars = (v1x, v1y, w1, v2x, v2y, w2, r1x, r1y, r2x, r2y, gamma, e) + ((mu_f,) if sliding else ())
    tolerances, flags = law_flags()
    return Kernel(
        name=name,
        doc=doc,
        inputs=inputs,
        checks=(
            finite_inputs(scalars, (m1, m2, I1, I2)),
            positive_or_fixed((m1, m2, I1, I2)),
            Guard((sp.Eq(IsFinite(m1), IsFinite(I1)), sp.Eq(IsFinite(m2), IsFinite(I2))), "BAD_MASS"),
        ),
        blocks=point_frame_blocks()
        + brach_critical_blocks()
        + _impulse_blocks(sliding)
        + _final_blocks(sliding)
        + (tolerances,),
        outputs=OUTPUTS,
        flags=flags,
        # mu and mu_c are NaN where undefined (Pn = 0; a sticking impulse with
        # Pn = 0): reported as such, not a failed row.
        finite=tuple(s for s in OUTPUTS if s not in (mu_used, mu_c)),
        constants=POINT_IMPULSE,
        integers=(slide,),
        family="kudlich_slibar",
        variant=(("contact", "sliding" if sliding else "full"),),
    )


def law_flags():
    """Flags of the other impact laws: energy created (TL, TLn or TLt below
    rounding), tensile Pn, e outside [0, 1]. No MU_BEYOND_CRITICAL: these laws
    set the ratio themselves (K–S's full impact reverses the slip by design)."""
    tolerances, flags = f.physics_flags((TL, TLn, TLt), ((Pn, gn), (Pt, gt)), restitution=e)
    return tolerances, tuple(fl for fl in flags if fl[0] != "MU_BEYOND_CRITICAL")


KERNELS = (kernel(sliding=False), kernel(sliding=True))
EMITTED = tuple(specialise.normal_form(k) for k in KERNELS)


# ---------------------------------------------------------------- proofs

KEEP = frozenset({k1, k2, j1, j2, nx, ny})
SMALL = frozenset({Knn, Knt, Ktt, gn, gt, e, detW})


def _zero(expr) -> bool:
    return f.reduce_unit_normal(expr) == 0


def _branch(expr, which):
    """The branch of a Piecewise (0: the first condition's) or `expr` itself."""
    return expr.args[which][0] if isinstance(expr, sp.Piecewise) else expr


def _six_equations(knl: Kernel) -> bool:
    """Momentum and angular impulse hold for the kernel's finals as functions
    of (Pn, Pt) (M = 0), and the final relative velocity at the impact centre
    is g - W (Pn, Pt) with W the kernel's compliance."""
    at = KEEP | {Pn, Pt, c1, c2}
    got = {s: knl.expanded(s, at).xreplace(_cross_of(knl)) for s in (V1x, V1y, W1, V2x, V2y, W2, Px, Py)}
    got[planar.M] = 0
    res, rel = planar.six_equation_residuals(got, sticking=False)
    Gn_, Gt_ = f.to_impact_frame(*rel)
    K = {s: knl.expanded(s, KEEP) for s in (Knn, Knt, Ktt, gn, gt)}
    return (
        all(_zero(r) for r in res[:6])
        and _zero(Gn_ - (K[gn] - K[Knn] * Pn - K[Knt] * Pt))
        and _zero(Gt_ - (K[gt] - K[Knt] * Pn - K[Ktt] * Pt))
    )


def _cross_of(knl: Kernel) -> dict:
    """c1 -> r1 x P, c2 -> r2 x P with (Pn, Pt) free (lemma `_levers_hold`)."""
    arms = {x: knl.expanded(x, KEEP) for x in (r1n, r1t, r2n, r2t)}
    return {
        c1: planar._cross(arms[r1n], arms[r1t], Pn, Pt),
        c2: planar._cross(arms[r2n], arms[r2t], Pn, Pt),
    }


def _levers_hold(knl: Kernel) -> bool:
    """Lemma: the kernel's c1, c2 are r1 x P, r2 x P of its (Pn, Pt): the
    Cramer form of the full impact (identity in the arms, kk, j, g, ε) and the
    plain cross product of the sliding branch."""
    defs = knl.definitions()
    W = {
        Knn: kk + j1 * r1t**2 + j2 * r2t**2,
        Knt: -(j1 * r1n * r1t + j2 * r2n * r2t),
        Ktt: kk + j1 * r1n**2 + j2 * r2n**2,
    }
    frame = {r12: r1n * r2t - r1t * r2n}
    det = W[Knn] * W[Ktt] - W[Knt] ** 2
    pn = ((1 + e) * (Ktt * gn - Knt * gt) / detW).xreplace(W).xreplace({detW: det})
    pt = ((1 + e) * (Knn * gt - Knt * gn) / detW).xreplace(W).xreplace({detW: det})
    ok = True
    for c, (rn, rt) in ((c1, (r1n, r1t)), (c2, (r2n, r2t))):
        full = _branch(defs[c], -1).xreplace(frame).xreplace({detW: det})
        ok = ok and sp.simplify(full - planar._cross(rn, rt, pn, pt)) == 0
        if isinstance(defs[c], sp.Piecewise):
            ok = ok and sp.expand(_branch(defs[c], 0) - planar._cross(rn, rt, Pn, Pt)) == 0
    return ok


def _compliance_is_planar_k() -> bool:
    """c1, c2, -c3 are planar.py's Ktt, Knn, Knt at e_m = 1 (which the rigid
    proofs derive from the six equations), and det W's Cauchy–Binet form is
    c1 c2 - c3²."""
    c1_, c2_, c3_ = compliance_coefficients()
    keff = planar.effective_compliance()
    sub = {
        planar.wa: j1,
        planar.wb: j2,
        planar.wc: 0,
        planar.drn: r1n - r2n,
        planar.drt: r1t - r2t,
    }
    same = all(sp.expand(a - keff[b].xreplace(sub)) == 0 for a, b in ((c1_, Ktt), (c2_, Knn), (-c3_, Knt)))
    knl = KERNELS[0]
    det = knl.expanded(detW, KEEP) - knl.expanded(ks_c1 * ks_c2 - ks_c3**2, KEEP)
    return same and _zero(det)


def _full_identities(knl: Kernel):
    """Full impact: W P = (1 + ε) g, so the final relative velocity is -ε g; the
    energy loss ½(1 - ε²) gᵀW⁻¹g; TL equals the kinetic energy lost."""
    pn, pt = (_branch(knl.expanded(s, SMALL), -1) for s in (Pn, Pt))
    lemma = {detW: Knn * Ktt - Knt**2}
    pn, pt = pn.xreplace(lemma), pt.xreplace(lemma)
    gn_f = gn - (Knn * pn + Knt * pt)
    gt_f = gt - (Knt * pn + Ktt * pt)
    reverse = sp.simplify(gn_f + e * gn) == 0 and sp.simplify(gt_f + e * gt) == 0
    winv_g = sp.Matrix([[Knn, Knt], [Knt, Ktt]]).inv() * sp.Matrix([gn, gt])
    quad = (sp.Matrix([[gn, gt]]) * winv_g)[0]
    tl = (pn * (gn + gn_f) + pt * (gt + gt_f)) / 2
    energy = sp.simplify(tl - (1 - e**2) * quad / 2) == 0
    return [
        (
            f"{knl.name}: full impact, final relative velocity is -eps times the initial (both components)",
            reverse,
        ),
        (f"{knl.name}: full impact, energy loss is (1 - eps^2)/2 g^T W^-1 g", energy),
    ]


def _energy_is_kinetic_loss(knl: Kernel) -> bool:
    """TLn + TLt (works on the straight path, with the final relative velocity
    G = g - W P, which the restitution identities show the kernel's (Gn, Gt)
    are) is the kinetic energy lost, for any (Pn, Pt): planar.py's lemma at
    M = 0, checked on this kernel's finals."""
    at = KEEP | {Pn, Pt}
    fin = {s: knl.expanded(s, at | {c1, c2}).xreplace(_cross_of(knl)) for s in (V1x, V1y, W1, V2x, V2y, W2)}

    def ke(vx, vy, w, k, j):
        return (vx**2 + vy**2) / (2 * k) + w**2 / (2 * j)

    before = ke(v1x, v1y, w1, k1, j1) + ke(v2x, v2y, w2, k2, j2)
    after = ke(fin[V1x], fin[V1y], fin[W1], k1, j1) + ke(fin[V2x], fin[V2y], fin[W2], k2, j2)
    g0 = tuple(c.xreplace({dvx: v2x - v1x, dvy: v2y - v1y}) for c in planar.relative_velocity())
    gn0, gt0 = f.to_impact_frame(*g0)
    K = {s: knl.expanded(s, KEEP).xreplace({gn: gn0, gt: gt0}) for s in (Knn, Knt, Ktt)}
    final = {Gn: gn0 - K[Knn] * Pn - K[Knt] * Pt, Gt: gt0 - K[Knt] * Pn - K[Ktt] * Pt}
    tl = knl.expanded(TL, at | {Gn, Gt}).xreplace(final).xreplace({gn: gn0, gt: gt0})
    return _zero(before - after - tl)


def _sliding_identities(knl: Kernel):
    """Sliding: |Pt| = μ|Pn| with Pt of the slip's sign (friction on vehicle 1
    drags it along vehicle 2's slip), the final normal relative velocity is
    -ε gn (Poisson = Newton at a constant ratio), and the full branch is the
    full kernel's."""
    defs = knl.definitions()
    pn = _branch(defs[Pn], 0)
    pt = _branch(defs[Pt], 0)
    sgn = sp.Symbol("s", real=True)
    sub = {mu_s: -mu_f * sgn}
    pn, pt = pn.xreplace(sub), pt.xreplace(sub)
    ds = _branch(defs[Ds], 0).xreplace({sgn_t: sgn})
    pn, pt = pn.xreplace({Ds: ds}).xreplace({sgn_t: sgn}), pt.xreplace({Ds: ds}).xreplace({sgn_t: sgn})
    ratio = sp.simplify(pt - (-mu_f * sgn) * pn) == 0
    # Pn < 0 (compressive) for gn < 0 and Ds > 0, so Pt = mu |Pn| s: the sign of the slip.
    along_slip = sp.simplify(pt - mu_f * sgn * (-pn)) == 0
    gn_f = gn - (Knn * pn + Knt * pt)
    restitution = sp.simplify(gn_f + e * gn) == 0
    sign_rule = defs[sgn_t] == sp.Piecewise((sp.sign(gt), sp.Ne(gt, 0)), (sp.sign(pt_full), True))
    full = KERNELS[0].definitions()
    same_full = defs[pn_full] == full[pn_full] and defs[pt_full] == full[pt_full]
    return [
        (
            f"{knl.name}: sliding, Pt = mu |Pn| sgn(slip): at its bound, opposing the slip of vehicle 1",
            ratio and along_slip and sign_rule,
        ),
        (f"{knl.name}: sliding, final normal relative velocity is -eps gn", restitution),
        (f"{knl.name}: otherwise the full impact", same_full),
    ]


def proofs():
    """(claim, passed) pairs for the Kudlich–Slibar kernels."""
    full, sliding = KERNELS
    out = [
        (
            "kudlich_slibar: W (c1, c2, c3) is planar.py's K at e_m = 1; det W = c1 c2 - c3^2",
            _compliance_is_planar_k(),
        )
    ]
    for knl in KERNELS:
        out.append((f"{knl.name}: c1, c2 are r1 x P, r2 x P (full impact: Cramer form)", _levers_hold(knl)))
        out.append(
            (f"{knl.name}: impulse-momentum (six equations 1, 2, M = 0) and G = g - W P", _six_equations(knl))
        )
        out.append((f"{knl.name}: TLn + TLt is the kinetic energy lost", _energy_is_kinetic_loss(knl)))
        out.append(
            (
                f"{knl.name}: dV1, dV2 are |V1 - v1|, |V2 - v2|",
                f.delta_v_magnitudes_hold(lambda x, k=knl: k.expanded(x, KEEP | {Pn, Pt})),
            )
        )
    out += _full_identities(full)
    out += _sliding_identities(sliding)
    return out
