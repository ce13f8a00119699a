"""The observation model of a fit: predictions y(x) and exact Jacobians dy/dx.

Everything physical comes from the generated evidence kernels (derive/evidence.py)
through :mod:`._door`; this module only composes them: the state is
z = z0 + T x, linear observations are a + B z (the kernel is affine in z, so its
value at z = 0 and its state Jacobian are a and B), and a magnitude, direction
or energy is the kernel's value with its state Jacobian chained through T.
"""

from __future__ import annotations

import math

import numpy as np

from ..codes import describe_status
from ..errors import SceneError
from ._door import evaluate
from .case import STATE, FitCase

LINEAR_PARAMS = ("m1", "m2", "I1", "I2", "r1x", "r1y", "r2x", "r2y", "theta1", "theta2", "e_m")
ENERGY_PARAMS = ("m1", "m2", "I1", "I2", "r1x", "r1y", "r2x", "r2y")
DERIVED_PARAMS = ENERGY_PARAMS + ("gamma", "e_m")


def _state_values(z) -> dict:
    return dict(zip(STATE, (float(c) for c in z)))


class Model:
    """Predictions and Jacobians of a case's observations at unknowns x."""

    def __init__(self, case: FitCase):
        self.case = case
        self._affine = {}  # (output, module) -> (a, b[9])
        rows, offsets = [], []
        for obs in case.observations:
            if obs.how[0] == "linear":
                a, b = self.affine(obs.how[1], obs.how[2])
            elif obs.how[0] == "combination":  # whitened correlated observations (rest_item.py)
                parts = [(c, self.affine(name)) for c, name in obs.how[1]]
                a, b = sum(c * ab[0] for c, ab in parts), sum(c * ab[1] for c, ab in parts)
            elif obs.how[0] == "state":
                a, b = 0.0, np.eye(9)[STATE.index(obs.how[1])]
            else:
                a, b = math.nan, None
            offsets.append(a)
            rows.append(b)
        self.one_sided = np.array([o.one_sided for o in case.observations], dtype=float)
        # a one-sided observation is affine but its residual is not: it is no part of a closed form
        self.linear = np.array([b is not None for b in rows]) & (self.one_sided == 0)
        self.affine_rows = np.array([b is not None for b in rows])
        self.values = np.array([o.value for o in case.observations])
        self.sd = np.array([o.sd for o in case.observations])
        self.angle = np.array([o.angle for o in case.observations])
        n = case.T.shape[1]
        self.B = np.array([(b @ case.T) if b is not None else np.zeros(n) for b in rows]).reshape(-1, n)
        self.a = np.array([(a + b @ case.z0) if b is not None else 0.0 for a, b in zip(offsets, rows)])

    def affine(self, output: str, module=(0.0, 0.0)):
        """(a, b) of an evidence_linear output: output = a + b·z (b over STATE)."""
        key = (output, tuple(module))
        if key not in self._affine:
            vehicle = output[-1] if output[:2] in ("dl", "dt") else "1"
            modules = {"a1": 0.0, "b1": 0.0, "a2": 0.0, "b2": 0.0}
            modules[f"a{vehicle}"], modules[f"b{vehicle}"] = module
            values = {k: self.case.params[k] for k in LINEAR_PARAMS} | modules | _state_values(np.zeros(9))
            out = evaluate("evidence_linear", values)
            if out["status"] != 0:
                raise SceneError(
                    f"cannot evaluate the observation equations: {describe_status(out['status'])}"
                )
            b = np.array([out[f"d_{output}__d_{s}"] for s in STATE])
            self._affine[key] = (out[output], b)
        return self._affine[key]

    def state(self, x) -> np.ndarray:
        return self.case.z0 + self.case.T @ x

    def predict(self, x, jacobian: bool = True):
        """(y, J): predictions of every observation at x and dy/dx (None if not
        `jacobian`); raises SceneError where a nonlinear observation is
        undefined (a zero vector has no direction)."""
        z = self.state(x)
        y = self.a + self.B @ x
        J = self.B.copy() if jacobian else None
        energy = None
        for k, obs in enumerate(self.case.observations):
            kind = obs.how[0]
            if kind in ("norm", "direction"):
                (ax, bx), (ay, by) = (self.affine(name) for name in obs.how[1])
                out = evaluate("evidence_vector", {"ax": ax + bx @ z, "ay": ay + by @ z})
                if out["status"] != 0:
                    raise SceneError(f"{obs.label}: the vector is zero, its {kind} is undefined")
                name = "norm" if kind == "norm" else "direction"
                y[k] = out[name]
                if jacobian:
                    J[k] = (out[f"d_{name}__d_ax"] * bx + out[f"d_{name}__d_ay"] * by) @ self.case.T
            elif kind == "energy":
                if energy is None:
                    values = {p: self.case.params[p] for p in ENERGY_PARAMS} | _state_values(z)
                    energy = evaluate("evidence_energy", values)
                y[k] = energy["TL"]
                if jacobian:
                    J[k] = np.array([energy[f"d_TL__d_{s}"] for s in STATE]) @ self.case.T
        return y, J

    def residuals(self, y) -> np.ndarray:
        """(y - value)/sd, angles wrapped to (-pi, pi], 0 for a one-sided
        observation whose prediction lies beyond its value in its sense."""
        diff = y - self.values
        diff = np.where(self.angle, (diff + math.pi) % (2 * math.pi) - math.pi, diff)
        diff = np.where(self._beyond(y), 0.0, diff)
        return diff / self.sd

    def _beyond(self, y) -> np.ndarray:
        """One-sided observations predicted beyond their value (by more than
        1e-9 sd: at the bound itself the observation still holds the fit)."""
        return self.one_sided * (y - self.values) > 1e-9 * self.sd

    def whitened(self, y, J):
        """(r, dr/dx): residuals and their Jacobian (rows of inactive one-sided observations 0)."""
        r = self.residuals(y)
        return r, np.where(self._beyond(y)[:, None], 0.0, J / self.sd[:, None])

    def derived(self, x, jacobian: bool = True) -> dict:
        """The evidence_derived outputs at x (e, mu, mu_c, Pn, Pt, TL, ...),
        with their gradients in x as ``grad_<name>`` when `jacobian`."""
        z = self.state(x)
        values = {p: self.case.params[p] for p in DERIVED_PARAMS} | _state_values(z)
        out = evaluate("evidence_derived", values)
        if jacobian and out["status"] == 0:
            for name in ("e", "mu", "mu_c", "Pn", "Pt", "TL", "TLn", "TLt", "TLm"):
                out[f"grad_{name}"] = np.array([out[f"d_{name}__d_{s}"] for s in STATE]) @ self.case.T
        return out

    def vector(self, x, pair, jacobian: bool = True):
        """(magnitude, direction, grad magnitude) of a pair of linear outputs at x."""
        z = self.state(x)
        (ax, bx), (ay, by) = (self.affine(name) for name in pair)
        out = evaluate("evidence_vector", {"ax": ax + bx @ z, "ay": ay + by @ z})
        if out["status"] != 0:
            return 0.0, math.nan, None
        grad = (out["d_norm__d_ax"] * bx + out["d_norm__d_ay"] * by) @ self.case.T if jacobian else None
        return out["norm"], out["direction"], grad


def energy_loss(model: Model, x, jacobian: bool = True):
    """(TL, grad TL in x) from evidence_energy at x."""
    z = model.state(x)
    out = evaluate("evidence_energy", {p: model.case.params[p] for p in ENERGY_PARAMS} | _state_values(z))
    grad = np.array([out[f"d_TL__d_{s}"] for s in STATE]) @ model.case.T if jacobian else None
    return out["TL"], grad
