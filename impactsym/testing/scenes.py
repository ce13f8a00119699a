"""Scene generators for the accuracy tests, the benchmarks and the notebooks.

Test support, not runtime code (``import impactsym`` never imports it); it never
imports ``derive`` or ``generated``.

Every generator returns *columns*: a dict mapping the batch input names of
conventions.md (``m1 m2 I1 I2 v1x v1y w1 v2x v2y w2 r1x r1y r2x r2y gamma e mu e_m``;
particles: ``m1 m2 v1x v1y v2x v2y gamma e mu``) to equal-length float64 NumPy arrays.
Angles are in radians; ``n = (cos gamma, sin gamma)`` points from vehicle 1 to 2.
"""

from __future__ import annotations

import functools

import numpy as np

from . import reference

RIGID = reference.RIGID_INPUTS
PARTICLE = reference.PARTICLE_INPUTS

MIN_APPROACH_FRACTION = 1e-2
"""Smallest closing speed |n.(u2 - u1)| accepted, as a fraction of the largest
contact-point or centre-of-gravity speed. Below it a scene is ill-conditioned
(outputs change by ~eps * speed/|gn| relative for a one-ulp change of an input), so
no float64 algorithm can meet 1e-12 of the natural scale; such grazing scenes
belong in a separate conditioning test, not in the accuracy sample."""


def _unit(angle):
    """Unit vectors (cos a, sin a) as two arrays."""
    return np.cos(angle), np.sin(angle)


def _draw_rigid(rng, n, barrier):
    """Raw passenger-car scenes in SI units (mu still unset).

    Masses 700-3000 kg; yaw inertia m k^2 with radius of gyration k in 1.1-1.5 m;
    speeds 0-35 m/s along each car's heading; yaw rates N(0, 0.2) clipped to +-1 rad/s;
    impact point inside the car outline (|x| <= 2.5 m, |y| <= 1 m in the car frame,
    rotated by the heading); gamma uniform; e in [0, 0.5]; e_m = 1 for half the rows,
    else uniform in [-1, 0]. ``barrier``: vehicle 2 is fixed (m2 = I2 = inf, v2 = w2 = 0).
    """
    c = {}
    for i in (1, 2):
        m = rng.uniform(700.0, 3000.0, n)
        k = rng.uniform(1.1, 1.5, n)
        heading = rng.uniform(-np.pi, np.pi, n)
        hx, hy = _unit(heading)
        speed = rng.uniform(0.0, 35.0, n)
        ax, ay = rng.uniform(-2.5, 2.5, n), rng.uniform(-1.0, 1.0, n)
        c[f"m{i}"], c[f"I{i}"] = m, m * k * k
        c[f"v{i}x"], c[f"v{i}y"] = speed * hx, speed * hy
        c[f"w{i}"] = np.clip(rng.normal(0.0, 0.2, n), -1.0, 1.0)
        c[f"r{i}x"], c[f"r{i}y"] = ax * hx - ay * hy, ax * hy + ay * hx
    if barrier:
        c["m2"], c["I2"] = np.full(n, np.inf), np.full(n, np.inf)
        c["v2x"], c["v2y"], c["w2"] = np.zeros(n), np.zeros(n), np.zeros(n)
    c["gamma"] = rng.uniform(-np.pi, np.pi, n)
    c["e"] = rng.uniform(0.0, 0.5, n)
    c["e_m"] = np.where(rng.random(n) < 0.5, 1.0, rng.uniform(-1.0, 0.0, n))
    return c


def _draw_particle(rng, n):
    """Raw particle scenes: the rigid draw without yaw fields."""
    c = _draw_rigid(rng, n, barrier=False)
    return {key: c[key] for key in PARTICLE if key != "mu"}


def _closing(c, model):
    """Closing speed gn = n.(u2 - u1) and the largest speed, float64 (m/s)."""
    nx, ny = _unit(c["gamma"])
    if model == "particle":
        u1 = (c["v1x"], c["v1y"])
        u2 = (c["v2x"], c["v2y"])
    else:
        u1 = reference_contact(c, 1)
        u2 = reference_contact(c, 2)
    gn = nx * (u2[0] - u1[0]) + ny * (u2[1] - u1[1])
    speed = np.max(
        [np.hypot(*u1), np.hypot(*u2), np.hypot(c["v1x"], c["v1y"]), np.hypot(c["v2x"], c["v2y"])], axis=0
    )
    return gn, speed


def reference_contact(c, i):
    """Contact-point velocity u_i = v_i + w_i (-r_iy, r_ix) of vehicle i, float64 arrays."""
    return (c[f"v{i}x"] - c[f"w{i}"] * c[f"r{i}y"], c[f"v{i}y"] + c[f"w{i}"] * c[f"r{i}x"])


def _approaching(c, model):
    """Flip the normal (gamma += pi) where the scene separates; return rows kept.

    Flipping reverses n and t, so gn changes sign while r vectors stay valid. Rows
    whose closing speed is below MIN_APPROACH_FRACTION of the largest speed are
    dropped (mask returned).
    """
    gn, speed = _closing(c, model)
    flip = gn >= 0
    c["gamma"] = np.where(flip, c["gamma"] + np.pi, c["gamma"])
    gn, speed = _closing(c, model)
    return (gn < 0) & (-gn >= MIN_APPROACH_FRACTION * speed) & (speed > 0)


MAX_VELOCITY_CHANGE = 20.0
"""Largest accepted velocity change (|V_i - v_i| and |W_i - w_i| * |r_i|), as a multiple
of the largest speed, in both the given-mu and the critical reference solutions. With
``e_m < 0`` the (P, M) system can be nearly singular (its effective contact compliance
becomes indefinite); such rows give absurd results (velocity changes of 1e5 times the
speed) whose float64 error is eps times the condition number, so they are dropped."""


def _accept(row, refs, speed):
    """True when no reference solution changes a velocity by more than MAX_VELOCITY_CHANGE."""
    for ref in refs:
        change = 0.0
        for i in (1, 2):
            if not np.isinf(row[f"m{i}"]):
                change = max(
                    change,
                    abs(float(ref[f"V{i}x"]) - row[f"v{i}x"]),
                    abs(float(ref[f"V{i}y"]) - row[f"v{i}y"]),
                )
            lever = np.hypot(row.get(f"r{i}x", 0.0), row.get(f"r{i}y", 0.0))
            change = max(change, abs(float(ref[f"W{i}"]) - row.get(f"w{i}", 0.0)) * lever)
        if not change <= MAX_VELOCITY_CHANGE * speed:
            return False
    return True


def _with_mu(c, rng, model, n):
    """Set mu and keep the first ``n`` well-conditioned rows.

    mu = U(0, 1) * mu_c, mu_c from the reference (so mu has mu_c's sign); about 10 %
    of rows get mu = 0. Rows failing ``_accept`` are dropped.
    """
    m = len(c["gamma"])
    frac = rng.random(m)
    frac[rng.random(m) < 0.1] = 0.0
    _, speed = _closing(c, model)
    mu = np.zeros(m)
    keep = []
    for i in range(m):
        if len(keep) == n:
            break
        row = reference.row_of(dict(c, mu="critical"), i)
        crit = reference.solve_reference(row, model, critical=True)
        row["mu"] = mu[i] = frac[i] * float(crit["mu_c"])
        ref = reference.solve_reference(row, model, critical=False)
        if _accept(row, (crit, ref), speed[i]):
            keep.append(i)
    c["mu"] = mu
    return {key: value[keep] for key, value in c.items()}


def random_realistic(n: int, seed: int, model: str = "rigid", barrier: bool = False) -> dict:
    """``n`` random approaching two-car scenes in SI units (see ``_draw_rigid``).

    ``model="particle"`` returns only the particle columns. ``barrier=True`` (rigid
    only) makes vehicle 2 a fixed barrier (m2 = I2 = inf, at rest). Every row
    approaches at the impact centre (n.(u2 - u1) < 0, by flipping gamma by pi where
    needed) with a closing speed of at least MIN_APPROACH_FRACTION of the largest
    speed. ``mu`` is a random fraction in [0, 1) of the row's critical impulse ratio
    mu_c (so it has mu_c's sign; 10 % of rows have mu = 0). Nearly singular rows are
    dropped (MAX_VELOCITY_CHANGE). Deterministic in ``seed``; costs two 50-digit
    solves per row (~5 s for 400 rows), so each argument set is drawn once per
    process and returned as fresh copies (a caller may change them in place).
    """
    return {key: value.copy() for key, value in _random_realistic(n, seed, model, barrier).items()}


@functools.lru_cache(maxsize=64)
def _random_realistic(n: int, seed: int, model: str, barrier: bool) -> dict:
    """The draw behind ``random_realistic``, memoised."""
    if model not in ("rigid", "particle"):
        raise ValueError(f"unknown model {model!r}")
    rng = np.random.default_rng(seed)
    kept, total = [], 0
    while total < n:
        m = (n - total) + (n - total) // 4 + 8
        c = _draw_particle(rng, m) if model == "particle" else _draw_rigid(rng, m, barrier)
        mask = _approaching(c, model)
        c = _with_mu({key: value[mask] for key, value in c.items()}, rng, model, n - total)
        kept.append(c)
        total += len(c["mu"])
    c = {key: np.concatenate([part[key] for part in kept]) for key in kept[0]}
    names = PARTICLE if model == "particle" else RIGID
    return {key: np.ascontiguousarray(c[key], dtype=np.float64) for key in names}


TABLE2_TL = np.array([96000.0, 192000.0, 96000.0, -192000.0, 0.0, 96000.0, 0.0, -288000.0])
"""Seed Table 2 energy loss T_L (ft lb) for the rows of ``table2_scenes``."""


def table2_scenes():
    """Seed Table 2 particle scenes (US units) and their energy losses.

    m1 = 100, m2 = 150 slug; v1 = 50 ft/s at 45 deg, v2 = 30 ft/s at 225 deg; gamma = 0
    (so r = 1, mean mass 60, mu_max = 1/(1+e)). Rows: e = 0 with mu = 0, 1, 2, 3 and
    e = 1 with mu = 0, 0.5, 1, 1.5. Each velocity's two components are the *same*
    float (50 sqrt(1/2), resp. -30 sqrt(1/2)), so r = 1 and mu_max hold exactly for
    the float64 inputs, not just to rounding.

    Returns ``(columns, expected_TL)``; ``expected_TL`` in ft lb (the seed's
    "2888000" is a misprint for 288000).
    """
    e = np.array([0.0] * 4 + [1.0] * 4)
    mu = np.array([0.0, 1.0, 2.0, 3.0, 0.0, 0.5, 1.0, 1.5])
    a1 = 50.0 * np.sqrt(0.5)
    a2 = -30.0 * np.sqrt(0.5)
    ones = np.ones(8)
    columns = dict(
        m1=100.0 * ones,
        m2=150.0 * ones,
        v1x=a1 * ones,
        v1y=a1 * ones,
        v2x=a2 * ones,
        v2y=a2 * ones,
        gamma=0.0 * ones,
        e=e,
        mu=mu,
    )
    return columns, TABLE2_TL.copy()


TABLE2_MU_MAX = np.array([1.0] * 4 + [0.5] * 4)
"""mu_max = r/(1+e) of the Table 2 rows (seed eq 18)."""
