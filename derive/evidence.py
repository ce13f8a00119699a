"""Evidence: the observation equations of a fit, with exact Jacobians in the state.

The state of an impact is z = (v1x, v1y, w1, v2x, v2y, w2, Px, Py, M): the
pre-impact velocities and yaw rates and the impulse on vehicle 1 (P, and the
moment impulse M). The six equations 1 and 2 (momentum, angular impulse) make
every post-impact velocity an affine function of z:

    V1 = v1 + P/m1,  V2 = v2 - P/m2,
    W1 = w1 + (r1 × P + M)/I1,  W2 = w2 - (r2 × P + M)/I2,

so a fit whose evidence is any mix of pre-impact speeds along the headings,
final velocities, yaw rates and delta-V components (at the centre of gravity
or at a module) is a linear least-squares problem in z. What is not linear:
final speeds and directions and delta-V magnitudes (|a| and the direction of a
vector, kernel `evidence_vector`), and the energy loss (quadratic in z, kernel
`evidence_energy`). The coefficients the state implies (e, μ, μ_c, the
energy partition, kernel `evidence_derived`) are ratios of its components.

Every kernel is emitted with its exact first derivatives with respect to the
state (derive/jacobian.py's forward-mode chain rule): `d_<output>__d_<state>`.
Headings θ (pre-impact direction of travel and orientation) and Γ are in
radians. Speeds `s_i` are the forward components h_i·v_i of the pre-impact
velocities (what an EDR's wheel speed measures). delta-V along and across a
vehicle (`dl`, `dt`) are in its axes at its heading (forward, left), at a
module at (a, b) (forward, left) from its centre of gravity: the change of
velocity of that body point, ΔV + ΔW × ρ.

Crush energy as an energy loss (kernel `evidence_crush_absorbed`). CRASH3's
option ``energy: absorbed`` reads a crush energy E as the energy absorbed up
to maximum crush: in CRASH3's one-dimensional impact of the effective masses
along the PDOF it is the relative kinetic energy m̄ v_c²/2 at the approach,
and with restitution e the energy lost over the whole impact is
T_L = (1 - e)(1 + e) E (written as a product: 1 - e² loses digits as e → 1).
Proved below twice: from the 1-D impact itself, and against the CRASH3
kernels' own relation (derive/crash3.py): the "dissipated" delta-V of the
energy T_L is the "absorbed" delta-V of E, for every e.
"""

from __future__ import annotations

import random

import sympy as sp

from . import crash3 as c3
from . import frame as f
from . import jacobian, planar
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
from .planar import drx, dry, r1n, r1t, r2n, r2t

theta1, theta2, a1, b1, a2, b2 = real("theta1 theta2 a1 b1 a2 b2")
h1x, h1y, h2x, h2y = real("h1x h1y h2x h2y")
L1, L2, dV1x, dV1y, dV2x, dV2y, dW1, dW2 = real("L1 L2 dV1x dV1y dV2x dV2y dW1 dW2")
s1, s2, dl1, dt1, dl2, dt2, R_em = real("s1 s2 dl1 dt1 dl2 dt2 R_em")
ax, ay, q2, norm, direction = real("ax ay q2 norm direction")
Gn, Gt, Wr, dVx, dVy = real("Gn Gt Wr dVx dVy")
E_absorbed, E_lost = real("E_absorbed E_lost")

STATE = (v1x, v1y, w1, v2x, v2y, w2, Px, Py, M)
MASSES = (m1, m2, I1, I2)
ARMS = (r1x, r1y, r2x, r2y)


def _impulse_blocks():
    """Inverse masses; the angular impulses L_i and the changes of velocity and
    yaw rate of each vehicle (six equations 1, 2). Written as ΔV = k·P, never
    as a difference of velocities, so a fixed body (k = j = 0) is exact."""
    return (
        Block(
            f.inverse_masses(MASSES, (k1, k2, j1, j2))
            + (
                (L1, r1x * Py - r1y * Px + M),
                (L2, -(r2x * Py - r2y * Px) - M),
            ),
            equation="inverse masses; angular impulse on each vehicle, r1 x P + M and -(r2 x P) - M",
        ),
        Block(
            (
                (dV1x, k1 * Px),
                (dV1y, k1 * Py),
                (dV2x, -k2 * Px),
                (dV2y, -k2 * Py),
                (dW1, j1 * L1),
                (dW2, j2 * L2),
            ),
            equation="m1 (V1 - v1) = P, m2 (V2 - v2) = -P, I_i (W_i - w_i) = L_i (six equations 1, 2)",
        ),
    )


def _linear_kernel() -> Kernel:
    """Every observation that is linear in the state."""
    params = MASSES + ARMS + (theta1, theta2, a1, b1, a2, b2, e_m)
    blocks = _impulse_blocks() + (
        Block(
            (
                (h1x, sp.cos(theta1)),
                (h1y, sp.sin(theta1)),
                (h2x, sp.cos(theta2)),
                (h2y, sp.sin(theta2)),
                (V1x, v1x + dV1x),
                (V1y, v1y + dV1y),
                (W1, w1 + dW1),
                (V2x, v2x + dV2x),
                (V2y, v2y + dV2y),
                (W2, w2 + dW2),
            ),
            equation="headings h_i = (cos theta_i, sin theta_i); finals V = v + dV, W = w + dW",
        ),
        Block(
            (
                (s1, h1x * v1x + h1y * v1y),
                (s2, h2x * v2x + h2y * v2y),
                # A module at (a, b) (forward, left) moves with the body:
                # its delta-V is dV + dW x rho, in the vehicle's axes (dV.h - dW b, dV.h_perp + dW a).
                (dl1, h1x * dV1x + h1y * dV1y - dW1 * b1),
                (dt1, h1x * dV1y - h1y * dV1x + dW1 * a1),
                (dl2, h2x * dV2x + h2y * dV2y - dW2 * b2),
                (dt2, h2x * dV2y - h2y * dV2x + dW2 * a2),
                (R_em, (1 - e_m) * (dW2 - dW1 + w2 - w1) - e_m * M * (j1 + j2)),
            ),
            equation="speeds along the headings; delta-V along and across each vehicle at its module; "
            "moment restitution residual (six equations 5)",
        ),
    )
    outputs = (s1, s2, V1x, V1y, W1, V2x, V2y, W2, dV1x, dV1y, dV2x, dV2y, dl1, dt1, dl2, dt2, R_em)
    return Kernel(
        name="evidence_linear",
        doc="Observations linear in the state (v, w, P, M): speeds, finals, delta-V.",
        inputs=params + STATE,
        checks=(
            finite_inputs(ARMS + (theta1, theta2, a1, b1, a2, b2, e_m) + STATE, MASSES),
            positive_or_fixed(MASSES),
        ),
        blocks=blocks,
        outputs=outputs,
    )


def _energy_kernel() -> Kernel:
    """The total energy loss as the negative work of the impulses: for each
    vehicle ΔT = P·v + k|P|²/2 + L w + j L²/2. Written with v2 - v1 formed
    first; a fixed body contributes exactly nothing."""
    relative = Px * (v2x - v1x) + Py * (v2y - v1y)
    quadratic = (k1 + k2) * (Px**2 + Py**2) + j1 * L1**2 + j2 * L2**2
    blocks = _impulse_blocks()[:1] + (
        Block(
            ((TL, relative - L1 * w1 - L2 * w2 - quadratic / 2),),
            equation="TL = T(before) - T(after) = -(work of P and M on both vehicles) (conventions.md energy)",
        ),
    )
    return Kernel(
        name="evidence_energy",
        doc="Total energy loss TL, quadratic in the state.",
        inputs=MASSES + ARMS + STATE,
        checks=(finite_inputs(ARMS + STATE, MASSES), positive_or_fixed(MASSES)),
        blocks=blocks,
        outputs=(TL,),
    )


def _vector_kernel() -> Kernel:
    """Magnitude and direction (radians, counter-clockwise from +x) of a vector:
    final speeds and directions, delta-V magnitudes."""
    return Kernel(
        name="evidence_vector",
        doc="Magnitude and direction of a vector (a, b): |(a, b)| and atan2(b, a).",
        inputs=(ax, ay),
        checks=(finite_inputs((ax, ay)),),
        blocks=(
            Block(
                ((q2, ax**2 + ay**2),),
                Guard((sp.StrictGreaterThan(q2, 0),), "SINGULAR"),
                equation="squared magnitude (a zero vector has no direction)",
            ),
            Block(((norm, sp.sqrt(q2)), (direction, sp.atan2(ay, ax))), equation="magnitude and direction"),
        ),
        outputs=(norm, direction),
    )


def _derived_kernel() -> Kernel:
    """The coefficients a state implies: e, μ, μ_c (for the given e_m), the
    impulse in the impact frame and the energy partition, with the physics
    flags of every model (conventions.md)."""
    g = planar.relative_velocity()
    G = tuple(c.xreplace({f.dvx: dVx, f.dvy: dVy, w1: W1, w2: W2}) for c in g)
    r1n_, r1t_ = f.to_impact_frame(r1x, r1y)
    r2n_, r2t_ = f.to_impact_frame(r2x, r2y)
    blocks = (
        _impulse_blocks()
        + (
            Block(
                f.normal_components()
                + (
                    (f.dvx, v2x - v1x),
                    (f.dvy, v2y - v1y),
                    (wr, w2 - w1),
                    (drx, r1x - r2x),
                    (dry, r1y - r2y),
                    (W1, w1 + dW1),
                    (W2, w2 + dW2),
                    (Wr, w2 - w1 + dW2 - dW1),
                ),
                equation="frame (conventions.md); final yaw rates",
            ),
            Block(
                (
                    (r1n, r1n_),
                    (r1t, r1t_),
                    (r2n, r2n_),
                    (r2t, r2t_),
                    (dVx, f.dvx + dV2x - dV1x),
                    (dVy, f.dvy + dV2y - dV1y),
                ),
                equation="arms in the impact frame; V2 - V1 = (v2 - v1) + (dV2 - dV1)",
            ),
            Block(
                (
                    (gn, f.to_impact_frame(*g)[0]),
                    (gt, f.to_impact_frame(*g)[1]),
                    (Gn, f.to_impact_frame(*G)[0]),
                    (Gt, f.to_impact_frame(*G)[1]),
                    (Pn, f.to_impact_frame(Px, Py)[0]),
                    (Pt, f.to_impact_frame(Px, Py)[1]),
                ),
                f.approach_guard(),
                equation="u2 - u1 at the impact centre before and after; P in the impact frame",
            ),
            Block(
                ((e, -Gn / gn),),
                Guard((sp.Ne(Pn, 0),), "SINGULAR"),
                equation="e = -Gn/gn (seed eq 3, six equations 3)",
            ),
            Block(
                (
                    (mu, Pt / Pn),
                    (TLn, Pn * (gn + Gn) / 2),
                    (TLt, Pt * (gt + Gt) / 2),
                    (TLm, M * (wr + Wr) / 2),
                ),
                equation="mu = Pt/Pn (seed eq 5, six equations 4); work of Pn, Pt, M (seed eqs 21-26)",
            ),
        )
        + planar.compliance_pieces()
        + planar.critical_ratio_blocks()
        + (Block(((TL, TLn + TLt + TLm),), equation="TL = TLn + TLt + TLm (conventions.md energy)"),)
    )
    tolerances, flags = f.physics_flags(
        (TL, TLn, TLt, TLm), ((Pn, gn), (Pt, gt), (M, wr)), mu_used=mu, restitution=e
    )
    return Kernel(
        name="evidence_derived",
        doc="Coefficients a state implies: e, mu, mu_c, Pn, Pt, the energy partition, physics flags.",
        inputs=MASSES + ARMS + (gamma, e_m) + STATE,
        checks=(finite_inputs(ARMS + (gamma, e_m) + STATE, MASSES), positive_or_fixed(MASSES)),
        blocks=blocks + (tolerances,),
        outputs=(e, mu, mu_c, Pn, Pt, TL, TLn, TLt, TLm),
        flags=flags,
    )


def _crush_kernel() -> Kernel:
    """The energy lost over the impact from a crush energy absorbed up to
    maximum crush, with restitution e (module docstring)."""
    return Kernel(
        name="evidence_crush_absorbed",
        doc="Energy lost over the impact from the crush energy E absorbed up to maximum crush: (1 - e)(1 + e) E.",
        inputs=(E_absorbed, e),
        checks=(
            finite_inputs((E_absorbed, e)),
            Guard(
                (sp.GreaterThan(E_absorbed, 0), sp.GreaterThan(e, 0), sp.LessThan(e, 1)),
                "ENERGY_INCONSISTENT",
            ),
        ),
        blocks=(
            Block(
                ((E_lost, (1 - e) * (1 + e) * E_absorbed),),
                equation="T_L = (1 - e^2) E_absorbed: CRASH3's 1-D impact (Rose et al. SAE 2006-01-0908)",
            ),
        ),
        outputs=(E_lost,),
    )


def _vector_inputs(knl: Kernel):
    return {"evidence_vector": (ax, ay), "evidence_crush_absorbed": (E_absorbed, e)}.get(knl.name, STATE)


KERNELS = (_linear_kernel(), _energy_kernel(), _vector_kernel(), _derived_kernel(), _crush_kernel())
EMITTED = tuple(
    jacobian.jacobian_kernel(k, name=k.name, wrt=_vector_inputs(k), family="evidence") for k in KERNELS
)


# ---------------------------------------------------------------- proofs

DIGITS = 50


def _zero(expr) -> bool:
    return sp.simplify(sp.together(f.reduce_unit_normal(expr))) == 0


def _linear_holds() -> list:
    """The linear kernel against the six equations 1, 2 and 5, its module
    delta-V against the motion of a body point, and its linearity in the state."""
    knl = KERNELS[0]
    got = {s: knl.expanded(s) for s in knl.outputs}
    six = all(
        sp.simplify(x) == 0
        for x in (
            m1 * (got[V1x] - v1x) - Px,
            m1 * (got[V1y] - v1y) - Py,
            m2 * (got[V2x] - v2x) + Px,
            m2 * (got[V2y] - v2y) + Py,
            I1 * (got[W1] - w1) - (r1x * Py - r1y * Px) - M,
            I2 * (got[W2] - w2) + (r2x * Py - r2y * Px) + M,
        )
    )
    restitution = (
        sp.simplify(got[R_em] - ((got[W2] - got[W1]) * (1 - e_m) - e_m * M * (1 / I1 + 1 / I2))) == 0
    )
    # The point rho = a h + b h_perp of each body: its velocity change dV + dW (-rho_y, rho_x),
    # projected on h and h_perp.
    module = True
    for th, a, b, Vx_, Vy_, vx_, vy_, W_, w_, dl, dt in (
        (theta1, a1, b1, V1x, V1y, v1x, v1y, W1, w1, dl1, dt1),
        (theta2, a2, b2, V2x, V2y, v2x, v2y, W2, w2, dl2, dt2),
    ):
        h = sp.Matrix([sp.cos(th), sp.sin(th)])
        hp = sp.Matrix([-sp.sin(th), sp.cos(th)])
        rho = a * h + b * hp
        dW = got[W_] - w_
        du = sp.Matrix([got[Vx_] - vx_ - dW * rho[1], got[Vy_] - vy_ + dW * rho[0]])
        module &= sp.simplify(got[dl] - h.dot(du)) == 0 and sp.simplify(got[dt] - hp.dot(du)) == 0
    speeds = sp.simplify(got[s1] - (sp.cos(theta1) * v1x + sp.sin(theta1) * v1y)) == 0
    linear = all(sp.diff(got[o], x, y) == 0 for o in knl.outputs for x in STATE for y in STATE)
    return [
        ("evidence_linear: V_i, W_i satisfy the six equations 1 and 2 (momentum, angular impulse)", six),
        ("evidence_linear: R_em is the moment restitution residual (six equations 5)", restitution),
        (
            "evidence_linear: module delta-V is the velocity change of the body point (a, b), in the vehicle axes",
            module,
        ),
        ("evidence_linear: s_i = h_i . v_i", speeds),
        ("evidence_linear: every output is linear in the state (all second derivatives 0)", linear),
    ]


def _energy_holds() -> bool:
    """TL equals the kinetic energy before minus after, finals from the six equations."""
    got = KERNELS[1].expanded(TL)
    lin = {s: KERNELS[0].expanded(s) for s in (V1x, V1y, W1, V2x, V2y, W2)}

    def ke(m, i, vx, vy, w):
        return m * (vx**2 + vy**2) / 2 + i * w**2 / 2

    before = ke(m1, I1, v1x, v1y, w1) + ke(m2, I2, v2x, v2y, w2)
    after = ke(m1, I1, lin[V1x], lin[V1y], lin[W1]) + ke(m2, I2, lin[V2x], lin[V2y], lin[W2])
    return sp.simplify(sp.expand(got - (before - after))) == 0


def _vector_holds(rng) -> bool:
    """|a| cos(direction) = ax, |a| sin(direction) = ay at random points, both signs of each component."""
    knl = KERNELS[2]
    for _ in range(8):
        point = {x: sp.Rational(rng.randint(-999, 999), 100) or sp.Rational(1, 7) for x in (ax, ay)}
        v = jacobian._evaluate(knl, point)
        if v is None:
            return False
        if abs(v[norm] * sp.cos(v[direction]) - point[ax]) > sp.Float("1e-40", DIGITS):
            return False
        if abs(v[norm] * sp.sin(v[direction]) - point[ay]) > sp.Float("1e-40", DIGITS):
            return False
    return True


def _derived_matches_forward(rng, points: int = 3) -> bool:
    """Run the forward rigid model (sliding, given e, μ, e_m) at random points;
    its initial state and impulse (Px, Py from Pn, Pt) fed to evidence_derived
    return the same e, μ, μ_c, TL and its parts (50 digits), and
    evidence_linear returns the forward model's finals."""
    fwd = planar.KERNELS[0]
    derived, lin = KERNELS[3], KERNELS[0]
    done = 0
    for _ in range(60 * points):
        point = jacobian._random_point(fwd, rng)
        out = jacobian._evaluate(fwd, point)
        if out is None:
            continue
        nx_, ny_ = sp.cos(point[gamma]), sp.sin(point[gamma])
        px, py = sp.N(out[Pn] * nx_ - out[Pt] * ny_, DIGITS), sp.N(out[Pn] * ny_ + out[Pt] * nx_, DIGITS)
        state = {x: point[x] for x in (v1x, v1y, w1, v2x, v2y, w2)} | {Px: px, Py: py, M: out[M]}
        common = {x: point[x] for x in MASSES + ARMS}
        got = jacobian._evaluate(derived, common | {gamma: point[gamma], e_m: point[e_m]} | state)
        zero = {theta1: 0, theta2: 0, a1: 0, b1: 0, a2: 0, b2: 0, e_m: point[e_m]}
        finals = jacobian._evaluate(lin, common | zero | state)
        if got is None or finals is None:
            return False
        want = {e: point[e], mu: point[mu], mu_c: out[mu_c], TL: out[TL], TLn: out[TLn], TLt: out[TLt]}
        for sym, value in want.items():
            if abs(got[sym] - value) > sp.Float("1e-35", DIGITS) * (abs(value) + 1):
                return False
        for sym in (V1x, V1y, W1, V2x, V2y, W2):
            if abs(finals[sym] - out[sym]) > sp.Float("1e-35", DIGITS) * (abs(out[sym]) + 1):
                return False
        if abs(finals[R_em]) > sp.Float("1e-35", DIGITS) * (abs(out[M]) + 1):
            return False
        done += 1
        if done == points:
            return True
    return False


def _derivatives_agree(knl: Kernel, base: Kernel, wrt, rng, points: int = 2) -> bool:
    """Each d_<output>__d_<state> output equals sympy.diff of the expanded value
    output at random rational points (50 digits); derivatives published as the
    constant 0 are identically 0."""
    import mpmath

    zeros = dict(knl.constants)
    grads = jacobian._sympy_gradients(base)
    done = 0
    for _ in range(50 * points):
        point = jacobian._random_point(knl, rng)
        values = jacobian._evaluate(knl, point)
        if values is None:
            continue
        with mpmath.workdps(DIGITS):
            args = [mpmath.mpf(point[x].p) / point[x].q for x in base.inputs]
            for out in base.outputs:
                scale = abs(values[out]) + 1
                for x, want in zip(base.inputs, grads[out](*args)):
                    if x not in wrt:
                        continue
                    want = sp.Float(want, DIGITS)
                    name = jacobian.derivative_name(base.public_name(out), x.name)
                    got = zeros[name] if name in zeros else values[jacobian._tangent_symbol(out, x)]
                    if abs(got - want) > jacobian.PROOF_TOLERANCE * max(abs(want), scale):
                        return False
        done += 1
        if done == points:
            return True
    return False


def _crush_holds() -> list:
    """evidence_crush_absorbed against the 1-D impact of two masses M1, M2
    (approach speed v > 0, impulse m̄ v (1 + e), m̄ = M1 M2/(M1 + M2)) and
    against CRASH3's absorbed/dissipated delta-V kernels."""
    M1, M2, v = sp.symbols("M1 M2 v", positive=True)
    lost = KERNELS[4].expanded(E_lost)

    def loss(restitution):
        impulse = M1 * M2 / (M1 + M2) * v * (1 + restitution)
        u1, u2 = v - impulse / M1, impulse / M2
        return M1 * v**2 / 2 - (M1 * u1**2 + M2 * u2**2) / 2, u2 - u1

    total, separation = loss(e)
    absorbed, _ = loss(0)
    one_d = (
        sp.simplify(total - lost.xreplace({E_absorbed: absorbed})) == 0
        and sp.simplify(separation - e * v) == 0
    )
    kernels = {k.name: k for k in c3.KERNELS}
    p_abs = kernels["crash3_delta_v_absorbed"].expanded(c3.P, frozenset({c3.ke1, c3.ke2}))
    p_dis = kernels["crash3_delta_v"].expanded(c3.P, frozenset({c3.ke1, c3.ke2}))
    same = sp.simplify(p_dis.xreplace({c3.E: lost.xreplace({E_absorbed: c3.E})}) ** 2 - p_abs**2) == 0
    return [
        (
            "evidence_crush_absorbed: in the 1-D impact with restitution e (separation e times approach) "
            "the energy lost is (1 - e^2) times the energy lost up to maximum crush (common velocity)",
            one_d,
        ),
        (
            "evidence_crush_absorbed: CRASH3's dissipated |P| of (1 - e^2) E equals its absorbed |P| of E "
            "(crash3_delta_v, crash3_delta_v_absorbed)",
            same,
        ),
    ]


def proofs():
    """(claim, passed) for the observation equations and their Jacobians."""
    rng = random.Random(20261124)
    claims = _linear_holds()
    claims.append(
        (
            "evidence_energy: TL = kinetic energy before - after (finals from the six equations)",
            _energy_holds(),
        )
    )
    claims.append(
        ("evidence_vector: |a| (cos, sin)(direction) = a in all four quadrants", _vector_holds(rng))
    )
    claims.append(
        (
            "evidence_derived: at forward rigid solutions the state gives back e, mu, mu_c, TL, TLn, TLt; "
            "evidence_linear gives back the finals and R_em = 0",
            _derived_matches_forward(rng),
        )
    )
    claims += _crush_holds()
    for knl, base in zip(EMITTED, KERNELS):
        claims.append(
            (
                f"{knl.name}: every d_output__d_state equals sympy.diff of the expanded output (2 points, 50 digits)",
                _derivatives_agree(knl, base, _vector_inputs(base), rng),
            )
        )
    return claims
