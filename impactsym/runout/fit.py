"""Fit a vehicle's separation velocity (vx, vy, w) to its measured rest pose.

Newton's method on the three unknowns with the exact sensitivities
d(x, y, psi)_rest/d(vx, vy, w) that the kernel integrates alongside the motion
(generated/runout_jit.py, derive/runout.py), with a backtracking line search on
the residual (heading weighted by the vehicle's wheel radius R_max, so that one
radian counts as R_max metres).

Starting estimate (documented; "straight slide plus spin energy"): the vehicle
travels straight from the separation to the rest position, d = |rest - sep|,
and turns by dpsi = psi_rest - psi_sep. Its kinetic energy goes into friction:
translation ``v0 = sqrt(2 mu_e g d)`` along rest - sep, rotation
``w0 = sgn(dpsi) sqrt(2 mu_e g sum(N_k |r_k|) |dpsi| / (I g))``, with mu_e the
wheels' mean longitudinal coefficient (mu locked, b mu braked, f_r rolling,
weighted by load) blended toward mu as the rotation grows to 90 deg (a
rotating vehicle slides its rolling wheels sideways).

Starts: the estimate is refined by a scan of forward run-outs (speed x 0.7, 1,
1.3; yaw rate x 1, 0.5, 0, -0.5, -1, 1.5, and +-1 rad/s when the estimate is
below 0.5 rad/s); Newton starts from the candidate nearest the rest pose.
Uniqueness: Newton also runs from the next three candidates whose yaw rates
differ by more than 0.3 rad/s from those already taken (the first start that
converges is used if the best does not; if none does, up to four further
scanned starts are tried); converged
states that differ from the reported one by more than 0.05 m/s or 0.02 rad/s
are named in the warnings (the reported one is the converged state nearest the
estimate).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .batch import columns, run_row
from .scene import RunoutVehicle, row_values

MAX_ITERATIONS = 40
POSITION_TOL = 1e-4  # m
HEADING_TOL = 1e-5  # rad
DISTINCT_SPEED = 0.05  # m/s
DISTINCT_YAW = 0.02  # rad/s
SPEED_SCALES = (0.7, 1.0, 1.3)
YAW_SCALES = (1.0, 0.5, 0.0, -0.5, -1.0, 1.5)
UNIQUE_STARTS = 3
DIVERSE_YAW = 0.3  # rad/s: extra starts differ at least this much in yaw rate
RESCUE_STARTS = 4  # further scanned starts tried when no start converged
UNIQUE_BUDGET = 12  # run-outs per extra start
LOOSE_TOL = 1e-5  # integrator tolerance of the scan (forward runs only)
# Newton's first stage and the extra starts: at 1e-5 and 1e-6 the integrated
# sensitivities of a sticking wheel were too poor for a descent (measured on
# examples/runout/sedan.json); 1e-7 converged like the default 1e-8.
NEWTON_TOL = 1e-7
COARSE = 100.0  # Newton's first stage stops at COARSE x (POSITION_TOL, HEADING_TOL)


@dataclass
class Fit:
    """A fitted separation state (SI) and how well it reaches the rest pose."""

    velocity: tuple[float, float]
    yaw_rate: float
    residual_position: float  # m
    residual_heading: float  # rad (absolute)
    iterations: int
    converged: bool
    start: tuple[float, float, float]
    alternatives: list = field(default_factory=list)
    marks: list = field(
        default_factory=list
    )  # residuals of the mark directions [rad], in vehicle.marks order


def _wheel_table(row: dict):
    """(loads N_k, |r_k|, longitudinal coefficients c_k) of the four wheels."""
    wb, a, half, m, g = row["L"], row["a"], row["track"] / 2, row["m"], row["g"]
    b = wb - a
    loads = np.array([m * g * b / (2 * wb)] * 2 + [m * g * a / (2 * wb)] * 2)
    radii = np.array([math.hypot(a, half)] * 2 + [math.hypot(b, half)] * 2)
    coeff = []
    for k in ("fl", "fr", "rl", "rr"):
        if row[f"state_{k}"] == 1.0:
            coeff.append(row["mu"])
        elif row[f"brake_{k}"] > 0:
            coeff.append(row[f"brake_{k}"] * row["mu"])
        else:
            coeff.append(row["f_r"])
    return loads, radii, np.array(coeff)


def starting_estimate(vehicle: RunoutVehicle) -> tuple[float, float, float]:
    """(vx, vy, w) from straight slide plus spin energy (module docstring)."""
    row = vehicle.row
    x_r, y_r, psi_r = vehicle.rest
    dx, dy = x_r - vehicle.position[0], y_r - vehicle.position[1]
    d, dpsi = math.hypot(dx, dy), psi_r - vehicle.heading
    loads, radii, coeff = _wheel_table(row)
    along = float(loads @ coeff / loads.sum())
    mu_e = along + (row["mu"] - along) * min(1.0, abs(dpsi) / (math.pi / 2))
    v0 = math.sqrt(2 * mu_e * row["g"] * d)
    w0 = math.copysign(math.sqrt(2 * mu_e * float(loads @ radii) * abs(dpsi) / row["I"]), dpsi)
    return (v0 * dx / d, v0 * dy / d, w0) if d > 0 else (0.0, 0.0, w0)


def _evaluate(vehicle, cols, p, tol):
    """(residual vector, Jacobian) at p = (vx, vy, w); residual None if the run fails."""
    y, _, status, _, _ = run_row(row_values(vehicle, cols, *p), tol=tol, sens=True)
    if status != 0:
        return None, None
    x_r, y_r, psi_r = vehicle.rest
    scale = _radius(vehicle.row)
    r = np.array([y[0] - x_r, y[1] - y_r, (y[2] - psi_r) * scale])
    S = y[7:].reshape(6, 4)
    J = S[:3, :3].copy()
    J[2] *= scale
    if vehicle.marks:
        rm, Jm = _mark_rows(vehicle, p, scale)
        r, J = np.concatenate([r, rm]), np.vstack([J, Jm])
    return r, J


def _mark_rows(vehicle: RunoutVehicle, p, scale: float):
    """Residuals (wrapped angle differences times `scale`) and Jacobian rows of
    the tyre-mark directions: a mark leaves along the wheel's contact-point
    velocity u = v + w (-r_y, r_x) at separation, r the wheel's position from
    the centre of gravity in the scene frame; d atan2(u_y, u_x) =
    (u_x du_y - u_y du_x)/|u|^2."""
    row, c, s = vehicle.row, math.cos(vehicle.heading), math.sin(vehicle.heading)
    half, b = row["track"] / 2, row["L"] - row["a"]
    spots = {"fl": (row["a"], half), "fr": (row["a"], -half), "rl": (-b, half), "rr": (-b, -half)}
    vx, vy, w = p
    res, rows = [], []
    for key, direction in vehicle.marks.items():
        rx = c * spots[key][0] - s * spots[key][1]
        ry = s * spots[key][0] + c * spots[key][1]
        ux, uy = vx - w * ry, vy + w * rx
        u2 = max(ux * ux + uy * uy, 1e-12)
        res.append(math.remainder(math.atan2(uy, ux) - direction, math.tau) * scale)
        rows.append([-uy / u2 * scale, ux / u2 * scale, (ux * rx + uy * ry) / u2 * scale])
    return np.array(res), np.array(rows)


def _radius(row) -> float:
    return math.hypot(max(row["a"], row["L"] - row["a"]), row["track"] / 2)


def _done(r, scale, coarse: bool = False) -> bool:
    k = COARSE if coarse else 1.0
    return math.hypot(r[0], r[1]) < k * POSITION_TOL and abs(r[2]) / scale < k * HEADING_TOL


def newton(vehicle: RunoutVehicle, start, tol: float | None = None, budget: int = MAX_ITERATIONS) -> Fit:
    """Newton to COARSE times the tolerances with the integrator at NEWTON_TOL
    (the early iterations), then on to the tolerances at `tol`."""
    first = _newton(vehicle, start, NEWTON_TOL, budget, coarse=True)
    if not first.converged:
        return first
    second = _newton(vehicle, (*first.velocity, first.yaw_rate), tol, budget)
    second.iterations += first.iterations
    second.start = tuple(start)
    return second


def _newton(vehicle: RunoutVehicle, start, tol, budget: int, coarse: bool = False) -> Fit:
    """Newton's method damped as Levenberg-Marquardt from `start` = (vx, vy, w):
    the step solves (J'J + lam diag(J'J)) dp = -J'r; lam shrinks tenfold after a
    step that lowers |r| and grows tenfold after one that does not (then the
    step is retried from the same point). `budget` caps the run-outs."""
    cols, scale = columns(), _radius(vehicle.row)
    p = np.array(start, dtype=float)
    r, J = _evaluate(vehicle, cols, p, tol)
    iterations, runs, lam, stalled = 0, 1, 1e-3, False
    while r is not None and not _done(r, scale, coarse) and runs < budget:
        A, g = J.T @ J, J.T @ r
        step = np.linalg.solve(A + lam * np.diag(np.diag(A) + 1e-12), -g)
        trial = p + step
        rt, Jt = _evaluate(vehicle, cols, trial, tol)
        runs += 1
        if rt is not None and float(rt @ rt) < float(r @ r):
            settled = float(r @ r) - float(rt @ rt) < 1e-12 * float(r @ r) + 1e-24
            p, r, J = trial, rt, Jt
            lam = max(lam / 10, 1e-9)
            iterations += 1
            if len(r) > 3 and settled:  # least squares with marks: the residual stops falling
                stalled = True
                break
        else:
            lam *= 10
            if lam > 1e8:
                stalled = len(r) > 3  # no step lowers the least-squares residual: its minimum
                break
    if r is None:
        return Fit((math.nan, math.nan), math.nan, math.inf, math.inf, iterations, False, tuple(start))
    return Fit(
        (float(p[0]), float(p[1])),
        float(p[2]),
        math.hypot(r[0], r[1]),
        abs(r[2]) / scale,
        iterations,
        bool(_done(r, scale, coarse) or stalled),
        tuple(start),
        marks=[float(x) / scale for x in r[3:]],
    )


def _yaw_candidates(w: float) -> list[float]:
    """Yaw rates to scan: the estimate times YAW_SCALES, and +-1 rad/s when the
    estimate is small (a rest pose that barely turned may still come from a spin)."""
    found = [w * s for s in YAW_SCALES]
    if abs(w) < 0.5:
        found += [1.0, -1.0]
    return found


def _scan(vehicle: RunoutVehicle, estimate, tol) -> list:
    """Candidate starts around the estimate, best residual first: speed x
    SPEED_SCALES, each yaw rate of `_yaw_candidates`, each run forward once."""
    cols, scale = columns(), _radius(vehicle.row)
    vx, vy, w = estimate
    x_r, y_r, psi_r = vehicle.rest
    found = []
    for sv in SPEED_SCALES:
        for yaw in _yaw_candidates(w):
            p = (vx * sv, vy * sv, yaw)
            y, _, status, _, _ = run_row(row_values(vehicle, cols, *p), tol=tol)
            if status == 0:
                res = math.hypot(math.hypot(y[0] - x_r, y[1] - y_r), (y[2] - psi_r) * scale)
                found.append((res, p))
    return [p for _, p in sorted(found)]


def _diverse(starts: list, count: int) -> list:
    """The first `count` starts after the first whose yaw rates differ from every
    one taken before (the first included) by more than DIVERSE_YAW."""
    taken = starts[:1]
    for p in starts[1:]:
        if len(taken) > count:
            break
        if all(abs(p[2] - q[2]) > DIVERSE_YAW for q in taken):
            taken.append(p)
    return taken[1:]


def fit_rest(vehicle: RunoutVehicle, tol: float | None = None, check_unique: bool = True) -> Fit:
    """The separation state reaching `vehicle.rest`. Newton starts from the
    best of the scanned candidates around the documented estimate; with
    `check_unique`, it also starts from the next UNIQUE_STARTS candidates and
    their distinct converged solutions are attached as `alternatives`."""
    estimate = starting_estimate(vehicle)
    starts = _scan(vehicle, estimate, LOOSE_TOL) or [estimate]
    fits = [newton(vehicle, starts[0], tol)]
    for start in _diverse(starts, UNIQUE_STARTS) if check_unique else []:
        fits.append(_newton(vehicle, start, NEWTON_TOL, UNIQUE_BUDGET, coarse=True))
    primary, distinct = fits[0], []
    for f in fits[1:]:
        if f.converged and _distinct(f, primary) and all(_distinct(f, g) for g in distinct):
            distinct.append(f)
    if not primary.converged:
        if not distinct:
            tried = [f.start for f in fits]
            for start in [p for p in starts if p not in tried][:RESCUE_STARTS]:
                rescue = newton(vehicle, start, tol)
                if rescue.converged:
                    return rescue
            return primary
        primary, distinct = distinct[0], distinct[1:]
    est = np.array(estimate)
    best = min([primary, *distinct], key=lambda f: _distance(f, est))
    if best is not primary or best.residual_position >= POSITION_TOL:  # polish at full tolerance
        polished = newton(vehicle, (*best.velocity, best.yaw_rate), tol)
        polished.iterations += best.iterations
        best, others = polished, [f for f in (primary, *distinct) if f is not best]
    else:
        others = distinct
    best.alternatives = others
    return best


def _distance(f: Fit, est) -> float:
    return float(np.linalg.norm(np.array([*f.velocity, f.yaw_rate]) - est))


def _distinct(f: Fit, g: Fit) -> bool:
    dv = math.hypot(f.velocity[0] - g.velocity[0], f.velocity[1] - g.velocity[1])
    return dv > DISTINCT_SPEED or abs(f.yaw_rate - g.yaw_rate) > DISTINCT_YAW
