"""Quasi-static load transfer for the run-out (optional: a vehicle's ``cg_height``).

The contract's run-out keeps every wheel at its static load. With the centre of
gravity at height h above the road, the tyre forces act h below it, and a
vehicle that decelerates or slides sideways pitches and rolls its weight onto
the wheels ahead of the acceleration. Quasi-static (no pitch or roll
dynamics, no suspension): the normal loads balance, at every instant, the
moments of the ground forces about the centre of gravity,

    sum dN_k = 0,  sum dN_k x_k = -m h a_l,  sum dN_k y_k = -m h a_s,

with (a_l, a_s) the acceleration in the vehicle frame (x forward, y left) and
(x_k, y_k) the wheels. Four wheels, three equations: the lateral transfer is
split between the axles in proportion to their static loads (front b/L, rear
a/L; the usual assumption when roll stiffnesses are not known). Then

    dN_k = m (c_l,k a_l + c_s,k a_s),  c_l = -+h/(2L) front/rear,
    c_s = -+ (b/L or a/L) h/track left/right   (`transfer_coefficients`).

Every tyre force of the run-out is its load times a function of the motion
(locked mu N, rolling f_r N and mu N clip(...), braked b mu N), so with H_k the
wheel's force at unit load (scene frame) and d_k = R(psi) c_k the total force
solves a 2x2 linear system,

    (I - A) F = G,  A = sum H_k d_k',  G = sum N0_k H_k,  N_k = N0_k + d_k . F,

and the moment is Mz = sum N_k Hz_k = Gz + A_z . F (`solved_forces`). Its
derivatives follow from the same system: with D = sum N_k dH_k (the wheel
Jacobians at the transferred loads) and, for the heading alone, the turn of
d_k (d d_k/dpsi = (-d_ky, d_kx)): (I - A) dF = D + [psi] (A_0 Fy - A_1 Fx),
dMz = Dz + A_z . dF + [psi] (A_z0 Fy - A_z1 Fx) (`force_derivatives`).

No wheel lifts: the row is refused (status RUNOUT_WHEEL_LIFT) unless for every
wheel sqrt(mu^2 + f_r^2) |c_k| < N0_k/(m g) (`lift_margins`; sqrt(mu^2 + f_r^2)
bounds every tyre force per unit load, derive/runout.py). Then sum over k of
sqrt(mu^2 + f_r^2)|c_k| < 1, so |A| < 1: the system has one solution, with
|F| <= sqrt(mu^2 + f_r^2) m g and every N_k > 0 (checked at 50 digits below).
"""

from __future__ import annotations

import random

import mpmath
import sympy as sp

from . import emit

h, wb, a, track, m, g = sp.symbols("h L a track m g", positive=True)
mu, fre = sp.symbols("mu f_r", positive=True)
al, as_ = sp.symbols("a_l a_s", real=True)
WHEEL_SPOTS = (("fl", 1, 1), ("fr", 1, -1), ("rl", -1, 1), ("rr", -1, -1))  # (name, front?, left?)


def _spots():
    """(x_k, y_k) of fl, fr, rl, rr (vehicle frame, centre of gravity at 0)."""
    b = wb - a
    return [(a if front > 0 else -b, left * track / 2) for _, front, left in WHEEL_SPOTS]


def static_loads():
    """N0_k: m g b/(2L) front, m g a/(2L) rear (derive/runout.py's _setup)."""
    b = wb - a
    return [m * g * (b if front > 0 else a) / (2 * wb) for _, front, _ in WHEEL_SPOTS]


def transfer_coefficients():
    """Per wheel (c_l, c_s): dN_k = m (c_l a_l + c_s a_s), solved from the three
    balances and the lateral split by static axle load (module docstring)."""
    b = wb - a
    dn = sp.symbols("dN_fl dN_fr dN_rl dN_rr")
    spots = _spots()
    eqs = [
        sum(dn),
        sum(d * x for d, (x, _) in zip(dn, spots)) + m * h * al,
        sum(d * y for d, (_, y) in zip(dn, spots)) + m * h * as_,
        (dn[0] - dn[1]) * track / 2 + (b / wb) * m * h * as_,  # front axle's share of the roll moment
    ]
    sol = sp.solve(eqs, dn, dict=True)[0]
    return [(sp.simplify(sol[d].diff(al) / m), sp.simplify(sol[d].diff(as_) / m)) for d in dn]


def lift_margins():
    """(front, rear): N0/(m g) - sqrt(mu^2 + f_r^2) |c|, positive when no wheel can lift."""
    grip = sp.sqrt(mu**2 + fre**2)
    coeffs = transfer_coefficients()
    loads = static_loads()
    return tuple(
        sp.simplify(loads[k] / (m * g) - grip * sp.sqrt(coeffs[k][0] ** 2 + coeffs[k][1] ** 2))
        for k in (0, 2)
    )


def height_limits():
    """(front, rear): the cg height at which the lift margin reaches 0 (a wheel could lift above it)."""
    return tuple(sp.simplify(sp.solve(e, h)[0]) for e in lift_margins())


def limit_function() -> str:
    """`cg_height_limit` as plain Python for generated/runout.py (the scene reader's check)."""
    front, rear = height_limits()
    names = ", ".join(str(x) for x in (wb, a, track, mu, fre))
    return (
        f"def cg_height_limit({names}):\n"
        '    """The highest centre of gravity [length] whose quasi-static load transfer cannot lift\n'
        "    a wheel: the smaller of the front and rear limits (derive/load_transfer.py\n"
        '    `height_limits`; a row at or above it gets status RUNOUT_WHEEL_LIFT)."""\n'
        f"    return min({emit.code(front)}, {emit.code(rear)})\n"
    )


# The 2x2 solve: A = sum H_k d_k' (rows x, y, z: force and moment per unit load
# times the load change per newton of force), G = sum N0_k H_k.
A = sp.Matrix(3, 2, sp.symbols("a00 a01 a10 a11 a20 a21", real=True))
G = sp.Matrix(sp.symbols("gx gy gz", real=True))
F = sp.Matrix(sp.symbols("fx fy", real=True))
D = sp.Matrix(sp.symbols("dx dy dz", real=True))
turn = sp.Symbol("turn", real=True)


def _inverse():
    """(adjugate, determinant) of I - A_xy, the determinant left unexpanded:
    (1 - a00)(1 - a11) - a01 a10 is close to 1 here (|A| < 1), so no cancellation."""
    M = sp.eye(2) - A[:2, :]
    return M.adjugate(), (1 - A[0, 0]) * (1 - A[1, 1]) - A[0, 1] * A[1, 0]


def solved_forces():
    """(Fx, Fy, Mz) of (I - A_xy) F = G_xy, Mz = Gz + A_z . F (Cramer's rule)."""
    adj, det = _inverse()
    f = adj * G[:2, :] / det
    return [f[0], f[1], G[2] + A[2, 0] * f[0] + A[2, 1] * f[1]]


def force_derivatives():
    """(dFx, dFy, dMz) with respect to one of (psi, vx, vy, w, mu): D = sum N_k dH_k
    (the wheel Jacobians at the transferred loads), turn = d psi/dz (d_k turns
    with the vehicle: d(d_k)/dpsi = (-d_ky, d_kx); 1 for psi, 0 otherwise, and
    by linearity d psi/dp along a sensitivity column p); F the forces."""
    E = D + turn * sp.Matrix([A[i, 0] * F[1] - A[i, 1] * F[0] for i in range(3)])
    adj, det = _inverse()
    df = adj * E[:2, :] / det
    return [df[0], df[1], E[2] + A[2, 0] * df[0] + A[2, 1] * df[1]]


def _function(name: str, args, outs, doc: str, jit: str, printer) -> str:
    """One njit function returning `outs` of `args`, after common-subexpression elimination."""
    temps, reduced = sp.cse(outs, symbols=sp.numbered_symbols("_t"))
    lines = [f"@{jit}", f"def {name}({', '.join(str(x) for x in args)}):", f'    """{doc}"""']
    lines += [f"    {t} = {printer.doprint(x)}" for t, x in temps]
    lines.append(f"    return {', '.join(printer.doprint(x) for x in reduced)}")
    return "\n".join(lines) + "\n"


# The run-out kernel's names for the symbols (derive/runout.py's _check and _setup read the row v).
ROW_NAMES = {h: "v[27]", wb: "v[2]", a: "v[3]", track: "v[4]", mu: "v[5]", fre: "v[7]"}


def check_lines(printer) -> list[str]:
    """`_check`'s lift test: both margins (front, rear) must be > 0 where cg_height > 0."""
    front, rear = (
        printer.doprint(e.xreplace({k: sp.Symbol(v) for k, v in ROW_NAMES.items()})) for e in lift_margins()
    )
    return [
        "    if v[27] > 0.0 and not (",
        f"        {front} > 0.0",
        f"        and {rear} > 0.0",
        "    ):",
        "        return STATUS_RUNOUT_WHEEL_LIFT",
    ]


def setup_lines(printer) -> list[str]:
    """`_setup`'s transfer coefficients (c_l, c_s) of fl, fr, rl, rr from the row v."""
    rep = {k: sp.Symbol(v) for k, v in ROW_NAMES.items()}
    cl, cs = zip(*transfer_coefficients())
    return [
        f"    cl = ({', '.join(printer.doprint(e.xreplace(rep)) for e in cl)})",
        f"    cs = ({', '.join(printer.doprint(e.xreplace(rep)) for e in cs)})",
    ]


def kernel_source(jit: str, printer) -> str:
    """`_transfer_solve` and `_transfer_d` as numba source (derive/runout.py emits them)."""
    solve = _function(
        "_transfer_solve",
        (*A, *G),
        solved_forces(),
        "(Fx, Fy, Mz) under quasi-static load transfer: (I - A) F = G, Mz = Gz + A_z . F\n"
        "    (derive/load_transfer.py; A = sum H_k d_k', G = sum N0_k H_k, H_k the unit-load wheel force).",
        jit,
        printer,
    )
    deriv = _function(
        "_transfer_d",
        (*A, *F, *D, turn),
        force_derivatives(),
        "d(Fx, Fy, Mz)/dz under load transfer, D = sum N_k dH_k/dz at the transferred loads,\n"
        "    turn = d psi/dz (d_k turns with the vehicle: 1 for z = psi, 0 for vx, vy, w, mu;\n"
        "    the sensitivity equations pass d psi/dp) (derive/load_transfer.py).",
        jit,
        printer,
    )
    return solve + "\n\n" + deriv


# --- proofs --------------------------------------------------------------------


def _balance_claims():
    coeffs = transfer_coefficients()
    spots = _spots()
    dn = [m * (cl * al + cs * as_) for cl, cs in coeffs]
    balanced = (
        sp.simplify(sum(dn)) == 0
        and sp.simplify(sum(d * x for d, (x, _) in zip(dn, spots)) + m * h * al) == 0
        and sp.simplify(sum(d * y for d, (_, y) in zip(dn, spots)) + m * h * as_) == 0
    )
    b = wb - a
    textbook = [
        (-h / (2 * wb), -(b / wb) * h / track),
        (-h / (2 * wb), (b / wb) * h / track),
        (h / (2 * wb), -(a / wb) * h / track),
        (h / (2 * wb), (a / wb) * h / track),
    ]
    same = all(sp.simplify(c - t) == 0 for pair, want in zip(coeffs, textbook) for c, t in zip(pair, want))
    whole = sp.simplify(sum(static_loads()) - m * g) == 0
    limits = all(
        sp.simplify(e.subs(h, lim)) == 0 and sp.simplify(e.diff(h) * wb * track) < 0
        for e, lim in zip(lift_margins(), height_limits())
    )
    return [
        ("load transfer: sum dN = 0 and the pitch and roll moments of the ground forces balance", balanced),
        ("load transfer: axle transfer m h a_l/L, lateral split by static axle load (textbook form)", same),
        ("load transfer: the static loads sum to m g (so the lift margins bound |A| below 1)", whole),
        ("load transfer: each lift margin falls with h and is 0 at cg_height_limit's bound", limits),
    ]


MARGIN_ARGS = (h, wb, a, track, mu, fre)


def _random_vehicle(rng: random.Random, margins):
    """A vehicle that passes the lift check, with random unit-load wheel forces
    inside sqrt(mu^2 + f_r^2) and a random heading."""
    while True:
        vals = {
            wb: mpmath.mpf(rng.uniform(2.2, 3.2)),
            track: mpmath.mpf(rng.uniform(1.3, 1.8)),
            h: mpmath.mpf(rng.uniform(0.2, 1.2)),
            mu: mpmath.mpf(rng.uniform(0.1, 1.2)),
            fre: mpmath.mpf(rng.uniform(0.0, 0.05)),
            m: mpmath.mpf(rng.uniform(800, 3000)),
            g: mpmath.mpf(9.80665),
        }
        vals[a] = vals[wb] * mpmath.mpf(rng.uniform(0.3, 0.7))
        if all(f(*(vals[x] for x in MARGIN_ARGS)) > 0 for f in margins):
            return vals


def _system(case, t, moves_psi: bool, solve):
    """(forces, loads, A, H) of one case (psi0, c, H, dH, N0) with H_k + t dH_k
    and the heading psi0 + t where `moves_psi`."""
    psi0, c, H, dH, n0 = case
    p = psi0 + (t if moves_psi else 0)
    d = [(mpmath.cos(p) * cl - mpmath.sin(p) * cs, mpmath.sin(p) * cl + mpmath.cos(p) * cs) for cl, cs in c]
    hk = [[H[k][i] + t * dH[k][i] for i in range(3)] for k in range(4)]
    aa = [sum(hk[k][i] * d[k][j] for k in range(4)) for i in range(3) for j in range(2)]
    gg = [sum(n0[k] * hk[k][i] for k in range(4)) for i in range(3)]
    f = solve(*aa, *gg)
    loads = [n0[k] + d[k][0] * f[0] + d[k][1] * f[1] for k in range(4)]
    return f, loads, aa, hk


def _numeric_claims(samples: int = 200):
    """At 50 digits, random vehicles that pass the lift check and random
    unit-load wheel forces (every direction, size up to sqrt(mu^2 + f_r^2); the
    wheel moments arbitrary): the solved loads are positive and satisfy
    N_k = N0_k + d_k . F with F = sum N_k H_k; and `force_derivatives` equals
    central differences of the solve with H_k and psi moved along a random line."""
    rng = random.Random(2010)
    margins = [sp.lambdify(MARGIN_ARGS, e, "mpmath") for e in lift_margins()]
    statics = sp.lambdify([m, g, wb, a], static_loads(), "mpmath")
    coeff = sp.lambdify([h, wb, a, track], transfer_coefficients(), "mpmath")
    solve = sp.lambdify([*A, *G], solved_forces(), "mpmath")
    deriv = sp.lambdify([*A, *F, *D, turn], force_derivatives(), "mpmath")
    positive = consistent = derivative = True
    worst = mpmath.mpf(0)
    with mpmath.workdps(50):
        for _ in range(samples):
            v = _random_vehicle(rng, margins)
            grip = mpmath.sqrt(v[mu] ** 2 + v[fre] ** 2)
            n0 = statics(v[m], v[g], v[wb], v[a])
            c = coeff(v[h], v[wb], v[a], v[track])
            H = []
            for _k in range(4):
                ang, size = rng.uniform(-3.2, 3.2), grip * mpmath.mpf(rng.uniform(0, 1))
                H.append([size * mpmath.cos(ang), size * mpmath.sin(ang), mpmath.mpf(rng.uniform(-2, 2))])
            dH = [[mpmath.mpf(rng.uniform(-1, 1)) for _ in range(3)] for _ in range(4)]
            psi0 = mpmath.mpf(rng.uniform(-3.2, 3.2))

            case = (psi0, c, H, dH, n0)
            f, loads, aa, hk = _system(case, 0, False, solve)
            positive &= all(x > 0 for x in loads)
            back = [sum(loads[k] * hk[k][i] for k in range(4)) for i in range(3)]
            consistent &= all(abs(x - y) < mpmath.mpf(10) ** -40 * v[m] * v[g] for x, y in zip(back, f))
            step = mpmath.mpf(10) ** -20
            for moves_psi in (False, True):
                up, dn_ = (_system(case, t, moves_psi, solve)[0] for t in (step, -step))
                dsum = [sum(loads[k] * dH[k][i] for k in range(4)) for i in range(3)]
                got = deriv(*aa, f[0], f[1], *dsum, 1 if moves_psi else 0)
                for x, y_up, y_dn in zip(got, up, dn_):
                    err = abs(x - (y_up - y_dn) / (2 * step)) / (v[m] * v[g])
                    worst = max(worst, err)
                    derivative &= err < mpmath.mpf(10) ** -15
    return [
        (
            f"load transfer: passing the lift check, every solved load is > 0 ({samples} random cases, 50 digits)",
            positive,
        ),
        ("load transfer: the solved forces reproduce F = sum N_k H_k with N_k = N0_k + d_k . F", consistent),
        (
            "load transfer: d(Fx, Fy, Mz) = central differences of the solve, heading included "
            f"(worst relative {mpmath.nstr(worst, 3)})",
            derivative,
        ),
    ]


def proofs():
    """(claim, passed) for the load transfer."""
    return _balance_claims() + _numeric_claims()
