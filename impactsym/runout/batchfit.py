"""Batched quasi-Newton on the rest pose: many separation states (vx, vy, w)
moved at once toward their rows' rest poses, every run-out forward through
`runout_batch`. Used by the draws' fits (drawfit.py) and by the grid search's
refined cells (grid.py); fit.py's Newton, with the exact sensitivities, is the
one-vehicle fit.

An iteration solves B s = -r for every open row (NumPy's batched 3x3 solve),
shortens s to a trust region (`capped`), runs the trials, takes every trial
whose run-out ran and whose miss did not grow more than GROWTH times (full,
non-monotone steps: in the curved valleys of a spinning car a Newton step may
first miss by more and then converge, where a descent rule crawls), and
updates B by Broyden's rank-one formula. A row whose trial did not cut its
squared miss fourfold gets a fresh B from forward differences of three
run-outs. Residuals are (x, y [m], psi x R_max) (`weights`: heading in metres
at the vehicle's farthest corner, as in fit.py).
"""

from __future__ import annotations

import numpy as np

from .batch import columns, runout_batch

MAX_ITERATIONS = 20  # batched trials at most
GROWTH = 100.0  # a trial missing by more than this times the current miss is not taken
STEP_SHARE, STEP_SPEED, STEP_YAW = 0.5, 2.0, 2.0  # trust region of a step (m/s, rad/s)
STALL = 0.25  # a trial that does not cut the squared residual by this much renews the Jacobian
FD_SHARE = 1e-3


def weights(table: np.ndarray) -> np.ndarray:
    """(rows, 3): the residuals' weights (1, 1, R_max [m]) of the run-out rows."""
    names = columns()
    a, wb, track = (table[:, names.index(c)] for c in ("a", "L", "track"))
    radius = np.hypot(np.maximum(a, wb - a), track / 2)
    return np.column_stack([np.ones(len(table)), np.ones(len(table)), radius])


def residual(table: np.ndarray, p: np.ndarray, target: np.ndarray, tol):
    """Rest-pose residuals (rows, 3; x, y [m], psi [rad]) of the separation
    states p, and the kernel status."""
    cols = {name: table[:, j] for j, name in enumerate(columns())}
    cols["vx"], cols["vy"], cols["w"] = p[:, 0], p[:, 1], p[:, 2]
    out = runout_batch(cols, tol=tol)
    rest = np.column_stack([out["x_rest"], out["y_rest"], out["psi_rest"]])
    return rest - target, out["status"]


def done(r: np.ndarray, tols: tuple[float, float]) -> np.ndarray:
    """Rows whose unweighted residual is within (position [m], heading [rad])."""
    return (np.hypot(r[:, 0], r[:, 1]) < tols[0]) & (np.abs(r[:, 2]) < tols[1])


def quasi_newton(table, target, p, r, failed, jacobian, weight, tol, tols, iterations: int = MAX_ITERATIONS):
    """The iterations of the module docstring from states p (rows, 3; copied)
    with weighted residuals r (rows, 3) and first Jacobians `jacobian` (rows,
    3, 3; d(x, y, psi)_rest/d(vx, vy, w)); rows `failed` are left alone.
    Returns (states, weighted residuals, rows still open, last Jacobians
    (unweighted), run-outs)."""
    p, r = np.array(p, dtype=np.float64, copy=True), np.array(r, dtype=np.float64, copy=True)
    B = jacobian * weight[:, :, None]
    open_ = ~failed & ~done(r / weight, tols)
    runouts = 0
    for _ in range(iterations):
        rows = np.flatnonzero(open_)
        if rows.size == 0:
            break
        step = capped(newton_step(B[rows], r[rows]), p[rows])
        trial = p[rows] + step
        rt, st = residual(table[rows], trial, target[rows], tol)
        rt *= weight[rows]
        runouts += rows.size
        before, after = np.einsum("ni,ni->n", r[rows], r[rows]), np.einsum("ni,ni->n", rt, rt)
        take = (st == 0) & (after < GROWTH**2 * before)
        _broyden(B, rows[take], step[take], rt[take] - r[rows[take]])
        p[rows[take]], r[rows[take]] = trial[take], rt[take]
        open_[rows[take]] = ~done(rt[take] / weight[rows[take]], tols)
        slow = rows[open_[rows] & ~(take & (after < STALL * before))]
        if slow.size:  # Broyden's Jacobian is not leading: differences of forward run-outs instead
            B[slow] = _differences(table[slow], p[slow], r[slow], target[slow], weight[slow], tol)
            runouts += 3 * slow.size
    return p, r, open_, B / weight[:, :, None], runouts


def _differences(table, p, r, target, weight, tol) -> np.ndarray:
    """Jacobians (rows, 3, 3) of the weighted residual by forward differences of
    forward run-outs (steps 1e-3 of the speed or yaw rate, at least 1e-3)."""
    m = p.shape[0]
    h = np.column_stack(
        [np.maximum(FD_SHARE * np.hypot(p[:, 0], p[:, 1]), FD_SHARE)] * 2
        + [np.maximum(FD_SHARE * np.abs(p[:, 2]), FD_SHARE)]
    )
    moved = np.repeat(p[None], 3, axis=0)
    for j in range(3):
        moved[j, :, j] += h[:, j]
    rt, _ = residual(np.tile(table, (3, 1)), moved.reshape(3 * m, 3), np.tile(target, (3, 1)), tol)
    rt = rt.reshape(3, m, 3) * weight[None]
    return np.stack([(rt[j] - r) / h[:, j, None] for j in range(3)], axis=2)


def newton_step(B: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Newton steps B s = -r, row by row (NumPy's batched 3x3 solve; a singular
    B gives the least-squares step)."""
    try:
        return np.linalg.solve(B, -r[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:
        return np.stack([np.linalg.lstsq(b, -x, rcond=None)[0] for b, x in zip(B, r)])


def capped(step: np.ndarray, p: np.ndarray) -> np.ndarray:
    """`step` shortened to the trust region: the velocity change at most
    STEP_SHARE of the speed (and at least STEP_SPEED m/s), the yaw-rate change
    at most STEP_SHARE of |w| (at least STEP_YAW rad/s). A trial far outside it
    can roll for minutes of simulated time and hold up the whole batch."""
    dv = np.hypot(step[:, 0], step[:, 1]) / np.maximum(STEP_SHARE * np.hypot(p[:, 0], p[:, 1]), STEP_SPEED)
    dw = np.abs(step[:, 2]) / np.maximum(STEP_SHARE * np.abs(p[:, 2]), STEP_YAW)
    return step / np.maximum(1.0, np.maximum(dv, dw))[:, None]


def _broyden(B: np.ndarray, rows: np.ndarray, s: np.ndarray, y: np.ndarray) -> None:
    """Broyden's update of the Jacobians B[rows] from steps s and residual
    changes y: B += (y - B s) s' / (s' s)."""
    if rows.size == 0:
        return
    Bs = np.einsum("nij,nj->ni", B[rows], s)
    ss = np.einsum("ni,ni->n", s, s)
    ok = ss > 0
    B[rows[ok]] += (y - Bs)[ok, :, None] * s[ok, None, :] / ss[ok, None, None]
