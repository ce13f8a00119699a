"""Fit many run-outs to their rest poses at once: one separation state
(vx, vy, w) per row of a run-out table, for the Monte Carlo draws of
``reconstruct --uncertainty`` through the run-out (uncertain.py).

Quasi-Newton across the rows, vectorised with NumPy: every row starts from
its own estimate (the nominal fit plus the linear prediction of the draw) with
the inverse of the exact Jacobian J = d(x, y, psi)_rest/d(vx, vy, w) at the
nominal fit (the sensitivities the kernel integrates, interval.py), and each
iteration runs the rows not yet converged through `runout_batch` (forward
only: no batch driver integrates the sensitivities, and a forward run-out
costs about half of one with them, measured in docs/runout.md) and updates
each row's inverse Jacobian by Broyden's rank-one formula (the "good" update,
Sherman-Morrison form: 3x3 per row, a few NumPy operations over all rows). A
step that does not lower a row's residual (heading weighted by the vehicle's
R_max, as in fit.py) is halved and retried without an update. A row is
converged at fit.py's tolerances (0.1 mm, 1e-5 rad). Rows still open after
`MAX_ITERATIONS` are handed to fit.py's exact Newton (sensitivities per row),
one by one; a row that does not converge there is reported as not fitted.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .batch import columns, runout_batch
from .fit import HEADING_TOL, POSITION_TOL, newton
from .scene import RunoutVehicle

MAX_ITERATIONS = 12
HALVINGS = 4  # step halvings before a row's step is taken anyway

#: Why a row was not fitted (the fitted state is NaN there).
NOT_CONVERGED = 1
RUN_FAILED = 2


@dataclasses.dataclass
class DrawFit:
    """The fitted states (rows, 3) [SI], per row 0 or NOT_CONVERGED/RUN_FAILED,
    and the work done: forward run-outs in the batch, rows refitted exactly."""

    state: np.ndarray
    status: np.ndarray
    runouts: int
    exact_rows: int


def _residual(table: np.ndarray, p: np.ndarray, target: np.ndarray, tol):
    """Rest-pose residuals (rows, 3) of the separation states p, and the kernel status."""
    cols = {name: table[:, j] for j, name in enumerate(columns())}
    cols["vx"], cols["vy"], cols["w"] = p[:, 0], p[:, 1], p[:, 2]
    out = runout_batch(cols, tol=tol)
    rest = np.column_stack([out["x_rest"], out["y_rest"], out["psi_rest"]])
    return rest - target, out["status"]


def _size(r: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """|r| with the heading weighted by R_max (one radian counts R_max metres)."""
    return np.sqrt(r[:, 0] ** 2 + r[:, 1] ** 2 + (r[:, 2] * radius) ** 2)


def _done(r: np.ndarray) -> np.ndarray:
    return (np.hypot(r[:, 0], r[:, 1]) < POSITION_TOL) & (np.abs(r[:, 2]) < HEADING_TOL)


def fit_draws(
    table: np.ndarray,
    target: np.ndarray,
    start: np.ndarray,
    jacobian: np.ndarray,
    vehicle: RunoutVehicle,
    tol: float | None = None,
) -> DrawFit:
    """Fit rows of the run-out `table` (rows, COLUMNS; its vx, vy, w ignored)
    to `target` (rows, 3: x, y [m], psi [rad]) from `start` (rows, 3) with
    `jacobian` (3x3 at the nominal fit) as every row's first Jacobian.
    `vehicle` is the nominal RunoutVehicle (its row layout for the exact
    fallback)."""
    n = table.shape[0]
    names = columns()
    radius = np.hypot(
        np.maximum(table[:, names.index("a")], table[:, names.index("L")] - table[:, names.index("a")]),
        table[:, names.index("track")] / 2,
    )
    p = np.array(start, dtype=np.float64, copy=True)
    H = np.broadcast_to(np.linalg.inv(jacobian), (n, 3, 3)).copy()
    r, status = _residual(table, p, target, tol)
    runouts = n
    failed = status != 0
    open_ = ~failed & ~_done(r)
    step = np.zeros((n, 3))
    for _ in range(MAX_ITERATIONS):
        rows = np.flatnonzero(open_)
        if rows.size == 0:
            break
        step[rows] = -np.einsum("nij,nj->ni", H[rows], r[rows])
        for halving in range(HALVINGS + 1):
            trial = p[rows] + step[rows]
            rt, st = _residual(table[rows], trial, target[rows], tol)
            runouts += rows.size
            better = (st == 0) & (_size(rt, radius[rows]) < _size(r[rows], radius[rows]))
            take = better | ((st == 0) & (halving == HALVINGS))
            _update(H, rows[take], step[rows[take]], rt[take] - r[rows[take]])
            p[rows[take]], r[rows[take]] = trial[take], rt[take]
            rows = rows[~take]
            if rows.size == 0:
                break
            step[rows] *= 0.5
        open_ &= ~_done(r)
    exact = np.flatnonzero(open_)
    for i in exact:
        fit = newton(_variant(vehicle, table[i], target[i]), tuple(p[i]), tol)
        if fit.converged:
            p[i] = (*fit.velocity, fit.yaw_rate)
            open_[i] = False
    out = np.where(failed, RUN_FAILED, np.where(open_, NOT_CONVERGED, 0))
    p[out != 0] = math.nan
    return DrawFit(p, out, runouts, int(exact.size))


def _update(H: np.ndarray, rows: np.ndarray, s: np.ndarray, y: np.ndarray) -> None:
    """Broyden's good update of the inverse Jacobians H[rows] for steps s and
    residual changes y: H += (s - H y) s' H / (s' H y); rows with s' H y = 0
    keep their H."""
    if rows.size == 0:
        return
    Hr = H[rows]
    Hy = np.einsum("nij,nj->ni", Hr, y)
    sH = np.einsum("ni,nij->nj", s, Hr)
    denom = np.einsum("ni,ni->n", s, Hy)
    ok = np.abs(denom) > 1e-300
    corr = (s - Hy)[ok, :, None] * sH[ok, None, :] / denom[ok, None, None]
    Hr[ok] += corr
    H[rows] = Hr


def _variant(vehicle: RunoutVehicle, row: np.ndarray, target: np.ndarray) -> RunoutVehicle:
    """The nominal vehicle with one drawn row and rest pose (fit.newton's input)."""
    values = dict(zip(columns(), (float(x) for x in row)))
    return dataclasses.replace(
        vehicle,
        row={k: values[k] for k in vehicle.row},
        position=(values["x"], values["y"]),
        heading=values["psi"],
        rest=tuple(float(x) for x in target),
        marks={},
    )
