"""Weighted least squares on the evidence, identifiability, and intervals.

Unknowns x (case.py); whitened residuals r = (y(x) - value)/sd. A moment
impulse (``impact.moment_restitution`` given) brings the exact linear
constraint R_em = 0, removed by parametrising x = xp + N u.

- Linear evidence only: one least-squares solve is the answer (closed form,
  SVD pseudo-inverse); the estimate is Gaussian with covariance
  (Jᵀ J)⁺ in the determined directions.
- Nonlinear evidence (final speeds and directions, |delta-V|, energy):
  Gauss–Newton with the exact Jacobians (step by the pseudo-inverse, halved
  while the sum of squares grows), started from a linear problem (the linear
  items, each direction as the line it puts the velocity on, a speed and a
  direction of one vector as its components, weak priors on the speeds).
- Identifiability: SVD of the whitened Jacobian with its columns scaled to
  unit norm; singular values below 1e-9 of the largest span the null space.
  A quantity is determined when its gradient has no component along the null
  space (relative 1e-6); otherwise it is reported null with the null
  direction as the reason.
- Intervals (90 %): affine quantities of a linear problem from the Gaussian
  covariance (±1.645 σ, exact); everything else by Monte Carlo over the
  evidence (each value redrawn from its normal, refitted; a linear problem
  without rest poses draws x from its Gaussian directly; rest poses and
  their frictions are redrawn and refitted through the run-out,
  rest_refit.py, since their observations are a linearisation): 5th and
  95th percentiles.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError
from .case import STATE, FitCase
from .model import Model
from .rest_refit import draw_whitened

RANK_TOL = 1e-9
DETERMINED_TOL = 1e-6
Z90 = 1.6448536269514722


def constraint(model: Model):
    """(xp, N): the unknowns satisfying moment restitution, x = xp + N u."""
    case = model.case
    n = case.T.shape[1]
    if not case.moment:
        return np.zeros(n), np.eye(n)
    a, b = model.affine("R_em")
    c = b @ case.T
    c0 = a + b @ case.z0
    if not np.any(c):
        return np.zeros(n), np.eye(n)
    xp = -c * c0 / (c @ c)
    _, _, vt = np.linalg.svd(c.reshape(1, -1))
    return xp, vt[1:].T


def _scaled_pinv_step(Jw, r):
    """The minimum-norm least-squares step of Jw·d = -r, columns scaled to unit norm."""
    scale = np.linalg.norm(Jw, axis=0)
    scale[scale == 0] = 1.0
    step, *_ = np.linalg.lstsq(Jw / scale, -r, rcond=RANK_TOL)
    return step / scale


MAX_ITERATIONS = 60


def gauss_newton(model: Model, xp, N, u0, values=None, max_iter=MAX_ITERATIONS):
    """Minimise |r|² over u (x = xp + N u) from u0; returns (u, iterations)."""
    saved = model.values
    if values is not None:
        model.values = values
    try:
        u = np.array(u0, dtype=float)
        r, Jw = model.whitened(*model.predict(xp + N @ u))
        cost = r @ r
        for iteration in range(1, max_iter + 1):
            step = _scaled_pinv_step(Jw @ N, r)
            t = 1.0
            while True:
                trial = u + t * step
                try:
                    r2, Jw2 = model.whitened(*model.predict(xp + N @ trial))
                    cost2 = r2 @ r2
                except SceneError:
                    cost2 = math.inf
                if cost2 <= cost * (1 + 1e-12):
                    break
                if t < 1e-6:  # no step along this direction lowers the sum of squares
                    return u, iteration
                t /= 2
            u, Jw, r, old, cost = trial, Jw2, r2, cost, cost2
            if np.linalg.norm(t * step) <= 1e-12 * (1 + np.linalg.norm(u)) or abs(old - cost) <= 1e-15 * (
                1 + old
            ):
                return u, iteration
        return u, max_iter
    finally:
        model.values = saved


def linear_solve(model: Model, xp, N, values=None):
    """The closed-form weighted least-squares answer of a linear problem (u)."""
    values = model.values if values is None else values
    Jw = (model.B / model.sd[:, None]) @ N
    r = (model.a + model.B @ xp - values) / model.sd
    return _scaled_pinv_step(Jw, r)


def start(model: Model, xp, N) -> np.ndarray:
    """A starting point for Gauss–Newton: the least-squares answer of a linear
    surrogate (see the module docstring)."""
    case = model.case
    rows, rhs, sds = [], [], []
    for k, obs in enumerate(case.observations):
        if model.affine_rows[k]:
            rows.append(model.B[k])
            rhs.append(model.values[k] - model.a[k])
            sds.append(obs.sd)
    scale = _speed_scale(model)
    directions = {o.how[1]: o for o in case.observations if o.how[0] == "direction"}
    for obs in case.observations:
        kind = obs.how[0]
        if kind == "direction":
            (ax, bx), (ay, by) = (model.affine(n) for n in obs.how[1])
            c, s = math.cos(obs.value), math.sin(obs.value)
            row = -s * bx + c * by
            rows.append(row @ case.T)
            rhs.append(-(-s * ax + c * ay + row @ case.z0))
            sds.append(max(obs.sd, 1e-3) * scale)
        elif kind == "norm" and obs.how[1] in directions:
            d = directions[obs.how[1]].value
            for (a, b), comp in zip((model.affine(n) for n in obs.how[1]), (math.cos(d), math.sin(d))):
                rows.append(b @ case.T)
                rhs.append(obs.value * comp - a - b @ case.z0)
                sds.append(obs.sd)
    masses = [case.params[m] for m in ("m1", "m2") if math.isfinite(case.params[m])]
    for j, name in enumerate(case.unknowns):
        prior = np.eye(len(case.unknowns))[j]
        if name.endswith(".speed"):
            rows.append(prior), rhs.append(scale), sds.append(100 * scale)
        else:
            rows.append(prior), rhs.append(0.0), sds.append(1e3 * scale * min(masses))
    A = np.array(rows) / np.array(sds)[:, None]
    b = (np.array(rhs) - np.array(rows) @ xp) / np.array(sds)
    return _scaled_pinv_step(A @ N, -b)


def _from_start(model: Model, xp, N, u0):
    """Gauss–Newton from u0, or, where an observation is undefined there (a
    zero delta-V or final velocity has no magnitude derivative or direction),
    from u0 moved by a fixed small offset of each unknown's scale."""
    try:
        return gauss_newton(model, xp, N, u0)
    except SceneError:
        scale = _speed_scale(model)
        masses = [model.case.params[m] for m in ("m1", "m2") if math.isfinite(model.case.params[m])]
        size = np.array([scale if n.endswith((".speed", ".yaw_rate")) else 0.1 * scale * min(masses)
                         for n in model.case.unknowns])  # fmt: skip
        offset = np.linalg.lstsq(N, size * np.cos(np.arange(len(size)) + 1.0), rcond=None)[0]
        return gauss_newton(model, xp, N, u0 + offset)


def _speed_scale(model: Model) -> float:
    speeds = [
        abs(o.value)
        for o in model.case.observations
        if o.label.endswith(("speed", "velocity[0]", "velocity[1]"))
    ]
    default = 10.0 if model.case.units == "SI" else 30.0
    return float(np.median(speeds)) if speeds and np.median(speeds) > 0 else default


class Identifiability:
    """SVD of the whitened, column-scaled Jacobian at the estimate."""

    def __init__(self, Jw, N):
        self.N = N
        M = Jw @ N
        scale = np.linalg.norm(M, axis=0)
        scale[scale == 0] = 1.0
        self.scale = scale
        _, s, vt = np.linalg.svd(M / scale, full_matrices=True)
        s = np.concatenate([s, np.zeros(vt.shape[0] - len(s))])
        self.singular = s
        self.rank = int(np.sum(s > RANK_TOL * s[0])) if s.size and s[0] > 0 else 0
        self.condition = float(s[0] / s[self.rank - 1]) if self.rank else math.inf
        self.null_u = vt[self.rank :].T  # scaled u space
        kept = vt[: self.rank].T
        cov_scaled = kept @ np.diag(1.0 / s[: self.rank] ** 2) @ kept.T
        cov_u = cov_scaled / np.outer(scale, scale)
        self.cov = N @ cov_u @ N.T  # in x

    def null_x(self) -> np.ndarray:
        """A basis of the null directions in x (columns) in reduced echelon
        form over the unknowns in order: each direction has a 1 on an unknown
        the others do not move (so a speed nothing reaches is a direction of
        its own, apart from a rotation of the impulse)."""
        vecs = self.N @ (self.null_u / self.scale[:, None])
        if not vecs.size:
            return vecs
        rows = (vecs / np.linalg.norm(vecs, axis=0)).T.copy()
        pivot_row = 0
        for j in range(rows.shape[1]):
            if pivot_row == rows.shape[0]:
                break
            r = pivot_row + int(np.argmax(np.abs(rows[pivot_row:, j])))
            if abs(rows[r, j]) < 1e-8:
                continue
            rows[[pivot_row, r]] = rows[[r, pivot_row]]
            rows[pivot_row] /= rows[pivot_row, j]
            for other in range(rows.shape[0]):
                if other != pivot_row:
                    rows[other] -= rows[other, j] * rows[pivot_row]
            pivot_row += 1
        rows[np.abs(rows) < 1e-12 * np.max(np.abs(rows), axis=1, keepdims=True)] = 0.0
        return rows.T

    def determined(self, grad) -> bool:
        """True when `grad` (in x) has no component along the null space."""
        if grad is None or not np.all(np.isfinite(grad)):
            return False
        g = (self.N.T @ grad) / self.scale
        size = np.linalg.norm(g)
        if size == 0 or self.null_u.shape[1] == 0:
            return True
        return bool(np.linalg.norm(self.null_u.T @ g) <= DETERMINED_TOL * size)


def draw_fits(model: Model, xp, N, u_hat, ident: Identifiability, linear: bool, draws: int, seed: int):
    """Monte Carlo over the evidence: (the unknowns x of each accepted draw,
    rest-pose refits that failed). A linear problem without rest poses draws x
    from its Gaussian; otherwise each draw redraws every observation value
    (rest poses refitted through the run-out, rest_refit.py) and refits."""
    rng = np.random.default_rng(seed)
    rest = model.case.rest
    if linear and rest is None:
        cov = ident.cov
        w, v = np.linalg.eigh((cov + cov.T) / 2)
        root = v * np.sqrt(np.clip(w, 0, None))
        x_hat = xp + N @ u_hat
        return [x_hat + root @ rng.standard_normal(len(w)) for _ in range(draws)], 0
    values = model.values + model.sd * rng.standard_normal((draws, len(model.sd)))
    whitened = draw_whitened(rest, rng, draws) if rest is not None else [None] * draws
    saved = model.a.copy(), model.B.copy(), model.sd.copy()
    outputs = _outputs(model, rest.outputs) if rest is not None else None
    out, failed = [], 0
    try:
        for drawn, rest_rows in zip(values, whitened):
            if rest is not None:
                if rest_rows is None:
                    failed += 1
                    continue
                _reweigh(model, rest.rows, outputs, rest_rows, drawn)
            x = _refit(model, xp, N, u_hat, linear, drawn)
            if x is not None:
                out.append(x)
    finally:
        model.a, model.B, model.sd = saved
    return out, failed


def _outputs(model: Model, names) -> tuple[np.ndarray, np.ndarray]:
    """(a, B): evidence_linear outputs `names` as a + B x in the unknowns."""
    pairs = [model.affine(name) for name in names]
    case = model.case
    return np.array([a + b @ case.z0 for a, b in pairs]), np.array([b @ case.T for _, b in pairs])


def _reweigh(model: Model, rows, outputs, rest_rows, drawn) -> None:
    """Set the rest observations' rows of `model` (offsets, Jacobian rows,
    sds) and their values in `drawn` to one Monte Carlo draw's whitening
    (rest_refit.draw_whitened); `outputs` = (a, B) of the stacked states."""
    unit_lower, sd, states = rest_rows
    a, B = outputs
    model.a[rows], model.B[rows], model.sd[rows] = unit_lower @ a, unit_lower @ B, sd
    drawn[rows] = unit_lower @ states


def _refit(model: Model, xp, N, u_hat, linear: bool, values):
    """The unknowns x fitted to one draw's `values` (None if Gauss–Newton fails)."""
    if linear:
        return xp + N @ linear_solve(model, xp, N, values)
    try:
        u, _ = gauss_newton(model, xp, N, u_hat, values=values, max_iter=20)
    except SceneError:
        return None
    return xp + N @ u


def fit_case(case: FitCase, draws: int = 400, seed: int = 0, method: str = "auto"):
    """Estimate x; return (model, x_hat, ident, samples, info)."""
    model = Model(case)
    xp, N = constraint(model)
    linear = bool(np.all(model.linear))
    if method == "gauss-newton" or not linear:
        u0 = start(model, xp, N) if not linear else np.zeros(N.shape[1])
        u_hat, iterations = _from_start(model, xp, N, u0)
    else:
        u_hat, iterations = linear_solve(model, xp, N), 0
    x_hat = xp + N @ u_hat
    y, J = model.predict(x_hat)
    ident = Identifiability(model.whitened(y, J)[1], N)
    samples, failed = draw_fits(model, xp, N, u_hat, ident, linear, draws, seed) if draws else ([], 0)
    info = {
        "linear": linear,
        "intervals": _intervals(linear, case, draws),
        "iterations": iterations,
        "converged": iterations < MAX_ITERATIONS,
        "method": "closed form" if iterations == 0 else "gauss-newton",
    }
    if case.rest is not None and draws:
        info["rest_refits_failed"] = failed
    return model, x_hat, y, ident, samples, info


def _intervals(linear: bool, case: FitCase, draws: int) -> str:
    """How the answer's 90 % intervals are found (``method.intervals``)."""
    if linear and (case.rest is None or not draws):
        return "gaussian" + (" (rest poses linearised)" if case.rest is not None else "")
    if not draws:
        return "linearised (no draws)"
    return "monte carlo over the evidence" + (", rest poses refitted" if case.rest is not None else "")


__all__ = ["STATE", "fit_case"]
