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

Starts: the estimate is refined by a scan of forward run-outs (speed x 0.7,
1, 1.3; yaw rate x 1, 0.5, 0, -0.5, -1, 1.5, and +-1 rad/s when the estimate
is below 0.5 rad/s); Newton starts from the candidate nearest the rest pose;
if it does not converge, from the next three candidates whose yaw rates
differ by more than 0.3 rad/s from those already taken, then from up to four
further candidates, in turn. Uniqueness: Newton also runs, to COARSE x the
tolerances, from those three diverse candidates left after the first start
that converged, deflated away from the state found; a run is abandoned as
soon as an iterate comes within the distinctness thresholds (0.05 m/s, 0.02
rad/s) of it (it is heading for that one). The scan's run-outs and the
uniqueness starts run on threads (threads.py; the row function releases the
GIL), so the starts do not deflate each other's states: two that find the
same new state name it once. A run that converges to a state not yet found is
polished by Newton to the full tolerances and named only if the polished state
still reaches the rest pose and is still distinct from every state found:
every alternative in the warnings is a separation state that reaches the rest
pose within the tolerances, and no two are the same state. The reported state
is the one nearest the estimate; the others are its `alternatives`. The search
is not exhaustive: a state no start leads to is not named. With `exhaustive`,
the fit also starts Newton from the local minima of a grid over the plausible
range (grid.py, `plausible_range`), and names what they reach the same way;
a fit none of whose starts converged runs that search as its last rescue.

Further evidence (least squares over all rows, Levenberg-Marquardt as above):
the direction of a wheel's tyre mark at separation (`mark_rows`) and poses the
vehicle passed through between separation and rest (via.py: the path's point
nearest a given position, and its heading). With such evidence the fit starts
from every state found that reaches the rest pose alone (`_fit_evidence`); the
reported state is the one with the least squared residual, and another is named
only if its squared residual is within EVIDENCE_COST_SHARE of that.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace

import numpy as np

from . import grid as grids
from . import threads, via
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
# Newton's first stage: with the Dormand-Prince-only integrator, 1e-5 and 1e-6
# gave sensitivities of a sticking wheel too poor for a descent (measured on
# examples/runout/sedan.json); 1e-7 converged like the default 1e-8.
NEWTON_TOL = 1e-7
# The uniqueness starts only have to come near a state (UNIQUE_COARSE x the
# tolerances, 10 cm); what they find is then polished by Newton (NEWTON_TOL,
# then the default, POLISH_BUDGET run-outs each) and named only if it
# converges. At 1e-6 and this budget the seed-5 round trips of the benchmark
# name the second state of row 1 (tests/test_runout_unique.py).
UNIQUE_TOL = 1e-6
UNIQUE_COARSE = 1000.0
POLISH_BUDGET = 12
DEFLATION_SCALE = np.array([0.5, 0.5, 0.2])  # m/s, m/s, rad/s: the reach of the deflation
COARSE = 100.0  # Newton's first stage stops at COARSE x (POSITION_TOL, HEADING_TOL)
# With marks or intermediate poses the fit is least squares: the state with the
# least squared residual is reported, and another state found is named only if
# its squared residual is within EVIDENCE_COST_SHARE times that (its misses at
# most twice as large) or within the tolerance per row: a state that reaches
# the rest pose but misses the other evidence is no alternative.
EVIDENCE_COST_SHARE = 4.0
# A least-squares fit (marks, intermediate poses) has settled when a step lowers
# its squared residual C by less than SETTLE of it (a state within about
# sqrt(SETTLE C / |J'J|) of the minimum: 3e-6 m/s at C = 1e-3 m^2), a coarse
# stage (Newton's first at NEWTON_TOL, the uniqueness starts) by less than
# SETTLE_COARSE. The integrator's error makes C noisy by about 5e-6 of itself
# at C = 1e-3 m^2: with 1e-12 for both, 2 of 1000 draws with an intermediate
# pose crept through all 40 run-outs of their budget at the same cost
# (docs/runout.md, "Uncertainty"), and so did `fit_rest` on them.
SETTLE = 1e-8
SETTLE_COARSE = 1e-6
# The grid search's default range (`plausible_range`): RANGE_SHARE times the
# starting estimate's speed and yaw rate, at least SPEED_FLOOR and YAW_FLOOR.
# Over the benchmark's 40 random round trips (seeds 5 and 6) the generating state
# used at most 0.65 of the speed range and 0.48 of the yaw-rate range
# (tests/test_runout_grid.py).
RANGE_SHARE = 2.0
SPEED_FLOOR = 10.0  # m/s
YAW_FLOOR = 4.0  # rad/s
# The rescue of a fit none of whose starts converged: the grid search at these
# resolutions (points each side of zero: vx and vy, w), coarse first (about 0.7 s
# a vehicle on the RICSAC run-outs against 3 s), until one converges. The coarse grid is no
# subset of the fine one: it fitted the RICSAC Pinto, the fine one did not.
RESCUE_CELLS = ((8, 8), (grids.SPEED_CELLS, grids.YAW_CELLS))


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
    via: list = field(
        default_factory=list
    )  # per intermediate pose: (position miss [m], heading miss [rad] or None)
    cost: float = math.inf  # squared norm of the weighted residual (rest, marks, poses)
    jacobian: np.ndarray | None = None  # of the weighted residual (rows as in evaluate) at the state
    grid: grids.Grid | None = None  # the grid search, when the fit ran one (exhaustive, or the rescue)


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


def evaluate(vehicle, cols, p, tol):
    """(residual vector, Jacobian) at p = (vx, vy, w) of the fit's weighted
    residual; residual None if the run fails. Rows: the rest pose (x, y, psi
    times R_max), the mark directions, the intermediate poses (via.py). `cols`
    the kernel's columns (batch.columns())."""
    points = via.PATH_ROWS if vehicle.via else 0
    y, _, status, _, path = run_row(
        row_values(vehicle, cols, *p), tol=tol, sens=True, path_points=points, path_columns=via.PATH_COLUMNS
    )
    if status != 0 or (points and path.shape[0] >= points):  # failed, or more steps than the path holds
        return None, None
    scale = heading_scale(vehicle.row)
    r = _rest_rows(vehicle, y, scale)
    S = y[7:].reshape(6, 4)
    J = S[:3, :3].copy()
    J[2] *= scale
    if vehicle.marks:
        rm, Jm = mark_rows(vehicle, p, scale)
        r, J = np.concatenate([r, rm]), np.vstack([J, Jm])
    if vehicle.via:
        rv, Jv = via.residuals(vehicle.via, path, scale, jacobian=True)
        r, J = np.concatenate([r, rv]), np.vstack([J, Jv])
    return r, J


def mark_rows(vehicle: RunoutVehicle, p, scale: float):
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


def heading_scale(row) -> float:
    """R_max [m], the heading residual's weight: the farthest wheel from the
    centre of gravity, so that one radian of heading counts as R_max metres."""
    return math.hypot(max(row["a"], row["L"] - row["a"]), row["track"] / 2)


def _done(r, scale, coarse: float = 1.0) -> bool:
    """The residual within `coarse` times (POSITION_TOL, HEADING_TOL), and each
    row of further evidence (marks, intermediate poses; metres, or radians
    times `scale`) within `coarse` times POSITION_TOL: a least-squares fit that
    cannot meet them all ends where its steps stop lowering the residual."""
    k = coarse
    rest = math.hypot(r[0], r[1]) < k * POSITION_TOL and abs(r[2]) / scale < k * HEADING_TOL
    return rest and bool(np.all(np.abs(r[3:]) < k * POSITION_TOL))


def newton(vehicle: RunoutVehicle, start, tol: float | None = None, budget: int = MAX_ITERATIONS) -> Fit:
    """Newton to COARSE times the tolerances with the integrator at NEWTON_TOL
    (the early iterations), then on to the tolerances at `tol`."""
    first = _newton(vehicle, start, NEWTON_TOL, budget, coarse=COARSE)
    if not first.converged:
        return first
    second = _newton(vehicle, (*first.velocity, first.yaw_rate), tol, budget)
    second.iterations += first.iterations
    second.start = tuple(start)
    return second


def _newton(vehicle: RunoutVehicle, start, tol, budget: int, coarse: float = 1.0, known=()) -> Fit:
    """Newton's method damped as Levenberg-Marquardt from `start` = (vx, vy, w):
    the step solves (J'J + lam diag(J'J)) dp = -J'r; lam shrinks tenfold after a
    step that lowers |r| and grows tenfold after one that does not (then the
    step is retried from the same point). `budget` caps the run-outs.

    With `known` Fits, the residual is deflated (Farrell, Birkisson & Funke,
    SIAM J. Sci. Comput. 37 (2015) A2026): Newton runs on m(p) r(p), m the
    product over the known states of 1/q + 1, q the squared distance in units
    of DEFLATION_SCALE, so it cannot converge to a known state (m grows without
    bound there) and converges to the same roots elsewhere; the step is the
    undeflated one times 1/(1 - grad(log m).dp). An iterate within the
    distinctness thresholds of a known state ends the run unconverged."""
    cols, scale = columns(), heading_scale(vehicle.row)
    p = np.array(start, dtype=float)
    r, J = evaluate(vehicle, cols, p, tol)
    iterations, runs, lam, stalled = 0, 1, 1e-3, False
    settle = SETTLE if coarse == 1.0 else SETTLE_COARSE
    while r is not None and not _done(r, scale, coarse) and runs < budget:
        if any(_near(p, k) for k in known):
            return Fit(
                (float(p[0]), float(p[1])), float(p[2]), math.inf, math.inf, iterations, False, tuple(start)
            )
        A, g = J.T @ J, J.T @ r
        step = np.linalg.solve(A + lam * np.diag(np.diag(A) + 1e-12), -g)
        log_m, grad = _deflation(p, known)
        step /= min(max(1.0 - float(grad @ step), 0.1), 10.0)
        trial = p + step
        rt, Jt = evaluate(vehicle, cols, trial, tol)
        runs += 1
        if rt is not None and 2 * _deflation(trial, known)[0] + math.log(float(rt @ rt) + 1e-300) < (
            2 * log_m + math.log(float(r @ r) + 1e-300)
        ):
            settled = float(r @ r) - float(rt @ rt) < settle * float(r @ r) + 1e-24
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
        marks=[float(x) / scale for x in r[3 : 3 + len(vehicle.marks)]],
        via=via.misses(vehicle.via, r[3 + len(vehicle.marks) :], scale),
        cost=float(r @ r),
        jacobian=J,
    )


def determination(vehicle: RunoutVehicle, fit: Fit) -> np.ndarray | None:
    """d(vx, vy, w)/d(x_rest, y_rest, psi_rest) at a converged fit (SI, per
    metre and per radian): how far the fitted separation state moves for a
    misread rest pose. A rest pose moved by dT moves the residual's rest rows
    by -E dT (E = diag(1, 1, R_max), the heading row's weight), and the
    least-squares state by pinv(J) E dT, J the residual's Jacobian at the fit
    (J^-1 E for the rest pose alone; with marks or intermediate poses the
    Gauss-Newton step, first order where the residual is not zero). None if
    the fit did not converge."""
    if fit.jacobian is None or not fit.converged:
        return None
    return np.linalg.pinv(fit.jacobian)[:, :3] * np.array([1.0, 1.0, heading_scale(vehicle.row)])


def _yaw_candidates(w: float) -> list[float]:
    """Yaw rates to scan: the estimate times YAW_SCALES, and +-1 rad/s when the
    estimate is small (a rest pose that barely turned may still come from a spin)."""
    found = [w * s for s in YAW_SCALES]
    if abs(w) < 0.5:
        found += [1.0, -1.0]
    return found


def _scan(vehicle: RunoutVehicle, estimate, tol) -> list:
    """Candidate starts around the estimate, best residual first: speed x
    SPEED_SCALES, each yaw rate of `_yaw_candidates`, each run forward (through
    `run_row`, the scene's one row function; with intermediate poses their
    misses count in the ranking, as the tyre-mark directions' do)."""
    cols, scale = columns(), heading_scale(vehicle.row)
    vx, vy, w = estimate
    starts = [(vx * sv, vy * sv, yaw) for sv in SPEED_SCALES for yaw in _yaw_candidates(w)]

    def miss2(p) -> float:
        miss = _forward_miss(vehicle, row_values(vehicle, cols, *p), tol, scale)
        if miss is not None and vehicle.marks:
            miss = np.concatenate([miss, mark_rows(vehicle, p, scale)[0]])
        return math.inf if miss is None else float(miss @ miss)

    res = list(threads.pool().map(miss2, starts))
    return [starts[i] for i in np.argsort(res, kind="stable") if math.isfinite(res[i])]


def _rest_rows(vehicle: RunoutVehicle, y, scale: float) -> np.ndarray:
    """Rest-pose residual (x, y, psi times `scale`) of a state at rest y."""
    x_r, y_r, psi_r = vehicle.rest
    return np.array([y[0] - x_r, y[1] - y_r, (y[2] - psi_r) * scale])


def _forward_miss(vehicle: RunoutVehicle, values, tol, scale: float):
    """Rest-pose residuals (and the intermediate poses') of one forward run-out; None if it fails."""
    points = via.PATH_ROWS if vehicle.via else 0
    y, _, status, _, path = run_row(values, tol=tol, path_points=points, path_columns=8)
    if status != 0 or (points and path.shape[0] >= points):
        return None
    rows = _rest_rows(vehicle, y, scale)
    return np.concatenate([rows, via.residuals(vehicle.via, path, scale, False)[0]]) if vehicle.via else rows


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


def fit_rest(
    vehicle: RunoutVehicle,
    tol: float | None = None,
    check_unique: bool = True,
    exhaustive: bool = False,
    speed_max: float | None = None,
    yaw_rate_max: float | None = None,
) -> Fit:
    """The separation state reaching `vehicle.rest`. Newton starts from the
    best of the scanned candidates around the documented estimate, then (until
    one converges) from the next UNIQUE_STARTS diverse ones and RESCUE_STARTS
    more; with `check_unique`, the diverse starts left after the first
    converged one run as the uniqueness check, and the other separation states
    found that reach the rest pose (polished to the full tolerances, distinct
    from each other) are attached as `alternatives` (module docstring).
    With `exhaustive`, Newton also starts from the grid search's minima over
    |v| <= `speed_max` [m/s], |w| <= `yaw_rate_max` [rad/s] (each defaults to
    `plausible_range`'s), and `Fit.grid` records the search.
    With tyre-mark directions or intermediate poses, see `_fit_evidence`."""
    span = plausible_range(vehicle, speed_max, yaw_rate_max) if exhaustive else None
    if vehicle.marks or vehicle.via:
        return _fit_evidence(vehicle, tol, check_unique, span)
    return _search(vehicle, tol, check_unique, span)


def plausible_range(
    vehicle: RunoutVehicle, speed_max: float | None = None, yaw_rate_max: float | None = None
) -> tuple[float, float]:
    """(speed_max [m/s], yaw_rate_max [rad/s]) of the grid search: the given
    values, else RANGE_SHARE times the starting estimate's speed and yaw rate,
    at least SPEED_FLOOR and YAW_FLOOR."""
    vx, vy, w = starting_estimate(vehicle)
    if speed_max is None:
        speed_max = max(RANGE_SHARE * math.hypot(vx, vy), SPEED_FLOOR)
    if yaw_rate_max is None:
        yaw_rate_max = max(RANGE_SHARE * abs(w), YAW_FLOOR)
    return float(speed_max), float(yaw_rate_max)


def _fit_evidence(vehicle: RunoutVehicle, tol, check_unique: bool, span=None) -> Fit:
    """Least squares over the rest pose and the further evidence, from every
    separation state that reaches the rest pose alone (the rest-only fit and
    its alternatives: each is a basin the evidence may choose; started from
    the scan instead, every start of seed-5 row 1 fell into the basin of the
    state that misses its intermediate pose by 9 cm). Where none of them meets
    the evidence (or none is found), the search also runs on the whole
    residual (`_search`) and the least squared residual of all is reported."""
    plain = _search(replace(vehicle, marks={}, via=()), tol, check_unique=True)
    found: list[Fit] = []
    for root in (plain, *plain.alternatives) if plain.converged else ():
        f = newton(vehicle, (*root.velocity, root.yaw_rate), tol)
        if f.converged and all(_distinct(f, g) for g in found):
            f.iterations += root.iterations
            found.append(f)
    if not any(_meets(vehicle, f) for f in found):  # no rest-pose state meets the evidence: search it all
        other = _search(vehicle, tol, check_unique)
        if not found:
            other.grid = plain.grid
            return other
        if other.converged and all(_distinct(other, g) for g in found):
            found.append(other)
    best = _least_cost(vehicle, found, check_unique)
    best.grid = plain.grid
    return best


def _least_cost(vehicle: RunoutVehicle, found: list, check_unique: bool) -> Fit:
    """Of the states `found` for a fit with further evidence, the one with the
    least squared residual; the others within EVIDENCE_COST_SHARE of it (or
    the tolerance per row) as its alternatives."""
    best = min(found, key=lambda f: f.cost)
    bound = EVIDENCE_COST_SHARE * best.cost + _rows(vehicle) * POSITION_TOL**2
    best.alternatives = [f for f in found if f is not best and f.cost <= bound] if check_unique else []
    return best


def _search(vehicle: RunoutVehicle, tol, check_unique: bool, span=None) -> Fit:
    """The scan, the Newton starts and the uniqueness check of `fit_rest`;
    with `span` = (speed_max, yaw_rate_max), the grid search's starts too,
    which also run over the default range (at RESCUE_CELLS) when no other
    start converged."""
    estimate = starting_estimate(vehicle)
    starts = _scan(vehicle, estimate, LOOSE_TOL) or [estimate]
    diverse = _diverse(starts, UNIQUE_STARTS)
    rescue = [p for p in starts[1:] if p not in diverse][:RESCUE_STARTS]
    found: list[Fit] = []
    first = None
    for i, start in enumerate([starts[0], *diverse, *rescue]):
        f = newton(vehicle, start, tol)  # Newton to the full tolerances until a start converges
        first = first or f
        if f.converged:
            found.append(f)
            if check_unique:
                unique = functools.partial(_unique, vehicle, tol=tol, known=list(found))
                for g in threads.pool().map(unique, diverse[i:]):
                    if g is not None and all(_distinct(g, h) for h in found):
                        found.append(g)
            break
    grid = None if span is None else _grid_states(vehicle, tol, span, found, refined=True)
    if not found and span is None:  # every start failed: the grid search is the last rescue
        for cells in RESCUE_CELLS:
            grid = _grid_states(vehicle, tol, plausible_range(vehicle), found, cells)
            if found:
                break
    if not found:
        first.grid = grid
        return first
    if vehicle.marks or vehicle.via:  # least squares: the state that fits the evidence best
        return _least_cost(vehicle, found, check_unique)
    est = np.array(estimate)
    best = min(found, key=lambda f: _distance(f, est))
    best.alternatives = [f for f in found if f is not best]
    best.grid = grid
    return best


def _grid_states(
    vehicle: RunoutVehicle,
    tol,
    span,
    found: list,
    cells=(grids.SPEED_CELLS, grids.YAW_CELLS),
    refined: bool = False,
) -> grids.Grid:
    """Run the grid search over `span` (at `cells`; with `refined`, its open
    cells refined: grid.py) and Newton (to the full tolerances) from each of
    its starts on the room's threads; append to `found` every converged state
    distinct from those already there. Returns the search."""
    apart = (DISTINCT_SPEED, DISTINCT_YAW) if refined else None
    grid = grids.scan(vehicle, *span, heading_scale(vehicle.row), LOOSE_TOL, cells, apart)
    for g in threads.pool().map(functools.partial(newton, vehicle, tol=tol), grid.starts):
        if g.converged and all(_distinct(g, h) for h in found):
            found.append(g)
    return grid


def _unique(vehicle: RunoutVehicle, start, *, tol, known: list) -> Fit | None:
    """A uniqueness start: deflated Newton from `start` away from the `known`
    states, then polished to the full tolerances; the state if it converges
    and is distinct from the known ones, else None."""
    f = _newton(vehicle, start, UNIQUE_TOL, UNIQUE_BUDGET, coarse=UNIQUE_COARSE, known=known)
    if not (f.converged and all(_distinct(f, g) for g in known)):
        return None
    polished = newton(vehicle, (*f.velocity, f.yaw_rate), tol, POLISH_BUDGET)
    if not (polished.converged and all(_distinct(polished, g) for g in known)):
        return None
    polished.iterations += f.iterations
    return polished


def _rows(vehicle: RunoutVehicle) -> int:
    """Residual rows of a fit: the rest pose, the marks, the intermediate poses."""
    return 3 + len(vehicle.marks) + sum(2 if psi is None else 3 for *_, psi in vehicle.via)


def _meets(vehicle: RunoutVehicle, f: Fit) -> bool:
    """`f` converged and, with further evidence, meets all of it (a squared
    residual within the position tolerance per row): a least-squares minimum
    that leaves part of the evidence unmet may be another start's basin, so
    the further starts are tried (the best of all is reported)."""
    if not (vehicle.marks or vehicle.via):
        return f.converged
    return f.converged and f.cost <= _rows(vehicle) * POSITION_TOL**2


def _distance(f: Fit, est) -> float:
    return float(np.linalg.norm(np.array([*f.velocity, f.yaw_rate]) - est))


def _distinct(f: Fit, g: Fit) -> bool:
    return not _near(np.array([*f.velocity, f.yaw_rate]), g)


def _deflation(p, known) -> tuple[float, np.ndarray]:
    """(log m(p), grad log m(p)) of the deflation in `_newton`: m = prod_k (1/q_k + 1),
    q_k = |(p - p_k)/DEFLATION_SCALE|^2 over the known states p_k."""
    log_m, grad = 0.0, np.zeros(3)
    for k in known:
        d = (p - np.array([*k.velocity, k.yaw_rate])) / DEFLATION_SCALE
        q = max(float(d @ d), 1e-300)
        log_m += math.log1p(1.0 / q)
        grad -= 2.0 * d / DEFLATION_SCALE / (q * (1.0 + q))
    return log_m, grad


def _near(p, g: Fit) -> bool:
    """p = (vx, vy, w) within DISTINCT_SPEED and DISTINCT_YAW of the state of `g`."""
    dv = math.hypot(p[0] - g.velocity[0], p[1] - g.velocity[1])
    return dv <= DISTINCT_SPEED and abs(p[2] - g.yaw_rate) <= DISTINCT_YAW
