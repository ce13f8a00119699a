"""Fit many run-outs to their rest poses at once: one separation state
(vx, vy, w) per row of a run-out table, for the Monte Carlo draws of
``reconstruct --uncertainty`` through the run-out (uncertain.py).

Quasi-Newton across the rows (batchfit.py: Broyden's Jacobians, trust region,
forward differences where Broyden stalls), every run-out forward through
`runout_batch` (no batch driver integrates the sensitivities), in waves
(`_waves`): the first FIRST_WAVE rows as below, every later row from a local
quadratic fit over the fitted rows near it (neighbours.py; the caller gives
where the draws lie: Neighbours).
Each row starts from its linear prediction (the nominal fit plus the linear
method's dp/dx times the draw's deviation) or, where that misses the rest
pose by more than FAR, the nominal fitted state if it misses by less, with
the exact Jacobian J = d(x, y, psi)_rest/d(vx, vy, w) of the nominal fit
moved to first order to the draw (the caller's; heading residuals weighted by
the vehicle's R_max, as in fit.py). A row is converged within `draw_tolerances`:
1 % of the draws' rest-pose spread, between fit.py's tolerances (0.1 mm,
1e-5 rad) and 1 mm, 0.01 deg; at 1 mm the run-outs run at the loosest
integrator tolerance of DRAW_TOLS that the first rows fitted show holds
(`_first_rows`). Rows still open after batchfit's iterations go to
fit.py's exact Newton, a row per task on the room's threads; a row that does
not converge there is reported as not fitted. With tyre-mark directions or
intermediate poses the fit is least squares over the rest pose and them, and
every row goes to that exact Newton (`_exact_rows`).

Measured (`python -m benchmarks uncertainty --parts runout`, 10^5 draws,
docs/runout.md): all wheels locked, 2.01 run-outs per draw (two vehicles: the
start alone for almost every row); the mixed-wheel example
(examples/runout/chain_reconstruct_uncertain.json), whose sedan spins, 2.61
(4.86 from the nearest fitted row's Newton step, 24.5 from the linear
prediction alone), and 6-7 of its 200,000 fits go to the exact Newton.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from .._util import require
from . import batchfit, neighbours, threads
from .batch import columns
from .fit import HEADING_TOL, POSITION_TOL, newton
from .scene import RunoutVehicle

FIRST_WAVE = 128  # rows fitted from the linear prediction before neighbours start the rest (_waves)
FAR = 0.05  # m (heading weighted by R_max): a start missing by more also tries the nominal state
# A draw's fit converges to DRAW_SHARE of the draws' rest-pose spread, at most
# 1 mm and 0.01 deg (the accuracy of a rest pose); where the position
# tolerance is 1 mm its run-outs run at the loosest of DRAW_TOLS whose error the
# first rows fitted show small enough (`_first_rows`, `_tolerance_holds`).
# Measured against 1e-12 on 6,000 of the mixed-wheel example's drawn run-outs
# (docs/runout.md): rest-position error worst / 99th percentile 0.23 / 0.04-0.10 mm
# at 1e-6 (0.82 mm worst in another sample), 0.23 / 0.01-0.02 mm at 3e-7, 0.06 /
# 0.01 mm at 1e-7; 26-27 % fewer steps at 1e-6 than at 1e-7, 13-14 % at 3e-7.
DRAW_SHARE = 0.01
DRAW_POSITION_TOL, DRAW_HEADING_TOL = 1e-3, math.radians(0.01)
DRAW_TOLS = (1e-6, 3e-7)
# The check of a tolerance on a scene: the first FIRST_WAVE fitted rows run again
# at CHECK_TOL; their rest poses must agree within CHECK_SHARE of the fit's tolerances.
CHECK_TOL, CHECK_SHARE = 1e-10, 1.0 / 3.0

#: Why a row was not fitted (the fitted state is NaN there).
NOT_CONVERGED = 1
RUN_FAILED = 2


@dataclasses.dataclass
class Neighbours:
    """Where the draws lie, for starting each from a fitted neighbour
    (`_waves`): `position` (rows, d), scaled so that the distance between two
    draws predicts how far apart their fitted states are; `shift` (rows, 3),
    how far each draw's inputs move the rest-pose residual at a fixed
    separation state, to first order (x, y [m], psi [rad])."""

    position: np.ndarray
    shift: np.ndarray


@dataclasses.dataclass
class DrawFit:
    """The fitted states (rows, 3) [SI], per row 0 or NOT_CONVERGED/RUN_FAILED,
    the work done (forward run-outs in the batch, rows refitted exactly) and
    the integrator tolerance the run-outs ran at (None: the kernel's default)."""

    state: np.ndarray
    status: np.ndarray
    runouts: int
    exact_rows: int
    tol: float | None = None


def draw_tolerances(jacobian: np.ndarray, deviations: np.ndarray) -> tuple[tuple[float, float], float | None]:
    """((position [m], heading [rad]) to which the draws' fits converge, and the
    integrator tolerance of their run-outs), from the nominal Jacobian
    d(x, y, psi)_rest/d(vx, vy, w) and the rows' linear state deviations from the
    nominal fit (rows, 3). A draw's fit only needs to be small against the spread
    of what the draws fit: DRAW_SHARE of the rest-pose spread those deviations
    make (J times them), between fit.py's tolerances and (DRAW_POSITION_TOL,
    DRAW_HEADING_TOL); where the position tolerance is the loose one the run-outs
    run at the loosest of DRAW_TOLS that holds on the scene (`_first_rows`)."""
    if deviations.shape[0] < 2:
        return (POSITION_TOL, HEADING_TOL), None
    spread = np.std(deviations @ jacobian.T, axis=0)
    position = float(np.clip(DRAW_SHARE * min(spread[0], spread[1]), POSITION_TOL, DRAW_POSITION_TOL))
    heading = float(np.clip(DRAW_SHARE * spread[2], HEADING_TOL, DRAW_HEADING_TOL))
    return (position, heading), DRAW_TOLS[0] if position >= DRAW_POSITION_TOL else None


def fit_draws(
    table: np.ndarray,
    target: np.ndarray,
    start: np.ndarray,
    nominal: np.ndarray,
    jacobian: np.ndarray,
    vehicle: RunoutVehicle,
    tol: float | None = None,
    tols: tuple[float, float] = (POSITION_TOL, HEADING_TOL),
    evidence=None,
    near: Neighbours | None = None,
) -> DrawFit:
    """Fit rows of the run-out `table` (rows, COLUMNS; its vx, vy, w ignored)
    to `target` (rows, 3: x, y [m], psi [rad]) from `start` (rows, 3) or the
    `nominal` fitted state (3,), with `jacobian` (3x3, or rows x 3x3) as the
    rows' first Jacobian.
    `vehicle` is the nominal RunoutVehicle (its row layout for the exact
    fallback); `tol` the integrator tolerance of the run-outs (None: the
    kernel's default), `tols` the (position [m], heading [rad]) misses within
    which a row is fitted (`draw_tolerances`). With `near` (where the draws
    lie: Neighbours) the rows are fitted in waves (`_waves`). With `evidence`
    (tyre-mark directions, intermediate poses per row: uncertain.Evidence) the
    fit is least squares over the rest pose and the evidence, which the batched
    steps here (a square system) do not solve: every row goes to fit.py's
    Newton from `start` (`_exact_rows`)."""
    if evidence is not None:
        return _exact_rows(vehicle, table, target, start, evidence, tol)
    jacobian = np.broadcast_to(jacobian, (table.shape[0], 3, 3))
    if near is None or table.shape[0] < 2 * FIRST_WAVE:
        return _first_rows(table, target, start, nominal, jacobian, vehicle, tol, tols)[0]
    return _waves(table, target, start, nominal, jacobian, vehicle, tol, tols, near)


def _first_rows(table, target, start, nominal, jacobian, vehicle, tol, tols):
    """`_batched` over the rows at integrator tolerance `tol`, and again at each
    tighter one of DRAW_TOLS, then the kernel's default, while the tolerance
    does not hold on them (`_tolerance_holds`): the DrawFit (its run-outs those
    of every try, its `tol` the one kept) and the last Jacobians."""
    spent = 0
    rungs = [None] if tol is None else [tol, *(t for t in DRAW_TOLS if t < tol), None]
    for rung in rungs:
        fit, B = _batched(table, target, start, nominal, jacobian, vehicle, rung, tols)
        if rung is None:
            break
        holds, checked = _tolerance_holds(table, fit.state, rung, tols)
        spent += checked
        if holds:
            break
        spent += fit.runouts
    return dataclasses.replace(fit, runouts=fit.runouts + spent), B


def _tolerance_holds(table, p, tol: float, tols: tuple[float, float]) -> tuple[bool, int]:
    """Whether run-outs at integrator tolerance `tol` rest within CHECK_SHARE of
    the fit's tolerances `tols` (position [m], heading [rad]) of the same
    run-outs at CHECK_TOL, over the first FIRST_WAVE fitted states p of
    `table` (rows, 3; NaN: not fitted), and the run-outs the check ran. The
    integration error of a draw adds to its fit's miss: a third of the
    tolerance keeps the two together within 4/3 of it. No fitted row: False."""
    rows = np.flatnonzero(np.isfinite(p).all(axis=1))[:FIRST_WAVE]
    if not rows.size:
        return False, 0
    zero = np.zeros((rows.size, 3))
    loose, _ = batchfit.residual(table[rows], p[rows], zero, tol)
    tight, status = batchfit.residual(table[rows], p[rows], zero, CHECK_TOL)
    d = (loose - tight)[status == 0]
    holds = (np.hypot(d[:, 0], d[:, 1]) <= CHECK_SHARE * tols[0]).all() and (
        np.abs(d[:, 2]) <= CHECK_SHARE * tols[1]
    ).all()
    return bool(holds) and (status == 0).all(), 2 * rows.size


def _waves(table, target, start, nominal, jacobian, vehicle, tol, tols, near: Neighbours) -> DrawFit:
    """The rows in waves, each as large as all before it: the first FIRST_WAVE
    from `start` and `jacobian` (the draws come in random order, so those are a
    sample of all), every later row from the fitted rows before it: the
    intercept of a local quadratic fit of their fitted states over its nearest
    ones in `near.position` (neighbours.py), with the nearest's last Jacobian
    B_j as its first. Where there are fewer fitted rows than that fit needs,
    the nearest's Newton step p_j + B_j^-1 (shift_i - shift_j) instead (first
    order in the draws' difference). Where the fitted state is a strongly
    curved function of the draw, the neighbours' states and Jacobian are far
    better than the nominal ones (docs/runout.md, "`reconstruct --uncertainty`
    through the run-out": the mixed-wheel example's spinning sedan). A wave
    whose earlier rows all failed starts from `start` instead. The first wave
    also chooses the integrator tolerance (`_first_rows`): the first of `tol`
    and the tighter ones that holds, which every later wave then runs at."""
    tree = require("scipy.spatial", extra="uncertainty", what="the draws' neighbour search").cKDTree
    n = table.shape[0]
    p, status = np.full((n, 3), math.nan), np.zeros(n, dtype=np.int64)
    B = np.array(jacobian, dtype=np.float64, copy=True)
    runouts = exact = 0
    lo, hi = 0, FIRST_WAVE
    while lo < n:
        rows = np.arange(lo, hi)
        fitted = np.flatnonzero(status[:lo] == 0)
        quadratic = (
            neighbours.predict(near.position[fitted], p[fitted], near.position[rows]) if fitted.size else None
        )
        if quadratic is not None:  # the local quadratic's start, kept within the trust region of the nearest
            moved, j = quadratic
            j = fitted[j]
            moved = p[j] + batchfit.capped(moved - p[j], p[j])
        elif fitted.size:  # too few fitted rows for the quadratic: the nearest's Newton step
            j = fitted[tree(near.position[fitted]).query(near.position[rows])[1]]
            moved = p[j] + batchfit.capped(batchfit.newton_step(B[j], near.shift[j] - near.shift[rows]), p[j])
        if fitted.size:
            fit, B[rows] = _batched(
                table[rows], target[rows], moved, nominal, B[j], vehicle, tol, tols, False
            )
        elif lo == 0:  # the first wave, where the integrator tolerance is checked
            fit, B[rows] = _first_rows(
                table[rows], target[rows], start[rows], nominal, B[rows], vehicle, tol, tols
            )
            tol = fit.tol
        else:
            fit, B[rows] = _batched(
                table[rows], target[rows], start[rows], nominal, B[rows], vehicle, tol, tols
            )
        p[rows], status[rows] = fit.state, fit.status
        runouts, exact = runouts + fit.runouts, exact + fit.exact_rows
        lo, hi = hi, min(n, 2 * hi)
    return DrawFit(p, status, runouts, exact, tol)


def _batched(table, target, start, nominal, jacobian, vehicle, tol, tols, try_nominal: bool = True):
    """The batched quasi-Newton of the module docstring over every row: the
    DrawFit and the rows' last Jacobians (rows, 3, 3; unweighted). Without
    `try_nominal` no row tries the nominal state (the starts are fitted neighbours)."""
    n = table.shape[0]
    weight = batchfit.weights(table)
    p = np.array(start, dtype=np.float64, copy=True)
    r, status = batchfit.residual(table, p, target, tol)
    r *= weight
    runouts = n
    # Where the linear prediction misses by more than FAR, the nominal state is
    # tried too and the better start kept (where the run-out is strongly
    # curved the prediction can land further off than the point it was taken at).
    far = np.flatnonzero((status != 0) | (np.einsum("ni,ni->n", r, r) > FAR**2)) if try_nominal else ()
    if len(far):
        other = np.broadcast_to(nominal, (far.size, 3))
        ro, so = batchfit.residual(table[far], other, target[far], tol)
        ro *= weight[far]
        runouts += far.size
        better = (so == 0) & (
            (status[far] != 0) | (np.einsum("ni,ni->n", ro, ro) < np.einsum("ni,ni->n", r[far], r[far]))
        )
        p[far[better]], r[far[better]], status[far[better]] = other[better], ro[better], 0
    failed = status != 0
    p, r, open_, B, spent = batchfit.quasi_newton(table, target, p, r, failed, jacobian, weight, tol, tols)
    runouts += spent
    exact = np.flatnonzero(open_)
    refit = functools.partial(_exact, vehicle, table, target, p, tol)
    for i, fit in zip(exact, threads.pool().map(refit, exact)):
        if fit.converged:
            p[i] = (*fit.velocity, fit.yaw_rate)
            open_[i] = False
    out = np.where(failed, RUN_FAILED, np.where(open_, NOT_CONVERGED, 0))
    p[out != 0] = math.nan
    return DrawFit(p, out, runouts, int(exact.size), tol), B


def _exact(vehicle: RunoutVehicle, table, target, p, tol, i: int, evidence=None):
    """Row i fitted by fit.py's exact Newton from its last state (on the room's
    threads); with `evidence` (its marks and intermediate poses per row), least
    squares over them too."""
    drawn = evidence.row(i) if evidence is not None else ()
    return newton(variant(vehicle, table[i], target[i], *drawn), tuple(p[i]), tol)


def _exact_rows(vehicle: RunoutVehicle, table, target, start, evidence, tol) -> DrawFit:
    """Every row by fit.py's Newton from `start` with its drawn tyre-mark
    directions and intermediate poses (the fit's tolerances; `runouts` is not
    counted there: every row is an exact one)."""
    p = np.array(start, dtype=np.float64, copy=True)
    refit = functools.partial(_exact, vehicle, table, target, p, tol, evidence=evidence)
    status = np.full(p.shape[0], NOT_CONVERGED)
    for i, fit in enumerate(threads.pool().map(refit, range(p.shape[0]))):
        p[i], status[i] = (*fit.velocity, fit.yaw_rate), 0 if fit.converged else NOT_CONVERGED
    p[status != 0] = math.nan
    return DrawFit(p, status, 0, int(p.shape[0]))


def variant(vehicle: RunoutVehicle, row: np.ndarray, target: np.ndarray, marks=None, via=()) -> RunoutVehicle:
    """The nominal vehicle with one drawn row, rest pose, tyre-mark directions
    (wheel key -> rad) and intermediate poses ((x, y [m], psi [rad] or None),
    ...), none of either by default (fit.newton's input)."""
    values = dict(zip(columns(), (float(x) for x in row)))
    return dataclasses.replace(
        vehicle,
        row={k: values[k] for k in vehicle.row},
        position=(values["x"], values["y"]),
        heading=values["psi"],
        rest=tuple(float(x) for x in target),
        marks=dict(marks or {}),
        via=tuple(via),
    )
