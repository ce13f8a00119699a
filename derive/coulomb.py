"""The Coulomb process: point impulse with Coulomb friction, slip that may stop or reverse.

The impact is followed in normal-impulse "time" p = -Pn ≥ 0 (the compressive
impulse on vehicle 2; q = -Pt). The relative velocity at the impact centre is
g(p) = g0 + W (p, q(p)) (W: the point-impulse compliance of kudlich_slibar.py,
planar.py's K at e_m = 1). Coulomb's law at friction μ: while the contact slips
in direction s = sgn(gt), dq/dp = -μ s (friction on vehicle 2 opposes its slip);
while it sticks, |dq/dp| ≤ μ. Each phase has a constant dg/dp, so a phase is a
straight line and the process has at most two phases:

* A: slip in the initial direction s0: dgn/dp = a1 = Knn - μ s0 Knt, and |gt|
  falls at the rate d1 = μ Ktt - s0 Knt. If d1 > 0 the slip stops at
  ps = |gt0|/d1; otherwise it continues to separation (phase B is then A again,
  with the break point at ps = 0). No initial slip: ps = 0.
* B after the slip stopped: stick when μ ≥ |Knt|/Ktt (dq/dp = -Knt/Ktt keeps
  gt = 0, dgn/dp = det W/Ktt), otherwise the slip reverses to sr = sgn(Knt)
  (dq/dp = -μ sr, |gt| grows at |Knt| - μ Ktt > 0). Both are final.

gn(p) is piecewise linear with the break point ps; compression ends at pc with
gn(pc) = 0. The impact ends at pf by one of three restitution laws:
Newton (kinematic) gn(pf) = -e gn0; Poisson (kinetic) pf = (1 + e) pc;
energetic (Stronge) ∫_pc^pf gn dp = -e² ∫_0^pc gn dp.

Energy: TLn = -∫ gn dp and TLt = -∫ gt dq along the path (conventions.md: the
works of the normal and tangential impulses); TLt ≥ 0 always (friction), and
under the energetic law TLn = -(1 - e²) ∫_0^pc gn dp ≥ 0, so T_L ≥ 0. Under
Newton, TLn can be negative when the slip reverses: flag 1 (energy created).

Every phase and transition is a closed form (Piecewise of at most three
branches; the emitted kernels have no loops). Divisions only by quantities
that are positive where they are used (a safe divisor elsewhere), so the
per-scene function never raises.
"""

from __future__ import annotations

import sympy as sp

from . import frame as f
from . import kudlich_slibar as ks
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
    e,
    gamma,
    gn,
    gt,
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
from .kudlich_slibar import detW, mu_f
from .planar import Knn, Knt, Ktt, kk, r1n, r1t, r2n, r2t, r12

LAWS = ("newton", "poisson", "energetic")
SLIP_CLASSES = {"continues": 0, "stops": 1, "reverses": 2}

s0, d1, a1, a1s, stops, stick, sr, ps, gns = real("s0 d1 a1 a1s stops stick sr ps gns")
betaB, a2, rho2, gts = real("betaB a2 rho2 gts")
inAc, pc, Wc, Rw, RA, pf, pA, xB, qf = real("inAc pc Wc Rw RA pf pA xB qf")
gnA, gnf, gtA, gtf, slip_class = real("gnA gnf gtA gtf slip_class")
lev1A, lev2A, lev1B, lev2B, c1, c2 = real("lev1A lev2A lev1B lev2B c1 c2")

INPUTS = (m1, m2, I1, I2, v1x, v1y, w1, v2x, v2y, w2, r1x, r1y, r2x, r2y, gamma, e, mu_f)
OUTPUTS = (V1x, V1y, W1, V2x, V2y, W2, Pn, Pt, mu_used, mu_c, dV1, dV2, TL, TLn, TLt, slip_class)

mu = mu_f  # the friction coefficient in these formulas


# ---------------------------------------------------------------- phases (one function per branch)
# Each returns the branch's formulas; the kernel joins the branches with
# Piecewise and the proofs check every branch alone.


def phase_b(mode: str) -> dict:
    """Phase B: dq/dp (betaB), dgn/dp (a2), growth rate of |gt| (rho2) and
    |gt| at its start (gts), for "continues" (slip never stopped: A again),
    "stick" and "reverse"."""
    if mode == "continues":
        return {betaB: -mu * s0, a2: a1, rho2: -d1, gts: sp.Abs(gt)}
    if mode == "stick":
        return {betaB: -Knt / Ktt, a2: detW / Ktt, rho2: sp.S.Zero, gts: sp.S.Zero}
    return {betaB: -mu * sr, a2: Knn - mu * sr * Knt, rho2: sp.Abs(Knt) - mu * Ktt, gts: sp.S.Zero}


def levers(mode: str):
    """(r1 x d, r2 x d) for a phase whose impulse on vehicle 2 grows along
    d = (1, dq/dp). For a sticking phase the yaw inertias' terms cancel exactly
    (d keeps the slip at zero, so with a small inertia d is nearly along the
    arm): written as -(kk r1t - j2 r2n r12)/Ktt and -(kk r2t + j1 r1n r12)/Ktt,
    with r12 = r1 x r2, which do not cancel (proved equal to r x d)."""
    if mode == "stick":
        return -(kk * r1t - j2 * r2n * r12) / Ktt, -(kk * r2t + j1 * r1n * r12) / Ktt
    beta = phase_b(mode)[betaB]
    return planar._cross(r1n, r1t, 1, beta), planar._cross(r2n, r2t, 1, beta)


def compression_end(in_a: bool):
    """pc with gn(pc) = 0: within phase A (slope a1 from gn0) or within B
    (slope a2 from gns at ps)."""
    return -gn / a1s if in_a else ps - gns / a2


def compression_work(in_a: bool):
    """Wc = ∫_0^pc gn dp (≤ 0): trapezoids of the linear pieces."""
    return gn * pc / 2 if in_a else (gn + gns) * ps / 2 + gns * (pc - ps) / 2


def newton_end(in_a: bool):
    """pf with gn(pf) = -e gn0."""
    return -(1 + e) * gn / a1s if in_a else ps + (-e * gn - gns) / a2


def energetic_end(branch: str):
    """pf with ∫_pc^pf gn dp = Rw = -e² Wc: "A" restitution ends in A, "AB"
    it starts in A (capacity RA) and ends in B, "B" it lies in B. The root of
    the quadratic in "AB" is written 2c/(b + sqrt(b² + 2 a c)), which does not
    cancel (b = gns ≥ 0)."""
    if branch == "A":
        return pc + sp.sqrt(2 * Rw / a1s)
    if branch == "AB":
        return ps + 2 * (Rw - RA) / (gns + sp.sqrt(gns**2 + 2 * a2 * (Rw - RA)))
    return pc + sp.sqrt(2 * Rw / a2)


def _ends_in_a():
    """Separation within phase A (only where the slip stopped after pf)."""
    return sp.StrictLessThan(pf, ps)


# ---------------------------------------------------------------- the kernel


def _phase_blocks():
    """Phase A, the stop of the slip, and phase B's mode."""
    b = {mode: phase_b(mode) for mode in ("continues", "stick", "reverse")}
    stopping = sp.Or(sp.Eq(gt, 0), sp.StrictGreaterThan(d1, 0))
    return (
        Block(
            (
                (s0, sp.sign(gt)),
                (sr, sp.sign(Knt)),
                (stick, sp.Piecewise((1, sp.GreaterThan(mu * Ktt, sp.Abs(Knt))), (0, True))),
            ),
            equation="slip direction at first contact; stick when mu >= |Knt|/Ktt, else reversal to sgn(Knt)",
        ),
        Block(
            ((d1, mu * Ktt - s0 * Knt), (a1, Knn - mu * s0 * Knt)),
            equation="phase A, slip in s0: dq/dp = -mu s0, dgn/dp = a1, d|gt|/dp = -d1",
        ),
        Block(
            (
                (stops, sp.Piecewise((1, stopping), (0, True))),
                # 1 where a1 is not positive: a1 divides only where compression ends in A (a1 > 0).
                (a1s, sp.Piecewise((a1, sp.StrictGreaterThan(a1, 0)), (1, True))),
                (ps, sp.Piecewise((sp.Abs(gt) / d1, sp.StrictGreaterThan(d1, 0)), (0, True))),
            ),
            equation="slip stops at ps = |gt0|/d1 when d1 > 0 (ps = 0: no initial slip, or it never stops)",
        ),
        Block(
            tuple(
                (
                    sym,
                    sp.Piecewise(
                        (b["continues"][sym], sp.Eq(stops, 0)),
                        (b["stick"][sym], sp.Eq(stick, 1)),
                        (b["reverse"][sym], True),
                    ),
                )
                for sym in (betaB, a2, rho2, gts)
            )
            + tuple(
                (
                    sym,
                    sp.Piecewise(
                        (levers("continues")[k], sp.Eq(stops, 0)),
                        (levers("stick")[k], sp.Eq(stick, 1)),
                        (levers("reverse")[k], True),
                    ),
                )
                for k, sym in enumerate((lev1B, lev2B))
            )
            + ((gns, gn + a1 * ps), (lev1A, levers("continues")[0]), (lev2A, levers("continues")[1])),
            Guard((sp.StrictGreaterThan(a2, 0),), "NO_END_OF_COMPRESSION"),
            equation="phase B: the slip continues (A again), sticks (dq/dp = -Knt/Ktt) or reverses "
            "(dq/dp = -mu sgn(Knt)); gns = gn at ps",
        ),
        Block(
            ((inAc, sp.Piecewise((1, sp.GreaterThan(gns, 0)), (0, True))),),
            equation="compression ends in phase A when gn >= 0 at ps",
        ),
        Block(
            ((pc, sp.Piecewise((compression_end(True), sp.Eq(inAc, 1)), (compression_end(False), True))),),
            equation="end of compression: gn(pc) = 0",
        ),
    )


def _restitution_blocks(law: str):
    """The end of the impact pf under `law`."""
    if law == "poisson":
        return (Block(((pf, (1 + e) * pc),), equation="Poisson (kinetic): pf = (1 + e) pc"),)
    if law == "newton":
        in_a = sp.GreaterThan(gns, -e * gn)
        return (
            Block(
                ((pf, sp.Piecewise((newton_end(True), in_a), (newton_end(False), True))),),
                equation="Newton (kinematic, seed eq 3): gn(pf) = -e gn0",
            ),
        )
    return (
        Block(
            (
                (Wc, sp.Piecewise((compression_work(True), sp.Eq(inAc, 1)), (compression_work(False), True))),
                (RA, sp.Piecewise((a1 * (ps - pc) ** 2 / 2, sp.Eq(inAc, 1)), (0, True))),
            ),
            equation="work of the normal impulse in compression, Wc = int_0^pc gn dp; "
            "restitution work phase A can take, RA",
        ),
        Block(((Rw, -(e**2) * Wc),), equation="energetic (Stronge): restitution work = -e^2 Wc"),
        Block(
            (
                (
                    pf,
                    sp.Piecewise(
                        (energetic_end("A"), sp.And(sp.Eq(inAc, 1), sp.LessThan(Rw, RA))),
                        (energetic_end("AB"), sp.Eq(inAc, 1)),
                        (energetic_end("B"), True),
                    ),
                ),
            ),
            equation="energetic: int_pc^pf gn dp = -e^2 Wc, within A, across the break or within B",
        ),
    )


def _final_blocks(law: str):
    """Impulses, the state at separation, the works and the slip class."""
    gn_final = (
        -e * gn
        if law == "newton"
        else sp.Piecewise((gn + a1 * pf, _ends_in_a()), (gns + a2 * (pf - ps), True))
    )
    px, py = f.to_scene_frame(Pn, Pt)
    tln = (1 - e) * (1 + e) * Wc if law == "energetic" else pA * (gn + gnA) / 2 + xB * (gns + gnf) / 2
    return (
        Block(
            ((pA, sp.Min(pf, ps)), (xB, sp.Max(pf - ps, 0)), (gnf, gn_final)),
            equation="the impulse spent in each phase; gn at separation",
        ),
        Block(
            (
                (qf, -mu * s0 * pA + betaB * xB),
                (gnA, sp.Piecewise((gnf, _ends_in_a()), (gns, True))),
                (gtA, sp.Abs(gt) - d1 * pA),
            ),
            equation="tangential impulse on vehicle 2 along the path; gn and |gt| at the end of phase A",
        ),
        Block(
            (
                (Pn, -pf),
                (Pt, -qf),
                (gtf, sp.Piecewise((gtA, _ends_in_a()), (gts + rho2 * xB, True))),
                (c1, -(pA * lev1A + xB * lev1B)),
                (c2, -(pA * lev2A + xB * lev2B)),
            ),
            equation="impulse on vehicle 1 (conventions.md); |gt| at separation; "
            "c = r x P summed over the phases",
        ),
        Block(
            (
                (Px, px),
                (Py, py),
                *f.delta_v_magnitudes(),
                (mu_used, sp.Piecewise((Pt / Pn, sp.Ne(Pn, 0)), (sp.nan, True))),
                (
                    slip_class,
                    sp.Piecewise(
                        (SLIP_CLASSES["continues"], sp.Eq(stops, 0)),
                        (SLIP_CLASSES["continues"], _ends_in_a()),
                        (SLIP_CLASSES["stops"], sp.Eq(stick, 1)),
                        (SLIP_CLASSES["stops"], sp.Eq(pf, ps)),
                        (SLIP_CLASSES["continues"], sp.Eq(gt, 0)),
                        (SLIP_CLASSES["reverses"], True),
                    ),
                ),
            ),
            equation="P in the scene frame; dV = |P|/m; realised ratio Pt/Pn; slip class "
            "(0 continues, 1 stops, 2 reverses)",
        ),
        Block(
            (
                (V1x, v1x + k1 * Px),
                (V1y, v1y + k1 * Py),
                (V2x, v2x - k2 * Px),
                (V2y, v2y - k2 * Py),
                (W1, w1 + j1 * c1),
                (W2, w2 - j2 * c2),
                (TLn, -tln),
                # mean slip speed times the friction impulse in each sliding phase
                (TLt, mu * (pA * (sp.Abs(gt) + gtA) + xB * (gts + gtf)) / 2),
            ),
            equation="final velocities (six equations 1, 2, M = 0); TLn = -int gn dp, TLt = -int gt dq "
            + ("(energetic: TLn = -(1 - e^2) Wc)" if law == "energetic" else "along the path"),
        ),
        Block(((TL, TLn + TLt),), equation="TL = TLn + TLt"),
    )


def kernel(law: str) -> Kernel:
    """The Coulomb process ended by `law` ("newton", "poisson", "energetic")."""
    scalars = (v1x, v1y, w1, v2x, v2y, w2, r1x, r1y, r2x, r2y, gamma, e, mu_f)
    tolerances, flags = ks.law_flags()
    return Kernel(
        name=f"coulomb_{law}",
        doc=f"Coulomb process at the impact centre (friction mu_f), {law} restitution.",
        inputs=INPUTS,
        checks=(
            finite_inputs(scalars, (m1, m2, I1, I2)),
            positive_or_fixed((m1, m2, I1, I2)),
            Guard((sp.Eq(IsFinite(m1), IsFinite(I1)), sp.Eq(IsFinite(m2), IsFinite(I2))), "BAD_MASS"),
            Guard((sp.GreaterThan(mu_f, 0),), "BAD_FRICTION"),
        ),
        blocks=ks.point_frame_blocks()
        + ks.brach_critical_blocks()
        + _phase_blocks()
        + _restitution_blocks(law)
        + _final_blocks(law)
        + (tolerances,),
        outputs=OUTPUTS,
        flags=flags,
        finite=tuple(s for s in OUTPUTS if s not in (mu_used, mu_c)),
        constants=ks.POINT_IMPULSE,
        integers=(slip_class,),
        family="coulomb",
        variant=(("restitution_law", law),),
    )


KERNELS = tuple(kernel(law) for law in LAWS)
EMITTED = tuple(specialise.normal_form(k) for k in KERNELS)


# ---------------------------------------------------------------- proofs

KEEP = frozenset({k1, k2, j1, j2, nx, ny})
p = sp.Symbol("p", nonnegative=True)


def _slope(direction):
    """dg/dp = W (1, dq/dp) for a phase with tangential ratio `direction`."""
    return Knn + Knt * direction, Knt + Ktt * direction


def _phase_claims():
    """Each phase against the friction law, with s0, sr = ±1."""
    out = []
    for sign in (1, -1):
        on = {s0: sign, sr: sign}
        an, at = _slope(-mu * s0)
        a_ok = sp.expand(an - (Knn - mu * s0 * Knt)) == 0
        # |gt| = s0 gt falls at d1: d(s0 gt)/dp = s0 at = -d1, and dq/dp·s0 = -mu (opposes the slip)
        d_ok = sp.expand((s0 * at + (mu * Ktt - s0 * Knt)).xreplace(on)) == 0
        opposes = sp.expand((-mu * s0 * s0).xreplace(on) + mu) == 0
        out.append(
            (
                f"coulomb: phase A (s0 = {sign}) slides at |dq/dp| = mu against the slip, dgn/dp = a1, d|gt|/dp = -d1",
                a_ok and d_ok and opposes,
            )
        )
        stick_b = phase_b("stick")
        sn, st = _slope(stick_b[betaB])
        stick_ok = (
            sp.simplify(st) == 0 and sp.simplify(sn - stick_b[a2].xreplace({detW: Knn * Ktt - Knt**2})) == 0
        )
        rev = phase_b("reverse")
        rn, rt = _slope(rev[betaB])
        # slip grows in sr = sgn(Knt): sr·dgt/dp = |Knt| - mu Ktt (= rho2), friction opposes it
        rev_ok = (
            sp.expand((sr * rt).xreplace(on) - rev[rho2].xreplace({sp.Abs(Knt): sign * Knt})) == 0
            and sp.expand(rn - rev[a2]) == 0
            and sp.expand((rev[betaB] * sr).xreplace(on) + mu) == 0
        )
        out.append(
            (
                f"coulomb: stick keeps gt = 0 (dgn/dp = det W/Ktt); reversal (sgn Knt = {sign}) slides against the new slip at rate rho2",
                stick_ok and rev_ok,
            )
        )
    # stick is admissible exactly when |dq/dp| = |Knt|/Ktt <= mu; reversal otherwise
    cond = sp.Abs(phase_b("stick")[betaB]) - sp.Abs(Knt) / Ktt
    out.append(
        (
            "coulomb: the stick ratio |Knt|/Ktt is the friction bound of the stick test",
            sp.simplify(cond.xreplace({Ktt: sp.Symbol("K", positive=True)})) == 0,
        )
    )
    # the slip stops at ps: |gt0| - d1 ps = 0
    stop = (sp.Abs(gt) - d1 * ps).xreplace({ps: sp.Abs(gt) / d1})
    out.append(("coulomb: |gt| reaches 0 at ps = |gt0|/d1", sp.simplify(stop) == 0))
    return out


def _gn_path(in_a_end: bool):
    """gn(p) on the phase that holds p: gn0 + a1 p in A, gns + a2 (p - ps) in B."""
    return gn + a1 * p if in_a_end else gns + a2 * (p - ps)


def _restitution_claims():
    """Each branch of each law meets its restitution condition exactly (a1s =
    a1 where it divides, gns = gn0 + a1 ps)."""
    sub = {a1s: a1, gns: gn + a1 * ps}
    out = []
    for in_a in (True, False):
        pc_ = compression_end(in_a).xreplace(sub)
        ok = sp.simplify(_gn_path(in_a).xreplace(sub).xreplace({p: pc_})) == 0
        out.append((f"coulomb: gn(pc) = 0 (compression ends in {'A' if in_a else 'B'})", ok))
        pf_ = newton_end(in_a).xreplace(sub)
        ok = sp.simplify(_gn_path(in_a).xreplace(sub).xreplace({p: pf_}) + e * gn) == 0
        out.append((f"coulomb newton: gn(pf) = -e gn0 (separation in {'A' if in_a else 'B'})", ok))
    # energetic: Wc is the integral; each pf branch gives restitution work Rw
    for in_a in (True, False):
        pc_ = compression_end(in_a).xreplace(sub)
        if in_a:
            integral = sp.integrate(gn + a1 * p, (p, 0, pc_))
        else:
            integral = sp.integrate(gn + a1 * p, (p, 0, ps)) + sp.integrate(
                _gn_path(False).xreplace(sub), (p, ps, pc_)
            )
        wc = compression_work(in_a).xreplace(sub).xreplace({pc: pc_})
        out.append(
            (
                f"coulomb energetic: Wc = int_0^pc gn dp (compression ends in {'A' if in_a else 'B'})",
                sp.simplify(integral - wc) == 0,
            )
        )
    a_pos, gns_pos, c = sp.symbols("alpha beta c", positive=True)
    # "A": restitution from pc (gn = 0) at slope a1: work a1 x²/2
    x = energetic_end("A").xreplace({a1s: a_pos, pc: 0})
    ok_a = sp.simplify((a_pos * x**2 / 2).xreplace({Rw: c}) - c) == 0
    # "AB": RA in A, then from gns at slope a2: RA + gns y + a2 y²/2 = Rw
    y = energetic_end("AB").xreplace({ps: 0, gns: gns_pos, a2: a_pos, Rw: c + RA})
    ok_ab = sp.simplify(gns_pos * y + a_pos * y**2 / 2 - c) == 0
    z = energetic_end("B").xreplace({pc: 0, a2: a_pos, Rw: c})
    ok_b = sp.simplify(a_pos * z**2 / 2 - c) == 0
    ra_ok = (
        sp.simplify(
            sp.integrate(gn + a1 * p, (p, pc, ps)).xreplace({pc: -gn / a1}) - a1 * (ps + gn / a1) ** 2 / 2
        )
        == 0
    )
    out.append(
        (
            "coulomb energetic: every pf branch gives restitution work -e^2 Wc (RA = int_pc^ps gn dp)",
            ok_a and ok_ab and ok_b and ra_ok,
        )
    )
    return out


def _energy_claims():
    """TLn = -int gn dp and TLt = -int gt dq on the two-phase path, and TLn +
    TLt = -(g0·Q + ½ QᵀWQ), the kinetic energy lost (W symmetric: the work is
    path independent), for every phase-B mode and both ends of the path."""
    out = []
    y = sp.Symbol("y", nonnegative=True)
    for mode in ("continues", "stick", "reverse"):
        for sign in (1, -1):
            on = {s0: sign, sr: sign}
            b = {k: v.xreplace(on) for k, v in phase_b(mode).items()}
            if mode == "continues":
                # no break point: phase A is empty
                base = {ps: sp.S.Zero, d1: mu * Ktt - s0 * Knt, a1: Knn - mu * s0 * Knt}
            else:
                base = {d1: mu * Ktt - s0 * Knt, a1: Knn - mu * s0 * Knt}
            base = {k: v.xreplace(on) for k, v in base.items()}
            gt0 = sign * sp.Symbol("G", positive=True)  # |gt0| = G, s0 = sgn(gt0)
            if mode != "continues":
                base[ps] = sp.Abs(gt0) / base[d1]
            b = {k: v.xreplace(base) for k, v in b.items()}
            for ends_in_a in (True, False) if mode != "continues" else (False,):
                # path: phase A for pa, phase B for xb
                pa = y if ends_in_a else base[ps]
                xb = 0 if ends_in_a else y
                qa = -mu * s0 * pa
                q_end = (qa + b[betaB] * xb).xreplace(on)
                pend = pa + xb
                # integrals along the path from g = g0 + W (p, q)
                t = sp.Symbol("t", nonnegative=True)
                gA = (gn + Knn * t + Knt * (-mu * sign * t), gt0 + Knt * t + Ktt * (-mu * sign * t))
                ga_end = tuple(c.xreplace({t: pa}) for c in gA)
                gB = (ga_end[0] + Knn * t + Knt * b[betaB] * t, ga_end[1] + Knt * t + Ktt * b[betaB] * t)
                int_n = sp.integrate(gA[0], (t, 0, pa)) + sp.integrate(gB[0], (t, 0, xb))
                int_t = sp.integrate(gA[1] * (-mu * sign), (t, 0, pa)) + sp.integrate(
                    gB[1] * b[betaB], (t, 0, xb)
                )
                # the kernel's TLn (trapezoids), TLt (mean slip speed) on this path
                gns_ = ga_end[0] if not ends_in_a else gn + base[a1] * base[ps]
                gnf_ = gB[0].xreplace({t: xb})
                gna_ = ga_end[0]
                tln = (
                    -(pa * (gn + gna_) / 2 + xb * (gns_ + gnf_) / 2)
                    if not ends_in_a
                    else -(pa * (gn + gna_) / 2)
                )
                gta = sp.Abs(gt0) - base[d1] * pa
                gts_ = b[gts].xreplace({sp.Abs(gt): sp.Abs(gt0)})
                tlt = mu * (pa * (sp.Abs(gt0) + gta) + xb * (gts_ + gts_ + b[rho2] * xb)) / 2
                tlt = tlt.xreplace({sp.Abs(Knt): sign * Knt})
                Q = sp.Matrix([pend, q_end])
                Wm = sp.Matrix([[Knn, Knt], [Knt, Ktt]])
                work = (sp.Matrix([[gn, gt0]]) * Q)[0] + (Q.T * Wm * Q)[0] / 2
                same_n = sp.simplify(tln + int_n) == 0
                same_t = sp.simplify(tlt + int_t) == 0
                total = sp.simplify(int_n + int_t - work) == 0
                out.append(
                    (
                        f"coulomb: TLn, TLt are the works on the path and sum to the kinetic energy lost "
                        f"(B {mode}, s0 = {sign}, separation in {'A' if ends_in_a else 'B'})",
                        same_n and same_t and total,
                    )
                )
    return out


def _lever_claims():
    """c1, c2 are r1 x P, r2 x P: for each phase-B mode, pA·(r x dA) + xB·(r x dB)
    is r x Q for Q = pA dA + xB dB (the stick levers' cancelled form included)."""
    W = {
        Knn: kk + j1 * r1t**2 + j2 * r2t**2,
        Knt: -(j1 * r1n * r1t + j2 * r2n * r2t),
        Ktt: kk + j1 * r1n**2 + j2 * r2n**2,
    }
    frame = {r12: r1n * r2t - r1t * r2n}
    pa, xb = sp.symbols("pa xb", real=True)
    ok = True
    for mode in ("continues", "stick", "reverse"):
        beta_b = phase_b(mode)[betaB]
        qn, qt = pa + xb, -mu * s0 * pa + beta_b * xb
        lb = levers(mode)
        la = levers("continues")
        for k, (rn, rt) in enumerate(((r1n, r1t), (r2n, r2t))):
            kernel_c = pa * la[k] + xb * lb[k]
            ok = (
                ok
                and sp.simplify((kernel_c - planar._cross(rn, rt, qn, qt)).xreplace(frame).xreplace(W)) == 0
            )
    return (
        "coulomb: c1, c2 = -(pA r x dA + xB r x dB) are r1 x P, r2 x P in every mode (stick levers cancelled exactly)",
        ok,
    )


def _energetic_tln():
    """Energetic: -int_0^pf gn dp = -(Wc + Rw) = -(1 - e²) Wc (the emitted form)."""
    return (
        "coulomb_energetic: TLn = -(Wc - e^2 Wc) = -(1 - e^2) Wc",
        sp.expand((Wc + (-(e**2) * Wc)) - (1 - e) * (1 + e) * Wc) == 0,
    )


def _kernel_claims(knl: Kernel):
    """Momentum and angular impulse for the kernel's finals (any Pn, Pt; M = 0)."""
    at = KEEP | {Pn, Pt, c1, c2}
    arms = {x: knl.expanded(x, KEEP) for x in (r1n, r1t, r2n, r2t)}
    cross = {
        c1: planar._cross(arms[r1n], arms[r1t], Pn, Pt),
        c2: planar._cross(arms[r2n], arms[r2t], Pn, Pt),
    }
    got = {s: knl.expanded(s, at).xreplace(cross) for s in (V1x, V1y, W1, V2x, V2y, W2, Px, Py)}
    got[planar.M] = 0
    res, _ = planar.six_equation_residuals(got, sticking=False)
    ok = all(ks._zero(r) for r in res[:6])
    dv = f.delta_v_magnitudes_hold(lambda x: knl.expanded(x, at))
    return [(f"{knl.name}: impulse-momentum (six equations 1, 2, M = 0); dV = |V - v|", ok and dv)]


def proofs():
    """(claim, passed) pairs for the Coulomb-process kernels."""
    out = _phase_claims() + _restitution_claims() + _energy_claims() + [_lever_claims(), _energetic_tln()]
    for knl in KERNELS:
        out += _kernel_claims(knl)
    return out
