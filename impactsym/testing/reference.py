"""Independent 50-digit reference solver for the planar impact equations.

Test support, not runtime code: ``import impactsym`` never imports it, it needs
mpmath (the ``test`` extra), and it never imports ``derive`` or ``generated``.
It shares no algebra with the package's closed forms: it writes the six
impact equations (the frame and signs below) as one linear system in the unknowns
``(V1x, V1y, W1, V2x, V2y, W2, Px, Py, M)`` and solves it numerically with
``mpmath.lu_solve`` at 50 significant digits.

Conventions:

* scene frame (x, y); ``n = (cos gamma, sin gamma)`` points from vehicle 1 toward
  vehicle 2, ``t = (-sin gamma, cos gamma)``; the vehicles approach when
  ``n . (u2 - u1) < 0``;
* ``P`` is the impulse on vehicle 1 (vehicle 2 receives ``-P``), ``M`` the moment
  impulse on vehicle 1; ``Pn = P . n`` (negative, i.e. compressive, in a real
  collision), ``Pt = P . t``;
* ``u_i = v_i + w_i * (-r_iy, r_ix)`` is the contact-point velocity;
* units are whatever consistent set the scene uses (SI: kg, m, kg m^2, m/s, rad/s,
  J; US: slug, ft, slug ft^2, ft/s, rad/s, ft lb).

Every float64 input is converted *exactly* to an ``mpf`` (``mp.mpf(float)`` is
exact), so the error of a float64 kernel measured against these values is the
kernel's alone. A fixed body (``m = inf`` and ``I = inf``) is exact: the equations
are written with inverse masses ``k = 1/m`` and ``j = 1/I``, which are then 0.

All arithmetic runs inside a local ``mp.workdps(DPS)`` context; the global mpmath
precision is never changed.
"""

from __future__ import annotations

import math

from mpmath import mp

DPS = 50
"""Working precision of the reference, in decimal digits."""

RIGID_INPUTS = [
    "m1",
    "m2",
    "I1",
    "I2",
    "v1x",
    "v1y",
    "w1",
    "v2x",
    "v2y",
    "w2",
    "r1x",
    "r1y",
    "r2x",
    "r2y",
    "gamma",
    "e",
    "mu",
    "e_m",
]
PARTICLE_INPUTS = ["m1", "m2", "v1x", "v1y", "v2x", "v2y", "gamma", "e", "mu"]
OUTPUTS = ["V1x", "V1y", "W1", "V2x", "V2y", "W2", "Pn", "Pt", "M", "mu", "mu_c", "TL", "TLn", "TLt", "TLm"]
VELOCITY_KEYS = ("V1x", "V1y", "V2x", "V2y")
YAW_KEYS = ("W1", "W2")
ENERGY_KEYS = ("TL", "TLn", "TLt", "TLm")

_TINY = "1e-300"  # floor of every natural scale, so a scale is never 0


# --------------------------------------------------------------------------- inputs


def _mp_scene(row: dict, model: str) -> dict:
    """Convert a scene row to exact ``mpf`` values (rigid fields filled in for particles).

    For ``model="particle"`` the yaw fields are set so that the rigid equations reduce
    to the particle ones: ``r = 0``, ``w = 0``, ``e_m = 1`` (no moment).
    Must be called inside a ``workdps`` context.
    """
    names = PARTICLE_INPUTS if model == "particle" else RIGID_INPUTS
    s = {}
    for name in names:
        if name == "mu" and isinstance(row[name], str):
            s[name] = None  # "critical": no numeric mu
            continue
        value = row[name]
        if isinstance(value, float) and math.isnan(value):
            raise ValueError(f"NaN input {name!r}")
        s[name] = mp.mpf(value)
    if model == "particle":
        for name in ("r1x", "r1y", "r2x", "r2y", "w1", "w2"):
            s[name] = mp.zero
        s["e_m"] = mp.one
    return s


def _inverse(x):
    """1/x with 1/inf = 0 exactly (a fixed body)."""
    return mp.zero if mp.isinf(x) else 1 / x


def _cross(ax, ay, bx, by):
    """z-component of the planar cross product a x b."""
    return ax * by - ay * bx


def _frame(gamma):
    """Unit normal n and tangent t of the impact frame, computed in mpmath."""
    c, s = mp.cos(gamma), mp.sin(gamma)
    return (c, s), (-s, c)


def contact_velocity(vx, vy, w, rx, ry):
    """Contact-point velocity ``v + w * (-ry, rx)`` (m/s or ft/s)."""
    return vx - w * ry, vy + w * rx


# --------------------------------------------------------------------------- system


def _rigid_system(s: dict, critical: bool):
    """Matrix A and right-hand side b of the 9x9 system in (V1x V1y W1 V2x V2y W2 Px Py M).

    Rows: 4 linear-momentum equations (inverse-mass form), 2 angular-impulse
    equations, restitution, impulse ratio (or the sticking condition when
    ``critical``), moment restitution.
    """
    k1, k2 = _inverse(s["m1"]), _inverse(s["m2"])
    j1, j2 = _inverse(s["I1"]), _inverse(s["I2"])
    r1x, r1y, r2x, r2y = s["r1x"], s["r1y"], s["r2x"], s["r2y"]
    (nx, ny), (tx, ty) = _frame(s["gamma"])
    e, em = s["e"], s["e_m"]
    u1 = contact_velocity(s["v1x"], s["v1y"], s["w1"], r1x, r1y)
    u2 = contact_velocity(s["v2x"], s["v2y"], s["w2"], r2x, r2y)
    gn = nx * (u2[0] - u1[0]) + ny * (u2[1] - u1[1])
    z = mp.zero
    # columns:  V1x V1y W1  V2x V2y W2  Px       Py        M
    A = [
        [1, 0, 0, 0, 0, 0, -k1, 0, 0],  # V1x - k1 Px = v1x
        [0, 1, 0, 0, 0, 0, 0, -k1, 0],  # V1y - k1 Py = v1y
        [0, 0, 1, 0, 0, 0, j1 * r1y, -j1 * r1x, -j1],  # W1 - j1 (r1xP + M) = w1
        [0, 0, 0, 1, 0, 0, k2, 0, 0],  # V2x + k2 Px = v2x
        [0, 0, 0, 0, 1, 0, 0, k2, 0],  # V2y + k2 Py = v2y
        [0, 0, 0, 0, 0, 1, -j2 * r2y, j2 * r2x, j2],  # W2 + j2 (r2xP + M) = w2
        [
            -nx,
            -ny,
            -_cross(r1x, r1y, nx, ny),  # n.(U2 - U1) = -e gn
            nx,
            ny,
            _cross(r2x, r2y, nx, ny),
            0,
            0,
            0,
        ],
        None,  # ratio / sticking
        [0, 0, -(1 - em), 0, 0, (1 - em), 0, 0, -em * (j1 + j2)],  # moment restitution
    ]
    b = [s["v1x"], s["v1y"], s["w1"], s["v2x"], s["v2y"], s["w2"], -e * gn, z, z]
    if critical:  # t.(U2 - U1) = 0
        A[7] = [-tx, -ty, -_cross(r1x, r1y, tx, ty), tx, ty, _cross(r2x, r2y, tx, ty), 0, 0, 0]
    else:  # P.t - mu P.n = 0
        mu = s["mu"]
        A[7] = [0, 0, 0, 0, 0, 0, tx - mu * nx, ty - mu * ny, 0]
    return A, b


def _particle_system(s: dict, critical: bool):
    """Matrix A and right-hand side b of the 6x6 particle system in (V1x V1y V2x V2y Px Py)."""
    k1, k2 = _inverse(s["m1"]), _inverse(s["m2"])
    (nx, ny), (tx, ty) = _frame(s["gamma"])
    gn = nx * (s["v2x"] - s["v1x"]) + ny * (s["v2y"] - s["v1y"])
    A = [
        [1, 0, 0, 0, -k1, 0],
        [0, 1, 0, 0, 0, -k1],
        [0, 0, 1, 0, k2, 0],
        [0, 0, 0, 1, 0, k2],
        [-nx, -ny, nx, ny, 0, 0],
        None,
    ]
    b = [s["v1x"], s["v1y"], s["v2x"], s["v2y"], -s["e"] * gn, mp.zero]
    if critical:
        A[5] = [-tx, -ty, tx, ty, 0, 0]
    else:
        mu = s["mu"]
        A[5] = [0, 0, 0, 0, tx - mu * nx, ty - mu * ny]
    return A, b


def _solve_raw(s: dict, model: str, critical: bool) -> dict:
    """Solve the linear system; return V1x V1y W1 V2x V2y W2 Px Py M as mpf."""
    if model == "particle":
        A, b = _particle_system(s, critical)
        V1x, V1y, V2x, V2y, Px, Py = mp.lu_solve(mp.matrix(A), mp.matrix(b))
        W1, W2, M = s["w1"], s["w2"], mp.zero
    else:
        A, b = _rigid_system(s, critical)
        V1x, V1y, W1, V2x, V2y, W2, Px, Py, M = mp.lu_solve(mp.matrix(A), mp.matrix(b))
    return dict(V1x=V1x, V1y=V1y, W1=W1, V2x=V2x, V2y=V2y, W2=W2, Px=Px, Py=Py, M=M)


# --------------------------------------------------------------------------- energy


def kinetic_energy(m, I, vx, vy, w):
    """Kinetic energy 0.5 m |v|^2 + 0.5 I w^2 of one body (J or ft lb); a fixed body gives 0.

    An infinite mass (or inertia) contributes nothing: a fixed body does not move.
    """
    T = mp.zero
    if not mp.isinf(m):
        T += m * (vx * vx + vy * vy) / 2
    if not mp.isinf(I):
        T += I * w * w / 2
    return T


def initial_kinetic_energy(row: dict, model: str = "rigid"):
    """Initial kinetic energy of the non-fixed bodies, as mpf at DPS digits."""
    with mp.workdps(DPS):
        s = _mp_scene(row, model)
        I1 = s.get("I1", mp.inf)
        I2 = s.get("I2", mp.inf)
        return kinetic_energy(s["m1"], I1, s["v1x"], s["v1y"], s["w1"]) + kinetic_energy(
            s["m2"], I2, s["v2x"], s["v2y"], s["w2"]
        )


def _energies(s: dict, x: dict, model: str) -> dict:
    """TL as a kinetic-energy difference, and the partition TLn, TLt, TLm (work of P and M)."""
    I1 = s["I1"] if model == "rigid" else mp.inf  # particles: no yaw energy
    I2 = s["I2"] if model == "rigid" else mp.inf
    before = kinetic_energy(s["m1"], I1, s["v1x"], s["v1y"], s["w1"]) + kinetic_energy(
        s["m2"], I2, s["v2x"], s["v2y"], s["w2"]
    )
    after = kinetic_energy(s["m1"], I1, x["V1x"], x["V1y"], x["W1"]) + kinetic_energy(
        s["m2"], I2, x["V2x"], x["V2y"], x["W2"]
    )
    (nx, ny), (tx, ty) = _frame(s["gamma"])
    u1 = contact_velocity(s["v1x"], s["v1y"], s["w1"], s["r1x"], s["r1y"])
    u2 = contact_velocity(s["v2x"], s["v2y"], s["w2"], s["r2x"], s["r2y"])
    U1 = contact_velocity(x["V1x"], x["V1y"], x["W1"], s["r1x"], s["r1y"])
    U2 = contact_velocity(x["V2x"], x["V2y"], x["W2"], s["r2x"], s["r2y"])
    g = (u2[0] - u1[0], u2[1] - u1[1])
    G = (U2[0] - U1[0], U2[1] - U1[1])
    gn, gt = nx * g[0] + ny * g[1], tx * g[0] + ty * g[1]
    Gn, Gt = nx * G[0] + ny * G[1], tx * G[0] + ty * G[1]
    Pn = nx * x["Px"] + ny * x["Py"]
    Pt = tx * x["Px"] + ty * x["Py"]
    TLm = x["M"] * ((s["w2"] - s["w1"]) + (x["W2"] - x["W1"])) / 2
    return dict(
        Pn=Pn,
        Pt=Pt,
        TL=before - after,
        TLn=Pn * (gn + Gn) / 2,
        TLt=Pt * (gt + Gt) / 2,
        TLm=TLm,
        gn=gn,
        gt=gt,
        Gn=Gn,
        Gt=Gt,
    )


# --------------------------------------------------------------------------- public


def _ratio(Pt, Pn):
    """Pt/Pn, NaN when Pn = 0 (no normal impulse: not an approaching scene)."""
    return mp.nan if Pn == 0 else Pt / Pn


def _solve_one(s: dict, model: str, critical: bool) -> dict:
    """One solve plus its impulses and energies (inside a workdps context)."""
    x = _solve_raw(s, model, critical)
    x.update(_energies(s, x, model))
    return x


def solve_reference(row: dict, model: str = "rigid", critical: bool | None = None) -> dict:
    """Solve one scene at 50 digits.

    ``row`` maps the batch input names to Python floats (SI or US units, angles in
    radians). ``row["mu"]`` may be the string ``"critical"``; ``critical=True`` forces
    the sticking solution (tangential relative velocity zero at separation) whatever
    ``mu`` holds. ``model`` is ``"rigid"`` or ``"particle"``.

    Returns a dict of mpf: ``V1x V1y W1 V2x V2y W2 Pn Pt M mu mu_c TL TLn TLt TLm``
    (plus the diagnostics ``Px Py gn gt Gn Gt``). ``mu`` is the impulse ratio used
    (``mu_c`` in critical mode); ``mu_c = Pt/Pn`` of the critical solve; ``TL`` is
    the kinetic energy before minus after (a 50-digit difference); ``TLn, TLt, TLm``
    the work partition of conventions.md. Particles have ``W1 = W2 = M = TLm = 0``.
    """
    if model not in ("rigid", "particle"):
        raise ValueError(f"unknown model {model!r}")
    if critical is None:
        critical = isinstance(row["mu"], str)
    if isinstance(row["mu"], str) and row["mu"] != "critical":
        raise ValueError(f"mu must be a number or 'critical', got {row['mu']!r}")
    with mp.workdps(DPS):
        s = _mp_scene(row, model)
        crit = _solve_one(s, model, critical=True)
        mu_c = _ratio(crit["Pt"], crit["Pn"])
        if critical:
            out = crit
            out["mu"] = mu_c
        else:
            if s["mu"] is None:
                raise ValueError("critical=False needs a numeric mu")
            out = _solve_one(s, model, critical=False)
            out["mu"] = s["mu"]
        out["mu_c"] = mu_c
        # unary plus rounds every value to the working precision once, here
        return {key: +value for key, value in out.items()}


def mu_critical(row: dict, model: str = "rigid"):
    """The critical impulse ratio mu_c of a scene (one critical solve; ``mu`` ignored)."""
    with mp.workdps(DPS):
        s = _mp_scene(dict(row, mu="critical"), model)
        crit = _solve_one(s, model, critical=True)
        return +_ratio(crit["Pt"], crit["Pn"])


def natural_scales(row: dict, ref: dict, model: str = "rigid") -> dict:
    """Natural scale of the error of each output (mpf, never below 1e-300).

    * velocities ``V1x..V2y``: the largest speed in the scene, max |v_i|, |V_i|;
    * yaw rates ``W1 W2``: max of the largest |w_i|, |W_i| and (when a lever arm is
      nonzero) the largest speed divided by the largest lever arm |r_i|;
    * impulses ``Pn Pt``: |P|;
    * moment impulse ``M``: max(|P| * largest lever arm, |M|) -- the moment that the
      impulse itself exerts about a centre of gravity sets the scale of M;
    * ``mu mu_c``: max(|mu_c|, |mu|, 1e-300);
    * energies ``TL TLn TLt TLm``: max(|TL|, |TLn|, |TLt|, |TLm|) + 1e-14 * the
      initial kinetic energy of the non-fixed bodies.

    For particles (no lever arm, no yaw) the yaw, M and TLm scales collapse to the
    floor, so their outputs must be exactly 0.
    """
    with mp.workdps(DPS):
        tiny = mp.mpf(_TINY)
        s = _mp_scene(row, model)
        finite = [mp.hypot(s[f"v{i}x"], s[f"v{i}y"]) for i in (1, 2)]
        finite += [mp.hypot(ref[f"V{i}x"], ref[f"V{i}y"]) for i in (1, 2)]
        speed = max(finite)
        lever = max(mp.hypot(s["r1x"], s["r1y"]), mp.hypot(s["r2x"], s["r2y"]))
        yaw = max(abs(s["w1"]), abs(s["w2"]), abs(ref["W1"]), abs(ref["W2"]))
        if lever > 0:
            yaw = max(yaw, speed / lever)
        P = mp.hypot(ref["Pn"], ref["Pt"])
        mu = max(abs(ref["mu_c"]) if mp.isfinite(ref["mu_c"]) else 0, abs(ref["mu"]))
        energy = max(abs(ref[key]) for key in ENERGY_KEYS)
        energy += mp.mpf("1e-14") * initial_kinetic_energy(row, model)
        scales = {key: speed for key in VELOCITY_KEYS}
        scales.update({key: yaw for key in YAW_KEYS})
        scales.update(Pn=P, Pt=P, M=max(P * lever, abs(ref["M"])), mu=mu, mu_c=mu)
        scales.update({key: energy for key in ENERGY_KEYS})
        return {key: max(value, tiny) for key, value in scales.items()}


def relative_errors(got: dict, ref: dict, scales: dict) -> dict:
    """|got - ref| / scale for every key of ``scales`` (floats; NaN/inf in ``got`` -> inf).

    ``got`` maps output names to Python floats (one row of a float64 result).
    A reference that is itself NaN (``mu_c`` of a scene without normal impulse) is
    matched only by a NaN.
    """
    errors = {}
    with mp.workdps(DPS):
        for key, scale in scales.items():
            value = float(got[key])
            if mp.isnan(ref[key]):
                errors[key] = 0.0 if math.isnan(value) else math.inf
            elif not math.isfinite(value):
                errors[key] = math.inf
            else:
                errors[key] = float(abs(mp.mpf(value) - ref[key]) / scale)
    return errors


def row_of(columns: dict, i: int) -> dict:
    """Row ``i`` of a columns dict as Python floats (a string column, e.g. "critical", is kept)."""
    return {key: (col if isinstance(col, str) else float(col[i])) for key, col in columns.items()}


def n_rows(columns: dict) -> int:
    """Number of rows of a columns dict (string columns broadcast)."""
    return next(len(col) for col in columns.values() if not isinstance(col, str))


def solve_columns(columns: dict, model: str = "rigid") -> list:
    """``solve_reference`` for every row of a columns dict; a list of result dicts."""
    return [solve_reference(row_of(columns, i), model) for i in range(n_rows(columns))]
