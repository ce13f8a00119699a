"""Post-impact run-out: a planar 3-DOF vehicle on four tyres, from separation to rest.

The model is conventions.md, "Post-impact run-out" (Steffan & Moser, SAE 960886,
planar form). State (scene frame, SI): x, y, psi, vx, vy, w. A wheel k sits at
(px, py) in the vehicle frame (x forward, y left), steered by delta; its contact
point moves at u = v + w·(-ry, rx); u_l is the component of u along the wheel
(axis at psi + delta) and u_s across it. With the static normal load N:

* locked wheel:  F = -mu N u/|u|;
* rolling wheel: F_l = -(b mu + f) N sgn(u_l), f = f_r when b = 0 (plain
  rolling: rolling resistance) and 0 when b > 0 (braked: the brake instead);
  F_s = -mu N sgn(u_s) min(alpha/alpha_max, cap), alpha = atan(|u_s|/|u_l|),
  cap = sqrt(1 - b^2) (1 for b = 0: the contract's lateral law; the braked
  wheel's lateral force capped at sqrt(1 - b^2) mu N).

m dv/dt = sum F, I dw/dt = sum r x F.

Smoothing near zero speed (the contract leaves it to the implementation):
every speed that divides or gives a sign enters as max(|u|, eps), eps = EPS =
0.5 mm/s (``Modulus``): sgn(u) becomes u/max(|u|, eps), u/|u| becomes
u/max(|u|, eps), and alpha·sgn(u_s) becomes atan2(u_s, max(|u_l|, eps)). Above
eps every force is the contract's exactly (a smooth u/sqrt(u^2 + eps^2) was
tried first: its relative deviation eps^2/(2u^2) reaches far above eps and
moved a rolling run-out from 20 m/s by 1.2 mm at eps = 5 mm/s); below eps the
forces fade linearly with speed, so the equations are Lipschitz (but stiff:
below). Two effects move the rest pose, both measured (eps against eps/10 on
random realistic run-outs, tests/test_runout_model.py; at eps = 5 mm/s the
second one reached 2.0 mm and 0.03 deg, hence 0.5 mm/s): the creep below eps,
eps^2/(2a) (a the deceleration; 1e-6 m even for rolling resistance alone), and
the creep of a wheel that sticks (a braked or rolling wheel whose sgn(u_l)
holds against the other forces, as static friction would): its u_l settles at
a share of eps instead of 0, so the vehicle creeps by a distance proportional
to eps for as long as it sticks (0.3 mm and 0.005 deg worst measured). The
run-out ends when |v| + |w| R_max < V_STOP = 1 mm/s (R_max the farthest wheel
from the centre of gravity): above eps the forces are the sharp ones, so the
remaining travel is at most V_STOP^2/(2 f_r g) = 5 um.

Stiffness: below eps a sliding wheel's force is a damper of slope mu N/eps
(locked: both directions; braked: along; rolling: along with f_r N/eps, and
across with mu N/(alpha_max max(|u_l|, eps)) at low speed). A wheel that
sticks (a locked wheel the car pivots about, a braked wheel holding) keeps
it there for as long as it sticks, with |lambda| up to ~1e4 1/s, where an
explicit step must stay below ~3/|lambda| (measured: 2,600 Dormand-Prince
steps of 0.25 ms for one run-out of examples/runout/sedan.json). The
integrator therefore switches per step: Dormand-Prince 5(4) while h |lambda|
is small, the L-stable Rosenbrock-W method ROS34PW2 (linearly implicit with
the emitted Jacobian; its order conditions are proved below) while a wheel
makes the equations stiff.

Emitted (``render``): generated/runout.py (plain: the constants, columns and
status codes) and generated/runout_jit.py (numba: the wheel forces and their
Jacobians with respect to (psi, vx, vy, w, mu), the right-hand side with its
sensitivity equations, the adaptive Dormand-Prince 5(4) / ROS34PW2 integrator
with its batch drivers; all in one file because numba's cache does not notice
a change of a jitted callee in another file).
"""

from __future__ import annotations

import random
import re

import mpmath
import sympy as sp

from . import emit, load_transfer

EPS = 0.0005  # m/s, smoothing speed of sgn and |.| (see the module docstring)
V_STOP = 1e-3  # m/s, |v| + |w| R_max below which the vehicle is at rest
T_MAX = 600.0  # s, a run-out still moving after this is reported NOT_STOPPED
MAX_STEPS = 200_000  # accepted plus rejected steps per row
TOL = 1e-8  # default local error tolerance per step (m, rad, m/s, rad/s; absolute)
H0 = 1e-3  # s, first trial step
H_MAX = 0.25  # s, longest step (keeps the path output legible)

# Stiff steps: ROS34PW2 (Rang & Angermann, BIT 45 (2005) 761-787: 4 stages,
# order 3 with an embedded order-2 solution, L-stable, stiffly accurate; a
# W-method, so its order holds with an approximate Jacobian, and built to keep
# it on stiff singularly perturbed problems, which a sticking wheel is), in the
# form (I - h GAMMA J) k_i = h f(y + sum_j ALPHA_ij k_j) + h J sum_j GAMMAS_ij k_j,
# y1 = y + sum_i B_i k_i. The order conditions are checked before emission.
W_GAMMA = 4.3586652150845900e-01
W_ALPHA = (
    (),
    (8.7173304301691801e-01,),
    (8.4457060015369423e-01, -1.1299064236484185e-01),
    (0.0, 0.0, 1.0),
)
W_GAMMAS = (
    (),
    (-8.7173304301691801e-01,),
    (-9.0338057013044082e-01, 5.4180672388095326e-02),
    (2.4212380706095346e-01, -1.2232505839045147e00, 5.4526025533510214e-01),
)
W_B = (2.4212380706095346e-01, -1.2232505839045147e00, 1.5452602553351020e00, 4.3586652150845900e-01)
W_B_EMBEDDED = (3.7810903145819369e-01, -9.6042292212423178e-02, 0.5, 2.1793326075422950e-01)
# Switching (docs/runout.md): a Dormand-Prince step with h |lambda| above
# W_ENTER (its stability interval on the negative axis ends near 3.3; its
# estimate of |lambda| runs low) hands over to ROS34PW2, which hands back when h
# times the Jacobian's bound on |lambda| falls below W_LEAVE.
W_ENTER = 2.0
W_LEAVE = 2.0
# A hand-over refused at once (h |lambda| bound below W_LEAVE: the explicit step
# is as long as the stiff one would be) is not tried again for W_WAIT steps
# (each try costs a Jacobian: a fifth of a step).
W_WAIT = 10
# The sensitivities' own local error (docs/runout.md, "Error control of the
# sensitivities"): in a Dormand-Prince step each entry S of d y/d(vx, vy, w, mu)
# is held to SENS_SHARE * tol * (1 + |S|). Riding on the state's steps alone,
# d(x, y, psi)_rest/d(vx, vy, w) at the default tolerance was off central
# differences by over 5 % on 7 of 60 random rows (worst 15 %; at tol 1e-6 one
# blew up): a wheel's force crossing its smoothing band kicks them where the
# state barely moves. With 100: worst 0.5 %, none over 1 %; a run-out with
# sensitivities takes 1.42 times the steps of the forward one (300 random
# rows; as many before; 1.27 since the steps land on kinks, KINK_PAST). 30 and 300 gave the same errors there, but 300 put
# the T-bone's struck car's d state/d rest heading 35 % off (100: 0.4 %). In
# the ROS34PW2 steps the same control changed nothing.
SENS_SHARE = 100.0
# Kinks (docs/runout.md, "Steps"): a wheel force has a kink where one of its
# switching functions (`switching_functions`) changes sign. A rejected
# Dormand-Prince trial across one retries up to it: the step shrinks to
# KINK_PAST times the fraction of the trial at which the first of them changes
# sign (linear in between; at least KINK_MIN of the step), landing just past
# the kink instead of halving towards it.
KINK_PAST = 1.0001
KINK_MIN = 0.01

# Row status codes of runout_batch (0 solved). 1 and 2 mean what they mean in
# solve_batch (derive/codes.py); 20-23 are the run-out's own.
STATUS = {
    "OK": 0,
    "NONFINITE_INPUT": 1,
    "BAD_MASS": 2,
    "RUNOUT_BAD_GEOMETRY": 20,
    "RUNOUT_BAD_TYRE": 21,
    "RUNOUT_NOT_STOPPED": 22,
    "RUNOUT_BAD_WHEEL": 23,
    "RUNOUT_WHEEL_LIFT": 24,
}
STATUS_TEXT = {
    1: "a non-finite input",
    2: "mass or yaw inertia not > 0",
    20: "wheelbase, cg_to_front_axle, track or cg_height out of range (need 0 < a < L, track > 0, h >= 0)",
    21: "friction, slip_angle_max, rolling_resistance or gravity out of range",
    22: "still moving at the time limit (no resisting force?)",
    23: "a wheel state not 0/1, brake not in [0, 1] or steer not in (-90, 90) deg",
    24: "cg_height too high for the friction: load transfer could lift a wheel "
    "(need sqrt(mu^2 + f_r^2) h sqrt(1 + (2 b/track)^2) < b, b = L - a, and the same with a at the rear)",
}

WHEELS = ("fl", "fr", "rl", "rr")
COLUMNS = (
    (
        "m",
        "I",
        "L",
        "a",
        "track",
        "mu",
        "alpha_max",
        "f_r",
        "g",
        "x",
        "y",
        "psi",
        "vx",
        "vy",
        "w",
    )
    + tuple(f"{kind}_{k}" for k in WHEELS for kind in ("state", "brake", "steer"))
    + ("h",)
)
# h: the centre of gravity's height, 0 for the contract's static loads (> 0: quasi-static
# load transfer, derive/load_transfer.py); appended so that the other columns keep their places.
OUTPUTS = ("x_rest", "y_rest", "psi_rest", "t", "distance", "status", "steps")
# Sensitivity columns: d(x_rest, y_rest, psi_rest)/d(vx, vy, w, mu) at separation.
SENSITIVITIES = tuple(f"d{o}_d{p}" for o in ("x", "y", "psi") for p in ("vx", "vy", "w", "mu"))

# --- the model -----------------------------------------------------------------

psi, vx, vy, w = sp.symbols("psi vx vy w", real=True)
px, py, cd, sd = sp.symbols("px py cd sd", real=True)
N, mu, amax, b, fre, cap, eps = sp.symbols("N mu amax b fre cap eps", positive=True)
c, s = sp.symbols("c s", real=True)  # cos psi, sin psi in the emitted code
Z = (psi, vx, vy, w, mu)  # what the wheel Jacobians differentiate with respect to


class Clip(sp.Function):
    """clip(z, -cap, cap): the saturated share min(alpha/alpha_max, cap) with its sign."""

    def fdiff(self, argindex=1):
        z, k = self.args
        if argindex == 1:
            return ClipSlope(z, k)
        return sp.sign(z) * (1 - ClipSlope(z, k))


class ClipSlope(sp.Function):
    """d clip(z, -cap, cap)/dz: 1 inside (-cap, cap), 0 outside."""

    def fdiff(self, argindex=1):
        return sp.S.Zero


def contact_velocity():
    """(u_x, u_y) of the contact point in the vehicle frame, and (u_l, u_s) in the
    wheel frame, as functions of psi, vx, vy, w."""
    vbx = sp.cos(psi) * vx + sp.sin(psi) * vy
    vby = -sp.sin(psi) * vx + sp.cos(psi) * vy
    ux, uy = vbx - w * py, vby + w * px
    return (ux, uy), (cd * ux + sd * uy, -sd * ux + cd * uy)


class Modulus(sp.Function):
    """Modulus(eps, u1, ...) = max(|(u1, ...)|, eps): a speed that never falls
    below the smoothing speed eps (the sharp modulus above it)."""

    def fdiff(self, argindex=1):
        if argindex == 1:
            return 1 - ModulusStep(*self.args)
        return ModulusStep(*self.args) * self.args[argindex - 1] / self


class ModulusStep(sp.Function):
    """1 where |(u1, ...)| > eps (Modulus follows the speed), 0 where it is eps."""

    def fdiff(self, argindex=1):
        return sp.S.Zero


def wheel_frame_forces(locked: bool):
    """(F_l, F_s): the tyre force in the wheel frame (contract formulas; a
    speed u in a sign or a denominator enters as Modulus(eps, u) = max(|u|, eps))."""
    _, (ul, us) = contact_velocity()
    if locked:
        h = Modulus(eps, ul, us)
        return -mu * N * ul / h, -mu * N * us / h
    hl = Modulus(eps, ul)
    return -(b * mu + fre) * N * ul / hl, -mu * N * Clip(sp.atan2(us, hl) / amax, cap)


def chassis(fl, fs):
    """(Fx, Fy, Mz) of a wheel-frame force (F_l, F_s): rotated by delta into the
    vehicle frame, its moment about the centre of gravity, then rotated by psi
    into the scene frame."""
    fbx, fby = cd * fl - sd * fs, sd * fl + cd * fs
    return sp.cos(psi) * fbx - sp.sin(psi) * fby, sp.sin(psi) * fbx + sp.cos(psi) * fby, px * fby - py * fbx


def scene_forces(locked: bool):
    """(Fx, Fy, Mz): the wheel's force in the scene frame and its moment about
    the centre of gravity."""
    return chassis(*wheel_frame_forces(locked))


def _to_cs(expr):
    return expr.xreplace({sp.cos(psi): c, sp.sin(psi): s})


def wheel_outputs(locked: bool, jacobian: bool):
    """The emitted outputs: (Fx, Fy, Mz), then with `jacobian` their derivatives
    with respect to Z = (psi, vx, vy, w, mu), row by row."""
    forces = scene_forces(locked)
    outs = list(forces)
    if jacobian:
        outs += [sp.diff(f, z) for f in forces for z in Z]
    return [_to_cs(o) for o in outs]


WHEEL_ARGS = (c, s, vx, vy, w, px, py, cd, sd, N, mu, amax, b, fre, cap, eps)
# tan(cap alpha_max): the forward rolling wheel's lateral share is saturated
# where |u_s| >= tl max(|u_l|, eps), and its atan2 is then skipped
# (SaturatingPrinter; _saturation_claims proves the two forms equal).
tl = sp.Symbol("tl", positive=True)


def switching_functions(locked: bool):
    """A wheel's switching functions, in (c, s, vx, vy, w, px, py, cd, sd, eps,
    tl): where one changes sign its force changes branch, a kink of the force
    in the state (the integrator lands its steps there: KINK_PAST). Rolling:
    u_l = eps and u_l = -eps (Modulus(eps, u_l), in its sign and its slip
    angle), and |u_s| = tl max(|u_l|, eps) (the lateral share's saturation,
    tl = tan(cap alpha_max)); `_switching_claims` checks that these are all its
    branch changes. Locked: none. Its one kink, |u| = eps, comes in a run-out's
    last milliseconds; landing there took 3 % more steps on 20,000 random
    all-locked rows (77.3 -> 79.8 at tolerance 1e-7) and moved no rest pose."""
    _, (ul, us) = contact_velocity()
    if locked:
        return []
    out = [ul - eps, ul + eps, sp.Abs(us) - tl * Modulus(eps, ul)]
    return [_to_cs(e) for e in out]


# --- proofs --------------------------------------------------------------------


def _rotation(d):
    """The rotation matrix by angle d (counter-clockwise, scene frame)."""
    return sp.Matrix([[sp.cos(d), -sp.sin(d)], [sp.sin(d), sp.cos(d)]])


def heading_sensitivity():
    """d(x, y, psi)_rest / d psi0 of the run-out map R(x0, y0, psi0, vx, vy, w, ...)
    from its invariance under a rotation of the start about its centre of gravity
    (proved in `_symbolic_claims`: the contact velocities in the wheel frames do not
    change, so every force turns with the vehicle): turning psi0 by d and the
    separation velocity v with it turns the rest pose by d about (x0, y0),
        R(x0, y0, psi0 + d, Q(d) v, w) = (c0 + Q(d) (r_R - c0), psi_R + d).
    Differentiated at d = 0, with J = dR/d(vx, vy):
        dR/dpsi0 = (-(y_R - y0), x_R - x0, 1) - J (-vy, vx).
    Returns (inputs, the three expressions); J's entries are Jxvx ... Jpsivy."""
    x0, y0, xr, yr, d = sp.symbols("x0 y0 x_rest y_rest d", real=True)
    J = sp.Matrix(3, 2, sp.symbols("J_x_vx J_x_vy J_y_vx J_y_vy J_psi_vx J_psi_vy", real=True))
    q = _rotation(d)
    start, rest = sp.Matrix([x0, y0]), sp.Matrix([xr, yr])
    turned = (start + q * (rest - start)).col_join(sp.Matrix([d]))
    dv = (q * sp.Matrix([vx, vy])).diff(d).subs(d, 0)
    total = turned.diff(d).subs(d, 0)  # = dR/dpsi0 + J dv/dd
    expr = [sp.simplify(e) for e in (total - J * dv)]
    return (x0, y0, xr, yr, vx, vy, *J), expr


def _rotation_claims():
    """The run-out is invariant under a rotation of the start: the wheel-frame
    contact velocities (u_l, u_s), the only way psi and v enter the wheel forces,
    are unchanged by (psi, v) -> (psi + d, Q(d) v); and `heading_sensitivity`
    solves the differentiated invariance for dR/dpsi0."""
    d = sp.Symbol("d", real=True)
    _, (ul, us) = contact_velocity()
    v2 = _rotation(d) * sp.Matrix([vx, vy])
    turn = {psi: psi + d, vx: v2[0], vy: v2[1]}
    same = all(sp.simplify(sp.expand_trig(u.xreplace(turn) - u)) == 0 for u in (ul, us))
    args, expr = heading_sensitivity()
    x0, y0, xr, yr = args[:4]
    J = sp.Matrix(3, 2, args[6:])
    want = sp.Matrix([-(yr - y0), xr - x0, 1]) - J * sp.Matrix([-vy, vx])
    solved = all(sp.simplify(a - b) == 0 for a, b in zip(expr, want))
    return [
        ("run-out: wheel-frame contact velocities are unchanged by turning psi and v together", same),
        ("run-out: dR/dpsi0 = (-(y_R - y0), x_R - x0, 1) - J (-vy, vx) from that invariance", solved),
    ]


def heading_sensitivity_function() -> str:
    """`rest_heading_sensitivity` as plain Python for generated/runout.py."""
    args, expr = heading_sensitivity()
    names = ", ".join(str(a) for a in args)
    body = ", ".join(emit.code(e) for e in expr)
    return (
        f"def rest_heading_sensitivity({names}):\n"
        '    """d(x_rest, y_rest, psi_rest)/d psi0 [m/rad, m/rad, 1] from the run-out\'s\n'
        "    invariance under a rotation of the start about its centre of gravity\n"
        '    (derive/runout.py `heading_sensitivity`); J_* = d(rest)/d(vx, vy) [s, s, s/m]."""\n'
        f"    return ({body})\n"
    )


def hermite_weights():
    """The cubic through (0, p0) and (1, p1) with slopes h m0 and h m1 (a step of
    length h in time, s = (t - t0)/h): its weights on (p0, m0, p1, m1) as
    functions of s and h, solved from the four end conditions. Returns
    ((s, h), weights of the value, of d/dt, of d2/dt2)."""
    s_, h_ = sp.symbols("s h", positive=True)
    c = sp.symbols("c0:4")
    p0, m0, p1, m1 = sp.symbols("p0 m0 p1 m1")
    cubic = sum(ci * s_**i for i, ci in enumerate(c))
    ends = [cubic.subs(s_, 0) - p0, cubic.diff(s_).subs(s_, 0) - h_ * m0]
    ends += [cubic.subs(s_, 1) - p1, cubic.diff(s_).subs(s_, 1) - h_ * m1]
    value = sp.expand(cubic.subs(sp.solve(ends, c)))
    rows = [value, value.diff(s_) / h_, value.diff(s_, 2) / h_**2]
    return (s_, h_), [[sp.factor(sp.expand(r).coeff(x)) for x in (p0, m0, p1, m1)] for r in rows]


def foot_time_sensitivity():
    """dt*/dp of the moment t* the path X(t, p) passes nearest a point q:
    t* solves g = (q - X)·V = 0 (V = dX/dt), so dt*/dp = -g_p/g_t =
    ((q - X)·V_p - V·X_p) / (|V|^2 - (q - X)·A), A = dV/dt, V_p = dX_p/dt
    (proved against the implicit differentiation of g in `_foot_claims`).
    Returns (inputs, expression)."""
    qx, qy, X1, X2, V1, V2, A1, A2 = sp.symbols("qx qy X1 X2 V1 V2 A1 A2", real=True)
    P1, P2, W1, W2 = sp.symbols("Xp1 Xp2 Vp1 Vp2", real=True)
    num = (qx - X1) * W1 + (qy - X2) * W2 - (V1 * P1 + V2 * P2)
    den = V1**2 + V2**2 - ((qx - X1) * A1 + (qy - X2) * A2)
    return (qx, qy, X1, X2, V1, V2, A1, A2, P1, P2, W1, W2), num / den


def _foot_claims():
    """The Hermite weights meet their end conditions; `foot_time_sensitivity`
    is -g_p/g_t of g(t, p) = (q - X(t, p))·dX/dt for a general path X."""
    (s_, h_), (value, slope, _) = hermite_weights()
    p = sp.symbols("p0 m0 p1 m1")
    v = sum(w * x for w, x in zip(value, p))
    d = sum(w * x for w, x in zip(slope, p))
    ends = [v.subs(s_, 0) - p[0], d.subs(s_, 0) - p[1], v.subs(s_, 1) - p[2], d.subs(s_, 1) - p[3]]
    hermite = all(sp.simplify(e) == 0 for e in ends) and sp.simplify(d - v.diff(s_) / h_) == 0
    t, pp = sp.symbols("t p", real=True)
    X = [sp.Function("X1")(t, pp), sp.Function("X2")(t, pp)]
    args, expr = foot_time_sensitivity()
    qx, qy = args[:2]
    g = (qx - X[0]) * X[0].diff(t) + (qy - X[1]) * X[1].diff(t)
    implicit = -g.diff(pp) / g.diff(t)
    names = dict(zip(args[2:], [X[0], X[1], X[0].diff(t), X[1].diff(t), X[0].diff(t, 2), X[1].diff(t, 2)]))
    names |= dict(zip(args[8:], [X[0].diff(pp), X[1].diff(pp), X[0].diff(t, pp), X[1].diff(t, pp)]))
    foot = sp.simplify(expr.xreplace(names) - implicit) == 0
    return [
        ("run-out path: the cubic Hermite weights meet p(0), p'(0), p(1), p'(1)", hermite),
        ("run-out path: dt*/dp of the nearest passage = -g_p/g_t, g = (q - X).dX/dt", foot),
    ]


def via_functions() -> str:
    """`hermite_weights` and `foot_time_sensitivity` as plain Python for
    generated/runout.py (impactsym/runout/via.py calls them; their arguments
    may be NumPy arrays)."""
    (s_, h_), rows = hermite_weights()
    weights = ",\n        ".join("(" + ", ".join(emit.code(w) for w in row) + ")" for row in rows)
    args, expr = foot_time_sensitivity()
    return (
        "def hermite_weights(s, h):\n"
        '    """Weights on (p0, m0, p1, m1) of the cubic Hermite interpolant at s in [0, 1]\n'
        '    of a step h [s]: (value, d/dt, d2/dt2) (derive/runout.py `hermite_weights`)."""\n'
        f"    return (\n        {weights},\n    )\n\n\n"
        f"def foot_time_sensitivity({', '.join(str(a) for a in args)}):\n"
        '    """dt*/dp of the moment the path passes nearest (qx, qy): X, V, A the position,\n'
        "    velocity and acceleration there, Xp, Vp their derivatives with respect to p\n"
        '    (derive/runout.py `foot_time_sensitivity`)."""\n'
        f"    return {emit.code(expr)}\n"
    )


def _symbolic_claims():
    """Chassis identities with arbitrary wheel-frame forces (F_l, F_s): the
    scene force is the wheel force rotated by psi + delta, with norm
    |F_l, F_s| (so a force inside its friction circle stays inside, and
    m dv/dt = sum F is the momentum balance), and its power
    Fx vx + Fy vy + Mz w equals the power at the contact point F_l u_l + F_s u_s."""
    fl, fs = sp.symbols("F_l F_s", real=True)
    delta = sp.Symbol("delta", real=True)
    rep = {cd: sp.cos(delta), sd: sp.sin(delta)}
    fx, fy, mz = chassis(fl, fs)
    rot = (
        sp.cos(psi + delta) * fl - sp.sin(psi + delta) * fs,
        sp.sin(psi + delta) * fl + sp.cos(psi + delta) * fs,
    )
    same = all(sp.simplify(sp.expand_trig((a - r).xreplace(rep))) == 0 for a, r in zip((fx, fy), rot))
    _, (ul, us) = contact_velocity()
    power = fx * vx + fy * vy + mz * w - (fl * ul + fs * us)
    zero = sp.simplify(sp.expand_trig(sp.expand(power.xreplace(rep)))) == 0
    return [
        ("run-out: a wheel's scene-frame force is its wheel-frame force rotated by psi + delta", same),
        ("run-out: power of a wheel force on the body Fx vx + Fy vy + Mz w = F_l u_l + F_s u_s", zero),
    ]


def _mp_functions(expr_list, args):
    """`expr_list` evaluated with mpmath at the working precision."""
    clip = lambda z, k: max(-k, min(z, k))  # noqa: E731
    slope = lambda z, k: mpmath.mpf(1) if abs(z) < k else mpmath.mpf(0)  # noqa: E731
    modulus = lambda e, *u: max(mpmath.sqrt(sum(x * x for x in u)), e)  # noqa: E731
    step = lambda e, *u: mpmath.mpf(1) if sum(x * x for x in u) > e * e else mpmath.mpf(0)  # noqa: E731
    fns = {"Clip": clip, "ClipSlope": slope, "Modulus": modulus, "ModulusStep": step, "sign": mpmath.sign}
    mods = [fns, "mpmath"]
    return sp.lambdify(args, expr_list, modules=mods)


def _random_state(rng: random.Random, locked: bool):
    """A random wheel situation, one in five at speeds comparable with eps."""
    scale = 0.01 if rng.random() < 0.2 else 20.0
    brake = 0.0 if locked or rng.random() < 0.4 else rng.random()
    return {
        psi: rng.uniform(-7, 7),
        vx: rng.uniform(-scale, scale),
        vy: rng.uniform(-scale, scale),
        w: rng.uniform(-scale, scale) / 2,
        px: rng.uniform(-2, 2),
        py: rng.uniform(-1, 1),
        sp.Symbol("delta"): rng.uniform(-0.6, 0.6),
        N: rng.uniform(1000, 6000),
        mu: rng.uniform(0.1, 1.2),
        amax: rng.uniform(0.02, 0.5),
        b: brake,
        fre: 0.0 if brake > 0 else rng.uniform(0, 0.05),
        eps: EPS,
    }


def _numeric_claims(samples: int = 300):
    """Friction circle, dissipation and the Jacobians, at 50 digits on random states."""
    rng = random.Random(960886)
    args = (psi, vx, vy, w, px, py, sp.Symbol("delta"), N, mu, amax, b, fre, eps)
    results = []
    with mpmath.workdps(50):
        for locked in (True, False):
            fl, fs = wheel_frame_forces(locked)
            _, (ul, us) = contact_velocity()
            exprs = [e.xreplace({cap: sp.sqrt(1 - b**2)}) for e in (fl, fs, fl * ul + fs * us)]
            jac = [sp.diff(f, z) for f in scene_forces(locked) for z in Z]
            forces = [e.xreplace({cap: sp.sqrt(1 - b**2)}) for e in scene_forces(locked)]
            delta = sp.Symbol("delta")
            rep = {cd: sp.cos(delta), sd: sp.sin(delta)}
            f_num = _mp_functions([e.xreplace(rep) for e in exprs], args)
            g_num = _mp_functions([e.xreplace(rep).xreplace({cap: sp.sqrt(1 - b**2)}) for e in forces], args)
            j_num = _mp_functions([e.xreplace(rep).xreplace({cap: sp.sqrt(1 - b**2)}) for e in jac], args)
            circle = power = grip = jac_ok = True
            worst_jac = mpmath.mpf(0)
            for _ in range(samples):
                st = _random_state(rng, locked)
                vals = [mpmath.mpf(st[a]) for a in args]
                f_l, f_s, p = f_num(*vals)
                n_mu = vals[7] * vals[8]
                room = 1 + mpmath.mpf(10) ** -40  # on the circle (|u| >= eps) up to 50-digit rounding
                if locked or vals[10] > 0:
                    circle &= f_l**2 + f_s**2 <= n_mu**2 * room
                else:  # rolling resistance is a loss in the tyre, not grip
                    grip &= (
                        abs(f_s) <= n_mu * room
                        and f_l**2 + f_s**2 <= (n_mu**2 + (vals[11] * vals[7]) ** 2) * room
                    )
                power &= p <= 0
                jac_ok, worst_jac = _check_jacobian(g_num, j_num, vals, jac_ok, worst_jac)
            kind = "locked" if locked else "rolling/braked"
            results.append(
                (
                    f"run-out: {kind} wheel force inside its friction circle |F| <= mu N "
                    f"({samples} random states, 50 digits)",
                    circle,
                )
            )
            if not locked:
                results.append(
                    (
                        "run-out: plain rolling wheel: lateral grip |F_s| <= mu N, and |F| <= "
                        "sqrt(mu^2 + f_r^2) N (rolling resistance on top)",
                        grip,
                    )
                )
            results.append((f"run-out: {kind} wheel power F.u <= 0 (dissipative)", power))
            results.append(
                (
                    f"run-out: {kind} wheel Jacobian d(Fx,Fy,Mz)/d(psi,vx,vy,w,mu) = central "
                    f"differences (worst relative {mpmath.nstr(worst_jac, 3)})",
                    jac_ok,
                )
            )
    return results


def _check_jacobian(g_num, j_num, vals, ok, worst):
    """Compare the symbolic Jacobian with 50-digit central differences at one
    state; a coordinate where the one-sided differences disagree (the state sits
    on the lateral-saturation kink) is skipped."""
    h = mpmath.mpf(10) ** -20
    jac, f0 = j_num(*vals), g_num(*vals)
    for k, at in enumerate((0, 1, 2, 3, 8)):  # psi, vx, vy, w, mu among the arguments
        up, dn = list(vals), list(vals)
        up[at] += h
        dn[at] -= h
        fu, fd = g_num(*up), g_num(*dn)
        for row in range(3):
            scale = max(abs(jac[row * 5 + k]), mpmath.mpf(1))
            right, left = (fu[row] - f0[row]) / h, (f0[row] - fd[row]) / h
            if abs(right - left) > scale * mpmath.mpf(10) ** -15:
                continue  # on the kink
            err = abs((fu[row] - fd[row]) / (2 * h) - jac[row * 5 + k]) / scale
            worst = max(worst, err)
            ok = ok and err < mpmath.mpf(10) ** -15
    return ok, worst


def _saturation_claims(samples: int = 2000):
    """The forward rolling wheel's shortcut (SaturatingPrinter): where
    |u_s| >= tan(cap alpha_max) h (h = max(|u_l|, eps) > 0, 0 <= cap <= 1,
    0 < alpha_max < 90 deg) the clip clip(atan2(u_s, h)/alpha_max, cap) is
    cap sgn(u_s); random points at 50 digits, half of them within 1e-12 of
    the boundary on either side."""
    rng = random.Random(1993)
    ok = True
    with mpmath.workdps(50):
        for i in range(samples):
            am = mpmath.mpf(rng.uniform(1e-3, 1.57))
            k = mpmath.mpf(rng.choice([0.0, 1.0, rng.uniform(0.0, 1.0)]))
            h = mpmath.mpf(10) ** rng.uniform(-4, 2)
            edge = mpmath.tan(k * am) * h
            u = edge * (1 + mpmath.mpf(rng.uniform(-1e-12, 1e-12))) if i % 2 else edge * rng.uniform(0, 3)
            u *= rng.choice([-1, 1])
            clip = min(max(mpmath.atan2(u, h) / am, -k), k)
            if abs(u) >= mpmath.tan(k * am) * h:
                ok &= abs(clip - mpmath.sign(u) * k) <= mpmath.mpf(10) ** -40
    return [
        (
            "run-out: rolling wheel's lateral share is cap sgn(u_s) wherever |u_s| >= tan(cap alpha_max) "
            f"max(|u_l|, eps) (the emitted shortcut; {samples} points, 50 digits)",
            ok,
        )
    ]


def _switching_claims(samples: int = 2000):
    """The rolling wheel's switching functions hold every branch change of its
    force: between two random states its branch (u_l above eps, inside the band
    |u_l| <= eps, or below -eps: Modulus; the lateral share saturated,
    |atan2(u_s, max(|u_l|, eps))| >= cap alpha_max) differs only where a
    switching function's sign differs (50 digits; the second state of a pair
    is the first with its velocities scaled by a factor in [-1.5, 1.5] plus
    noise, so that many pairs straddle a boundary, which the claim requires)."""
    rng = random.Random(1998)
    delta = sp.Symbol("delta")
    rep = {cd: sp.cos(delta), sd: sp.sin(delta), c: sp.cos(psi), s: sp.sin(psi), tl: sp.tan(cap * amax)}
    args = (psi, vx, vy, w, px, py, delta, amax, cap, eps)
    g_num = _mp_functions([e.xreplace(rep) for e in switching_functions(False)], args)
    _, (ul, us) = contact_velocity()
    u_num = _mp_functions([e.xreplace(rep) for e in (ul, us)], args)

    def branch(vals):
        u_l, u_s = u_num(*vals)
        band = 0 if abs(u_l) <= vals[9] else int(mpmath.sign(u_l))
        angle = abs(mpmath.atan2(u_s, max(abs(u_l), vals[9]))) / vals[7]
        return band, angle >= vals[8]

    ok, straddled = True, 0
    with mpmath.workdps(50):
        for _ in range(samples):
            st = _random_state(rng, False)
            vals = [mpmath.mpf(st.get(a, 0)) for a in args]
            vals[8] = mpmath.sqrt(1 - mpmath.mpf(st[b]) ** 2)  # cap
            other = list(vals)
            k = rng.uniform(-1.5, 1.5)
            for i in (1, 2, 3):
                other[i] = vals[i] * k + mpmath.mpf(rng.gauss(0, 1)) * abs(vals[i]) * 0.1
            if branch(vals) != branch(other):
                straddled += 1
                ok &= any((x > 0) != (y > 0) for x, y in zip(g_num(*vals), g_num(*other)))
    return [
        (
            "run-out: a rolling wheel's force changes branch only where one of its switching functions "
            f"changes sign ({straddled} of {samples} random pairs straddle a branch change, 50 digits)",
            ok and straddled > samples // 5,
        )
    ]


def _stiff_step_claims():
    """ROS34PW2's tables (Hairer & Wanner IV.7, Table 7.1 conditions, beta = alpha
    + gamma): B has order 3, B_EMBEDDED order 2, the method is stiffly accurate
    (B = the last row of beta with GAMMA on the diagonal), and where the
    Jacobian it is given is zero (a W-method's row) it is an explicit
    Runge-Kutta method of order 3 (B alpha^k = 1/(k + 1), B ALPHA alpha = 1/6); all to 1e-14 in
    50-digit arithmetic."""
    with mpmath.workdps(50):
        g = mpmath.mpf(W_GAMMA)
        alpha = [[mpmath.mpf(x) for x in r] + [0] * (4 - len(r)) for r in W_ALPHA]
        beta = [
            [alpha[i][j] + (mpmath.mpf(W_GAMMAS[i][j]) if j < i else 0) for j in range(4)] for i in range(4)
        ]
        a = [sum(r) for r in alpha]
        bp = [sum(r) for r in beta]

        def misfits(b, order):
            b = [mpmath.mpf(x) for x in b]
            out = [sum(b) - 1, sum(bi * x for bi, x in zip(b, bp)) - (mpmath.mpf(1) / 2 - g)]
            if order >= 3:
                bbb = sum(b[i] * beta[i][j] * bp[j] for i in range(4) for j in range(4))
                out += [
                    sum(bi * x * x for bi, x in zip(b, a)) - mpmath.mpf(1) / 3,
                    bbb - (mpmath.mpf(1) / 6 - g + g * g),
                ]
            return out

        tiny = mpmath.mpf(10) ** -14
        order3 = all(abs(x) < tiny for x in misfits(W_B, 3))
        order2 = all(abs(x) < tiny for x in misfits(W_B_EMBEDDED, 2))
        stiffly = all(abs(beta[3][j] + (g if j == 3 else 0) - mpmath.mpf(W_B[j])) < tiny for j in range(4))
        quad = all(
            abs(sum(mpmath.mpf(bi) * x**k for bi, x in zip(W_B, a)) - mpmath.mpf(1) / (k + 1)) < tiny
            for k in range(3)
        )
        tall = sum(mpmath.mpf(W_B[i]) * alpha[i][j] * a[j] for i in range(4) for j in range(4))
        quad = quad and abs(tall - mpmath.mpf(1) / 6) < tiny
    return [
        (
            "run-out: ROS34PW2 (stiff steps) has order 3, its embedded solution order 2 (1e-14)",
            order3 and order2,
        ),
        (
            "run-out: ROS34PW2 is stiffly accurate, and of order 3 as an explicit method where J = 0",
            stiffly and quad,
        ),
    ]


def proofs():
    """(claim, passed) for the run-out model."""
    return (
        _symbolic_claims()
        + _rotation_claims()
        + _foot_claims()
        + _numeric_claims()
        + _saturation_claims()
        + _switching_claims()
        + _stiff_step_claims()
    )


# --- emission ------------------------------------------------------------------


class RunoutPrinter(emit.KernelPrinter):
    """The kernel printer plus the saturation functions of the lateral law."""

    def _print_Clip(self, expr):
        z, k = (self._print(a) for a in expr.args)
        return f"min(max({z}, -{k}), {k})"

    def _print_ClipSlope(self, expr):
        z, k = (self._print(a) for a in expr.args)
        return f"(1.0 if abs({z}) < {k} else 0.0)"

    def _print_Modulus(self, expr):
        e, *u = (self._print(a) for a in expr.args)
        if len(u) == 1:
            return f"max(abs({u[0]}), {e})"
        return f"max(math.sqrt({' + '.join(f'{x}*{x}' for x in u)}), {e})"

    def _print_ModulusStep(self, expr):
        e, *u = (self._print(a) for a in expr.args)
        return f"(1.0 if {' + '.join(f'{x}*{x}' for x in u)} > {e}*{e} else 0.0)"

    def _print_sign(self, expr):
        return f"math.copysign(1.0, {self._print(expr.args[0])})"


class SaturatingPrinter(RunoutPrinter):
    """RunoutPrinter for the forward rolling wheel: Clip(atan2(u_s, h)/alpha_max, cap)
    is printed as cap sgn(u_s) where |u_s| >= tl h (tl = tan(cap alpha_max), the
    saturated side: no atan2 there; measured in docs/runout.md), else as the
    clip. Both forms agree wherever the test decides (`_saturation_claims`)."""

    def _print_Clip(self, expr):
        z, k = expr.args
        angle = [f for f in sp.Mul.make_args(z) if isinstance(f, sp.atan2)]
        if len(angle) != 1 or sp.simplify(z - angle[0] / amax) != 0:
            return super()._print_Clip(expr)
        a, h = (self._print(x) for x in angle[0].args)
        kk = self._print(k)
        return f"(math.copysign({kk}, {a}) if abs({a}) >= tl*{h} else {super()._print_Clip(expr)})"


PRINTER = RunoutPrinter({"fully_qualified_modules": True, "standard": "python3"})
SATURATING = SaturatingPrinter({"fully_qualified_modules": True, "standard": "python3"})
# The entry points (the row functions and batch drivers, called from Python).
JIT = 'njit(cache=True, error_model="numpy")'
# Every other kernel is called only from kernels: without the CPython wrapper
# numba builds, optimises and compiles for each function, a first fit with
# cg_height compiled in 7.3-7.7 s against 8.0-8.6 s (docs/runout.md, "First use").
JIT_INNER = 'njit(cache=True, error_model="numpy", no_cpython_wrapper=True)'


def wheel_function(name: str, locked: bool, jacobian: bool) -> tuple[str, int]:
    """One wheel's (Fx, Fy, Mz) [and their derivatives] as numba source, and its
    operation count after common-subexpression elimination."""
    outs = wheel_outputs(locked, jacobian)
    temps, reduced = sp.cse(outs, symbols=sp.numbered_symbols("_t"))
    ops = int(sum(sp.count_ops(x) for _, x in temps) + sum(sp.count_ops(x) for x in reduced))
    kind = (
        "locked: F = -mu N u/|u|"
        if locked
        else "rolling/braked: F_l = -(b mu + f) N sgn(u_l), F_s = -mu N clip(alpha/alpha_max, cap)"
    )
    what = "(Fx, Fy, Mz) and d/d(psi, vx, vy, w, mu) of each, row by row" if jacobian else "(Fx, Fy, Mz)"
    saturating = not (locked or jacobian)
    printer = SATURATING if saturating else PRINTER
    args = WHEEL_ARGS + ((tl,) if saturating else ())
    lines = [f"@{JIT_INNER}"]
    lines += emit._wrap(f"def {name}(", [str(a) for a in args], "):", " " * 8)
    lines.append(f'    """Wheel {kind} (conventions.md, run-out; derive/runout.py): {what}."""')
    lines += [f"    {t} = {printer.doprint(x)}" for t, x in temps]
    lines += emit._wrap("    return (", [printer.doprint(x) for x in reduced], ")", " " * 8)
    return "\n".join(lines) + "\n", ops


def _constants() -> list[str]:
    return [
        f"EPS = {EPS!r}  # m/s, smoothing speed of sgn and |.|",
        f"V_STOP = {V_STOP!r}  # m/s, at rest when |v| + |w| R_max < V_STOP",
        f"T_MAX = {T_MAX!r}  # s",
        f"MAX_STEPS = {MAX_STEPS!r}",
        f"TOL = {TOL!r}  # default local error tolerance per step",
        f"H0 = {H0!r}  # s",
        f"H_MAX = {H_MAX!r}  # s",
    ] + [f"STATUS_{k} = {v!r}" for k, v in STATUS.items()]


# Dormand-Prince 5(4) (Dormand & Prince 1980): stage rows DP_A (the seventh is
# the fifth-order solution, FSAL), error weights DP_E = b5 - b4.
DP_A = (
    (),
    ("1/5",),
    ("3/40", "9/40"),
    ("44/45", "-56/15", "32/9"),
    ("19372/6561", "-25360/2187", "64448/6561", "-212/729"),
    ("9017/3168", "-355/33", "46732/5247", "49/176", "-5103/18656"),
    ("35/384", "0", "500/1113", "125/192", "-2187/6784", "11/84"),
)
DP_E = ("71/57600", "0", "-71/16695", "71/1920", "-17253/339200", "22/525", "-1/40")


def _w_constants() -> list[str]:
    """The Dormand-Prince and ROS34PW2 tables as numba-frozen arrays (numba folds global arrays into the code)."""

    def table(rows, width=4):
        full = [list(r) + [0.0] * (width - len(r)) for r in rows]
        return "np.array([" + ", ".join("[" + ", ".join(repr(x) for x in r) + "]" for r in full) + "])"

    def table7(rows):
        return table(rows, 7)

    dp = [[float(sp.Rational(x)) for x in r] for r in DP_A]
    return [
        f"DP_A = {table7(dp)}",
        f"DP_E = np.array({[float(sp.Rational(x)) for x in DP_E]!r})",
        f"W_GAMMA = {W_GAMMA!r}",
        f"W_ALPHA = {table(W_ALPHA)}",
        f"W_GAMMAS = {table(W_GAMMAS)}",
        f"W_B = np.array({list(W_B)!r})",
        f"W_E = np.array({[b - e for b, e in zip(W_B, W_B_EMBEDDED)]!r})  # B - B_EMBEDDED",
        f"W_ENTER = {W_ENTER!r}  # h |lambda| that hands a step to ROS34PW2",
        f"W_LEAVE = {W_LEAVE!r}  # h |lambda| bound below which Dormand-Prince takes over again",
        f"W_WAIT = {W_WAIT!r}  # Dormand-Prince steps before a refused hand-over is tried again",
        f"SENS_SHARE = {SENS_SHARE!r}  # a sensitivity S is held to SENS_SHARE tol (1 + |S|) per explicit step",
        f"KINK_PAST = {KINK_PAST!r}  # a trial rejected across a kink retries to KINK_PAST times the kink's fraction",
        f"KINK_MIN = {KINK_MIN!r}  # of the step, at least",
    ]


# The kernels a first use compiles in a second process while the first compiles
# the run-out's row function (impactsym/runout/prime.py): callees of the row
# functions whose compile the first process reaches only after its right-hand
# side's, in the order it reaches them, with the argument types the row
# functions pass them (numba's signature syntax; tests/test_runout_prime.py
# checks that a first use loads each from the cache). A first fit with cg_height
# on an empty cache: 5.0-5.7 s, 7.1-8.0 s without the second process; this
# order against the same list last first and with _rhs_sens first
# (docs/runout.md, "First use").
_V, _M = "float64[::1]", "float64[:, ::1]"
PRIME = (
    ("_jac", (_V, _V, _M, _M)),
    ("_stiffness", (_M, "float64")),
    ("_w_inverse", (_M, "float64")),
    ("_w_stage", (_M, "int64", _V, "float64", "float64", _M, _M, "float64", "float64", _V)),
    ("_kink", (_V, _V, _V, _M)),
    ("_to_stop", (_V, _V, _V, _V, "float64", "float64", _V)),
)


def _prime_lines() -> list[str]:
    """PRIME as generated source: (kernel, signature) pairs."""
    pairs = [f'    ("{name}", "({", ".join(types)})"),' for name, types in PRIME]
    return [
        "# (kernel, argument types) a second process compiles into numba's cache at a first",
        "# use while this one compiles the row function (impactsym/runout/prime.py).",
        "PRIME = (",
        *pairs,
        ")",
    ]


def render_plain(digest: str) -> str:
    """generated/runout.py: constants, columns, outputs and status texts (plain Python)."""
    parts = [
        emit.header("runout.py", digest).rstrip("\n"),
        f"# 0 kernels; rest_heading_sensitivity: {sum(sp.count_ops(e) for e in heading_sensitivity()[1])} "
        "arithmetic operations after common-subexpression elimination;",
        f"# foot_time_sensitivity: {sp.count_ops(foot_time_sensitivity()[1])} operations; "
        f"hermite_weights: {sum(sp.count_ops(w) for row in hermite_weights()[1] for w in row)} operations;",
        "# constants otherwise;",
        "# the wheel forces, batch driver and integrator are in generated/runout_jit.py.",
        "",
        '"""Post-impact run-out: constants, batch columns and status codes (numba code: runout_jit.py)."""',
        "",
        "import math",
        "",
        *_constants(),
        "",
        f"COLUMNS = {COLUMNS!r}",
        f"OUTPUTS = {OUTPUTS!r}",
        f"SENSITIVITIES = {SENSITIVITIES!r}",
        f"STATUS_TEXT = {STATUS_TEXT!r}",
        f"WHEELS = {WHEELS!r}",
        "GRAVITY_SI = 9.80665",
        "RIGHT_ANGLE = math.pi / 2",
        "",
        "",
        heading_sensitivity_function().rstrip("\n"),
        "",
        "",
        via_functions().rstrip("\n"),
        "",
        "",
        load_transfer.limit_function().rstrip("\n"),
    ]
    return "\n".join(parts) + "\n"


def render(digest: str) -> dict[str, str]:
    """File name -> text of the run-out's generated files."""
    funcs, ops, counts = [], [], []
    for name, locked, jac in (
        ("_wheel_locked", True, False),
        ("_wheel_rolling", False, False),
        ("_wheel_locked_jac", True, True),
        ("_wheel_rolling_jac", False, True),
    ):
        text, count = wheel_function(name, locked, jac)
        funcs.append(text)
        counts.append(count)
        ops.append(f"#   {name}: {count} operations")
    parts = [
        emit.header("runout.py", digest).rstrip("\n"),
        f"# {len(ops)} wheel-force kernels, {sum(counts)} arithmetic operations after "
        "common-subexpression elimination:",
        *ops,
        "",
        '"""Post-impact run-out (numba): wheel forces, right-hand side with sensitivities,',
        'Dormand-Prince 5(4) integrator to rest, its row functions and batch driver (derive/runout.py)."""',
        "",
        "import math",
        "",
        "import numpy as np",
        "from numba import njit",
        "",
        *_constants(),
        *_w_constants(),
        *_prime_lines(),
        "",
        *("\n" + f for f in funcs),
        INTEGRATOR_SOURCE,
    ]
    text = "\n".join(parts).rstrip("\n") + "\n"
    for name, types in PRIME:  # every primed kernel is an inner kernel taking that many arguments
        head = re.search(rf"@{re.escape(JIT_INNER)}\ndef {name}\(([^)]*)\):", text)
        assert head and len(head.group(1).split(",")) == len(types), name
    return {"runout.py": render_plain(digest), "runout_jit.py": text}


def _wheel_call(load: str, jacobian: bool) -> str:
    """The loop body that reads wheel k's row of W and evaluates its force (and
    with `jacobian` its derivatives) at normal load `load` into r."""
    kind = "_jac" if jacobian else ""
    tail = "" if jacobian else ", W[k, 9]"  # the forward rolling wheel's saturation threshold
    args = f"c, s, vx, vy, w, px, py, cd, sd, {load}, mu, amax, b, fre, cap, eps"
    return (
        "        px, py, cd, sd, n = W[k, 0], W[k, 1], W[k, 2], W[k, 3], W[k, 4]\n"
        "        b, fre, cap = W[k, 5], W[k, 6], W[k, 7]\n"
        "        if W[k, 8] != 0.0:\n"
        f"            r = _wheel_locked{kind}({args})\n"
        "        else:\n"
        f"            r = _wheel_rolling{kind}({args}{tail})"
    )


def _sensitivity_lines() -> str:
    """dS/dt = J S (+ df/dmu in the mu column) for the 6 x 4 sensitivity block
    S[i, j] = y[7 + 4 i + j] (j: vx, vy, w at separation, then mu)."""
    lines = []
    for j in range(4):
        sj = [f"y[{7 + 4 * i + j}]" for i in range(6)]
        lines += [
            f"        f[{7 + 4 * 0 + j}] = {sj[3]}",
            f"        f[{7 + 4 * 1 + j}] = {sj[4]}",
            f"        f[{7 + 4 * 2 + j}] = {sj[5]}",
        ]
        for row, div in enumerate(("m", "m", "inertia")):
            terms = " + ".join(f"d{'xyz'[row]}{k}*{sj[2 + k]}" for k in range(4))
            extra = f" + d{'xyz'[row]}4" if j == 3 else ""
            lines.append(f"        f[{7 + 4 * (3 + row) + j}] = ({terms}{extra})/{div}")
    return "\n".join(lines)


INTEGRATOR_SOURCE = '''

# Per-row tables built by _setup: P = (m, I, mu, alpha_max, eps, R_max, h) and
# W[k] = (px, py, cos delta, sin delta, N, b, f, cap, locked, tan(cap alpha_max), c_l, c_s)
# for k = fl, fr, rl, rr (c_l, c_s: the load change per newton of force along and across the
# vehicle, derive/load_transfer.py). A row with h > 0 runs through the _lt functions
# (TRANSFER_SOURCE) and its own row functions and batch driver, which numba
# compiles only when such a row comes: the static model's code and first use
# stay as they were (the transfer inside _rhs, _rhs_sens and _jac cost 1.2 s
# of every first fit).


@__JIT__
def _rhs(y, P, W, f):
    """State derivative f(y), y = (x, y, psi, vx, vy, w, distance):
    m dv/dt = sum F, I dw/dt = sum Mz, d distance/dt = |v| (conventions.md, run-out)."""
    c = math.cos(y[2])
    s = math.sin(y[2])
    vx, vy, w = y[3], y[4], y[5]
    m, inertia, mu, amax, eps = P[0], P[1], P[2], P[3], P[4]
    fx = 0.0
    fy = 0.0
    mz = 0.0
    for k in range(4):
__WHEEL__
        fx += r[0]
        fy += r[1]
        mz += r[2]
    f[0] = vx
    f[1] = vy
    f[2] = w
    f[3] = fx/m
    f[4] = fy/m
    f[5] = mz/inertia
    f[6] = math.sqrt(vx*vx + vy*vy)


@__JIT__
def _rhs_sens(y, P, W, f):
    """_rhs and the sensitivity equations dS/dt = J S (+ df/dmu), S[i, j] =
    y[7 + 4 i + j] = d y_i/d(vx, vy, w at separation, mu)_j."""
    c = math.cos(y[2])
    s = math.sin(y[2])
    vx, vy, w = y[3], y[4], y[5]
    m, inertia, mu, amax, eps = P[0], P[1], P[2], P[3], P[4]
    fx = 0.0
    fy = 0.0
    mz = 0.0
__ACC_INIT__
    for k in range(4):
__WHEEL_JAC__
__ACC_ADD__
    f[0] = vx
    f[1] = vy
    f[2] = w
    f[3] = fx/m
    f[4] = fy/m
    f[5] = mz/inertia
    f[6] = math.sqrt(vx*vx + vy*vy)
__SENS__


__TRANSFER__@__JIT__
def _speed(y, P):
    """|v| + |w| R_max: the fastest any wheel can move."""
    return math.sqrt(y[3]*y[3] + y[4]*y[4]) + abs(y[5])*P[5]


__INTEGRATE__@__JIT__
def _check(v):
    """The row's status before integration (0: fine). v holds the COLUMNS values."""
    for i in range(v.shape[0]):
        if not math.isfinite(v[i]):
            return STATUS_NONFINITE_INPUT
    if not (v[0] > 0.0 and v[1] > 0.0):
        return STATUS_BAD_MASS
    if not (v[2] > 0.0 and v[3] > 0.0 and v[3] < v[2] and v[4] > 0.0 and v[27] >= 0.0):
        return STATUS_RUNOUT_BAD_GEOMETRY
    if not (v[5] > 0.0 and v[6] > 0.0 and v[6] < 0.5*math.pi and v[7] >= 0.0 and v[8] > 0.0):
        return STATUS_RUNOUT_BAD_TYRE
    for k in range(4):
        state, brake, steer = v[15 + 3*k], v[16 + 3*k], v[17 + 3*k]
        if not ((state == 0.0 or state == 1.0) and brake >= 0.0 and brake <= 1.0 and abs(steer) < 0.5*math.pi):
            return STATUS_RUNOUT_BAD_WHEEL
__LIFT__
    return STATUS_OK


@__JIT__
def _setup(v, eps):
    """(y, P, W) of a checked row: state at separation, vehicle and wheel tables.
    Static loads m g b/(2L) front, m g a/(2L) rear; wheels at (a, +-track/2)
    and (-b, +-track/2), left first (conventions.md, run-out)."""
    m, inertia, wb, a, track, mu, amax, f_r, g = v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]
    b_ = wb - a
    half = 0.5*track
    W = np.empty((4, 12))
    xs = (a, a, -b_, -b_)
    ys = (half, -half, half, -half)
    loads = (m*g*b_/(2.0*wb), m*g*b_/(2.0*wb), m*g*a/(2.0*wb), m*g*a/(2.0*wb))
    # load change per newton of body-frame force (derive/load_transfer.py; 0 when h = 0)
__TRANSFER_SETUP__
    for k in range(4):
        state, brake, steer = v[15 + 3*k], v[16 + 3*k], v[17 + 3*k]
        W[k, 0] = xs[k]
        W[k, 1] = ys[k]
        W[k, 2] = math.cos(steer)
        W[k, 3] = math.sin(steer)
        W[k, 4] = loads[k]
        W[k, 5] = brake
        W[k, 6] = f_r if brake == 0.0 else 0.0
        W[k, 7] = math.sqrt((1.0 - brake)*(1.0 + brake))
        W[k, 8] = state
        W[k, 9] = math.tan(W[k, 7]*amax)
        W[k, 10] = cl[k]
        W[k, 11] = cs[k]
    P = np.empty(7)
    P[0], P[1], P[2], P[3], P[4] = m, inertia, mu, amax, eps
    P[5] = math.sqrt(max(a, b_)**2 + half*half)
    P[6] = v[27]
    return P, W


__ROW____BATCH__'''
INTEGRATE_TEMPLATE = '''@__JIT__
def _integrate__SUFFIX__(y, P, W, tol, path):
    """Adaptive integration from t = 0 until the vehicle stops (_speed < V_STOP),
    in place on y. Non-stiff steps: Dormand-Prince 5(4) (FSAL, local
    extrapolation; tableau DP_A, error weights DP_E). Stiff steps (a wheel near
    stick, where a smoothed sign is a damper of slope mu N/EPS): the L-stable
    Rosenbrock-W method ROS34PW2 (constants W_*; stage i solves the linear
    system (I - h GAMMA J) k_i = h f(y + sum_j ALPHA_ij k_j) + h J sum_j
    GAMMAS_ij k_j with J the Jacobian at y (_jac; the distance's row
    d|v|/dv; each sensitivity column takes the state's block, the second
    derivatives of the wheel forces left out, which a W-method allows); the
    local error is the largest difference from the embedded solution over
    the state). A Dormand-Prince step whose
    estimate h |lambda| (Hairer's, from its last two stages) exceeds W_ENTER
    hands the next step to ROS34PW2; a ROS34PW2 step whose h |lambda|
    (_stiffness, from the Jacobian) is below W_LEAVE hands back. The local
    error of the state (x, y, psi, vx, vy, w) is kept below `tol` (absolute,
    SI) per step, and in a Dormand-Prince step each sensitivity S's below
    SENS_SHARE tol (1 + |S|) (in the forward kernels, which have none, the
    steps are the state's alone); the distance rides on the same steps. A step
    after a rejected trial does not grow. The step in which the vehicle stops
    is cut back to where _speed falls through V_STOP (_to_stop). Accepted
    points go to `path` while it has room: __PATH_DOC__.
    Returns (t, status, steps, points).

    The ROS34PW2 step is written here, not a function of its own: numba links
    and optimises every callee again into each caller's module; with the
    level fewer and the inner kernels' wrappers gone (JIT_INNER) a first fit
    with cg_height compiled in 7.8-8.0 s against 8.6-8.9 s (docs/runout.md,
    "First use").
    The row function stays apart: with it merged in, the run-outs with
    sensitivities ran 7-15 % slower. The stages are a loop with one call of
    the right-hand side, not written out: seven call sites tripled the compile
    time of first use."""
    n = y.shape[0]
    k = np.empty((7, n))
    z = np.empty(n)
    z6 = np.empty(6)
    y0 = np.empty(n)
    f0 = np.empty(n)
    K = np.empty((4, n))
    J = np.empty((3, 4))
    scratch = np.empty(12)
    t = 0.0
    h = H0
    steps = 0
    points = 0
    stiff = False
    taken = False  # the last step was a ROS34PW2 step
    wait = 0  # Dormand-Prince steps before the stiffness is looked at again
    fresh = False  # J holds the Jacobian at y
    rejected = False  # the last trial was rejected
    if path.shape[0] > 0:
        __PATH_FIRST__
        points = 1
    if _speed(y, P) < V_STOP:
        return t, STATUS_OK, steps, points
    _rhs__SUFFIX__(y, P, W, k[0])
    while True:
        if steps >= MAX_STEPS or t >= T_MAX:
            return t, STATUS_RUNOUT_NOT_STOPPED, steps, points
        steps += 1
        if stiff:
            if not fresh:
                _jac__LT__(y, P, W, J)
                fresh = True
            stiff = h*_stiffness(J, P[5]) >= W_LEAVE
            if not (stiff or taken):  # handed straight back: look again W_WAIT steps later
                wait = W_WAIT
        if stiff:
            taken = True
            # one ROS34PW2 step: stages into K (k[1] the right-hand side at
            # each stage's point), the new state into k[2]
            hg = h*W_GAMMA
            Q = _w_inverse(J, hg)
            speed = math.sqrt(y[3]*y[3] + y[4]*y[4])
            ex = y[3]/speed if speed > 0.0 else 0.0
            ey = y[4]/speed if speed > 0.0 else 0.0
            for i in range(4):
                if i == 0:
                    for c in range(n):
                        k[1, c] = k[0, c]
                else:
                    for c in range(n):
                        acc = y[c]
                        for j in range(i):
                            acc += W_ALPHA[i, j]*K[j, c]
                        z[c] = acc
                    _rhs__SUFFIX__(z, P, W, k[1])
                _w_stage(K, i, k[1], h, hg, J, Q, ex, ey, scratch)
            err = 0.0
            for c in range(n):
                k[2, c] = y[c] + W_B[0]*K[0, c] + W_B[1]*K[1, c] + W_B[2]*K[2, c] + W_B[3]*K[3, c]
            for c in range(6):
                err = max(err, abs(W_E[0]*K[0, c] + W_E[1]*K[1, c] + W_E[2]*K[2, c] + W_E[3]*K[3, c]))
            err = err/tol
            if not (err <= 1.0):  # rejected (NaN included)
                h *= 0.1 if not math.isfinite(err) else max(0.2, 0.9*err**(-1.0/3.0))
                rejected = True
                continue
            for i in range(n):
                z[i] = k[2, i]
            grow = 5.0 if err < 1e-10 else min(5.0, 0.9*err**(-1.0/3.0))
        else:
            for s in range(1, 7):
                for i in range(n):
                    acc = 0.0
                    for j in range(s):
                        acc += DP_A[s, j]*k[j, i]
                    z[i] = y[i] + h*acc
                if s == 5:
                    for i in range(6):
                        z6[i] = z[i]
                _rhs__SUFFIX__(z, P, W, k[s])
            err = 0.0
            for i in range(6):
                e = 0.0
                for j in range(7):
                    e += DP_E[j]*k[j, i]
                err = max(err, abs(h*e)/tol)
            for i in range(7, n):  # the sensitivities (none in the forward kernels)
                e = 0.0
                for j in range(7):
                    e += DP_E[j]*k[j, i]
                err = max(err, abs(h*e)/(tol*SENS_SHARE*(1.0 + abs(z[i]))))
            if not (err <= 1.0):  # rejected (NaN included)
                kink = _kink(y, z, P, W)
                if kink < 1.0 and math.isfinite(err):  # across a kink: land just past it
                    h *= min(max(KINK_PAST*kink, KINK_MIN), 0.9)
                else:
                    h *= 0.1 if not math.isfinite(err) else max(0.2, 0.9*err**-0.2)
                rejected = True
                continue
            # Hairer's stiffness estimate (DOPRI5): |lambda| ~ |k7 - k6|/|z7 - z6|
            num = 0.0
            den = 0.0
            for i in range(6):
                num += (k[6, i] - k[5, i])**2
                den += (z[i] - z6[i])**2
            stiff = wait == 0 and h*h*num > W_ENTER*W_ENTER*den
            wait = max(wait - 1, 0)
            taken = False
            grow = 5.0 if err < 1e-10 else min(5.0, 0.9*err**-0.2)
        t += h
        for i in range(n):
            y0[i] = y[i]
            f0[i] = k[0, i]
            y[i] = z[i]
        if taken:
            _rhs__SUFFIX__(y, P, W, k[0])
        else:
            for i in range(n):
                k[0, i] = k[6, i]
        fresh = False
        stopped = _speed(y, P) < V_STOP
        if stopped:
            t = _to_stop(y0, f0, y, k[0], t, h, P)
        if points < path.shape[0]:
            __PATH_NEXT__
            points += 1
        if stopped:
            return t, STATUS_OK, steps, points
        # Hairer's rule (DOPRI5, RODAS): a step after a rejected trial does not
        # grow. Without it a kink (a wheel's force entering or leaving its
        # smoothing band, its lateral force saturating) cost cycles of a step
        # grown fivefold and rejected (docs/runout.md, "Steps").
        h = min(h*(min(grow, 1.0) if rejected else grow), H_MAX)
        rejected = False


'''
W_SOURCE = '''@__JIT__
def _jac(y, P, W, J):
    """J[r, c] = d(ax, ay, alpha)_r/d(psi, vx, vy, w)_c at y: the wheel
    Jacobians summed, over m (rows ax, ay) and I (row alpha)."""
    c = math.cos(y[2])
    s = math.sin(y[2])
    vx, vy, w = y[3], y[4], y[5]
    mu, amax, eps = P[2], P[3], P[4]
    for row in range(3):
        for col in range(4):
            J[row, col] = 0.0
    for k in range(4):
__WHEEL_JAC__
        for row in range(3):
            for col in range(4):
                J[row, col] += r[3 + 5*row + col]
    for col in range(4):
        J[0, col] /= P[0]
        J[1, col] /= P[0]
        J[2, col] /= P[1]


@__JIT__
def _to_stop(y0, f0, y1, f1, t1, h, P):
    """Cut the last step (y0, f0 at t1 - h; y1, f1 at t1) back to where the
    speed |v| + |w| R_max falls through V_STOP (as the reference's stop event
    does): bisection on the cubic Hermite interpolant of the step, accurate to
    O(h^4); writes the state there into y1 and returns its time. Without it
    the run-out would end wherever the step that crossed V_STOP ended, which
    a long L-stable step puts up to V_STOP h further on."""
    lo = 0.0
    hi = 1.0
    for _ in range(40):
        mid = 0.5*(lo + hi)
        a, b, c, d = _hermite(mid)
        vx = a*y0[3] + b*h*f0[3] + c*y1[3] + d*h*f1[3]
        vy = a*y0[4] + b*h*f0[4] + c*y1[4] + d*h*f1[4]
        w = a*y0[5] + b*h*f0[5] + c*y1[5] + d*h*f1[5]
        if math.sqrt(vx*vx + vy*vy) + abs(w)*P[5] < V_STOP:
            hi = mid
        else:
            lo = mid
    a, b, c, d = _hermite(hi)
    for i in range(y1.shape[0]):
        y1[i] = a*y0[i] + b*h*f0[i] + c*y1[i] + d*h*f1[i]
    return t1 - h + hi*h


@__JIT__
def _hermite(s):
    """Weights of y0, h f0, y1, h f1 in the cubic Hermite interpolant at s in [0, 1]."""
    return 2.0*s**3 - 3.0*s*s + 1.0, s**3 - 2.0*s*s + s, 3.0*s*s - 2.0*s**3, s**3 - s*s


@__JIT__
def _stiffness(J, R):
    """|lambda| of the state's Jacobian, estimated: the largest eigenvalue of
    the damping block d(ax, ay, alpha)/d(vx, vy, w) by 12 power iterations (the
    growth of the last 8, geometric mean), the yaw row and column scaled by R
    (R_max: a similarity, so the eigenvalues stay and the start vector weighs
    the entries alike), plus the square root of the largest scaled
    |d(ax, ay, alpha)/d psi| (the heading's stiffness)."""
    turn = max(abs(J[0, 0]), abs(J[1, 0]), R*abs(J[2, 0]))/R
    x0 = 1.0
    x1 = 1.0
    x2 = 1.0
    growth = 0.0
    for k in range(12):
        u0 = J[0, 1]*x0 + J[0, 2]*x1 + J[0, 3]*x2/R
        u1 = J[1, 1]*x0 + J[1, 2]*x1 + J[1, 3]*x2/R
        u2 = R*(J[2, 1]*x0 + J[2, 2]*x1) + J[2, 3]*x2
        norm = max(abs(u0), abs(u1), abs(u2))
        if not norm > 0.0:
            return math.sqrt(turn)
        if k >= 4:
            growth += math.log(norm)
        x0 = u0/norm
        x1 = u1/norm
        x2 = u2/norm
    return math.exp(growth/8.0) + math.sqrt(turn)


@__JIT__
def _w_inverse(J, hg):
    """(I - hg A - hg^2 a_psi e_w')^-1 by its adjugate, with A = J[:, 1:4] and
    a_psi the column J[:, 0]: the velocity block of (I - hg J_state) once the
    positions are eliminated (x, y, psi change by hg times the velocities)."""
    M = np.empty((3, 3))
    for r in range(3):
        for c in range(3):
            M[r, c] = (1.0 if r == c else 0.0) - hg*J[r, 1 + c]
        M[r, 2] -= hg*hg*J[r, 0]
    Q = np.empty((3, 3))
    Q[0, 0] = M[1, 1]*M[2, 2] - M[1, 2]*M[2, 1]
    Q[0, 1] = M[0, 2]*M[2, 1] - M[0, 1]*M[2, 2]
    Q[0, 2] = M[0, 1]*M[1, 2] - M[0, 2]*M[1, 1]
    Q[1, 0] = M[1, 2]*M[2, 0] - M[1, 0]*M[2, 2]
    Q[1, 1] = M[0, 0]*M[2, 2] - M[0, 2]*M[2, 0]
    Q[1, 2] = M[0, 2]*M[1, 0] - M[0, 0]*M[1, 2]
    Q[2, 0] = M[1, 0]*M[2, 1] - M[1, 1]*M[2, 0]
    Q[2, 1] = M[0, 1]*M[2, 0] - M[0, 0]*M[2, 1]
    Q[2, 2] = M[0, 0]*M[1, 1] - M[0, 1]*M[1, 0]
    det = M[0, 0]*Q[0, 0] + M[0, 1]*Q[1, 0] + M[0, 2]*Q[2, 0]
    for r in range(3):
        for c in range(3):
            Q[r, c] /= det
    return Q


@__JIT__
def _w_stage(K, i, fz, h, hg, J, Q, ex, ey, g):
    """k_i of a ROS34PW2 stage, (I - hg J) k_i = h fz + h J sum_{j<i}
    GAMMAS_ij k_j, block by block: the state y[0:6] with the distance (its row
    of J: (ex, ey) = v/|v| on vx, vy), then each sensitivity column
    y[7 + 4 r + j] (r = 0..5). The velocities' part is Q (r_v + hg a_psi r_psi),
    the positions' r_p + hg times it."""
    n = K.shape[1]
    for blk in range(1 + (n - 7)//6):
        off = 0 if blk == 0 else 6 + blk
        st = 1 if blk == 0 else 4
        for c in range(6):
            acc = 0.0
            for j in range(i):
                acc += W_GAMMAS[i, j]*K[j, off + st*c]
            g[c] = acc
        for c in range(3):
            g[6 + c] = h*(fz[off + st*c] + g[3 + c])
            g[9 + c] = h*(fz[off + st*(3 + c)] + J[c, 0]*g[2] + J[c, 1]*g[3] + J[c, 2]*g[4] + J[c, 3]*g[5])
            if blk == 0:
                g[0] = h*(fz[6] + ex*g[3] + ey*g[4])  # the distance's right-hand side (g[0] is free now)
        for c in range(3):
            g[3 + c] = g[9 + c] + hg*J[c, 0]*g[8]
        for c in range(3):
            kv = Q[c, 0]*g[3] + Q[c, 1]*g[4] + Q[c, 2]*g[5]
            K[i, off + st*(3 + c)] = kv
            K[i, off + st*c] = g[6 + c] + hg*kv
        if blk == 0:
            K[i, 6] = g[0] + hg*(ex*K[i, 3] + ey*K[i, 4])


'''
TRANSFER_SOURCE = '''@__JIT__
def _transfer_forces(c, s, vx, vy, w, P, W):
    """Quasi-static load transfer (a row's h > 0, derive/load_transfer.py): each
    wheel at unit load gives H_k; G = sum N0_k H_k and A = sum H_k d_k', d_k =
    R(psi) (c_l, c_s)_k; returns (Fx, Fy, Mz) of (I - A) F = G, Mz = Gz + A_z . F
    (_transfer_solve), then A's six entries."""
    mu, amax, eps = P[2], P[3], P[4]
    gx = 0.0
    gy = 0.0
    gz = 0.0
    a00 = 0.0
    a01 = 0.0
    a10 = 0.0
    a11 = 0.0
    a20 = 0.0
    a21 = 0.0
    for k in range(4):
__WHEEL_UNIT__
        dkx = c*W[k, 10] - s*W[k, 11]
        dky = s*W[k, 10] + c*W[k, 11]
        gx += n*r[0]
        gy += n*r[1]
        gz += n*r[2]
        a00 += r[0]*dkx
        a01 += r[0]*dky
        a10 += r[1]*dkx
        a11 += r[1]*dky
        a20 += r[2]*dkx
        a21 += r[2]*dky
    fx, fy, mz = _transfer_solve(a00, a01, a10, a11, a20, a21, gx, gy, gz)
    return fx, fy, mz, a00, a01, a10, a11, a20, a21


@__JIT__
def _transferred(c, s, q, W):
    """W with each wheel's load moved to N_k = N0_k + d_k . F (q from _transfer_forces)."""
    Wn = W.copy()
    for k in range(4):
        Wn[k, 4] += (c*W[k, 10] - s*W[k, 11])*q[0] + (s*W[k, 10] + c*W[k, 11])*q[1]
    return Wn


__TRANSFER_KERNELS__


@__JIT__
def _rhs_lt(y, P, W, f):
    """_rhs under quasi-static load transfer (_transfer_forces)."""
    c = math.cos(y[2])
    s = math.sin(y[2])
    vx, vy, w = y[3], y[4], y[5]
    q = _transfer_forces(c, s, vx, vy, w, P, W)
    f[0] = vx
    f[1] = vy
    f[2] = w
    f[3] = q[0]/P[0]
    f[4] = q[1]/P[0]
    f[5] = q[2]/P[1]
    f[6] = math.sqrt(vx*vx + vy*vy)


@__JIT__
def _rhs_sens_lt(y, P, W, f):
    """_rhs_lt and its sensitivity equations: _rhs_sens with the wheels at the
    solved loads gives D S (D = sum N_k dH_k, S the sensitivities); the
    transfer's share enters through the solve column by column, dF = M^-1 (D S
    + e dpsi/dp) (_transfer_d with turn = dpsi/dp_j = S[2, j]: the load changes
    turn with the heading). The static model's code, reused: a written-out copy
    of its own made a transferring fit's first use longer (6.7-7.5 s against
    6.4-6.7 s, docs/runout.md)."""
    c = math.cos(y[2])
    s = math.sin(y[2])
    q = _transfer_forces(c, s, y[3], y[4], y[5], P, W)
    _rhs_sens(y, P, _transferred(c, s, q, W), f)
    f[3] = q[0]/P[0]
    f[4] = q[1]/P[0]
    f[5] = q[2]/P[1]
    for j in range(4):
        ax, ay, az = _transfer_d(
            q[3], q[4], q[5], q[6], q[7], q[8], q[0], q[1],
            f[19 + j]*P[0], f[23 + j]*P[0], f[27 + j]*P[1], y[15 + j],
        )
        f[19 + j] = ax/P[0]
        f[23 + j] = ay/P[0]
        f[27 + j] = az/P[1]


@__JIT__
def _jac_lt(y, P, W, J):
    """_jac under load transfer: _jac at the solved loads, each column through
    the solve (_transfer_d; the heading's column also turns the load changes)."""
    c = math.cos(y[2])
    s = math.sin(y[2])
    q = _transfer_forces(c, s, y[3], y[4], y[5], P, W)
    _jac(y, P, _transferred(c, s, q, W), J)
    for col in range(4):
        turn = 1.0 if col == 0 else 0.0
        ax, ay, az = _transfer_d(
            q[3], q[4], q[5], q[6], q[7], q[8], q[0], q[1], J[0, col]*P[0], J[1, col]*P[0], J[2, col]*P[1], turn
        )
        J[0, col] = ax/P[0]
        J[1, col] = ay/P[0]
        J[2, col] = az/P[1]


'''
ROW_TEMPLATE = '''@__ENTRY__
def runout_row__SUFFIX__(v, tol, eps, path):
    """One run-out: v the COLUMNS values (SI, radians). Returns (y, t, status,
    steps, points): y = (x, y, psi, vx, vy, w, distance) at rest__DOC__."""
    n = __N__
    y = np.zeros(n)
    status = _check(v)
    if status != STATUS_OK:
        y[:] = np.nan
        return y, np.nan, status, 0, 0
    P, W = _setup(v, eps)
    for i in range(6):
        y[i] = v[9 + i]
__SINIT__    t, status, steps, points = _integrate__SUFFIX__(y, P, W, tol, path)
    if status != STATUS_OK:
        y[:] = np.nan
    return y, t, status, steps, points


'''
BATCH_TEMPLATE = '''@__DECORATOR__
def runout_batch__SUFFIX__(c, lo, hi, out_x_rest, out_y_rest, out_psi_rest, out_t, out_distance, out_status, out_steps, tol, eps):
    """Rows lo..hi-1 of the (rows, COLUMNS) input table c through runout_row__SUFFIX__.
    One serial loop that releases the GIL: the runtime runs chunks of rows on
    threads (impactsym/runout/batch.py). It replaced a prange driver and its
    serial twin: the same run-outs per second on two threads, one compile (a
    prange loop alone took 5.9 s to compile on an empty cache, this 0.5 s
    after runout_row)."""
    empty = np.empty((0, 4))
    for i in range(lo, hi):
        y, t, status, steps, _ = runout_row__SUFFIX__(c[i], tol, eps, empty)
        out_x_rest[i] = y[0]
        out_y_rest[i] = y[1]
        out_psi_rest[i] = y[2]
        out_t[i] = t
        out_distance[i] = y[6]
        out_status[i] = status
        out_steps[i] = steps
'''


def _path_writes(template: str, suffix: str) -> str:
    """The integrator's path records: (t, x, y, psi) in the forward integrator;
    t and the state's first path.shape[1] - 1 entries in the one with
    sensitivities (the whole state with them for a fit's intermediate poses,
    impactsym/runout/via.py). Two forms, not the loop in both: with the loop
    the forward batch ran 5-9 % fewer run-outs a second (28,000-28,600 against
    29,500-31,000 on the locked Monte Carlo's rows)."""
    if "sens" in suffix:
        first = "path[0, 0] = 0.0\n        for i in range(min(path.shape[1] - 1, n)):\n            path[0, 1 + i] = y[i]"
        nxt = (
            "path[points, 0] = t\n            for i in range(min(path.shape[1] - 1, n)):\n"
            "                path[points, 1 + i] = y[i]"
        )
        doc = "t, then the state's first\n    path.shape[1] - 1 entries"
    else:
        first = "path[0, 0], path[0, 1], path[0, 2], path[0, 3] = 0.0, y[0], y[1], y[2]"
        nxt = "path[points, 0], path[points, 1], path[points, 2], path[points, 3] = t, y[0], y[1], y[2]"
        doc = "(t, x, y, psi)"
    return (
        template.replace("__PATH_FIRST__", first).replace("__PATH_NEXT__", nxt).replace("__PATH_DOC__", doc)
    )


ACC = [f"d{a}{k}" for a in "xyz" for k in range(5)]
# Integrator variants by suffix: forward and with sensitivities, each with static
# loads and with load transfer ("_lt": _rhs_lt, _rhs_sens_lt, _jac_lt of TRANSFER_SOURCE).
VARIANTS = ("", "_sens", "_lt", "_sens_lt")


def _acc_add() -> str:
    """_rhs_sens: the sums of one wheel result r."""
    return "\n".join(
        ["        fx += r[0]", "        fy += r[1]", "        mz += r[2]"]
        + [f"        {name} += r[{3 + i}]" for i, name in enumerate(ACC)]
    )


def switching_source() -> str:
    """`_switching` (a rolling wheel's switching functions, derive's
    `switching_functions`) and `_kink` (where in a step the first changes sign)."""
    temps, reduced = sp.cse(switching_functions(False), symbols=sp.numbered_symbols("_t"))
    lines = [f"    {t} = {PRINTER.doprint(x)}" for t, x in temps]
    lines += emit._wrap("    return (", [PRINTER.doprint(x) for x in reduced], ")", " " * 8)
    return SWITCHING_SOURCE.replace("__ROLLING__", "\n".join(lines)).replace("__JIT__", JIT_INNER)


SWITCHING_SOURCE = '''@__JIT__
def _switching(c, s, vx, vy, w, px, py, cd, sd, eps, tl):
    """A rolling wheel's switching functions (derive/runout.py `switching_functions`)."""
__ROLLING__


@__JIT__
def _kink(y0, y1, P, W):
    """The fraction of a step from y0 to y1 at which the first switching
    function of a rolling wheel changes sign (linear between the ends), 2.0
    where none does."""
    c0, s0 = math.cos(y0[2]), math.sin(y0[2])
    c1, s1 = math.cos(y1[2]), math.sin(y1[2])
    out = 2.0
    for k in range(4):
        if W[k, 8] != 0.0:
            continue
        px, py, cd, sd, tl = W[k, 0], W[k, 1], W[k, 2], W[k, 3], W[k, 9]
        a0, a1, a2 = _switching(c0, s0, y0[3], y0[4], y0[5], px, py, cd, sd, P[4], tl)
        b0, b1, b2 = _switching(c1, s1, y1[3], y1[4], y1[5], px, py, cd, sd, P[4], tl)
        if (a0 > 0.0) != (b0 > 0.0):
            out = min(out, a0/(a0 - b0))
        if (a1 > 0.0) != (b1 > 0.0):
            out = min(out, a1/(a1 - b1))
        if (a2 > 0.0) != (b2 > 0.0):
            out = min(out, a2/(a2 - b2))
    return out


'''


def _rows() -> str:
    """runout_row__SUFFIX__ for every variant: the forward ones with 7 states,
    the ones with sensitivities with 31 and nogil (the fit runs its uniqueness
    starts on threads, impactsym/runout/fit.py)."""
    out = []
    for suffix in VARIANTS:
        text = ROW_TEMPLATE.replace("__SUFFIX__", suffix)
        if "sens" in suffix:
            text = (
                text.replace("@__ENTRY__", "@" + JIT[:-1] + ", nogil=True)")
                .replace("__N__", "31")
                .replace(
                    "__DOC__",
                    ", then the sensitivities S[i, j] = d y_i/d p_j at y[7 + 4 i + j], "
                    "p = (vx, vy, w at separation, mu)",
                )
                .replace(
                    "__SINIT__",
                    "    y[7 + 4*3 + 0] = 1.0\n    y[7 + 4*4 + 1] = 1.0\n    y[7 + 4*5 + 2] = 1.0\n",
                )
            )
        else:
            text = (
                text.replace("@__ENTRY__", "@" + JIT)
                .replace("__N__", "7")
                .replace("__DOC__", "")
                .replace("__SINIT__", "")
            )
        out.append(text)
    return "\n\n".join(out)


INTEGRATOR_SOURCE = (
    INTEGRATOR_SOURCE.replace("__TRANSFER__", TRANSFER_SOURCE)
    .replace("__TRANSFER_KERNELS__", load_transfer.kernel_source(JIT_INNER, PRINTER))
    .replace("__LIFT__", "\n".join(load_transfer.check_lines(PRINTER)))
    .replace("__TRANSFER_SETUP__", "\n".join(load_transfer.setup_lines(PRINTER)))
    .replace("__ACC_INIT__", "\n".join(f"    {name} = 0.0" for name in ACC))
    .replace("__ACC_ADD__", _acc_add())
    .replace("__SENS__", "\n".join(line[4:] for line in _sensitivity_lines().splitlines()))
    .replace(
        "__INTEGRATE__",
        switching_source()
        + W_SOURCE
        + "".join(
            _path_writes(INTEGRATE_TEMPLATE, suffix)
            .replace("__SUFFIX__", suffix)
            .replace("__LT__", "_lt" if "lt" in suffix else "")
            + "\n\n"
            for suffix in VARIANTS
        ),
    )
    .replace("__ROW__", _rows())
    .replace("__WHEEL_JAC__", _wheel_call("n", True))
    .replace("__WHEEL_UNIT__", _wheel_call("1.0", False))
    .replace("__WHEEL__", _wheel_call("n", False))
    .replace(
        "__BATCH__",
        "\n\n".join(
            BATCH_TEMPLATE.replace("__DECORATOR__", JIT[:-1] + ", nogil=True)").replace("__SUFFIX__", suffix)
            for suffix in ("", "_lt")
        ),
    )
    .replace("__JIT__", JIT_INNER)
)
