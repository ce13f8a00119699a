"""Independent 50-digit reference for the impact laws (Kudlich–Slibar, the Coulomb process).

Test support, not runtime code: ``import impactsym`` never imports it; it needs
mpmath and never imports ``derive`` or ``generated``.

It shares no algebra with derive/: no compliance formula, no phase closed form.
The state is the six body velocities; an impulse increment Q on vehicle 2 (-Q on
vehicle 1) at the impact centre is applied to them with the impulse-momentum
equations (conventions.md), and the relative velocity g = u2 - u1 at the impact
centre is measured on the state. Within a phase the impulse grows along a fixed
direction (dp normal, dq = beta dp tangential), so g is linear in p: its rate is
measured by applying a unit increment to a copy of the state. The process is
then followed phase by phase (slip, stop, stick or reversal), events (slip
stops, compression ends, restitution ends) found as roots of those linear (or,
for the energetic law, quadratic) functions, and the energy loss taken as the
50-digit kinetic-energy difference; TLn = -∫ gn dp and TLt = -∫ gt dq summed
over the phases.

Kudlich–Slibar: the impulse Pc that zeroes both components of g is solved with
``mpmath.lu_solve`` on the measured rates; the sliding contact follows the
conventions.md rule.

Also: scene draws for the law tests (realistic passenger-car scenes with a
friction coefficient, and a stress set with extreme arms, masses and friction).
"""

from __future__ import annotations

import math

import numpy as np
from mpmath import mp

from . import reference

DPS = 50
INPUTS = reference.RIGID_INPUTS[:-3] + ["e", "mu_f"]
OUTPUTS = ["V1x", "V1y", "W1", "V2x", "V2y", "W2", "Pn", "Pt", "TL", "TLn", "TLt"]
SLIP_CLASSES = {"continues": 0, "stops": 1, "reverses": 2}


class _State:
    """Body velocities at 50 digits and the scene's geometry."""

    def __init__(self, s):
        self.s = s
        self.v = [s["v1x"], s["v1y"], s["w1"], s["v2x"], s["v2y"], s["w2"]]
        g = s["gamma"]
        self.n = (mp.cos(g), mp.sin(g))
        self.t = (-self.n[1], self.n[0])
        self.k = [
            1 / s["m1"] if not mp.isinf(s["m1"]) else mp.zero,
            1 / s["m2"] if not mp.isinf(s["m2"]) else mp.zero,
        ]
        self.j = [
            1 / s["I1"] if not mp.isinf(s["I1"]) else mp.zero,
            1 / s["I2"] if not mp.isinf(s["I2"]) else mp.zero,
        ]

    def copy(self):
        other = _State.__new__(_State)
        other.s, other.v, other.n, other.t, other.k, other.j = (
            self.s,
            list(self.v),
            self.n,
            self.t,
            self.k,
            self.j,
        )
        return other

    def apply(self, qn, qt):
        """Impulse (qn, qt) in the impact frame on vehicle 2, its opposite on vehicle 1."""
        qx = qn * self.n[0] + qt * self.t[0]
        qy = qn * self.n[1] + qt * self.t[1]
        s = self.s
        self.v[0] -= self.k[0] * qx
        self.v[1] -= self.k[0] * qy
        self.v[2] -= self.j[0] * (s["r1x"] * qy - s["r1y"] * qx)
        self.v[3] += self.k[1] * qx
        self.v[4] += self.k[1] * qy
        self.v[5] += self.j[1] * (s["r2x"] * qy - s["r2y"] * qx)

    def g(self):
        """(gn, gt) of u2 - u1 at the impact centre."""
        s, v = self.s, self.v
        u1 = (v[0] - v[2] * s["r1y"], v[1] + v[2] * s["r1x"])
        u2 = (v[3] - v[5] * s["r2y"], v[4] + v[5] * s["r2x"])
        d = (u2[0] - u1[0], u2[1] - u1[1])
        return d[0] * self.n[0] + d[1] * self.n[1], d[0] * self.t[0] + d[1] * self.t[1]

    def rate(self, beta):
        """d(gn, gt)/dp along the direction (1, beta), measured on a copy."""
        probe = self.copy()
        g0 = probe.g()
        probe.apply(mp.one, beta)
        g1 = probe.g()
        return g1[0] - g0[0], g1[1] - g0[1]

    def energy(self):
        s, v = self.s, self.v
        return reference.kinetic_energy(s["m1"], s["I1"], v[0], v[1], v[2]) + reference.kinetic_energy(
            s["m2"], s["I2"], v[3], v[4], v[5]
        )


def _mp_row(row: dict) -> dict:
    return {key: mp.mpf(float(row[key])) if key in row else mp.zero for key in INPUTS}


def _slide_or_stick(state: _State, mu):
    """The phase after the slip stopped (or with no slip): stick when a ratio
    |beta| <= mu keeps gt = 0, else the slip direction whose friction lets it grow."""
    an, at = state.rate(mp.zero)
    bn, bt = state.rate(mp.one)
    dt_dbeta = bt - at  # gt rate per unit tangential ratio
    beta_stick = -at / dt_dbeta
    if abs(beta_stick) <= mu:
        return "stick", beta_stick, 0
    for sign in (1, -1):
        rn, rt = state.rate(-mu * sign)
        if sign * rt > 0:
            return "slip", -mu * sign, sign
    raise ArithmeticError("no consistent phase")


def coulomb_reference(row: dict, law: str) -> dict:
    """The Coulomb process of one scene (``row``: the law's batch columns as
    floats, friction ``mu_f``) ended by ``law`` ("newton", "poisson",
    "energetic"), at 50 digits. Returns mpf outputs plus ``slip_class``."""
    with mp.workdps(DPS):
        s = _mp_row(row)
        e, mu = s["e"], s["mu_f"]
        state = _State(s)
        before = state.energy()
        gn0, gt0 = state.g()
        s0 = (gt0 > 0) - (gt0 < 0)
        p = qsum = mp.zero
        work_n = work_t = mp.zero
        comp_work = None  # work of gn in compression, once known
        p_c = None
        mode, beta, direction = ("slip", -mu * s0, s0) if s0 else _slide_or_stick(state, mu)
        for _ in range(4):  # at most A, stop, B: a bound, not a loop of steps
            rn, rt = state.rate(beta)
            gn, gt = state.g()
            # events along this phase, as increments x of p
            x_stop = -gt / rt if (mode == "slip" and direction * rt < 0 and gt * direction > 0) else mp.inf
            x_end, p_c_here = _end_of_impact(law, e, gn0, gn, rn, p, p_c, comp_work, work_n, x_stop)
            x = min(x_stop, x_end)
            if p_c is None and gn + rn * x >= 0:
                p_c = p_c_here if p_c_here is not None else p + (-gn / rn)
                comp_work = work_n + (gn * (p_c - p)) / 2  # gn from gn to 0 over p_c - p
            work_n += x * (gn + (gn + rn * x)) / 2
            work_t += beta * x * (gt + (gt + rt * x)) / 2
            state.apply(x, beta * x)
            p += x
            qsum += beta * x
            if x == x_end:
                break
            mode, beta, direction = _slide_or_stick(state, mu)
        after = state.energy()
        gtf = state.g()[1]
        if s0 == 0:
            slip = "stops" if mode == "stick" else "continues"
        elif mode == "stick":
            slip = "stops"
        else:
            slip = "continues" if direction == s0 else "reverses"
        return _finish(state, s, p, qsum, before - after, -work_n, -work_t, slip, gtf)


def _end_of_impact(law, e, gn0, gn, rn, p, p_c, comp_work, work_n, x_stop):
    """Increment x at which the impact ends within the current phase (inf if
    beyond it), and the end of compression when it falls in this phase."""
    p_c_here = None
    if p_c is None:
        x_c = -gn / rn if rn > 0 else mp.inf
        if x_c <= x_stop:
            p_c_here = p + x_c
    if law == "newton":
        x = (-e * gn0 - gn) / rn if rn > 0 else mp.inf
        return (x if x <= x_stop else mp.inf), p_c_here
    if law == "poisson":
        pc = p_c if p_c is not None else p_c_here
        if pc is None:
            return mp.inf, None
        x = (1 + e) * pc - p
        return (x if x <= x_stop else mp.inf), p_c_here
    # energetic: restitution work int_{p_c}^{p} gn dp = -e^2 * compression work
    if p_c is None and p_c_here is None:
        return mp.inf, None
    if p_c is None:
        wc = work_n + gn * (p_c_here - p) / 2
        done = mp.zero  # restitution work so far
        start, g_start = p_c_here - p, mp.zero
    else:
        wc = comp_work
        done = work_n - comp_work
        start, g_start = mp.zero, gn
    need = -e * e * wc - done
    # g_start y + rn y^2/2 = need, y >= 0 from `start`
    if need <= 0:
        y = mp.zero
    elif rn == 0:
        y = need / g_start
    else:
        y = (-g_start + mp.sqrt(g_start * g_start + 2 * rn * need)) / rn
    x = start + y
    return (x if x <= x_stop else mp.inf), p_c_here


def _finish(state, s, p, q, tl, tln, tlt, slip, gtf):
    """Outputs in the kernels' names and signs (P on vehicle 1 = -Q)."""
    v = state.v
    out = dict(V1x=v[0], V1y=v[1], W1=v[2], V2x=v[3], V2y=v[4], W2=v[5], Pn=-p, Pt=-q)
    out.update(TL=tl, TLn=tln, TLt=tlt, M=mp.zero, TLm=mp.zero)
    out["mu"] = out["Pt"] / out["Pn"]
    out["slip_class"] = SLIP_CLASSES[slip]
    out["Gt"] = gtf
    return {k: (+v if isinstance(v, mp.mpf) else v) for k, v in out.items()}


def kudlich_slibar_reference(row: dict, contact: str = "full") -> dict:
    """Kudlich–Slibar of one scene at 50 digits (``row``: batch columns, ``e``
    = ε, ``mu_f`` for the sliding contact). Returns mpf outputs plus ``sliding``."""
    with mp.workdps(DPS):
        s = _mp_row(row)
        e = s["e"]
        state = _State(s)
        before = state.energy()
        gn, gt = state.g()
        an, at = state.rate(mp.zero)  # per unit normal increment (beta = 0)
        bn, bt = state.rate(mp.one)
        # W columns: d g / d qn = (an, at), d g / d qt = (bn - an, bt - at)
        W = mp.matrix([[an, bn - an], [at, bt - at]])
        qc = mp.lu_solve(W, mp.matrix([-gn, -gt]))
        qn, qt = (1 + e) * qc[0], (1 + e) * qc[1]
        sliding = 0
        if contact == "sliding" and abs(qt) > s["mu_f"] * qn:
            sliding = 1
            sign = (gt > 0) - (gt < 0) or ((-qt > 0) - (-qt < 0))
            beta = -s["mu_f"] * sign  # Q on vehicle 2 opposes the slip: Pt = -qt has the slip's sign
            rn, _ = state.rate(beta)
            if rn <= 0:
                raise ArithmeticError("compression never ends")
            pc = -gn / rn
            qn, qt = (1 + e) * pc, (1 + e) * pc * beta
        g_path = (gn, gt)
        state.apply(qn, qt)
        Gn, Gt = state.g()
        out = _finish(state, s, qn, qt, before - state.energy(), mp.zero, mp.zero, "continues", Gt)
        # straight impulse path: works of each component on the mean relative velocity
        out["TLn"] = +(out["Pn"] * (g_path[0] + Gn) / 2)
        out["TLt"] = +(out["Pt"] * (g_path[1] + Gt) / 2)
        out.pop("slip_class")
        out["sliding"] = sliding
        return out


def brach_mu_c(row: dict):
    """Brach's critical ratio μ_c at e (point impulse, e_m = 1), from reference.py."""
    full = {key: float(row[key]) for key in reference.RIGID_INPUTS[:-3] + ["e"]}
    return reference.mu_critical(dict(full, mu=0.0, e_m=1.0))


def errors_against(got: dict, ref: dict, row: dict) -> dict:
    """Relative errors of a float64 row `got` against `ref` at reference.py's
    natural scales (velocities: largest speed; yaw: speed/arm; impulses |P|;
    energies: largest part + 1e-14 of the initial kinetic energy)."""
    full = dict({k: float(v) for k, v in row.items()}, mu=0.0, e_m=1.0)
    with mp.workdps(DPS):
        r = dict(ref, M=mp.zero, TLm=mp.zero, mu_c=mp.zero)
        scales = reference.natural_scales(full, r)
    keys = OUTPUTS
    return reference.relative_errors(got, ref, {k: scales[k] for k in keys})


# --------------------------------------------------------------------------- scene draws


def _approaching(c: dict) -> dict:
    """Flip gamma by pi where the row does not approach (n·(u2 - u1) >= 0)."""
    gx = (c["v2x"] - c["w2"] * c["r2y"]) - (c["v1x"] - c["w1"] * c["r1y"])
    gy = (c["v2y"] + c["w2"] * c["r2x"]) - (c["v1y"] + c["w1"] * c["r1x"])
    gn = gx * np.cos(c["gamma"]) + gy * np.sin(c["gamma"])
    c["gamma"] = np.where(gn < 0, c["gamma"], c["gamma"] + np.pi)
    speed = np.maximum(np.hypot(c["v1x"], c["v1y"]), np.hypot(c["v2x"], c["v2y"]))
    keep = np.abs(gn) > 1e-2 * np.maximum(speed, 1.0)
    return {k: v[keep] for k, v in c.items()}


def realistic(n: int, seed: int) -> dict:
    """Passenger-car scenes (SI) with friction: masses 700–3000 kg, k 1.1–1.5 m,
    speeds 0–35 m/s, yaw rates N(0, 0.2), impact points inside the outline,
    e in [0, 0.6], mu_f in [0, 1.2]. Approaching rows only (fewer than n kept)."""
    rng = np.random.default_rng(seed)
    c = {}
    for i in (1, 2):
        m = rng.uniform(700.0, 3000.0, n)
        k = rng.uniform(1.1, 1.5, n)
        heading = rng.uniform(-math.pi, math.pi, n)
        speed = rng.uniform(0.0, 35.0, n)
        ax, ay = rng.uniform(-2.5, 2.5, n), rng.uniform(-1.0, 1.0, n)
        hx, hy = np.cos(heading), np.sin(heading)
        c[f"m{i}"], c[f"I{i}"] = m, m * k * k
        c[f"v{i}x"], c[f"v{i}y"] = speed * hx, speed * hy
        c[f"w{i}"] = np.clip(rng.normal(0.0, 0.2, n), -1.0, 1.0)
        c[f"r{i}x"], c[f"r{i}y"] = ax * hx - ay * hy, ax * hy + ay * hx
    c["gamma"] = rng.uniform(-math.pi, math.pi, n)
    c["e"] = rng.uniform(0.0, 0.6, n)
    c["mu_f"] = rng.uniform(0.0, 1.2, n)
    return _approaching(c)


def stress(n: int, seed: int) -> dict:
    """Hard scenes: radii of gyration down to 0.05 m (large W_tn coupling and
    slip reversal), arms up to 6 m, mass ratios up to 1e4, friction 0–5, e in
    [0, 1], a fixed vehicle 2 on a tenth of the rows."""
    rng = np.random.default_rng(seed)
    c = {}
    for i in (1, 2):
        m = 10.0 ** rng.uniform(2.0, 4.0 + 2.0 * (i - 1), n)
        k = 10.0 ** rng.uniform(-1.3, 0.3, n)
        heading = rng.uniform(-math.pi, math.pi, n)
        speed = rng.uniform(0.0, 40.0, n)
        hx, hy = np.cos(heading), np.sin(heading)
        arm = rng.uniform(0.0, 6.0, n)
        at = rng.uniform(-math.pi, math.pi, n)
        c[f"m{i}"], c[f"I{i}"] = m, m * k * k
        c[f"v{i}x"], c[f"v{i}y"] = speed * hx, speed * hy
        c[f"w{i}"] = rng.normal(0.0, 0.5, n)
        c[f"r{i}x"], c[f"r{i}y"] = arm * np.cos(at), arm * np.sin(at)
    fixed = rng.random(n) < 0.1
    c["m2"] = np.where(fixed, np.inf, c["m2"])
    c["I2"] = np.where(fixed, np.inf, c["I2"])
    for key in ("v2x", "v2y", "w2"):
        c[key] = np.where(fixed, 0.0, c[key])
    c["gamma"] = rng.uniform(-math.pi, math.pi, n)
    c["e"] = rng.uniform(0.0, 1.0, n)
    c["mu_f"] = rng.uniform(0.0, 5.0, n)
    return _approaching(c)


def row_of(columns: dict, i: int) -> dict:
    """Row i of columns as floats."""
    return {k: float(v[i]) for k, v in columns.items()}
