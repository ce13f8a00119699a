"""CRASH3 (McHenry, NHTSA): crush energy from a damage profile, and delta-V from that energy.

Crush energy. The damaged face is a row of springs: the force per unit width at
residual crush C is F/w = A + B·C, and the crush starts only past the force A
(the "no-damage" energy G = A²/(2B) per unit width, the work of the line
A + B·c from c = -A/B to 0). The energy per unit width at crush C is then the
work of that line from -A/B to C, A·C + B·C²/2 + G = (A + B·C)²/(2B) ≥ 0. A
profile of N = 2, 4 or 6 equally spaced depths C1..CN over the damage width L,
linear between them, is integrated symbolically segment by segment. The
principal direction of force (PDOF) at an angle α to the normal of the damaged
face scales the energy by CRASH3's energy correction factor 1 + tan²α (the
crush measured along the normal underestimates the work of an oblique force),
or by Woolley's 1/cos α (R. L. Woolley, SAE 850437 / 851659: the force along the
PDOF does work over the crush projected on it). EDCRASH caps the CRASH3 factor
at 2, i.e. α at 45° (Day & Hargens, SAE 870045, citing the EDCRASH manual; the
McHenry Software notes on the "Energy Correction Factor" give the same
maximum of 2.0 for CRASH3): both factors are computed at min(|α|, 45°), and a
capped row raises the PDOF_CAPPED flag. |α| ≥ 90° (a force pulling the face
out) is the status PDOF_BEYOND_LIMIT.

Delta-V. CRASH3 treats the impact as one-dimensional along the PDOF with a
common velocity at the impact centre (e = 0; restitution e optional): each
vehicle enters with its effective mass m·γ, γ = k²/(k² + h²), k the radius of
gyration and h the moment arm of the PDOF about the centre of gravity (γ = 1
without yaw: k = ∞ or h = 0). The energy E of the 1-D impact of effective
masses with restitution e fixes the impulse |P| = √(2 E m̄ (1 + e)/(1 - e)),
m̄ = 1/(1/(γ1 m1) + 1/(γ2 m2)), and ΔV_i = |P|/m_i, directed along the PDOF:
the force on vehicle 1 is -|P|·(cos(Γ + α1), sin(Γ + α1)) (α1 measured from its
inward normal -n) and on vehicle 2 +|P|·(cos(Γ + α2), sin(Γ + α2)).

Restitution and the crush energy (Rose, Fenton & Beauchamp, SAE 2006-01-0908).
"dissipated" (kernel crash3_delta_v): E is the energy lost over the whole
impact, E = m̄ v_c² (1 - e²)/2, so |P| = m̄ v_c (1 + e) = √(2 E m̄ (1 + e)/(1 - e)).
"absorbed" (kernel crash3_delta_v_absorbed): E is the energy absorbed up to
maximum crush (the common-velocity instant), E = m̄ v_c²/2; the approach impulse
is √(2 E m̄) and the total (1 + e) times it. For the same E the two differ by
the factor √(1 - e²) (proved below); at e = 0 they coincide.

Which delta-V. ΔV_i = |P|/m_i is the change of the centre-of-gravity velocity
(what an accelerometer at the CG measures, and what Brach, Neades and Rose
report). EDCRASH (Day & Hargens) prints √(2E/(M1(1 + M1/M2))) with M = γ m, the
change of velocity of the effective mass, |P|/(γ_i m_i) = ke_i |P|: the kernels
output it as dV1_eff, dV2_eff, and ΔV_cg = γ ΔV_eff (proved below).

The seed's criticism: CRASH uses μ = μ_max (a common velocity) for |ΔV| but the
user's PDOF for the direction. The impulse-momentum model's own PDOF is
α = atan2(-Pt, -Pn), so tan α = μ = Pt/Pn: its PDOF correction 1 + tan²α is the
(1 + μ²) of seed eq 27. The proofs show that CRASH3 given the PDOF and the
energy loss of the common-velocity rigid solution returns exactly that
solution's impulse, so any difference between the two comes from the entered
PDOF and the crush energy, not from the effective-mass formula.
"""

from __future__ import annotations

import sympy as sp

from . import frame as f
from . import planar
from .frame import Pn, Pt, e, gamma, j1, j2, k1, k2, m1, m2
from .kernel import Block, Guard, Kernel, finite_inputs, positive_or_fixed, real

A, B, width, alpha, G, E_crush, E = real("A B width alpha G E_crush E")
DEPTHS = real("C1 C2 C3 C4 C5 C6")
PROFILE_SIZES = (2, 4, 6)
PDOF_CAP = sp.pi / 4  # EDCRASH's cap: the factor 1 + tan²α at most 2, α at most 45°
PDOF_LIMIT = sp.pi / 2  # beyond it the force would pull the damaged face out

# Per-segment integration symbols: crush Ca..Cb over a segment of width d.
c, w, d, Ca, Cb = real("c w d Ca Cb")


def energy_density():
    """Crush energy per unit width at crush C: the work of F/w = A + B·c from
    c = -A/B (where the force vanishes) to C, split as A·C + B·C²/2 + G."""
    return sp.integrate(A + B * c, (c, -A / B, Ca))


def segment_energy():
    """∫ over one segment of width d of the energy density, crush linear from Ca to Cb."""
    crush = Ca + (Cb - Ca) * w / d
    density = sp.expand(energy_density()).xreplace({A**2 / (2 * B): G})
    return sp.factor_terms(sp.expand(sp.integrate(density.xreplace({Ca: crush}), (w, 0, d))))


def profile_energy(n: int):
    """Crush energy of an n-point profile (segments of width L/(n - 1))."""
    seg = segment_energy()
    return sum(seg.xreplace({Ca: DEPTHS[i], Cb: DEPTHS[i + 1], d: width / (n - 1)}) for i in range(n - 1))


alpha_c, E_woolley = real("alpha_c E_woolley")


def energy_kernel(n: int) -> Kernel:
    """CRASH3 crush energy of one vehicle from an n-point profile (n = 2, 4, 6),
    with CRASH3's (E) and Woolley's (E_woolley) oblique corrections at the
    capped angle alpha_c = min(|α|, 45°)."""
    depths = DEPTHS[:n]
    valid = (sp.GreaterThan(A, 0), sp.StrictGreaterThan(B, 0), sp.StrictGreaterThan(width, 0)) + tuple(
        sp.GreaterThan(ci, 0) for ci in depths
    )
    return Kernel(
        family="crash3_energy",
        variant=(("points", n),),
        name=f"crash3_energy_{n}",
        doc=f"CRASH3 crush energy of a {n}-point profile, F/w = A + B*C; E = E_crush*(1 + tan^2 "
        "alpha_c), E_woolley = E_crush/cos(alpha_c), alpha_c = min(|alpha|, 45 deg).",
        inputs=(A, B, width, *depths, alpha),
        checks=(
            finite_inputs((A, B, width, *depths, alpha)),
            Guard(valid, "BAD_CRUSH"),
            Guard((sp.StrictLessThan(sp.Abs(alpha), PDOF_LIMIT),), "PDOF_BEYOND_LIMIT"),
        ),
        blocks=(
            Block(
                ((G, A**2 / (2 * B)), (alpha_c, sp.Min(sp.Abs(alpha), PDOF_CAP))),
                equation="no-damage energy G = A^2/(2B) (CRASH3 manual); alpha capped at 45 deg "
                "(EDCRASH; Day & Hargens SAE 870045)",
            ),
            Block(
                ((E_crush, profile_energy(n)),),
                equation=f"{n}-point crush energy: F/w = A + B C integrated per segment "
                "(CRASH3 manual; Day & Hargens SAE 870045)",
            ),
            Block(
                ((E, E_crush * (1 + sp.tan(alpha_c) ** 2)), (E_woolley, E_crush / sp.cos(alpha_c))),
                equation="oblique force: CRASH3's 1 + tan^2 alpha (CRASH3 manual; Day & Hargens SAE 870045), "
                "Woolley's 1/cos alpha",
            ),
        ),
        outputs=(E_crush, E, E_woolley),
        flags=(("PDOF_CAPPED", (sp.StrictGreaterThan(sp.Abs(alpha), PDOF_CAP),)),),
    )


# ---------------------------------------------------------------- delta-V

rg1, rg2, h1, h2, alpha1, alpha2 = real("rg1 rg2 h1 h2 alpha1 alpha2")
rx, ry, theta, mass, inertia, rg = real("rx ry theta mass inertia rg")
ke1, ke2, ome, P, dV1, dV2 = real("ke1 ke2 one_minus_e P dV1 dV2")
dV1x, dV1y, dV2x, dV2y, mass_factor1, mass_factor2, h = real(
    "dV1x dV1y dV2x dV2y mass_factor1 mass_factor2 h"
)
dV1_eff, dV2_eff = real("dV1_eff dV2_eff")
ENERGY_MODES = ("dissipated", "absorbed")
pdof = sp.Symbol("pdof", real=True)


def delta_v_kernel(energy: str = "dissipated") -> Kernel:
    """|P|, |ΔV_i| (centre of gravity), the effective-mass factors, the
    effective-mass delta-V and the ΔV vectors along the PDOFs. `energy` says
    what the crush energy E is: "dissipated" over the whole impact or
    "absorbed" up to maximum crush (module docstring)."""
    if energy == "dissipated":
        name, e_range = "crash3_delta_v", sp.StrictLessThan(e, 1)
        impulse = sp.sqrt(2 * E * (1 + e) / (ome * (ke1 + ke2)))
        impulse_equation = (
            "|P| = sqrt(2 E mbar (1 + e)/(1 - e)): E lost over the impact (CRASH3 at e = 0; "
            "Rose et al. SAE 2006-01-0908)"
        )
        doc = (
            "CRASH3 delta-V from the total crush energy E dissipated over the impact: 1-D "
            "impact of effective masses gamma_i*m_i along the PDOF, restitution e "
            "(0 = common velocity)."
        )
    else:
        name, e_range = "crash3_delta_v_absorbed", sp.LessThan(e, 1)
        impulse = (1 + e) * sp.sqrt(2 * E / (ke1 + ke2))
        impulse_equation = (
            "|P| = (1 + e) sqrt(2 E mbar): E absorbed up to maximum crush (Rose et al. SAE 2006-01-0908)"
        )
        doc = (
            "CRASH3 delta-V from the crush energy E absorbed up to maximum crush: approach "
            "impulse sqrt(2 E mbar), total (1 + e) times it (Rose et al., SAE 2006-01-0908)."
        )
    return Kernel(
        name=name,
        doc=doc,
        inputs=(m1, m2, rg1, rg2, h1, h2, E, e, gamma, alpha1, alpha2),
        checks=(
            finite_inputs((h1, h2, E, e, gamma, alpha1, alpha2), (m1, m2, rg1, rg2)),
            positive_or_fixed((m1, m2, rg1, rg2)),
            Guard((sp.GreaterThan(E, 0), sp.GreaterThan(e, 0), e_range), "ENERGY_INCONSISTENT"),
        ),
        blocks=(
            Block(
                f.inverse_masses((m1, m2), (k1, k2))
                + (
                    (mass_factor1, 1 / (1 + (h1 / rg1) ** 2)),
                    (mass_factor2, 1 / (1 + (h2 / rg2) ** 2)),
                    (ome, 1 - e),
                ),
                equation="effective-mass factor gamma = k^2/(k^2 + h^2) (CRASH3 manual; Day & Hargens SAE 870045)",
            ),
            # 1/(γ m) = (1/m)(1 + h²/k²): exactly 0 for a fixed body.
            Block(
                ((ke1, k1 * (1 + (h1 / rg1) ** 2)), (ke2, k2 * (1 + (h2 / rg2) ** 2))),
                Guard((sp.StrictGreaterThan(ke1 + ke2, 0),), "SINGULAR"),
                equation="inverse effective masses 1/(gamma m) = (1/m)(1 + h^2/k^2) (CRASH3 manual; Day & Hargens SAE 870045)",
            ),
            Block(((P, impulse),), equation=impulse_equation),
            Block(
                ((dV1, k1 * P), (dV2, k2 * P), (dV1_eff, ke1 * P), (dV2_eff, ke2 * P)),
                equation="dV_i = |P|/m_i (centre of gravity); |P|/(gamma_i m_i), EDCRASH's effective-mass "
                "delta-V (Day & Hargens SAE 870045)",
            ),
            Block(
                (
                    (dV1x, -dV1 * sp.cos(gamma + alpha1)),
                    (dV1y, -dV1 * sp.sin(gamma + alpha1)),
                    (dV2x, dV2 * sp.cos(gamma + alpha2)),
                    (dV2y, dV2 * sp.sin(gamma + alpha2)),
                ),
                equation="delta-V vectors along each vehicle's PDOF, alpha_i from its inward normal "
                "(conventions.md frame)",
            ),
        ),
        outputs=(P, dV1, dV2, mass_factor1, mass_factor2, dV1x, dV1y, dV2x, dV2y, dV1_eff, dV2_eff),
    )


def moment_arm_kernel() -> Kernel:
    """Signed moment arm h = r × d of the PDOF line through the impact centre
    about the centre of gravity (r from the CG to the impact centre, d at
    angle theta in the scene frame)."""
    return Kernel(
        name="crash3_moment_arm",
        doc="Moment arm h = r x (cos theta, sin theta) of the PDOF about the centre of gravity.",
        inputs=(rx, ry, theta),
        checks=(finite_inputs((rx, ry, theta)),),
        blocks=(
            Block(
                ((h, rx * sp.sin(theta) - ry * sp.cos(theta)),),
                equation="moment arm h = r x d of the PDOF about the CG, the h of gamma "
                "(CRASH3 manual; Day & Hargens SAE 870045)",
            ),
        ),
        outputs=(h,),
    )


def radius_of_gyration_kernel() -> Kernel:
    """k = √(I/m) from a vehicle's mass and yaw inertia."""
    return Kernel(
        name="crash3_radius_of_gyration",
        doc="Radius of gyration k = sqrt(I/m).",
        inputs=(mass, inertia),
        checks=(finite_inputs((), (mass, inertia)), positive_or_fixed((mass, inertia))),
        blocks=(Block(((rg, sp.sqrt(inertia / mass)),), equation="radius of gyration k = sqrt(I/m)"),),
        outputs=(rg,),
    )


def implied_pdof_kernel() -> Kernel:
    """The PDOF an impulse-momentum solution implies: the angle of the force on
    each vehicle from its inward normal, α = atan2(-Pt, -Pn) (tan α = μ)."""
    return Kernel(
        name="crash3_implied_pdof",
        doc="PDOF implied by an impulse (Pn, Pt) on vehicle 1: alpha = atan2(-Pt, -Pn).",
        inputs=(Pn, Pt),
        checks=(finite_inputs((Pn, Pt)),),
        blocks=(
            Block(
                ((pdof, sp.atan2(-Pt, -Pn)),),
                equation="PDOF = direction of the resultant impulse (seed, CRASH section): "
                "tan alpha = Pt/Pn = mu (seed eq 5)",
            ),
        ),
        outputs=(pdof,),
    )


KERNELS = tuple(energy_kernel(n) for n in PROFILE_SIZES) + (
    delta_v_kernel(),
    moment_arm_kernel(),
    radius_of_gyration_kernel(),
    implied_pdof_kernel(),
    delta_v_kernel("absorbed"),
)


# ---------------------------------------------------------------- proofs


def published_six_point():
    """The CRASH3 manual's six-point crush energy, as printed there:
    (L/5)[A/2 (C1 + 2C2 + 2C3 + 2C4 + 2C5 + C6) + B/6 (C1² + 2C2² + 2C3² + 2C4²
    + 2C5² + C6² + C1C2 + C2C3 + C3C4 + C4C5 + C5C6) + 5G]."""
    C = DEPTHS
    return (
        width
        / 5
        * (
            A / 2 * (C[0] + 2 * C[1] + 2 * C[2] + 2 * C[3] + 2 * C[4] + C[5])
            + B
            / 6
            * (
                C[0] ** 2
                + 2 * C[1] ** 2
                + 2 * C[2] ** 2
                + 2 * C[3] ** 2
                + 2 * C[4] ** 2
                + C[5] ** 2
                + C[0] * C[1]
                + C[1] * C[2]
                + C[2] * C[3]
                + C[3] * C[4]
                + C[4] * C[5]
            )
            + 5 * G
        )
    )


def _energy_claims():
    g_value = A**2 / (2 * B)
    density = energy_density()
    out = [
        (
            "crash3: energy density = A C + B C^2/2 + G = (A + B C)^2/(2B), G = A^2/(2B) "
            "the work below zero crush",
            sp.simplify(density - (A * Ca + B * Ca**2 / 2 + g_value)) == 0
            and sp.simplify(density - (A + B * Ca) ** 2 / (2 * B)) == 0
            and sp.simplify(sp.integrate(A + B * c, (c, -A / B, 0)) - g_value) == 0,
        )
    ]
    energies = {n: KERNELS[i].expanded(E_crush, frozenset({G})) for i, n in enumerate(PROFILE_SIZES)}
    out.append(
        (
            "crash3: the 6-point energy equals the CRASH3 manual's formula",
            sp.expand(energies[6] - published_six_point()) == 0,
        )
    )
    out.append(
        (
            "crash3: the 2-point energy is L [A (C1 + C2)/2 + B (C1^2 + C1 C2 + C2^2)/6 + G]",
            sp.expand(
                energies[2]
                - width
                * (
                    A * (DEPTHS[0] + DEPTHS[1]) / 2
                    + B * (DEPTHS[0] ** 2 + DEPTHS[0] * DEPTHS[1] + DEPTHS[1] ** 2) / 6
                    + G
                )
            )
            == 0,
        )
    )
    uniform = sp.Symbol("C", nonnegative=True)
    out.append(
        (
            "crash3: a uniform crush C gives L (A C + B C^2/2 + G) for 2, 4 and 6 points",
            all(
                sp.expand(
                    energies[n].xreplace({ci: uniform for ci in DEPTHS})
                    - width * (A * uniform + B * uniform**2 / 2 + G)
                )
                == 0
                for n in PROFILE_SIZES
            ),
        )
    )
    out += _correction_claims()
    return out


def _correction_claims():
    """The oblique corrections: below the cap E = E_crush/cos²α (CRASH3) and
    E_woolley = E_crush/cos α; at the cap 2 E_crush and √2 E_crush; the capped
    angle is |α| below 45° and 45° above (checked at sample angles)."""
    cap = {sp.Min(sp.Abs(alpha), PDOF_CAP): PDOF_CAP}
    below = {sp.Min(sp.Abs(alpha), PDOF_CAP): alpha}  # tan², cos are even: |α| → α
    ok_below = ok_cap = True
    for knl in KERNELS[:3]:
        crash, woolley = (knl.expanded(x, frozenset({E_crush})) for x in (E, E_woolley))
        ok_below &= (
            sp.simplify(crash.xreplace(below) - E_crush / sp.cos(alpha) ** 2) == 0
            and sp.simplify(woolley.xreplace(below) - E_crush / sp.cos(alpha)) == 0
            and sp.simplify(woolley.xreplace(below) / crash.xreplace(below) - sp.cos(alpha)) == 0
        )
        ok_cap &= (
            sp.simplify(crash.xreplace(cap) - 2 * E_crush) == 0
            and sp.simplify(woolley.xreplace(cap) - sp.sqrt(2) * E_crush) == 0
        )
    capped = KERNELS[0].expanded(alpha_c)
    samples = {
        sp.Rational(3, 10): sp.Rational(3, 10),
        -sp.Rational(3, 10): sp.Rational(3, 10),
        sp.Rational(6, 5): PDOF_CAP,
        -sp.Rational(6, 5): PDOF_CAP,
    }
    ok_clamp = all(capped.xreplace({alpha: a}) == want for a, want in samples.items())
    return [
        (
            "crash3: below the cap E = E_crush/cos^2(alpha) (CRASH3) and E_woolley = "
            "E_crush/cos(alpha) = cos(alpha) E (Woolley)",
            ok_below,
        ),
        ("crash3: at the EDCRASH cap (45 deg) E = 2 E_crush and E_woolley = sqrt(2) E_crush", ok_cap),
        ("crash3: the corrected angle is min(|alpha|, 45 deg)", ok_clamp),
    ]


def _one_dimensional_impulse():
    """|P| and the energy loss of a 1-D impact of masses M1, M2 (inverse ke1,
    ke2) closing at speed vc, with restitution e, solved by SymPy from momentum
    and restitution."""
    u1, U1, U2, vc = real("u1 U1 U2 vc")
    sol = sp.solve(
        [U1 / ke1 + U2 / ke2 - (u1 / ke1 + (u1 - vc) / ke2), (U2 - U1) - e * vc], [U1, U2], dict=True
    )[0]
    impulse = (u1 - sol[U1]) / ke1
    lost = (u1**2 / ke1 + (u1 - vc) ** 2 / ke2 - sol[U1] ** 2 / ke1 - sol[U2] ** 2 / ke2) / 2
    return sp.simplify(impulse), sp.simplify(lost), vc


def _delta_v_claims():
    knl = KERNELS[3]
    p_kernel = knl.expanded(P, frozenset({ke1, ke2}))
    impulse, lost, vc = _one_dimensional_impulse()
    one_d = sp.simplify(p_kernel**2 - impulse**2).xreplace({E: lost})
    out = [
        (
            "crash3_delta_v: |P| is the impulse of the 1-D impact of effective masses "
            "with energy loss E and restitution e",
            sp.simplify(one_d) == 0,
        )
    ]
    # Effective mass: the velocity change of the impact centre along d per unit
    # impulse is 1/m + (r × d)^2/I, i.e. (1/m)(1 + h^2/k^2) with I = m k^2.
    # Unit direction d = (nx, ny) (frame's symbols, so reduce_unit_normal applies).
    mass_i, rg_i = sp.symbols("mass_i rg_i", positive=True)
    d_vec = sp.Matrix([f.nx, f.ny])
    point = d_vec / mass_i + (rx * f.ny - ry * f.nx) / (mass_i * rg_i**2) * sp.Matrix([-ry, rx])
    along = (point.T * d_vec)[0]
    arm = moment_arm_kernel().expanded(h).xreplace({sp.sin(theta): f.ny, sp.cos(theta): f.nx})
    effective = knl.expanded(ke1, frozenset({k1})).xreplace({k1: 1 / mass_i, rg1: rg_i, h1: arm})
    out.append(
        (
            "crash3_delta_v: 1/(gamma m) = 1/m + h^2/I is the impact centre's compliance "
            "along the PDOF, h = r x d, gamma = k^2/(k^2 + h^2)",
            f.reduce_unit_normal(along - effective) == 0
            and sp.simplify(knl.expanded(mass_factor1) - rg1**2 / (rg1**2 + h1**2)) == 0,
        )
    )
    out.append(
        (
            "crash3_delta_v: m1 dV1 = m2 dV2, and with equal PDOFs the vectors conserve momentum",
            _momentum_claim(knl),
        )
    )
    out.append(
        (
            "crash3_delta_v: the CG delta-V is gamma times the effective-mass delta-V "
            "(dV_i = gamma_i dV_i_eff, dV_i_eff = |P|/(gamma_i m_i))",
            all(
                sp.simplify(kn.expanded(dV - mf * dv_eff, frozenset({P}))) == 0
                for kn in (knl, KERNELS[7])
                for dV, mf, dv_eff in ((dV1, mass_factor1, dV1_eff), (dV2, mass_factor2, dV2_eff))
            ),
        )
    )
    out += _absorbed_claims(knl, impulse, lost)
    out.append(
        (
            "crash3_delta_v: given the common-velocity rigid solution's PDOF and energy "
            "loss it returns that solution's |P| exactly",
            _common_velocity_claim(knl),
        )
    )
    return out


def _absorbed_claims(dissipated: Kernel, impulse, lost):
    """The "absorbed" kernel: E is the energy lost up to maximum crush (the 1-D
    loss at e = 0, the relative kinetic energy at the approach), its |P| is
    (1 + e) times the approach impulse, which is the 1-D impulse with
    restitution e; for the same E the absorbed |P| is √(1 - e²) times the
    dissipated one."""
    knl = KERNELS[7]
    p_abs = knl.expanded(P, frozenset({ke1, ke2}))
    approach_loss = lost.xreplace({e: 0})
    full = sp.simplify(p_abs.xreplace({E: approach_loss}) ** 2 - impulse**2)
    total = sp.simplify(impulse - (1 + e) * impulse.xreplace({e: 0}))
    ratio = p_abs / dissipated.expanded(P, frozenset({ke1, ke2}))
    return [
        (
            "crash3_delta_v_absorbed: with E the energy absorbed to maximum crush, |P| is the "
            "1-D impulse with restitution e, (1 + e) times the approach impulse",
            full == 0 and total == 0,
        ),
        (
            "crash3_delta_v_absorbed: for the same E, |P|_absorbed = sqrt(1 - e^2) |P|_dissipated",
            sp.simplify(ratio**2 - (1 - e**2)) == 0,
        ),
    ]


def _momentum_claim(knl: Kernel) -> bool:
    same = {alpha2: alpha1}
    x = knl.expanded(dV1x / k1 + dV2x / k2, frozenset({P})).xreplace(same)
    y = knl.expanded(dV1y / k1 + dV2y / k2, frozenset({P})).xreplace(same)
    ratio = knl.expanded(dV1 / k1 - dV2 / k2, frozenset({P, k1, k2}))
    return sp.simplify(x) == 0 and sp.simplify(y) == 0 and sp.simplify(ratio) == 0


def _common_velocity_claim(knl: Kernel) -> bool:
    """With e = 0 and e_m = 1 the common-velocity impulse P solves K P = g, so its
    energy loss is T_L = P·g/2 = PᵀKP/2 (presets.py: Gn = Gt = 0, T_L the work).
    K = (k1 + k2) I + j1 s1 s1ᵀ + j2 s2 s2ᵀ (s_i = z × r_i), so PᵀKP =
    |P|² (k1 + k2) + j1 (r1 × P)² + j2 (r2 × P)²; along d = P/|P| the kernel's
    effective compliance is ke1 + ke2 = PᵀKP/|P|², and 2 T_L/(ke1 + ke2) = |P|²."""
    r1n, r1t, r2n, r2t = planar.r1n, planar.r1t, planar.r2n, planar.r2t
    keff = {
        s: x.xreplace({planar.wa: j1, planar.wb: j2, planar.wc: 0, planar.kk: k1 + k2})
        for s, x in planar.effective_compliance().items()
    }
    Kmat = sp.Matrix([[keff[planar.Knn], keff[planar.Knt]], [keff[planar.Knt], keff[planar.Ktt]]])
    vec = sp.Matrix([Pn, Pt])
    quad = sp.expand((vec.T * Kmat * vec)[0])
    size = Pn**2 + Pt**2
    arms = {
        h1: planar._cross(r1n, r1t, Pn, Pt) / sp.sqrt(size),
        h2: planar._cross(r2n, r2t, Pn, Pt) / sp.sqrt(size),
    }
    # k_i (1 + h_i²/rg_i²) with rg_i² = 1/(m_i j_i) = k_i/j_i: k_i + j_i h_i².
    inertia = {rg1: sp.sqrt(k1 / j1), rg2: sp.sqrt(k2 / j2)}
    p2 = knl.expanded(P, frozenset({k1, k2})).xreplace({e: 0}).xreplace(inertia).xreplace(arms) ** 2
    return sp.simplify(p2.xreplace({E: quad / 2}) - size) == 0


def _implied_pdof_claim():
    knl = KERNELS[6]
    a = knl.expanded(pdof)
    size = sp.sqrt(Pn**2 + Pt**2)
    force = [-size * sp.cos(gamma + a), -size * sp.sin(gamma + a)]
    impulse = f.to_scene_frame(Pn, Pt)
    n_t = {f.nx: sp.cos(gamma), f.ny: sp.sin(gamma)}
    same = all(sp.simplify(sp.expand_trig(fc) - ic.xreplace(n_t)) == 0 for fc, ic in zip(force, impulse))
    return [
        (
            "crash3_implied_pdof: the force on vehicle 1 is -|P| (cos(G + alpha), "
            "sin(G + alpha)) and tan(alpha) = Pt/Pn = mu",
            same and sp.simplify(sp.tan(a) - Pt / Pn) == 0,
        )
    ]


def proofs():
    """(claim, passed) pairs for the crush energy, the delta-V and the PDOF kernels."""
    return _energy_claims() + _delta_v_claims() + _implied_pdof_claim()
