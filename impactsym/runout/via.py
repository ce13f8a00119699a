"""Intermediate poses as evidence of a run-out: where the path passed a point.

A scene may give, per vehicle, ``intermediate`` poses it passed through between
separation and rest (a position read from tyre marks, a gouge or a struck
object; optionally the heading there). Each is compared with the run-out at
the moment t* the centre of gravity passes nearest to the given position.

The path between two accepted steps of the integrator is the cubic Hermite
interpolant of the positions and velocities at both ends (error O(h^4) in the
step h, as the steps themselves; the heading likewise from psi and w, the
sensitivities d(x, y)/dp from d(x, y)/dp and d(vx, vy)/dp, which are their time
derivatives). t* minimises |q - X(t)| over the whole path: the chord nearest to
q picks the step, Newton on (q - X)·V = 0 refines it in that step and its two
neighbours.

Residuals (SI): X(t*) - q (two rows; the component along the path vanishes
unless t* is the path's start or end) and, if the heading is given,
psi(t*) - psi_q. Their derivatives with respect to the separation state
p = (vx, vy, w) follow the foot of the perpendicular: differentiating
(q - X(t*, p))·V(t*, p) = 0 gives

    dt*/dp = ((q - X)·V_p - V·X_p) / (|V|^2 - (q - X)·A),

A the acceleration, so dX(t*)/dp = X_p + V dt*/dp and dpsi(t*)/dp =
psi_p + w dt*/dp (dt*/dp = 0 when t* is an end of the path). The Hermite weights
and dt*/dp are derived and proved in derive/runout.py (`hermite_weights`,
`foot_time_sensitivity`) and emitted into generated/runout.py.

Path rows (`run_row` with ``path_columns=PATH_COLUMNS``): t, then the state
(x, y, psi, vx, vy, w, distance) and its sensitivities S[i, j] = d y_i/d p_j at
column 8 + 4 i + j (generated/runout_jit.py).
"""

from __future__ import annotations

import numpy as np

from . import _door

PATH_COLUMNS = 32  # t, the 7 states, the 6 x 4 sensitivities
PATH_ROWS = 50_000  # accepted steps held (the buffer is only touched as far as it is filled)
NEWTON_STEPS = 12


def _sens(i: int) -> slice:
    """Path columns of d y_i / d(vx, vy, w) (the separation state, not mu)."""
    return slice(8 + 4 * i, 8 + 4 * i + 3)


def _hermite(s: float, h: float):
    """Weights of the cubic Hermite interpolant at s in [0, 1] of a step h [s]:
    (value, d/dt, d2/dt2) weights for (p0, m0, p1, m1) (generated/runout.py,
    derived and proved in derive/runout.py)."""
    return tuple(np.array(w) for w in _door.plain().hermite_weights(s, h))


def _at(path: np.ndarray, k: int, s: float):
    """Interpolated (X, V, A, psi, w) at s of step k (rows k, k + 1), and the
    weights used (for the sensitivities)."""
    a, b = path[k], path[k + 1]
    h = max(b[0] - a[0], 1e-12)  # a step cut back to zero length at the stop
    value, slope, curve = _hermite(s, h)
    xy = np.array([[a[1], a[2]], [a[4], a[5]], [b[1], b[2]], [b[4], b[5]]])  # p0, m0, p1, m1
    psi = np.array([a[3], a[6], b[3], b[6]])
    return value @ xy, slope @ xy, curve @ xy, float(value @ psi), float(slope @ psi), (value, slope)


def _refine(path: np.ndarray, k: int, q: np.ndarray) -> tuple[float, float]:
    """(s, squared distance) of the point of step k nearest to q: Newton on
    g(s) = (q - X)·dX/ds, kept in [0, 1]."""
    a, b = path[k, 1:3], path[k + 1, 1:3]
    d = b - a
    s = float(np.clip((q - a) @ d / max(d @ d, 1e-300), 0.0, 1.0))
    h = path[k + 1, 0] - path[k, 0]
    if h <= 0.0:
        return s, float((q - a) @ (q - a))
    for _ in range(NEWTON_STEPS):
        X, V, A, _, _, _ = _at(path, k, s)
        g = float((q - X) @ V) * h
        dg = (-float(V @ V) + float((q - X) @ A)) * h * h
        if dg >= 0.0:  # not a minimum of the distance along this step
            break
        s_new = float(np.clip(s - g / dg, 0.0, 1.0))
        if abs(s_new - s) < 1e-14:
            break
        s = s_new
    X = _at(path, k, s)[0]
    return s, float((q - X) @ (q - X))


def foot(path: np.ndarray, q: np.ndarray) -> tuple[int, float]:
    """(step k, s) of the point of the path nearest to q (module docstring)."""
    xy = path[:, 1:3]
    if xy.shape[0] < 2:
        return 0, 0.0
    a, d = xy[:-1], np.diff(xy, axis=0)
    t = np.clip(np.einsum("ij,ij->i", q - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    gap = q - (a + t[:, None] * d)
    k0 = int(np.argmin(np.einsum("ij,ij->i", gap, gap)))
    best = None
    for k in range(max(k0 - 1, 0), min(k0 + 2, xy.shape[0] - 1)):
        s, dist = _refine(path, k, q)
        if best is None or dist < best[2]:
            best = (k, s, dist)
    return best[0], best[1]


def residuals(via, path: np.ndarray, scale: float, jacobian: bool):
    """Residual rows of the intermediate poses `via` ((x, y, psi or None) each,
    SI) against the run-out `path` (rows of PATH_COLUMNS, or 8 without
    sensitivities), heading rows times `scale` [m/rad] as in the fit; and, with
    `jacobian`, their derivatives (rows, 3) with respect to (vx, vy, w)."""
    res, rows = [], []
    last = path.shape[0] - 1
    for x, y, psi in via:
        q = np.array([x, y])
        k, s = foot(path, q)
        if path.shape[0] < 2:
            X, V, A, ps, w = path[0, 1:3], path[0, 4:6], np.zeros(2), float(path[0, 3]), float(path[0, 6])
            value = slope = None
        else:
            X, V, A, ps, w, (value, slope) = _at(path, k, s)
        res += [X[0] - x, X[1] - y]
        if psi is not None:
            res.append((ps - psi) * scale)
        if not jacobian:
            continue
        Xp, Vp, psip = _sensitivities(path, k, value, slope)
        at_end = (k == 0 and s == 0.0) or (k == last - 1 and s == 1.0) or value is None
        denom = float(V @ V) - float((q - X) @ A)  # > 0 at a nearest passage
        dt = (
            np.zeros(3)
            if at_end or denom <= 0.0
            else _door.plain().foot_time_sensitivity(*q, *X, *V, *A, *Xp, *Vp)
        )
        J = Xp + np.outer(V, dt)
        rows += [J[0], J[1]]
        if psi is not None:
            rows.append((psip + w * dt) * scale)
    return np.array(res), (np.array(rows).reshape(-1, 3) if jacobian else None)


def misses(via, rows, scale: float) -> list:
    """(position miss [m], heading miss [rad] or None) per intermediate pose, from
    its residual rows (`residuals`, heading rows times `scale`)."""
    out = []
    for _, _, psi in via:
        out.append((float(np.hypot(rows[0], rows[1])), None if psi is None else abs(float(rows[2])) / scale))
        rows = rows[2 if psi is None else 3 :]
    return out


def _sensitivities(path: np.ndarray, k: int, value, slope):
    """(X_p (2, 3), V_p (2, 3), psi_p (3,)) at the interpolated point."""
    if value is None:
        row = path[0]
        return (
            np.array([row[_sens(0)], row[_sens(1)]]),
            np.array([row[_sens(3)], row[_sens(4)]]),
            row[_sens(2)],
        )
    a, b = path[k], path[k + 1]
    Xp, Vp = np.empty((2, 3)), np.empty((2, 3))
    for i, (pos, vel) in enumerate(((0, 3), (1, 4))):
        stack = np.array([a[_sens(pos)], a[_sens(vel)], b[_sens(pos)], b[_sens(vel)]])
        Xp[i], Vp[i] = value @ stack, slope @ stack
    psip = value @ np.array([a[_sens(2)], a[_sens(5)], b[_sens(2)], b[_sens(5)]])
    return Xp, Vp, psip
