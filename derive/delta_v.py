"""Delta-V from energy loss: the seed's eqs 27–29, derived for the planar model.

The seed relates the scalar delta-V of each vehicle to the energy loss T_L of a
planar impact without moment impulse (e_m = 1):

    ΔV1 = (1/m1) √[ 2 m̄ (1 + μ²)(1 + e) q T_L / ((1 - e) + 2μr - μ² r/μ_max) ]   (27)
    ΔV2 = m1 ΔV1 / m2                                                              (28)
    1/q = 1 + m̄ d_a²/I2 + m̄ d_c²/I1 - μ (m̄ d_c d_d/I1 + m̄ d_a d_b/I2)             (29)

with r = gt/gn the ratio of tangential to normal approach velocity at the
impact centre. Here the relation is derived from the rigid-body solution: with
K the 2x2 compliance of the impact centre and D = Knn + μ·Knt (so 1/q = m̄·D),
T_L = Pn² D/(2(1 + e))·B, B = (1 - e) + 2μr - μ(1 + e)(Knt + μ·Ktt)/D, and
|ΔV1| = |P|/m1 = |Pn| √(1 + μ²)/m1. For particles (zero lever arms) the last
term of B is exactly the seed's μ²·r/μ_max; for eccentric impacts it is the
exact generalisation (the seed's form with μ_max would need μ_max to depend on
μ). The proofs show both: agreement with the forward model, and eq 27 itself
for central impacts.
"""

from __future__ import annotations

import sympy as sp

from . import frame as f
from . import planar
from .frame import I1, I2, e, gamma, j1, j2, k1, k2, m1, m2, mu, r1x, r1y, r2x, r2y
from .kernel import Block, Guard, Kernel, finite_inputs, positive_or_fixed, real
from .planar import Cnn, Cnt, Ctt, D, r1n, r1t, r2n, r2t

r, TL_in, dV1, dV2, q, B, P_abs, ome = real("r TL dV1 dV2 q B P_abs one_minus_e")

INPUTS = (m1, m2, I1, I2, r1x, r1y, r2x, r2y, gamma, e, mu, r, TL_in)
OUTPUTS = (dV1, dV2, q)


def _blocks():
    C = planar.compliance()
    r1n_, r1t_ = f.to_impact_frame(r1x, r1y)
    r2n_, r2t_ = f.to_impact_frame(r2x, r2y)
    return (
        Block(
            f.inverse_masses((m1, m2, I1, I2), (k1, k2, j1, j2)) + f.normal_components(),
            Guard((sp.StrictGreaterThan(k1 + k2, 0),), "SINGULAR"),
            equation="conventions.md frame: k = 1/m, j = 1/I, n = (cos gamma, sin gamma)",
        ),
        Block(
            ((r1n, r1n_), (r1t, r1t_), (r2n, r2n_), (r2t, r2t_)),
            equation="arms in the impact frame: the seed's d_d, d_c (vehicle 1), d_b, d_a (vehicle 2) of eq 29",
        ),
        Block(
            ((Cnn, C[0, 0]), (Cnt, C[0, 1]), (Ctt, C[1, 1])),
            equation="compliance C of the impact centre from impulse-momentum (seed appendix eqs 1-3)",
        ),
        # 1 - e as one rounded quantity (SymPy would flatten it into the sum).
        Block(
            ((D, Cnn + mu * Cnt), (ome, 1 - e)),
            Guard((sp.Ne(D, 0),), "SINGULAR"),
            equation="D = Cnn + mu Cnt, so 1/q = mbar D (seed eq 29)",
        ),
        Block(
            ((q, (k1 + k2) / D), (B, ome + 2 * mu * r - mu * (1 + e) * (Cnt + mu * Ctt) / D)),
            # T_L = Pn² D B / (2(1 + e)): a real |P| needs D·B > 0.
            Guard((sp.StrictGreaterThan(D * B, 0),), "ENERGY_INCONSISTENT"),
            equation="q (seed eq 29); B, the denominator of seed eq 27 with mu^2 r/mu_max generalised",
        ),
        Block(
            ((P_abs, sp.sqrt(2 * (1 + mu**2) * (1 + e) * TL_in / (D * B))),),
            equation="|P| = m1 dV1 from TL (seed eq 27)",
        ),
        Block(
            ((dV1, k1 * P_abs), (dV2, k2 * P_abs)), equation="dV1 (seed eq 27); dV2 = m1 dV1/m2 (seed eq 28)"
        ),
    )


KERNELS = (
    Kernel(
        name="delta_v_from_energy",
        doc="Delta-V of each vehicle from the energy loss TL (seed eqs 27-29; e_m = 1).",
        inputs=INPUTS,
        checks=(
            finite_inputs((r1x, r1y, r2x, r2y, gamma, e, mu, r, TL_in), (m1, m2, I1, I2)),
            positive_or_fixed((m1, m2, I1, I2)),
            Guard((sp.GreaterThan(TL_in, 0), sp.StrictGreaterThan(1 + e, 0)), "ENERGY_INCONSISTENT"),
        ),
        blocks=_blocks(),
        outputs=OUTPUTS,
    ),
)


# ---------------------------------------------------------------- proofs


def proofs():
    """The relation agrees with the forward rigid model (e_m = 1) and is eq 27
    with eq 29 for central impacts."""
    knl = KERNELS[0]
    fwd = planar.KERNELS[0]
    gn, gt = f.gn, f.gt
    atoms = frozenset({k1, k2, j1, j2, r1n, r1t, r2n, r2t, f.gn, f.gt})
    no_moment = {f.e_m: 1}
    pn = fwd.expanded(f.Pn, atoms).xreplace(no_moment)
    tl = fwd.expanded(f.TL, atoms).xreplace(no_moment)
    inputs_here = {r: gt / gn, TL_in: tl}
    dv1 = knl.expanded(dV1, atoms).xreplace(inputs_here)
    agrees = sp.simplify(dv1**2 - k1**2 * pn**2 * (1 + mu**2)) == 0
    central = {r1n: 0, r1t: 0, r2n: 0, r2t: 0}
    mbar = 1 / (k1 + k2)
    mu_max = r / (1 + e)
    eq27 = k1 * sp.sqrt(
        2
        * mbar
        * (1 + mu**2)
        * (1 + e)
        * knl.expanded(q, atoms)
        * TL_in
        / ((1 - e) + 2 * mu * r - mu**2 * r / mu_max)
    )
    is_eq27 = sp.simplify((knl.expanded(dV1, atoms) - eq27).xreplace(central)) == 0
    # Eq 29 with the seed's arms d_c = r1t, d_d = r1n, d_a = r2t, d_b = r2n.
    eq29 = 1 + mbar * r2t**2 * j2 + mbar * r1t**2 * j1 - mu * (mbar * r1t * r1n * j1 + mbar * r2t * r2n * j2)
    is_eq29 = sp.simplify(1 / knl.expanded(q, atoms) - eq29) == 0
    dv2_ratio = sp.simplify(knl.expanded(dV2, atoms) - k2 / k1 * knl.expanded(dV1, atoms)) == 0
    return [
        ("delta_v_from_energy: |ΔV1| from T_L equals the forward model's |P|/m1", agrees),
        ("delta_v_from_energy: central impacts give the seed's eq 27", is_eq27),
        ("delta_v_from_energy: 1/q is the seed's eq 29", is_eq29),
        ("delta_v_from_energy: ΔV2 = m1 ΔV1 / m2 (eq 28)", dv2_ratio),
    ]
