"""The seed's impulse-momentum models as presets of the general model, and IMPAC's sideswipe kernel.

The seed shows that Brach's general planar model "with the proper restrictions"
reproduces the models of Limpert (Table 3), Macmillan (Table 4) and Woolley's
IMPAC with its common-velocity constraint (Table 7). Each restriction is a
choice of the three coefficients, restitution e, impulse ratio μ and moment
restitution e_m, so those models are presets: a row of PRESETS names the kernel
family that solves it, the coefficients it fixes, and the ones the scene gives.

- Limpert: e = 0 (his oblique non-central solution has no restitution),
  μ = μ_c (both bodies reach a common velocity at the impact centre: no sliding
  at separation, so not for sideswipes) and no moment impulse (e_m = 1).
- Macmillan: e and μ = Pt/Pn given, no moment impulse (e_m = 1).
- IMPAC, common-velocity constraint: the vehicles have the same velocity at the
  impact centre after the exchange of momentum: e = 0, μ = μ_c, e_m = 1.
- IMPAC, sideswipe constraint: normal restitution e = 0 and the final
  tangential relative velocity at the impact centre a given fraction `slip` of
  the initial one, no moment impulse. That prescribes a final velocity, not μ,
  so it is not a coefficient choice: its closed form is derived here. With the
  effective compliance K of planar.py at e_m = 1 (h = 0), the two constraints
  Gn = 0 and Gt = slip·gt read K (Pn, Pt) = (gn, (1 - slip)·gt).
- Brach ("rigid" or "brach") and "particle": the core models, every
  coefficient from the scene.

PRESETS is emitted to generated/presets.py as data, with the scene-file names of
the coefficients (the keys of a scene's ``impact`` table); the runtime reads it
there. The proofs show each preset's stated assumptions hold for its kernel and
coefficients, and that the sideswipe kernel at slip = 0 is the common-velocity
(Limpert, IMPAC) solution.
"""

from __future__ import annotations

import sympy as sp

from . import frame as f
from . import particle, planar, specialise
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
from .planar import D, Dc, Knn, Knt, Ktt, bn, bt, c1, c2, hn, ht, kk, r1n, r1t, r2n, r2t, r12

slip, Dcrit = real("slip Dcrit")

# Scene-file coefficient names and the kernel symbols they feed.
COEFFICIENTS = {"restitution": e, "impulse_ratio": mu, "moment_restitution": e_m, "slip": slip}

_COMMON_VELOCITY = {"restitution": 0.0, "impulse_ratio": "critical", "moment_restitution": 1.0}
_GENERAL = {
    "kernel": "rigid",
    "fixed": {},
    "required": ("restitution", "impulse_ratio"),
    "optional": {"moment_restitution": 1.0},
    "assumptions": "Brach's general planar rigid-body model (seed appendix): restitution e, "
    'impulse ratio mu (a number, or "critical" for no sliding at separation) '
    "and moment restitution e_m (default 1: no moment impulse) from the scene.",
}

PRESETS = {
    "rigid": _GENERAL,
    "brach": _GENERAL,
    "particle": {
        "kernel": "particle",
        "fixed": {},
        "required": ("restitution", "impulse_ratio"),
        "optional": {},
        "assumptions": "Two particles (seed eqs 1-18): no yaw and no lever arms; restitution e "
        "and impulse ratio mu from the scene.",
    },
    "limpert": {
        "kernel": "rigid",
        "fixed": _COMMON_VELOCITY,
        "required": (),
        "optional": {},
        "assumptions": "Limpert: perfectly inelastic (e = 0), a common velocity at the impact "
        "centre at separation (mu = mu_c: sliding ends, so not for sideswipes) and "
        "no moment impulse (e_m = 1); seed Table 3.",
    },
    "macmillan": {
        "kernel": "rigid",
        "fixed": {"moment_restitution": 1.0},
        "required": ("restitution", "impulse_ratio"),
        "optional": {},
        "assumptions": "Macmillan: restitution e and impulse ratio mu = Pt/Pn from the scene, "
        "no moment impulse (e_m = 1); seed Table 4.",
    },
    "impac": {
        "kernel": "rigid",
        "fixed": _COMMON_VELOCITY,
        "required": (),
        "optional": {},
        "assumptions": "Woolley's IMPAC, common-velocity constraint: the same velocity at the "
        "impact centre after the exchange of momentum (e = 0, mu = mu_c) and no "
        "moment impulse (e_m = 1); seed Tables 5-7.",
    },
    "impac_sideswipe": {
        "kernel": "impac_sideswipe",
        "fixed": {"restitution": 0.0, "moment_restitution": 1.0},
        "required": (),
        "optional": {"slip": 0.0},
        "assumptions": "Woolley's IMPAC, sideswipe constraint: no normal restitution (e = 0), the "
        "final tangential relative velocity at the impact centre is `slip` times the "
        "initial one (default 0, the common-velocity solution), no moment impulse "
        "(e_m = 1).",
    },
}

DATA = (("PRESETS", PRESETS), ("COEFFICIENT_INPUTS", {k: str(v) for k, v in COEFFICIENTS.items()}))

INPUTS = (m1, m2, I1, I2, v1x, v1y, w1, v2x, v2y, w2, r1x, r1y, r2x, r2y, gamma, slip)

# The effective compliance and its determinant without a moment impulse (e_m = 1).
NO_MOMENT = {planar.wa: j1, planar.wb: j2, planar.wc: 0}


def _frame_blocks():
    """Inverse masses, the normal, the lever arms and the relative velocity at
    the impact centre (as planar.py, without the moment-impulse pieces)."""
    r1n_, r1t_ = f.to_impact_frame(r1x, r1y)
    r2n_, r2t_ = f.to_impact_frame(r2x, r2y)
    gx_, gy_ = planar.relative_velocity()
    gn_, gt_ = f.to_impact_frame(gx, gy)
    return (
        Block(
            f.inverse_masses((m1, m2, I1, I2), (k1, k2, j1, j2))
            + f.normal_components()
            + ((dvx, v2x - v1x), (dvy, v2y - v1y), (r12, r1x * r2y - r1y * r2x)),
            Guard((sp.StrictGreaterThan(k1 + k2, 0), sp.StrictGreaterThan(j1 + j2, 0)), "SINGULAR"),
            equation="conventions.md frame: k = 1/m, j = 1/I, n = (cos gamma, sin gamma)",
        ),
        Block(
            ((r1n, r1n_), (r1t, r1t_), (r2n, r2n_), (r2t, r2t_), (gx, gx_), (gy, gy_), (kk, k1 + k2)),
            equation="arms in the impact frame; u2 - u1 at the impact centre, u_i = v_i + w_i z x r_i",
        ),
        Block(
            ((gn, gn_), (gt, gt_)),
            f.approach_guard(),
            equation="approach at the impact centre in the impact frame (conventions.md frame)",
        ),
    )


def _impulse_blocks():
    """K (Pn, Pt) = (bn, bt) = (gn, (1 - slip)·gt): Gn = 0 and Gt = slip·gt, by
    Cramer's rule. μ_c is the ratio of the same scene's slip = 0 (common-velocity)
    impulse."""
    keff = {
        k: v.xreplace(NO_MOMENT) for k, v in planar.effective_compliance().items() if k in (Knn, Knt, Ktt)
    }
    return (
        Block(
            tuple(keff.items())
            + ((D, planar.effective_determinant().xreplace(NO_MOMENT)), (bn, gn), (bt, (1 - slip) * gt)),
            equation="K at e_m = 1 (M = 0); IMPAC sideswipe constraint (seed, Woolley): Gn = 0 (e = 0), "
            "Gt = slip gt",
        ),
        Block(
            ((Dc, Ktt * bn - Knt * bt), (Dcrit, Ktt * bn - Knt * gt)),
            Guard((sp.Ne(D, 0), sp.Ne(Dc, 0), sp.Ne(Dcrit, 0)), "SINGULAR"),
            equation="Cramer's rule for K (Pn, Pt) = (bn, bt), and for the common-velocity (slip = 0) impulse",
        ),
        Block(
            (
                (Pn, Dc / D),
                (Pt, (Knn * bt - Knt * bn) / D),
                (mu_used, (Knn * bt - Knt * bn) / Dc),
                (mu_c, (Knn * gt - Knt * bn) / Dcrit),
            ),
            equation="impulses; mu = Pt/Pn (seed eq 5); mu_c of the common-velocity impulse, the seed's "
            "mu_max (eq 18)",
        ),
    )


def _final_blocks():
    """Finals from the impulse (no moment impulse), energy as the work of Pn and Pt:
    Gn = 0 and Gt = slip·gt, so TLn = Pn·gn/2 and TLt = Pt·(1 + slip)·gt/2. The
    lever products c_i = r_i × P come from Cramer's rule (planar.py's sticking
    form, valid for any right-hand side (bn, bt)), so a small yaw inertia, which
    turns P nearly parallel to r_i, does not cancel them."""
    px, py = f.to_scene_frame(Pn, Pt)
    lever1, lever2 = (x.xreplace(NO_MOMENT) for x in planar.lever_products_sticking()[:2])
    return (
        Block(
            (
                (Px, px),
                (Py, py),
                (c1, lever1),
                (c2, lever2),
                (M, sp.Integer(0)),
                *f.delta_v_magnitudes(),
                (TLn, Pn * gn / 2),
                (TLt, Pt * (1 + slip) * gt / 2),
            ),
            equation="P in the scene frame; dV = |P|/m; M = 0; work of Pn, Pt (seed eqs 21-26)",
        ),
        Block(
            (
                (V1x, v1x + k1 * Px),
                (V1y, v1y + k1 * Py),
                (V2x, v2x - k2 * Px),
                (V2y, v2y - k2 * Py),
                (W1, w1 + j1 * c1),
                (W2, w2 - j2 * c2),
                (TLm, sp.Integer(0)),
            ),
            equation="final velocities from impulse-momentum (seed appendix eqs 1-3)",
        ),
        Block(((TL, TLn + TLt),), equation="TL = TLn + TLt (conventions.md energy)"),
    )


def sideswipe_kernel() -> Kernel:
    """IMPAC's sideswipe constraint as a kernel (inputs: the rigid model's, with
    `slip` in place of e, μ, e_m)."""
    scalars = (v1x, v1y, w1, v2x, v2y, w2, r1x, r1y, r2x, r2y, gamma, slip)
    tolerances, flags = f.physics_flags((TL, TLn, TLt, TLm), ((Pn, gn), (Pt, gt)))
    return Kernel(
        name="impac_sideswipe",
        doc="IMPAC sideswipe constraint (Woolley): e = 0, final tangential slip at the impact "
        "centre = slip times the initial one, no moment impulse.",
        inputs=INPUTS,
        checks=(
            finite_inputs(scalars, (m1, m2, I1, I2)),
            positive_or_fixed((m1, m2, I1, I2)),
            Guard((sp.Eq(IsFinite(m1), IsFinite(I1)), sp.Eq(IsFinite(m2), IsFinite(I2))), "BAD_MASS"),
        ),
        blocks=_frame_blocks() + _impulse_blocks() + _final_blocks() + (tolerances,),
        outputs=planar.OUTPUTS,
        flags=flags,
    )


KERNELS = (sideswipe_kernel(),)
EMITTED = (specialise.normal_form(KERNELS[0]),)  # what generated/presets.py holds


# ---------------------------------------------------------------- proofs

KEEP = planar.KEEP
ATOMS = frozenset({Knn, Knt, Ktt, gn, gt, D})
DET_K = {D: Knn * Ktt - Knt**2}


def _zero(expr) -> bool:
    return f.reduce_unit_normal(expr) == 0


def _with_levers(knl: Kernel, sym, keep=frozenset()):
    """`sym` expanded down to KEEP ∪ keep, with the lever products c = r × P in
    terms of (Pn, Pt) (planar._expanded: the rigid critical kernel computes them
    by Cramer's rule, which planar.py proves equal to r × P at its impulse)."""
    return planar._expanded(knl, sym, frozenset(keep))


def _final_relative_velocity(knl: Kernel, fix: dict):
    """(Gn, Gt) at separation from the kernel's finals with (Pn, Pt) free, and
    the residuals of the momentum, angular-impulse and moment-restitution
    equations (fix: the coefficient values the preset holds fixed)."""
    free = {
        sym: _with_levers(knl, sym, {Pn, Pt}).xreplace(fix) for sym in (V1x, V1y, W1, V2x, V2y, W2, M, Px, Py)
    }
    res, rel = planar.six_equation_residuals(free, sticking=False)
    return f.to_impact_frame(*rel), [r.xreplace(fix) for r in res[:6] + res[7:8]], free


def _compliance_lemma(knl: Kernel, fix: dict, G) -> bool:
    """G = g - K (Pn, Pt) - h for any impulse, with K, h, g the kernel's."""
    kx = {s: knl.expanded(s, KEEP).xreplace(fix) for s in (Knn, Knt, Ktt, gn, gt)}
    h = {s: (knl.expanded(s, KEEP).xreplace(fix) if s in knl.definitions() else 0) for s in (hn, ht)}
    return _zero(G[0] - (kx[gn] - kx[Knn] * Pn - kx[Knt] * Pt - h[hn])) and _zero(
        G[1] - (kx[gt] - kx[Knt] * Pn - kx[Ktt] * Pt - h[ht])
    )


def _impulse_in_atoms(knl: Kernel, fix: dict):
    """The kernel's (Pn, Pt) in terms of K, gn, gt, det K (and h), coefficients fixed."""
    atoms = ATOMS | {hn, ht}
    return tuple(knl.expanded(s, atoms).xreplace(fix).xreplace(DET_K) for s in (Pn, Pt))


def _fixed_values(name: str) -> dict:
    """The preset's fixed numeric coefficients as kernel-symbol substitutions."""
    return {
        COEFFICIENTS[k]: sp.nsimplify(v) for k, v in PRESETS[name]["fixed"].items() if k != "impulse_ratio"
    }


def _common_velocity_claims(name: str):
    """Limpert and IMPAC (common velocity): their fixed coefficients select the
    rigid critical kernel at e = 0, e_m = 1, which leaves no moment impulse and
    no relative velocity at the impact centre."""
    fix = _fixed_values(name)
    knl = planar.KERNELS[PRESETS[name]["fixed"]["impulse_ratio"] == "critical"]
    G, residuals, free = _final_relative_velocity(knl, fix)
    no_h = all(sp.simplify(knl.expanded(s, KEEP).xreplace(fix)) == 0 for s in (hn, ht))
    pn, pt = _impulse_in_atoms(knl, {**fix, hn: 0, ht: 0})
    common = sp.simplify(gn - Knn * pn - Knt * pt) == 0 and sp.simplify(gt - Knt * pn - Ktt * pt) == 0
    return [
        (
            f"{name}: {knl.name} at {fix} has M = 0 and Gn = Gt = 0 (common velocity at the impact centre)",
            knl.name == "rigid_critical"
            and _zero(free[M])
            and no_h
            and all(_zero(r) for r in residuals)
            and _compliance_lemma(knl, fix, G)
            and common,
        )
    ]


def _macmillan_claims():
    """Macmillan: the rigid kernels at its fixed e_m = 1 have no moment impulse,
    for any impulse."""
    fix = _fixed_values("macmillan")
    ok = all(
        _zero(_with_levers(knl, M, {Pn, Pt}).xreplace(fix))
        and all(_zero(r) for r in _final_relative_velocity(knl, fix)[1])
        for knl in planar.KERNELS
    )
    return [("macmillan: rigid and rigid_critical at e_m = 1 have M = 0", ok)]


def _table_claims():
    """Every preset names an emitted kernel family, and its fixed, required and
    optional coefficients are exactly that family's coefficient inputs."""
    families = {"rigid": planar.KERNELS, "particle": particle.KERNELS, "impac_sideswipe": KERNELS}
    ok = True
    for row in PRESETS.values():
        knls = families[row["kernel"]]
        inputs = {s for knl in knls for s in knl.inputs} & set(COEFFICIENTS.values())
        given = {COEFFICIENTS[k] for k in (*row["required"], *row["optional"])}
        fixed = {COEFFICIENTS[k] for k in row["fixed"]}
        derived_at = {e, e_m} if row["kernel"] == "impac_sideswipe" else set()
        ok = ok and given | (fixed - derived_at) == inputs and not given & fixed
    return [("presets: each names a kernel family and covers exactly its coefficients", ok)]


def _sideswipe_claims():
    """The sideswipe kernel satisfies momentum, angular impulse, M = 0, Gn = 0,
    Gt = slip·gt; its energy parts are the work of Pn and Pt; at slip = 0 it is
    the rigid critical kernel at e = 0, e_m = 1."""
    knl = KERNELS[0]
    tag = knl.name
    # The kernel was derived at its preset's e = 0, e_m = 1 (it has neither input).
    G, residuals, free = _final_relative_velocity(knl, _fixed_values(tag))
    pn, pt = _impulse_in_atoms(knl, {})
    constraints = (
        sp.simplify(gn - Knn * pn - Knt * pt) == 0 and sp.simplify(gt - Knt * pn - Ktt * pt - slip * gt) == 0
    )
    det = _zero(knl.expanded(D, KEEP) - knl.expanded(Knn * Ktt - Knt**2, KEEP))
    back = f.to_impact_frame(free[Px], free[Py])
    out = [
        (
            f"{tag}: momentum, angular impulse and M = 0 hold; Gn = 0 and Gt = slip*gt",
            _zero(free[M])
            and all(_zero(r) for r in residuals)
            and _compliance_lemma(knl, {}, G)
            and constraints
            and det
            and _zero(back[0] - Pn)
            and _zero(back[1] - Pt),
        )
    ]
    out.append(
        (
            f"{tag}: dV1, dV2 are |V1 - v1|, |V2 - v2|",
            f.delta_v_magnitudes_hold(lambda x: knl.expanded(x, KEEP | {Pn, Pt})),
        )
    )
    # Energy: for any (Pn, Pt) the kinetic energy lost is the work on the mean
    # relative velocity; with Gn = 0 and Gt = slip*gt that is TLn + TLt.
    gn0, gt0 = (knl.expanded(s, KEEP) for s in (gn, gt))
    ke = [
        (vx**2 + vy**2) / (2 * k) + w**2 / (2 * j)
        for vx, vy, w, k, j in ((v1x, v1y, w1, k1, j1), (v2x, v2y, w2, k2, j2))
    ]
    KE = [
        (free[a] ** 2 + free[b] ** 2) / (2 * k) + free[c] ** 2 / (2 * j)
        for a, b, c, k, j in ((V1x, V1y, W1, k1, j1), (V2x, V2y, W2, k2, j2))
    ]
    work = Pn * (gn0 + G[0]) / 2 + Pt * (gt0 + G[1]) / 2
    at = KEEP | {Pn, Pt}
    out.append(
        (
            f"{tag}: kinetic energy lost = TLn + TLt, the work of Pn and Pt",
            _zero(sum(ke) - sum(KE) - work)
            and _zero(knl.expanded(TLn, at) - Pn * (gn0 + 0) / 2)
            and _zero(knl.expanded(TLt, at) - Pt * (gt0 + slip * gt0) / 2)
            and sp.expand(knl.expanded(TL - TLn - TLt, at)) == 0,
        )
    )
    out.append((f"{tag}: the Cramer lever products equal r_i x P at its impulse", _cramer_levers(knl)))
    out.append(
        (
            f"{tag}: slip = 0 equals rigid_critical at e = 0, e_m = 1 (common velocity)",
            _sideswipe_is_common_velocity(knl),
        )
    )
    return out


def _cramer_levers(knl: Kernel) -> bool:
    """Lemma: the kernel's c_i (Cramer's rule) equal r_i × P of its (Pn, Pt), as
    identities in the impact-frame lever arms, kk, j1, j2 and (bn, bt)."""
    atoms = frozenset({r1n, r1t, r2n, r2t, kk, j1, j2, bn, bt, r12, D})
    sub = {r12: r1n * r2t - r1t * r2n}

    def at_atoms(sym):
        return knl.expanded(sym, atoms).xreplace(sub)

    sub[D] = sp.expand(at_atoms(Knn * Ktt - Knt**2))
    pn, pt = at_atoms(Pn).xreplace(sub), at_atoms(Pt).xreplace(sub)
    return all(
        sp.simplify(at_atoms(c).xreplace(sub) - planar._cross(rn, rt, pn, pt)) == 0
        for c, rn, rt in ((c1, r1n, r1t), (c2, r2n, r2t))
    )


def _sideswipe_is_common_velocity(knl: Kernel) -> bool:
    """Same K, g, det K; same finals as functions of (Pn, Pt); same (Pn, Pt, μ_c)."""
    crit = planar.KERNELS[1]
    fix = {e: 0, e_m: 1}
    same_atoms = all(
        _zero(knl.expanded(s, KEEP) - crit.expanded(s, KEEP).xreplace(fix))
        for s in (Knn, Knt, Ktt, gn, gt, D)
    )
    same_finals = all(
        _zero(_with_levers(knl, o, {Pn, Pt}) - _with_levers(crit, o, {Pn, Pt}).xreplace(fix))
        for o in (V1x, V1y, W1, V2x, V2y, W2, M)
    )
    no_h = all(sp.simplify(crit.expanded(s, KEEP).xreplace(fix)) == 0 for s in (hn, ht))
    atoms = ATOMS | {hn, ht}
    crit_fix = {**fix, hn: 0, ht: 0}
    same_impulse = all(
        sp.simplify(knl.expanded(s, atoms).xreplace({slip: 0}) - crit.expanded(s, atoms).xreplace(crit_fix))
        == 0
        for s in (Pn, Pt, mu_c)
    )
    return same_atoms and same_finals and no_h and same_impulse


def proofs():
    """(claim, passed) pairs for the preset table and the sideswipe kernel."""
    return (
        _table_claims()
        + _common_velocity_claims("limpert")
        + _common_velocity_claims("impac")
        + _macmillan_claims()
        + _sideswipe_claims()
    )
