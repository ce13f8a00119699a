"""`fit(scene)`: the pre-impact motion from whatever evidence a scene lists.

The answer (conventions.md, "Reconstruction from evidence") holds every
quantity the evidence determines with its 90 % interval, and null for every
quantity it does not determine, with the reason (the direction in unknown
space no evidence reaches). Admissibility (T_L ≥ 0, a compressive normal
impulse, 0 ≤ e ≤ 1, μ between 0 and μ_c) is checked as flags on the answer,
not imposed as constraints: evidence that calls for an impossible impact is
shown, not bent. Units are the scene's (angles in degrees).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..codes import describe_flags, describe_status
from ..result import json_number
from .case import STATE, FitCase, read_case
from .law import law_reading
from .model import Model, energy_loss
from .rest_item import linearity_warnings
from .solve import Z90, Identifiability, fit_case

#: Flag bits of evidence_derived (conventions.md) and the quantities each needs determined.
FLAG_NEEDS = {
    1: ("energy_loss.total",),
    2: ("impulse.normal",),
    4: ("impulse_ratio", "critical_impulse_ratio"),
    8: ("restitution",),
}
DERIVED = {
    "impulse.normal": "Pn",
    "impulse.tangential": "Pt",
    "restitution": "e",
    "impulse_ratio": "mu",
    "critical_impulse_ratio": "mu_c",
}
UNBOUNDED = 1e3
NO_ANGLE = (
    "no evidence reaches the crush-surface angle: a point impulse (Px, Py) fits any; give "
    "impact.normal_angle (a number or a distribution)"
)
NO_NORMAL = (
    "needs impact.normal_angle: the impulse (Px, Py) does not say how it splits into normal and "
    "tangential parts"
)
ENERGY_PARTS = {"energy_loss.normal": "TLn", "energy_loss.tangential": "TLt", "energy_loss.moment": "TLm"}


def quantities(model: Model, x, gradients: bool = True) -> dict:
    """path -> (value, gradient in x or None, affine) at unknowns x."""
    case = model.case
    z = model.state(x)
    q = {}

    def affine(path, output):
        a, b = model.affine(output)
        q[path] = (a + b @ z, b @ case.T, True)

    for i in range(2):
        n = i + 1
        affine(f"vehicles[{i}].speed", f"s{n}")
        for j, c in enumerate("xy"):
            row = 3 * i + j
            q[f"vehicles[{i}].velocity[{j}]"] = (z[row], case.T[row], True)
            affine(f"vehicles[{i}].final_velocity[{j}]", f"V{n}{c}")
            affine(f"vehicles[{i}].delta_v[{j}]", f"dV{n}{c}")
        q[f"vehicles[{i}].yaw_rate"] = (z[3 * i + 2], case.T[3 * i + 2], True)
        affine(f"vehicles[{i}].final_yaw_rate", f"W{n}")
        size, _, grad = model.vector(x, (f"dV{n}x", f"dV{n}y"), gradients)
        q[f"vehicles[{i}].delta_v_magnitude"] = (size, grad, False)
    for j, name in enumerate(("x", "y", "moment")):
        q[f"impulse.{name}"] = (z[6 + j], case.T[6 + j], True)
    total, grad = energy_loss(model, x, gradients)
    q["energy_loss.total"] = (total, grad, False)
    if case.has_normal:
        out = model.derived(x, gradients)
        for path, name in {**DERIVED, **ENERGY_PARTS}.items():
            value = out[name] if out["status"] == 0 else math.nan
            # with an uncertain normal angle even Pn, Pt are not affine in x alone
            q[path] = (value, out.get(f"grad_{name}"), path.startswith("impulse.") and case.normal is None)
        q["_derived"] = out
    return q


@dataclass
class Estimate:
    """One quantity: its estimate, sd and 90 % interval, or why it is not determined."""

    value: float | None
    sd: float | None = None
    interval: tuple[float, float] | None = None
    determined: bool = True
    why: str = ""


@dataclass
class FitResult:
    """The fitted impact (scene units; angles in degrees)."""

    units: str
    names: tuple[str, str]
    estimates: dict[str, Estimate]
    unknowns: list[str]
    rank: int
    condition: float
    null_space: list[dict]
    residuals: list[dict]
    flags: int
    info: dict
    warnings: list[str] = field(default_factory=list)
    law: dict | None = None  # the fit read as an alternative impact law (evidence/law.py)
    kind = "fit"

    def value(self, path: str):
        est = self.estimates[path]
        return json_number(est.value) if est.determined and est.value is not None else None

    def to_json_dict(self) -> dict[str, Any]:
        """The object ``impactsym fit --json`` prints (conventions.md)."""
        vehicles = []
        for i, name in enumerate(self.names):
            p = f"vehicles[{i}]"
            speed = self.estimates[f"{p}.speed"]
            vehicles.append(
                {
                    "name": name,
                    "speed": self.value(f"{p}.speed"),
                    "speed_sd": json_number(speed.sd) if speed.determined and speed.sd is not None else None,
                    "speed_interval": [_end(v) for v in speed.interval]
                    if speed.determined and speed.interval
                    else None,
                    "velocity": [self.value(f"{p}.velocity[{j}]") for j in range(2)],
                    "yaw_rate": self.value(f"{p}.yaw_rate"),
                    "final_velocity": [self.value(f"{p}.final_velocity[{j}]") for j in range(2)],
                    "final_yaw_rate": self.value(f"{p}.final_yaw_rate"),
                    "delta_v": [self.value(f"{p}.delta_v[{j}]") for j in range(2)],
                    "delta_v_magnitude": self.value(f"{p}.delta_v_magnitude"),
                }
            )
        has = self.estimates.get
        return {
            "units": self.units,
            "vehicles": vehicles,
            "impulse": {
                "x": self.value("impulse.x"),
                "y": self.value("impulse.y"),
                "normal": self.value("impulse.normal") if has("impulse.normal") else None,
                "tangential": self.value("impulse.tangential") if has("impulse.tangential") else None,
                "moment": self.value("impulse.moment"),
            },
            "restitution": self.value("restitution") if has("restitution") else None,
            "impulse_ratio": self.value("impulse_ratio") if has("impulse_ratio") else None,
            "critical_impulse_ratio": self.value("critical_impulse_ratio")
            if has("critical_impulse_ratio")
            else None,
            "energy_loss": {
                part: (self.value(f"energy_loss.{part}") if has(f"energy_loss.{part}") else None)
                for part in ("total", "normal", "tangential", "moment")
            },
            "identifiability": {
                "unknowns": list(self.unknowns),
                "rank": self.rank,
                "condition": json_number(self.condition),
                "determined": [p for p, e in self.estimates.items() if e.determined],
                "not_determined": [p for p, e in self.estimates.items() if not e.determined],
                "why": [
                    {"quantity": p, "reason": e.why} for p, e in self.estimates.items() if not e.determined
                ],
                "null_space": self.null_space,
            },
            "estimates": [
                {
                    "quantity": p,
                    "value": self.value(p),
                    "sd": json_number(e.sd) if e.determined and e.sd is not None else None,
                    "interval": [_end(v) for v in e.interval] if e.determined and e.interval else None,
                    "determined": e.determined,
                }
                for p, e in self.estimates.items()
            ],
            "residuals": self.residuals,
            "admissibility": {
                "checked_as": "flags",
                "flags": self.flags,
                "violations": describe_flags(self.flags),
            },
            "method": self.info,
            "warnings": list(self.warnings),
        } | ({"law": self.law} if self.law is not None else {})

    def table(self) -> str:
        from .report import table

        return table(self)


def fit(scene: Mapping | str | Path, draws: int = 400, seed: int = 0, method: str = "auto") -> FitResult:
    """Fit the impact model to a scene's evidence (conventions.md,
    "Reconstruction from evidence"). `draws` Monte Carlo draws over the
    evidence give the intervals of nonlinear quantities (0: none); `method`
    ``"auto"`` (closed form on linear evidence) or ``"gauss-newton"``.
    Raises SceneError (one line) for bad input."""
    case = read_case(scene)
    model, x_hat, y, ident, samples, info = fit_case(case, draws, seed, method)
    at = quantities(model, x_hat)
    derived = at.pop("_derived", None)
    drawn = _drawn(model, samples, _normal_draws(case, len(samples), seed))
    gaussian = info["intervals"].startswith("gaussian")
    estimates = {
        p: _estimate(p, v, g, aff, ident, gaussian, drawn.get(p), derived, case.unknowns)
        for p, (v, g, aff) in at.items()
    }
    if not case.has_normal:
        for path in (*DERIVED, *ENERGY_PARTS):
            estimates[path] = Estimate(None, determined=False, why=NO_NORMAL)
        estimates["impact.normal_angle"] = Estimate(None, determined=False, why=NO_ANGLE)
    elif case.normal is not None:
        degrees = np.degrees(_normal_draws(case, 4000, seed))
        estimates["impact.normal_angle"] = Estimate(
            math.degrees(case.params["gamma"]),
            float(np.std(degrees)),
            tuple(float(v) for v in np.percentile(degrees, [5, 95])),
        )
    residuals, worst = _residuals(case, model, y)
    flags = _flags(derived, estimates)
    warnings = _warnings(case, len(model.values), ident.rank, estimates, derived, flags, worst)
    if case.rest is not None and not samples:
        warnings += linearity_warnings(case.rest)
    if info.get("rest_refits_failed"):
        warnings.append(
            f"{info['rest_refits_failed']} of {draws} Monte Carlo draws were dropped: no separation state "
            "reaches their drawn rest pose"
        )
    if not info["converged"]:
        warnings.append(f"Gauss-Newton stopped after {info['iterations']} iterations without converging")
    return FitResult(
        units=case.units,
        names=case.names,
        estimates=estimates,
        unknowns=list(case.unknowns),
        rank=ident.rank,
        condition=ident.condition,
        null_space=_null_space(case, ident),
        residuals=residuals,
        flags=flags,
        info=info | {"draws": len(samples)},
        warnings=warnings,
        law=law_reading(case, model.state(x_hat), derived, estimates),
    )


def _warnings(case: FitCase, observations: int, rank: int, estimates, derived, flags, worst) -> list[str]:
    """The answer's warnings: the scene's, the admissibility flags, interval ends
    that run away, the item that disagrees most, the unknowns not determined."""
    warnings = list(case.warnings) + describe_flags(flags)
    unbounded = [p for p, e in estimates.items() if e.determined and e.interval and None in e.interval]
    if unbounded:
        warnings.append(
            f"the 90 % interval of {', '.join(unbounded)} is unbounded on one side: the evidence lets it run "
            "away (its end is null; e.g. a departure direction close to the heading allows any speed)"
        )
    if derived is not None and derived["status"] != 0:
        warnings.append(
            f"e, mu and mu_c are not defined at the estimate: {describe_status(derived['status'])}"
        )
    if worst is not None and observations > rank and abs(worst["z"]) > 1e-6:
        warnings.append(
            f"evidence[{worst['evidence']}] ({worst['label']}) disagrees most with the fit: z = {worst['z']:.3g}"
            + (" (beyond 3 standard deviations)" if abs(worst["z"]) > 3 else "")
        )
    elif worst is not None:
        warnings.append("the fit reproduces every item: no evidence checks another")
    restitution = estimates.get("restitution")
    if case.crush_restitution is not None and restitution is not None and restitution.interval:
        low, high = restitution.interval
        e = case.crush_restitution
        if (low is not None and e < low) or (high is not None and e > high):
            warnings.append(
                f"the crush energies were read as absorbed with crash3.restitution {e:g}, outside the fitted "
                "restitution's 90 % interval: the two readings of the impact disagree"
            )
    missing = [p for p, e in estimates.items() if not e.determined and p in case.unknowns]
    if missing:
        warnings.append(f"the evidence does not determine {', '.join(missing)} (see identifiability)")
    return warnings


def _end(value):
    return None if value is None else json_number(value)


def _normal_draws(case: FitCase, n: int, seed: int):
    """n draws of the normal angle [rad] from its distribution (None when it is a plain number)."""
    if case.normal is None or n == 0:
        return None
    kind, params, offset = case.normal
    rng = np.random.default_rng([seed, 24])
    degrees = {"normal": rng.normal, "uniform": rng.uniform, "triangular": rng.triangular}[kind](
        *params, size=n
    )
    return np.radians(degrees + offset)


def _drawn(model: Model, samples, gammas=None) -> dict:
    """path -> array of the quantity over the Monte Carlo draws (each draw with
    its own normal angle when the scene gives a distribution for it)."""
    if not samples:
        return {}
    rows, nominal = [], model.case.params["gamma"]
    try:
        for k, x in enumerate(samples):
            if gammas is not None:
                model.case.params["gamma"] = float(gammas[k])
            q = quantities(model, x, gradients=False)
            q.pop("_derived", None)
            rows.append({p: v[0] for p, v in q.items()})
    finally:
        model.case.params["gamma"] = nominal
    return {p: np.array([r[p] for r in rows], dtype=float) for p in rows[0]}


def _estimate(
    path, value, grad, affine, ident: Identifiability, gaussian, drawn, derived, unknowns
) -> Estimate:
    if not math.isfinite(value):
        why = describe_status(derived["status"]) if derived is not None and derived["status"] else "undefined"
        return Estimate(None, determined=False, why=f"not defined at the estimate: {why}")
    if not ident.determined(grad):
        return Estimate(None, determined=False, why=_why(ident, grad, unknowns))
    if affine and gaussian:
        sd = float(math.sqrt(max(grad @ ident.cov @ grad, 0.0)))
        return Estimate(float(value), sd, (value - Z90 * sd, value + Z90 * sd))
    if drawn is None or not np.isfinite(drawn).any():
        sd = float(math.sqrt(max(grad @ ident.cov @ grad, 0.0)))
        return Estimate(float(value), sd, (value - Z90 * sd, value + Z90 * sd))
    ok = drawn[np.isfinite(drawn)]
    low, high = (float(v) for v in np.percentile(ok, [5, 95]))
    # A tail a thousand times wider than the estimate and its linearised sd is
    # not an interval: the evidence lets the quantity run away (a departure
    # direction along the heading allows any speed). That end is null.
    reach = UNBOUNDED * (abs(value) + math.sqrt(max(grad @ ident.cov @ grad, 0.0)))
    ends = (None if value - low > reach else low, None if high - value > reach else high)
    sd = float(np.std(ok, ddof=1)) if None not in ends else None
    return Estimate(float(value), sd, ends)


def _why(ident: Identifiability, grad, unknowns) -> str:
    """The null directions the quantity changes along, in words."""
    if grad is None or not np.all(np.isfinite(grad)):
        return "its derivative is undefined at the estimate"
    vecs = ident.null_x()
    along = np.abs(grad @ vecs)
    words = [
        "(" + " ".join(f"{c:+.4g}·{name}" for c, name in zip(vecs[:, j], unknowns) if c != 0) + ")"
        for j in np.nonzero(along > 1e-6 * along.max())[0]
    ]
    return f"changes along {' and '.join(words)} in the unknowns, which no evidence reaches"


def _null_space(case: FitCase, ident: Identifiability) -> list[list[float]]:
    """The null directions, components in the order of `unknowns`, largest 1."""
    vecs = ident.null_x()
    return [[round(float(c), 6) + 0.0 for c in vecs[:, j]] for j in range(vecs.shape[1] if vecs.size else 0)]


def _residuals(case: FitCase, model: Model, y):
    r = model.residuals(y)
    out, worst = [], None
    for k, obs in enumerate(case.observations):
        scale = math.degrees(1.0) if obs.angle else 1.0
        fitted = y[k] if not obs.angle else obs.value + r[k] * obs.sd
        row = {
            "evidence": obs.evidence,
            "label": obs.label,
            "value": json_number(obs.value * scale),
            "fitted": json_number(float(fitted) * scale),
            "z": json_number(float(r[k])),
        }
        out.append(row)
        if worst is None or abs(r[k]) > abs(worst["z"]):
            worst = row | {"z": float(r[k])}
    return out, worst


def _flags(derived, estimates) -> int:
    """Admissibility flag bits whose quantities the evidence determines. Without
    a normal (no evidence_derived) only the energy loss can be checked: T_L < 0,
    beyond 1e-12 of its interval's width, is energy created (bit 1)."""
    if derived is None:
        total = estimates["energy_loss.total"]
        if total.determined and total.value is not None:
            width = (
                max(abs(v) for v in total.interval if v is not None) if total.interval else abs(total.value)
            )
            return 1 if total.value < -1e-12 * width else 0
        return 0
    if derived["status"] != 0:
        return 0
    flags = 0
    for bit, needs in FLAG_NEEDS.items():
        if derived["flags"] & bit and all(estimates[p].determined for p in needs):
            flags |= bit
    return flags


__all__ = ["FitResult", "STATE", "fit"]
