"""Monte Carlo over rest-pose evidence: each drawn rest pose (and friction)
refitted to its separation state, all draws of an item at once.

A rest item's observations are a linearisation of the run-out at the fitted
separation state (rest_item.py); for some wheel setups (front wheels locked,
rear rolling) the run-out is far from linear over a rest pose's spread and
intervals from that linearisation undercover (71 and 75 of 100 trials held the
truth at 90 %, session 7). Here each Monte Carlo draw of the fit redraws every
rest pose from its normal (independent coordinates, sds as given) and every
friction source once (a road's friction shared by the items that read it),
and refits the separation state that reaches it: the drawn observation values
are then what the fit would have seen with that rest pose, with no
linearisation, and so are their weights: the covariance that whitens them is
recomputed from the exact sensitivities at each refitted state (with the
weights held at the measured rest poses' the struck car's interval of the
slow coverage test's setup held the truth in 172 of 200 trials, recomputed in
180 of 200, seed 99) (in one dimension the percentile interval of a monotone function
of normal data is exact whatever its curvature; measured coverage in
tests/test_evidence_rest.py and the report of this change).

The refit is batched: every draw of an item starts at the linear prediction
p̂ + J⁻¹(R* - R̂) + dp/dμ (μ* - μ̂) and iterates Broyden's ("good") update of
the inverse Jacobian, per draw, from J⁻¹ at the fitted state, each iteration one
run-out of all unconverged draws through the batch driver
(impactsym.runout.runout_batch). Each draw has a trust radius (scaled: heading
and yaw rate times the wheelbase), first TRUST times the fitted state's size:
a step that does not lower the residual is rejected (its secant still updates
the inverse) and the radius quartered; an accepted one at least doubles it.
Without it the first secant steps of a strongly curved run-out reached 1,000 m/s
(measured), where one run-out takes seconds. Draws not within REFIT_POSITION and
REFIT_HEADING of their rest pose after BROYDEN_STEPS iterations are refitted
one by one with the exact sensitivities (runout.fit.newton); a draw that still
fails is dropped (counted in the fit's ``method.rest_refits_failed``). The
sensitivities at the refitted states cost one run-out with sensitivities per
draw and item (runout.interval.separation_sensitivity).
"""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np

from ..runout import runout_batch
from ..runout.fit import newton
from ..runout.interval import separation_sensitivity
from .rest_item import RestEvidence, RestFit

BROYDEN_STEPS = 30
TRUST = 0.25  # first step at most this share of the fitted separation state (scaled norm)
# A draw is refitted once its run-out ends within these of the drawn rest pose:
# far below any rest pose's sd, and 10 x the run-out fit's own tolerances
# (runout.fit: 1e-4 m, 1e-5 rad), which the integrator's noise would blur for
# secant updates.
REFIT_POSITION = 1e-3  # m
REFIT_HEADING = 1e-4  # rad


def draw_whitened(evidence: RestEvidence, rng: np.random.Generator, draws: int) -> list:
    """Per draw, the rest observations as the fit would have read them from
    that draw's rest poses and frictions: (unit_lower, sd, P), P the stacked
    refitted separation states (scene units) and unit_lower, sd the whitening
    of their covariance from the sensitivities at the refitted states
    (rest_item.RestEvidence.whitening), so each draw re-runs the whole
    estimator, weights included; None for a draw whose refit failed."""
    mu = {
        name: mean + sd * rng.standard_normal(draws) if sd > 0 else np.full(draws, mean)
        for name, (mean, sd) in evidence.frictions.items()
    }
    states, sensitivities = [], []
    for rest in evidence.items:
        poses = np.array(rest.runout.rest) + rest.sigma * rng.standard_normal((draws, 3))
        p = refit(rest, poses, mu[rest.friction])
        states.append(p * rest.to_scene)
        sensitivities.append([_sensitivity(rest, p[j], mu[rest.friction][j]) for j in range(draws)])
    out = []
    for j, stacked in enumerate(np.hstack(states)):
        sens = [s[j] for s in sensitivities]
        if not np.all(np.isfinite(stacked)) or any(s is None for s in sens):
            out.append(None)
            continue
        try:
            unit_lower, sd = evidence.whitening(sens)
        except np.linalg.LinAlgError:
            out.append(None)
            continue
        out.append((unit_lower, sd, stacked))
    return out


def _sensitivity(rest: RestFit, p: np.ndarray, mu: float):
    """d(vx, vy, w)/d(x, y, psi, mu) at separation state p (SI) with friction
    mu (runout.interval.separation_sensitivity), or None where undefined."""
    if not np.all(np.isfinite(p)):
        return None
    vehicle = dataclasses.replace(rest.runout, row=dict(rest.runout.row, mu=float(mu)))
    try:
        return separation_sensitivity(vehicle, SimpleNamespace(velocity=(p[0], p[1]), yaw_rate=p[2]))
    except (ValueError, np.linalg.LinAlgError):
        return None


def refit(rest: RestFit, poses: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """Separation states (draws x 3, SI) reaching `poses` (draws x 3: x, y, psi,
    SI) with friction `mu` (draws); NaN where no refit converged (module
    docstring)."""
    n = len(poses)
    sens = rest.sensitivity
    scale = np.array([1.0, 1.0, rest.runout.row["L"]])  # heading and yaw rate as metres at the wheelbase
    p_hat = np.array([*rest.fit.velocity, rest.fit.yaw_rate])
    p = p_hat + (poses - np.array(rest.runout.rest)) @ sens[:, :3].T
    p += np.outer(mu - rest.runout.row["mu"], sens[:, 3])
    # Broyden's inverse in the scaled variables: d(p*scale)/d(residual*scale)
    inverse = np.repeat((scale[:, None] * sens[:, :3] / scale[None, :])[None], n, axis=0)
    residual = _residual(rest, p, poses, mu) * scale
    radius = np.full(n, TRUST * np.linalg.norm(p_hat * scale))
    todo = np.nonzero(np.all(np.isfinite(residual), axis=1))[0]
    for _ in range(BROYDEN_STEPS):
        todo = todo[~_close(residual[todo] / scale) & (radius[todo] > 1e-9 * radius.max())]
        if not todo.size:
            break
        step = -np.einsum("nij,nj->ni", inverse[todo], residual[todo])
        length = np.linalg.norm(step, axis=1)
        step *= np.minimum(1.0, radius[todo] / np.maximum(length, 1e-300))[:, None]
        moved = p[todo] + step / scale
        new = _residual(rest, moved, poses[todo], mu[todo]) * scale
        change = new - residual[todo]
        s_h = np.einsum("ni,nij->nj", step, inverse[todo])
        denom = np.einsum("ni,ni->n", s_h, change)
        learn = np.all(np.isfinite(new), axis=1) & (np.abs(denom) > 0)
        # Broyden's good update of the inverse, H += (s - H y) sT H / (sT H y), from every
        # finite trial (a rejected step still tells the secant)
        h_change = np.einsum("nij,nj->ni", inverse[todo], change)
        safe = np.where(learn, denom, 1.0)[:, None, None]
        inverse[todo[learn]] += (np.einsum("ni,nj->nij", step - h_change, s_h) / safe)[learn]
        better = learn & (np.linalg.norm(new, axis=1) < np.linalg.norm(residual[todo], axis=1))
        rows = todo[better]
        p[rows], residual[rows] = moved[better], new[better]
        radius[rows] = np.maximum(radius[rows], 2 * length[better])
        radius[todo[~better]] /= 4
    for j in np.nonzero(~_close(residual / scale))[0]:
        row = dict(rest.runout.row, mu=float(mu[j]))
        vehicle = dataclasses.replace(rest.runout, rest=tuple(poses[j]), row=row)
        found = newton(vehicle, tuple(p[j]))
        p[j] = (*found.velocity, found.yaw_rate) if found.converged else (np.nan,) * 3
    return p


def _residual(rest: RestFit, p: np.ndarray, poses: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """Rest pose reached minus drawn (draws x 3, SI; NaN rows where the run-out failed)."""
    columns = dict(rest.runout.row, vx=p[:, 0], vy=p[:, 1], w=p[:, 2], mu=mu)
    out = runout_batch(columns)
    reached = np.column_stack([out["x_rest"], out["y_rest"], out["psi_rest"]])
    reached[out["status"] != 0] = np.nan
    return reached - poses


def _close(residual: np.ndarray) -> np.ndarray:
    """Draws within REFIT_POSITION and REFIT_HEADING of their rest pose (False for NaN)."""
    return (np.hypot(residual[:, 0], residual[:, 1]) < REFIT_POSITION) & (
        np.abs(residual[:, 2]) < REFIT_HEADING
    )
