"""Two-particle impact model: seed eqs 1–18 and the energy partition, eqs 21–26.

The seed writes the model in the impact frame with masses: conservation of
momentum along n and t (eqs 1, 2), restitution (eq 3), and either the impulse
ratio μ = Pt/Pn (eq 5, combined with momentum into eq 7: sliding at separation)
or equal final tangential velocities (eq 8: sliding ends, "sticking"). Here
SymPy solves those equations, checks the solution against eqs 10–15 as printed,
and re-expresses it for code: inverse masses (exact for a fixed barrier),
the approach velocity gn = n·(v2 - v1) formed once from the scene-frame
difference v2 - v1, and energy loss as the work of the impulse components.
"""

from __future__ import annotations

import sympy as sp

from . import frame as f
from . import specialise
from .frame import (
    TL,
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
    dgn,
    dgt,
    dV1,
    dV2,
    dvx,
    dvy,
    e,
    gamma,
    gn,
    gt,
    k1,
    k2,
    m1,
    m2,
    mu,
    mu_c,
    mu_used,
    nx,
    ny,
    v1x,
    v1y,
    v2x,
    v2y,
)
from .kernel import Block, Guard, Kernel, finite_inputs, positive_or_fixed, real

INPUTS = (m1, m2, v1x, v1y, v2x, v2y, gamma, e, mu)
OUTPUTS = (V1x, V1y, V2x, V2y, Pn, Pt, mu_used, mu_c, dV1, dV2, TL, TLn, TLt)

mbar = sp.Symbol("mbar", positive=True)  # the seed's m̄ = m1·m2/(m1 + m2)

# Impact-frame components for the seed's own equations.
v1n, v1t, v2n, v2t, V1n, V1t, V2n, V2t = real("v1n v1t v2n v2t V1n V1t V2n V2t")


def seed_equations(sticking: bool):
    """Eqs 1, 2, 3 and 7 (sliding) or 8 (sticking), as residuals = 0."""
    eqs = [
        m1 * v1n + m2 * v2n - (m1 * V1n + m2 * V2n),  # (1)
        m1 * v1t + m2 * v2t - (m1 * V1t + m2 * V2t),  # (2)
        (V1n - V2n) + e * (v1n - v2n),  # (3)
    ]
    if sticking:
        eqs.append(V1t - V2t)  # (8)
    else:
        eqs.append(
            (mu * m1 * V1n - m1 * V1t - mu * m2 * V2n + m2 * V2t)
            - (mu * m1 * v1n - m1 * v1t - mu * m2 * v2n + m2 * v2t)
        )  # (7)
    return eqs


def seed_printed_solution(sticking: bool):
    """Eqs 10–13 (sliding) or 10, 12, 14, 15 (sticking) exactly as printed."""
    msum = m1 + m2
    sol = {
        V1n: v1n + m2 * (1 + e) * (v2n - v1n) / msum,  # (10)
        V2n: v2n - m1 * (1 + e) * (v2n - v1n) / msum,  # (12)
    }
    if sticking:
        sol[V1t] = v1t + m2 * (v2t - v1t) / msum  # (14)
        sol[V2t] = v2t - m1 * (v2t - v1t) / msum  # (15)
    else:
        sol[V1t] = v1t + mu * m2 * (1 + e) * (v2n - v1n) / msum  # (11)
        sol[V2t] = v2t - mu * m1 * (1 + e) * (v2n - v1n) / msum  # (13)
    return sol


def seed_energy_loss():
    """Eq 17, T_L = m̄ (v2n - v1n)² (1+e) [(1-e) + 2μr - (1+e)μ²] / 2, and eq 18."""
    r = (v2t - v1t) / (v2n - v1n)
    m_bar = m1 * m2 / (m1 + m2)
    tl = m_bar * (v2n - v1n) ** 2 * (1 + e) * ((1 - e) + 2 * mu * r - (1 + e) * mu**2) / 2
    return tl, r / (1 + e)


def _kernel_blocks(sticking: bool):
    """The particle kernel's formulas, in evaluation order."""
    gn_, gt_ = f.to_impact_frame(dvx, dvy)
    # Restitution fixes the change of the normal approach velocity; the impulse
    # ratio (sliding) or the end of sliding (sticking) fixes the tangential one.
    # Both are kept as single quantities so (1 + e)·gn is rounded once.
    dgt_ = -gt if sticking else mu * -(1 + e) * gn
    px, py = f.to_scene_frame(Pn, Pt)
    gn_final = -e * gn  # eq 3
    gt_final = gt + dgt
    return (
        Block(
            f.inverse_masses((m1, m2), (k1, k2))
            + f.normal_components()
            + ((dvx, v2x - v1x), (dvy, v2y - v1y)),
            Guard((sp.StrictGreaterThan(k1 + k2, 0),), "SINGULAR"),
            equation="conventions.md frame: k = 1/m, n = (cos gamma, sin gamma)",
        ),
        Block(
            ((gn, gn_), (gt, gt_), (mbar, 1 / (k1 + k2))),
            f.approach_guard(),
            equation="approach in the impact frame (seed Fig. 1); reduced mass (seed eq 17)",
        ),
        # e = -1 (or an underflowing product) gives no normal impulse: mu_c divides by dgn.
        Block(
            ((dgn, -(1 + e) * gn), (dgt, dgt_)),
            Guard((sp.Ne(dgn, 0),), "SINGULAR"),
            equation="restitution (seed eq 3); "
            + ("end of sliding (seed eq 8)" if sticking else "impulse ratio (seed eq 5)"),
        ),
        Block(
            (
                # Δ(v2 - v1) = -(1/m1 + 1/m2)·P, so P = -m̄·Δg (eqs 4, 6).
                (Pn, -mbar * dgn),
                (Pt, -mbar * dgt),
                (mu_c, -gt / dgn),  # eq 18: μ_max = r/(1 + e)
                (mu_used, -gt / dgn if sticking else mu),
            ),
            equation="impulses (seed eqs 4, 6); mu_max (seed eq 18)",
        ),
        Block(
            (
                (Px, px),
                (Py, py),
                *f.delta_v_magnitudes(),
                # Work of each impulse component on the mean relative velocity
                # (eqs 21–26). (gn + Gn) factors to (1 - e)·gn: never a sum of
                # nearly opposite velocities when e is close to 1.
                (TLn, Pn * sp.factor(gn + gn_final) / 2),
                (TLt, Pt * (gt + gt_final) / 2),
            ),
            equation="P in the scene frame; work of Pn, Pt (seed eqs 21-26)",
        ),
        Block(
            (
                (V1x, v1x + k1 * Px),
                (V1y, v1y + k1 * Py),
                (V2x, v2x - k2 * Px),
                (V2y, v2y - k2 * Py),
                (TL, TLn + TLt),
            ),
            equation="final velocities (seed eqs 10-15); TL (seed eq 16)",
        ),
    )


def kernel(sticking: bool) -> Kernel:
    """The particle kernel, sliding (given μ) or sticking (μ = μ_max)."""
    name = "particle_critical" if sticking else "particle"
    doc = "Two-particle impact, " + (
        "sliding ends before separation (mu = mu_c, seed eqs 10, 12, 14, 15)."
        if sticking
        else "impulse ratio mu given (seed eqs 10-13)."
    )
    tolerances, flags = f.physics_flags((TL, TLn, TLt), ((Pn, gn), (Pt, gt)), restitution=e)
    return Kernel(
        name=name,
        doc=doc,
        inputs=INPUTS,
        checks=(
            finite_inputs((v1x, v1y, v2x, v2y, gamma, e) + (() if sticking else (mu,)), (m1, m2)),
            positive_or_fixed((m1, m2)),
        ),
        blocks=_kernel_blocks(sticking) + (tolerances,),
        outputs=OUTPUTS,
        flags=flags,
        constants=NO_ROTATION,
        family="particle",
        variant=(("critical", True),) if sticking else (),
    )


# Particles neither turn nor take a moment: the rigid model's outputs they lack.
NO_ROTATION = (("W1", 0.0), ("W2", 0.0), ("M", 0.0), ("TLm", 0.0))

KERNELS = (kernel(sticking=False), kernel(sticking=True))

# What generated/particle.py holds: each kernel in normal form, for every output tier.
EMITTED = tuple(k for base in KERNELS for k in specialise.tiers(specialise.normal_form(base)))


# ---------------------------------------------------------------- proofs


def _seed_frame_values():
    """The seed's impact-frame symbols in terms of the kernel's inputs."""
    n1, t1 = f.to_impact_frame(v1x, v1y)
    n2, t2 = f.to_impact_frame(v2x, v2y)
    return {v1n: n1, v1t: t1, v2n: n2, v2t: t2, m1: 1 / k1, m2: 1 / k2}


def _zero(expr) -> bool:
    return f.reduce_unit_normal(expr) == 0


def proofs():
    """(claim, passed) pairs: the seed's solution, the kernels, energy, μ_max."""
    keep = frozenset({k1, k2, nx, ny})
    seed_vals = _seed_frame_values()
    out = []
    for knl, sticking in zip(KERNELS, (False, True)):
        tag = knl.name
        solved = sp.solve(seed_equations(sticking), [V1n, V1t, V2n, V2t], dict=True)[0]
        printed = seed_printed_solution(sticking)
        out.append(
            (
                f"{tag}: SymPy's solution of eqs 1-3,{'8' if sticking else '7'} equals the printed eqs",
                all(sp.simplify(solved[s] - printed[s]) == 0 for s in printed),
            )
        )
        got = {s: knl.expanded(s, keep) for s in (V1x, V1y, V2x, V2y, Pn, Pt, TL, TLn, TLt, mu_c, mu_used)}
        finals = {}
        for (sx, sy), (sn, st) in (((V1x, V1y), (V1n, V1t)), ((V2x, V2y), (V2n, V2t))):
            finals[sn], finals[st] = f.to_impact_frame(got[sx], got[sy])
        out.append(
            (
                f"{tag}: kernel final velocities equal the printed solution",
                all(_zero(finals[s] - printed[s].xreplace(seed_vals)) for s in printed),
            )
        )
        out.append(
            (
                f"{tag}: dV1, dV2 are |V1 - v1|, |V2 - v2|",
                f.delta_v_magnitudes_hold(lambda x, knl=knl: knl.expanded(x, keep | {Pn, Pt})),
            )
        )
        out.append(
            (
                f"{tag}: P equals m1 (V1 - v1) (eqs 4, 6)",
                _zero(got[Pn] - (finals[V1n] - seed_vals[v1n]) / k1)
                and _zero(got[Pt] - (finals[V1t] - seed_vals[v1t]) / k1),
            )
        )
        ke_before = (v1x**2 + v1y**2) / (2 * k1) + (v2x**2 + v2y**2) / (2 * k2)
        ke_after = (got[V1x] ** 2 + got[V1y] ** 2) / (2 * k1) + (got[V2x] ** 2 + got[V2y] ** 2) / (2 * k2)
        out.append(
            (f"{tag}: TL equals the kinetic-energy difference (eq 16)", _zero(ke_before - ke_after - got[TL]))
        )
        gn_i = seed_vals[v2n] - seed_vals[v1n]
        gt_i = seed_vals[v2t] - seed_vals[v1t]
        out.append(
            (
                f"{tag}: TLn = Pn (gn + Gn)/2 and TLt = Pt (gt + Gt)/2 (eqs 21-26)",
                _zero(got[TLn] - got[Pn] * (gn_i + finals[V2n] - finals[V1n]) / 2)
                and _zero(got[TLt] - got[Pt] * (gt_i + finals[V2t] - finals[V1t]) / 2),
            )
        )
        tl17, mu_max = seed_energy_loss()
        mu_here = mu_max if sticking else mu
        out.append(
            (
                f"{tag}: TL equals eq 17, mu_c equals eq 18",
                _zero(got[TL] - tl17.xreplace({mu: mu_here}).xreplace(seed_vals))
                and _zero(got[mu_c] - mu_max.xreplace(seed_vals)),
            )
        )
        if sticking:
            out.append(
                (f"{tag}: final tangential velocities are equal (eq 8)", _zero(finals[V1t] - finals[V2t]))
            )
        else:
            at_crit = {mu: got[mu_c]}
            out.append(
                (
                    f"{tag}: mu = mu_c ends sliding (Gt = 0) and maximises TL",
                    _zero((finals[V2t] - finals[V1t]).xreplace(at_crit))
                    and _zero(sp.diff(got[TL], mu).xreplace(at_crit)),
                )
            )
    return out
