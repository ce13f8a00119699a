"""A ``rest`` evidence item: a vehicle's rest pose, read through its run-out.

``{"vehicle": k, "quantity": "rest", "value": {"position": [x, y], "heading": deg},
"sd": {"position": σ_p, "heading": σ_ψ}}`` with the scene's top-level ``runout``
block and the vehicle's run-out data (``wheelbase``, ``cg_to_front_axle``,
``track``, ``wheels``, optionally ``separation.position`` / ``.heading`` and
``friction``; conventions.md, "Post-impact run-out").

The run-out's separation state p = (V_kx, V_ky, W_k) is fitted to the rest pose
R (impactsym.runout.fit_rest). To first order dp = J⁻¹ (dR - S_μ dμ), J = dR/dp
and S_μ = dR/dμ the exact sensitivities the run-out kernel integrates
(runout.interval.separation_sensitivity). The friction μ may be uncertain:
``runout.friction`` given as ``{"normal": [mean, sd]}`` is one road shared by
every rest item (both vehicles' observations move together with it), a
vehicle's own ``friction`` distribution is that vehicle's alone. So the rest
items together observe the stacked separation states P with the covariance

    C = blockdiag(J_k⁻¹ diag(σ_p², σ_p², σ_ψ²) J_k⁻ᵀ) + Σ_sources σ_μ² s sᵀ,

s the stacked dp_k/dμ of the items that read that friction (zero elsewhere).
P is linear in the fit's unknowns; the correlated observations are whitened
with the Cholesky factor C = L Lᵀ in its unit-lower form: observation i is
(L_ii L⁻¹)_i · P with sd L_ii (V_1x, then V_1y given V_1x, ...; the sum of the
squared residuals is the full-covariance one). This linearisation weights the
fit and gives its point estimate; the intervals come from Monte Carlo refits
of drawn rest poses and frictions, each draw re-weighed at its refitted states
(rest_refit.py), since the run-out is far from linear over a rest pose's
spread for some wheel setups.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import SceneError, show_value
from ..runout import fit_rest, load_runout
from ..runout.fit import Fit, newton
from ..runout.interval import separation_sensitivity
from ..runout.scene import RUNOUT_VEHICLE_KEYS as RUNOUT_KEYS
from ..runout.scene import RunoutVehicle
from ..scene.casefile import LeafReader, check_keys
from .items import Observation, vehicle_index

#: A fit vehicle's keys that only a rest item reads (the run-out's chassis and
#: tyres; the item's own pose is its value, and intermediate poses are not read).
RUNOUT_VEHICLE_KEYS = tuple(key for key in RUNOUT_KEYS if key not in ("rest", "intermediate"))
POSE_KEYS = ("position", "heading")
NONLINEAR = 0.2  # sd of the separation state: a linearisation departing more is named
LABELS = ("Vx", "Vy", "W")


@dataclass
class RestFit:
    """One rest item read: the vehicle's run-out (SI, nominal friction, the
    measured rest pose), its fitted separation state and the sensitivities
    there, the rest pose's sds (SI, rad) and the friction it reads."""

    evidence: int
    vehicle: int
    runout: RunoutVehicle
    fit: Fit
    sigma: np.ndarray  # sd of (x, y, psi) at rest: m, m, rad
    friction: str  # "runout.friction" or "vehicles[i].friction"
    length: float  # metres per scene length unit
    sensitivity: np.ndarray  # d(vx, vy, w)/d(x, y, psi, mu), SI, 3 x 4

    @property
    def label(self) -> str:
        return f"vehicles[{self.vehicle}].rest"

    @property
    def outputs(self) -> tuple[str, str, str]:
        n = self.vehicle + 1
        return (f"V{n}x", f"V{n}y", f"W{n}")

    @property
    def to_scene(self) -> np.ndarray:
        """Scene units per SI unit of (vx, vy, w)."""
        return np.array([1 / self.length, 1 / self.length, 1.0])

    def state(self) -> np.ndarray:
        """The fitted separation state, scene units."""
        return np.array([*self.fit.velocity, self.fit.yaw_rate]) * self.to_scene


@dataclass
class RestEvidence:
    """Every rest item of a fit, whitened together: `rows` are the indices of
    their observations in the case's list (in the order of the stacked
    states), `frictions` each friction source's (mean, sd)."""

    items: list[RestFit]
    frictions: dict
    rows: list[int] = dataclasses.field(default_factory=list)

    @property
    def outputs(self) -> list[str]:
        """The stacked separation states' outputs (V1x, V1y, W1, ...), in row order."""
        return [name for rest in self.items for name in rest.outputs]

    def whitening(self, sensitivities=None):
        """(unit_lower, sd): the observations of the stacked states P are
        unit_lower @ P with sds `sd` (module docstring), from each item's
        sensitivities (3 x 4 SI; default: at its fitted state)."""
        size = 3 * len(self.items)
        cov = np.zeros((size, size))
        shared = {name: np.zeros(size) for name in self.frictions}
        for j, rest in enumerate(self.items):
            sens = rest.sensitivity if sensitivities is None else sensitivities[j]
            block = slice(3 * j, 3 * j + 3)
            spread = sens[:, :3] * rest.sigma * rest.to_scene[:, None]
            cov[block, block] = spread @ spread.T
            shared[rest.friction][block] = sens[:, 3] * rest.to_scene
        for name, (_, sd) in self.frictions.items():
            cov += sd**2 * np.outer(shared[name], shared[name])
        chol = np.linalg.cholesky((cov + cov.T) / 2)
        return np.diag(np.diag(chol)) @ np.linalg.inv(chol), np.diag(chol).copy()


def read_rest(item: Mapping, k: int, data: Mapping, case_values, warnings: list) -> RestFit:
    """Rest item `k` read and fitted (module docstring). `case_values` =
    (units, names, fixed, params) of the fit case (scene units, radians); fit
    warnings are appended to `warnings`."""
    units, names, fixed, params = case_values
    path = f"evidence[{k}]"
    if "at" in item:
        raise SceneError("only delta_v_longitudinal and delta_v_lateral are read at a module", f"{path}.at")
    i = vehicle_index(item.get("vehicle"), names, f"{path}.vehicle")
    if fixed[i]:
        raise SceneError("vehicle is fixed: it has no run-out", f"{path}.vehicle")
    leaves = LeafReader(units)
    pose = _pose(item.get("value"), f"{path}.value", leaves, "value")
    sd = _pose(item.get("sd"), f"{path}.sd", leaves, "sd")
    vehicle = _runout_vehicle(data, i, pose, params)
    fit = fit_rest(vehicle)
    length = 0.3048 if units == "US" else 1.0
    label = f"vehicles[{i}].rest"
    if not fit.converged:
        warnings.append(
            f"{path} ({label}): the run-out fit to the rest pose did not converge in {fit.iterations} "
            f"iterations (residual {fit.residual_position / length:.3g} {_unit(units)}, "
            f"{math.degrees(fit.residual_heading):.3g} deg); its observations are where it stopped"
        )
    for alt in fit.alternatives:
        warnings.append(
            f"{path} ({label}): another separation state reaches the same rest pose: velocity "
            f"[{alt.velocity[0] / length:.3f}, {alt.velocity[1] / length:.3f}] {_unit(units)}/s, yaw rate "
            f"{alt.yaw_rate:.3f} rad/s (used: the one nearest the run-out's starting estimate)"
        )
    try:
        sensitivity = separation_sensitivity(vehicle, fit)
    except (ValueError, np.linalg.LinAlgError):
        raise SceneError(
            "the run-out at the fitted separation state has no invertible sensitivity to it", path
        ) from None
    sigma = np.array([sd[0] * length, sd[1] * length, math.radians(sd[2])])  # SI, rad
    own = "friction" in data["vehicles"][i]
    source = f"vehicles[{i}].friction" if own else "runout.friction"
    return RestFit(k, i, vehicle, fit, sigma, source, length, sensitivity)


def frictions(data: Mapping, rests: list[RestFit]) -> dict:
    """Each friction source the rest items read -> (mean, sd); sd 0 for a plain number."""
    out = {}
    for rest in rests:
        if rest.friction not in out:
            head, key = rest.friction.rsplit(".", 1)
            holder = data["runout"] if head == "runout" else data["vehicles"][rest.vehicle]
            out[rest.friction] = friction_prior(holder[key], rest.friction)
    return out


def friction_prior(raw, path: str) -> tuple[float, float]:
    """(mean, sd) of a friction given as a number or ``{"normal": [mean, sd]}``."""
    leaf = LeafReader("SI")
    leaf.number(raw, path, "number", "positive")
    found = leaf.leaves[path]
    if found.kind not in (None, "normal"):
        raise SceneError(
            f'a fit carries an uncertain friction as {{"normal": [mean, sd]}}, got {show_value(raw)}', path
        )
    return (found.nominal, found.params[1] if found.kind else 0.0)


def rest_evidence(rests: list[RestFit], sources: dict) -> tuple[list[Observation], RestEvidence]:
    """The whitened observations of every rest item together (module
    docstring), in item order, and the record the Monte Carlo redraws."""
    evidence = RestEvidence(rests, dict(sources))
    try:
        unit_lower, sd = evidence.whitening()
    except np.linalg.LinAlgError:
        raise SceneError(
            "the rest pose does not fix the separation state (singular covariance)",
            f"evidence[{rests[0].evidence}]",
        ) from None
    states = np.concatenate([rest.state() for rest in rests])
    outputs = evidence.outputs
    observations = []
    for row in range(len(outputs)):
        rest = rests[row // 3]
        given = " (whitened)" if np.any(unit_lower[row, :row]) else ""
        combination = tuple(
            (float(unit_lower[row, m]), outputs[m]) for m in range(row + 1) if unit_lower[row, m] != 0.0
        )
        observations.append(
            Observation(
                rest.evidence,
                f"{rest.label}: {LABELS[row % 3]}{given}",
                float(unit_lower[row] @ states),
                float(sd[row]),
                ("combination", combination),
            )
        )
    return observations, evidence


def linearity_warnings(evidence: RestEvidence) -> list[str]:
    """A warning per rest item whose run-out is far from linear over its rest
    pose's sd (the linearised intervals a fit without draws reports are then
    too narrow)."""
    out = []
    for rest in evidence.items:
        departure = _nonlinearity(rest)
        if departure > NONLINEAR:
            out.append(
                f"evidence[{rest.evidence}] ({rest.label}): the run-out is not linear over the rest pose's "
                f"sd (refitted at +-1 sd the separation state is {departure:.2g} sd from the linear "
                "prediction): without Monte Carlo draws the intervals it drives are linearised and too "
                "narrow; give draws"
            )
    return out


def _nonlinearity(rest: RestFit) -> float:
    """The largest departure, in standard deviations of the separation state
    (whitened by its Cholesky factor, SI), of the state refitted to the rest
    pose moved by +-1 sd of each coordinate from the linear prediction
    p +- J^-1 sigma_j (Newton from the fitted state, runout.fit.newton)."""
    spread = rest.sensitivity[:, :3] * rest.sigma
    chol = np.linalg.cholesky(spread @ spread.T)
    start = (*rest.fit.velocity, rest.fit.yaw_rate)
    p0 = np.array(start)
    worst = 0.0
    for j in range(3):
        for sign in (1.0, -1.0):
            moved_rest = list(rest.runout.rest)
            moved_rest[j] += sign * rest.sigma[j]
            moved = newton(dataclasses.replace(rest.runout, rest=tuple(moved_rest)), start)
            if not moved.converged:
                return math.inf
            error = np.array([*moved.velocity, moved.yaw_rate]) - p0 - sign * spread[:, j]
            worst = max(worst, float(np.linalg.norm(np.linalg.solve(chol, error))))
    return worst


def _pose(raw, path: str, leaves: LeafReader, what: str) -> tuple[float, float, float]:
    """(x, y, heading) of a rest value, or (σ_p, σ_p, σ_ψ) of its sd (scene
    length unit, degrees as given)."""
    if raw is None:
        hint = "(every evidence item needs its standard deviation)" if what == "sd" else ""
        raise SceneError(f"missing {hint}".strip(), path)
    if not isinstance(raw, Mapping):
        form = '{"position": sd, "heading": sd}' if what == "sd" else '{"position": [x, y], "heading": deg}'
        raise SceneError(f"must be {form}, got {show_value(raw)}", path)
    check_keys(raw, POSE_KEYS, path)
    for key in POSE_KEYS:
        if key not in raw:
            raise SceneError("missing", f"{path}.{key}")
    if what == "sd":
        sigma = leaves.number(raw["position"], f"{path}.position", "length", "positive")
        return (sigma, sigma, leaves.number(raw["heading"], f"{path}.heading", "angle", "positive"))
    position = raw["position"]
    if not isinstance(position, list) or len(position) != 2:
        raise SceneError(f"must be [x, y], got {show_value(position)}", f"{path}.position")
    x, y = (leaves.number(c, f"{path}.position[{j}]", "length") for j, c in enumerate(position))
    return (x, y, leaves.number(raw["heading"], f"{path}.heading", "angle"))


def _runout_vehicle(data: Mapping, i: int, pose, params: dict):
    """Vehicle i's run-out (impactsym.runout.load_runout) with the fit's mass,
    inertia, heading and impact point (scene units), the rest pose `pose` and
    the nominal friction (the mean of a friction distribution)."""
    if "runout" not in data:
        raise SceneError("missing (a rest item needs the run-out's tyre data)", "runout")
    entry = data["vehicles"][i]
    path = f"vehicles[{i}]"
    for key in ("wheelbase", "cg_to_front_axle", "track", "wheels"):
        if key not in entry:
            raise SceneError("missing (a rest item of this vehicle needs its run-out data)", f"{path}.{key}")
    separation = entry.get("separation", {})
    if isinstance(separation, Mapping):
        for key in ("velocity", "yaw_rate", "mark_directions"):
            if key in separation:
                raise SceneError(
                    "not read by fit: the rest item fits the separation state (give it as final_velocity, "
                    "final_yaw_rate or final_direction evidence)",
                    f"{path}.separation.{key}",
                )
    n = i + 1
    vehicle = {key: entry[key] for key in RUNOUT_VEHICLE_KEYS if key in entry}
    if "friction" in vehicle:
        vehicle["friction"] = friction_prior(vehicle["friction"], f"{path}.friction")[0]
    vehicle |= {
        "name": str(entry.get("name", f"vehicle {n}")),
        "mass": params[f"m{n}"],
        "yaw_inertia": params[f"I{n}"],
        "heading": math.degrees(params[f"theta{n}"]),
        "impact_point": [params[f"r{n}x"], params[f"r{n}y"]],
        "rest": {"position": [pose[0], pose[1]], "heading": pose[2]},
    }
    road = data["runout"]
    if isinstance(road, Mapping) and "friction" in road:
        road = {**road, "friction": friction_prior(road["friction"], "runout.friction")[0]}
    scene = {"units": data["units"], "runout": road, "vehicles": [vehicle]}
    impact = data.get("impact", {})
    if isinstance(impact, Mapping) and "position" in impact:
        scene["impact"] = {"position": impact["position"]}
    try:
        return load_runout(scene).vehicles[0]
    except SceneError as exc:  # the run-out reader names vehicles[0]: name the fit's vehicle
        field = exc.field or ""
        message = str(exc)[len(field) + 2 :] if field else str(exc)
        raise SceneError(message, field.replace("vehicles[0]", path, 1) or None) from None


def _unit(units: str) -> str:
    return "ft" if units == "US" else "m"
