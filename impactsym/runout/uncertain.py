"""``reconstruct --uncertainty`` of a scene that gives rest poses: the
distributions propagated through both run-outs and the impact.

Inputs (conventions.md, "Uncertainty"): every numeric leaf the impact reading
takes (``impactsym.scene.load_scene``: masses, inertias, headings, impact
points, the normal ...) and the run-out's leaves, read by the same
:class:`~impactsym.scene.casefile.LeafReader` (numbers, unit strings or
distributions): ``runout.friction``, ``runout.slip_angle_max``,
``runout.rolling_resistance``, ``impact.position``, and per vehicle
``friction``, ``rest.position``, ``rest.heading``, ``separation.position``,
``separation.heading``, each wheel's ``brake`` and ``steer`` (and ``state`` as
probabilities of locked and rolling: a CHOICE input, `_state_leaf`), each tyre-mark
direction (``separation.mark_directions.<wheel>``) and each intermediate pose
(``intermediate[j].position``, ``.heading``). The impact leaves a run-out also
uses (mass, yaw inertia, heading, impact point) enter both.

Monte Carlo (`impactsym.uncertainty.propagate`, the engine of every
``--uncertainty``): per draw each vehicle's separation state is fitted to its
drawn rest pose under its drawn run-out (drawfit.py: batched over the draws,
the first started from the nominal fit plus the linear prediction below, with
the nominal J plus its first-order change dJ/dx dx, central differences of the
integrated sensitivities along each input's prediction, the rest from their
nearest fitted draw: `reach`, drawfit.Neighbours), then the impact is
reconstructed from the fitted states. A draw whose fit fails is
rejected and counted by reason.

Linear method: at the nominal fit p of a vehicle, R(p, theta) = T (rest pose
reached = rest pose given), so dp/dx = J^-1 (dT/dx - dR/dtheta dtheta/dx) for
each input x, with J = dR/dp and dR/dmu the sensitivities the kernel
integrates, dR/d(x0, y0) the identity (the run-out does not depend on where it
starts) and dR/dpsi0 from its invariance under rotation (rotating the start
pose and the separation velocity about the start rotates the rest pose),
``dR/dpsi0 = (-(y_R - y0), x_R - x0, 1) - J (-vy, vx, 0)``, derived and emitted as
generated/runout.py `rest_heading_sensitivity` (derive/runout.py). The kernel has no
sensitivities for the other run-out columns (m, I, alpha_max, f_r, brake,
steer): those come from central differences of forward run-outs at
`FD_TOL`, step 1 % of the input's sd. The separation states so linearised go
through the engine's chain (the scene map, the exact reconstruct Jacobian,
the JSON map) to ``sd_linear`` and ``budget``. A vehicle with tyre-mark
directions or intermediate poses is fitted in least squares over its rest pose
and them: its dp/dx is -pinv(J_r) dr/dx over all (`_least_squares_slopes`),
and each draw is fitted by fit.py's Newton (drawfit.py).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from ..errors import SceneError
from ..residue import without_json_residue
from ..scene import load_scene, scene_columns, scene_data
from ..scene.casefile import parse_correlations
from ..uncertainty import Source, propagate
from ..uncertainty.commands import RECONSTRUCT, Command
from ..uncertainty.inputs import Input
from ..uncertainty.propagation import linear_method, linearity_notes
from . import _door
from .batch import columns, run_row, runout_batch
from .chain import reconstruct_from_rest
from .drawfit import NOT_CONVERGED, Neighbours, draw_tolerances, fit_draws, variant
from .fit import evaluate, heading_scale
from .leaves import WHEEL_KEYS, nominal_data, runout_reasons, with_final
from .scene import SLUG, RunoutScene, load_runout, row_values

FD_TOL = 1e-10  # integrator tolerance of the central differences (docs/runout.md: error ~6e-7 m)
# Integrator tolerance of the nominal sensitivities: at the default 1e-8 they were 2 % off the
# central differences of forward run-outs for a braked wheel (chain_solve's SUV; 1e-12: 0.05 %).
SENS_TOL = 1e-12
FD_STEP = 1e-2  # of the input's sd
# The neighbour-search scale of a wheel's locked/rolling choice (m/s per unit, `reach`):
# far beyond any drawn state's spread, so that draws of other wheel states are never near.
APART = 1e6
# Why a draw's fit failed (its rejection reason, after "vehicles[k] run-out: ").
MISSED = "no separation state reaches the drawn rest pose"
UNSETTLED = "the least squares over the drawn rest pose, marks and poses did not converge"
#: Run-out columns whose sensitivity the kernel integrates or the module doc derives.
KNOWN = ("vx", "vy", "w", "mu", "x", "y", "psi")


@dataclass
class Evidence:
    """A vehicle's tyre-mark directions (wheel key -> (rows,) [rad]) and
    intermediate poses ([(x, y [m], psi [rad] or None), ...], each (rows,))
    per row of a run-out table."""

    marks: dict
    via: list

    def row(self, i: int) -> tuple[dict, tuple]:
        """(marks, via) of row i, as a RunoutVehicle holds them."""
        marks = {key: float(a[i]) for key, a in self.marks.items()}
        via = tuple(
            (float(x[i]), float(y[i]), None if psi is None else float(psi[i])) for x, y, psi in self.via
        )
        return marks, via

    def rows(self, index: np.ndarray) -> Evidence:
        """The rows `index` only."""
        return Evidence(
            {key: a[index] for key, a in self.marks.items()},
            [(x[index], y[index], None if psi is None else psi[index]) for x, y, psi in self.via],
        )


@dataclass
class Chained:
    """A reconstruction from rest poses read for propagation (SI inside, scene
    units at the edges): the impact Scene with the nominal fitted final
    motion, the nominal run-out scene, the run-out leaves, the nominal fitted
    states p (SI), their Jacobians J, linear predictions A (3 x inputs) and
    the Jacobians' slopes dJ (inputs x 3 x 3) along those predictions;
    `work` counts the draws' run-outs, fitted rows and exact-Newton rows."""

    result: dict
    impact: object
    runout: RunoutScene
    leaves: dict
    inputs: tuple
    correlations: tuple
    p: list
    J: list = field(default_factory=list)
    A: list = field(default_factory=list)
    dJ: list = field(default_factory=list)
    work: dict = field(default_factory=lambda: {"runouts": 0, "exact_rows": 0, "fit_rows": 0})

    @property
    def length(self) -> float:
        return self.runout.length()

    # ------------------------------------------------------------------ the draws' run-out rows

    def split(self, overrides: Mapping) -> tuple[dict, dict, np.ndarray, int]:
        """(impact columns, run-out leaf values, reason per row, rows) of `overrides`."""
        impact = {k: v for k, v in overrides.items() if k not in self.leaves}
        arrays = {k: np.asarray(v, dtype=np.float64) for k, v in overrides.items() if k in self.leaves}
        sc = scene_columns(self.impact, impact)
        n = max([sc.rows] + [a.shape[0] for a in arrays.values()])
        reason = np.broadcast_to(sc.reason, (n,)).copy()
        own = runout_reasons(self.leaves, arrays, n)
        reason[reason == ""] = own[reason == ""]
        values = {path: leaf.nominal for path, leaf in self.leaves.items()}
        values.update(arrays)
        return dict(sc.columns), values, reason, n

    def table(self, k: int, values: Mapping, cols: Mapping, n: int) -> tuple[np.ndarray, np.ndarray]:
        """Vehicle k's run-out rows (n, COLUMNS; vx, vy, w zero) and rest targets (n, 3), SI."""
        vehicle, length, num = self.runout.vehicles[k], self.length, k + 1
        mass = SLUG if self.runout.units == "US" else 1.0
        p = f"vehicles[{k}]"
        row = dict(vehicle.row, vx=0.0, vy=0.0, w=0.0)
        row["m"], row["I"] = cols[f"m{num}"] * mass, cols[f"I{num}"] * mass * length**2
        if f"{p}.separation.position[0]" in values:
            row["x"] = values[f"{p}.separation.position[0]"] * length
            row["y"] = values[f"{p}.separation.position[1]"] * length
        else:
            row["x"] = (values.get("impact.position[0]", 0.0) - cols[f"r{num}x"]) * length
            row["y"] = (values.get("impact.position[1]", 0.0) - cols[f"r{num}y"]) * length
        heading = values.get(f"{p}.separation.heading")
        row["psi"] = cols[f"theta{num}"] if heading is None else np.deg2rad(heading)
        row["mu"] = values.get(f"{p}.friction", values.get("runout.friction", row["mu"]))
        if f"{p}.cg_height" in values:
            row["h"] = values[f"{p}.cg_height"] * length
        if "runout.slip_angle_max" in values:
            row["alpha_max"] = np.deg2rad(values["runout.slip_angle_max"])
        row["f_r"] = values.get("runout.rolling_resistance", row["f_r"])
        for name, key in WHEEL_KEYS.items():
            row[f"state_{key}"] = values.get(f"{p}.wheels.{name}.state", row[f"state_{key}"])
            row[f"brake_{key}"] = values.get(f"{p}.wheels.{name}.brake", row[f"brake_{key}"])
            steer = values.get(f"{p}.wheels.{name}.steer")
            if steer is not None:
                row[f"steer_{key}"] = np.deg2rad(steer)
        table = np.column_stack(
            [np.broadcast_to(np.asarray(row[c], dtype=np.float64), (n,)) for c in columns()]
        )
        rest = [values[f"{p}.rest.position[0]"] * length, values[f"{p}.rest.position[1]"] * length]
        target = np.column_stack(
            [
                np.broadcast_to(np.asarray(x, dtype=np.float64), (n,))
                for x in (*rest, np.deg2rad(values[f"{p}.rest.heading"]))
            ]
        )
        return table, target

    def evidence(self, k: int, values: Mapping, n: int) -> Evidence | None:
        """Vehicle k's tyre-mark directions and intermediate poses per row (SI,
        rad), None without them."""
        vehicle, length, p = self.runout.vehicles[k], self.length, f"vehicles[{k}]"
        if not (vehicle.marks or vehicle.via):
            return None

        def column(path: str, scale: float) -> np.ndarray:
            return np.broadcast_to(np.asarray(values[path], dtype=np.float64) * scale, (n,))

        marks = {
            key: column(f"{p}.separation.mark_directions.{name}", math.pi / 180)
            for name, key in WHEEL_KEYS.items()
            if key in vehicle.marks
        }
        via = [
            (
                column(f"{p}.intermediate[{j}].position[0]", length),
                column(f"{p}.intermediate[{j}].position[1]", length),
                None if psi is None else column(f"{p}.intermediate[{j}].heading", math.pi / 180),
            )
            for j, (*_, psi) in enumerate(vehicle.via)
        ]
        return Evidence(marks, via)

    def deviation(self, overrides: Mapping, n: int) -> np.ndarray:
        """(n, inputs): each input's draw minus its nominal value."""
        return (
            np.column_stack(
                [
                    np.broadcast_to(np.asarray(overrides[x.path], dtype=np.float64), (n,)) - x.nominal
                    for x in self.inputs
                ]
            )
            if self.inputs
            else np.zeros((n, 0))
        )

    def set_final(self, cols: dict, k: int, p: np.ndarray) -> None:
        """The reconstruct columns of vehicle k's final motion from separation states p (SI)."""
        num = k + 1
        cols[f"V{num}x"], cols[f"V{num}y"], cols[f"W{num}"] = (
            p[:, 0] / self.length,
            p[:, 1] / self.length,
            p[:, 2],
        )

    # ------------------------------------------------------------------ the two column maps

    def exact_columns(self, overrides: Mapping):
        """Reconstruct columns with every vehicle's separation state fitted per
        draw. The vehicles' fits run at once (`_fit_vehicle` on a thread each:
        their run-outs share the room's threads, so one vehicle's Python
        between two batches overlaps the other's run-outs); a row fails with
        the first vehicle whose fit fails there."""
        cols, values, reason, n = self.split(overrides)
        dx = self.deviation(overrides, n)
        rows = np.flatnonzero(reason == "")
        ks = range(len(self.runout.vehicles))
        with ThreadPoolExecutor(max_workers=len(ks), thread_name_prefix="impactsym-vehicle") as side:
            fits = list(side.map(lambda k: self._fit_vehicle(k, values, cols, n, dx, rows), ks))
        for k, (p, failed, work) in zip(ks, fits):
            for key, count in work.items():
                self.work[key] += count
            for code, text in failed:
                own = rows[code]
                reason[own[reason[own] == ""]] = f"vehicles[{k}] run-out: {text}"
            self.set_final(cols, k, p)
        return cols, reason

    def _fit_vehicle(self, k: int, values, cols, n: int, dx: np.ndarray, rows: np.ndarray):
        """Vehicle k's fitted states (n, 3; NaN where not fitted) at `rows`, its
        failures ((mask over `rows`, reason text) per failure code) and its
        work (counts for `work`)."""
        vehicle = self.runout.vehicles[k]
        table, target = self.table(k, values, cols, n)
        evidence = self.evidence(k, values, n)
        p = np.full((n, 3), math.nan)
        if not rows.size:
            return p, (), {}
        start = self.p[k] + dx[rows] @ self.A[k].T
        first = self.J[k] + np.einsum("nj,jab->nab", dx[rows], self.dJ[k])
        tols, tol = draw_tolerances(self.J[k], start - self.p[k])
        drawn = evidence.rows(rows) if evidence is not None else None
        near = Neighbours(dx[rows] * self.reach(k, vehicle), dx[rows] @ (self.J[k] @ self.A[k]).T)
        fit = fit_draws(table[rows], target[rows], start, self.p[k], first, vehicle, tol, tols, drawn, near)
        p[rows] = fit.state
        work = {"runouts": fit.runouts, "exact_rows": fit.exact_rows, "fit_rows": rows.size}
        failed = [
            (fit.status == code, text)
            for code, text in (
                (NOT_CONVERGED, MISSED if evidence is None else UNSETTLED),
                (2, "the run-out failed"),
            )
        ]
        return p, failed, work

    def reach(self, k: int, vehicle) -> np.ndarray:
        """(inputs,): how far vehicle k's fitted state moves per unit of each
        input to first order, |diag(1, 1, R_max) dp/dx_j| (m/s per input unit):
        the scale of drawfit's neighbour search, where a draw's deviations
        times it place the draws whose fitted states are alike near each other."""
        scale = np.array([1.0, 1.0, heading_scale(vehicle.row)])
        reach = np.linalg.norm(self.A[k] * scale[:, None], axis=0)
        own = [x.discrete and x.path.startswith(f"vehicles[{k}].") for x in self.inputs]
        reach[own] = APART  # a draw's neighbours share its wheel states
        return reach

    def linear_columns(self, overrides: Mapping):
        """Reconstruct columns with the separation states linear in the inputs."""
        cols, _values, reason, n = self.split(overrides)
        dx = self.deviation(overrides, n)
        for k in range(len(self.runout.vehicles)):
            self.set_final(cols, k, self.p[k] + dx @ self.A[k].T)
        return cols, reason

    # ------------------------------------------------------------------ linear prediction

    def linearise(self) -> None:
        """J and A of each vehicle at its nominal fit (module docstring)."""
        names = columns()
        k = len(self.inputs)
        # a choice (a wheel locked or rolling) has no derivative: it stays at its nominal
        # value, its columns of A and dJ/dx come out zero (the linear method leaves it out)
        step = np.array([0.0 if x.discrete else FD_STEP * x.sd for x in self.inputs])
        h = np.where(step > 0.0, step, 1.0)
        x0 = np.array([x.nominal for x in self.inputs])
        grid = np.repeat(x0[None, :], 2 * k, axis=0)
        for j in range(k):
            grid[2 * j, j] += step[j]
            grid[2 * j + 1, j] -= step[j]
        over = {x.path: grid[:, j] for j, x in enumerate(self.inputs)}
        cols, values, _, n = self.split(over) if k else self.split({})
        base_cols, base_values, _, _ = self.split({})
        other = [i for i, c in enumerate(names) if c not in KNOWN]
        for kv, vehicle in enumerate(self.runout.vehicles):
            p = self.p[kv]
            y, _, status, _, _ = run_row(row_values(vehicle, names, *p), tol=SENS_TOL, sens=True)
            if status != 0:
                raise SceneError("the run-out at the nominal fitted state failed", f"vehicles[{kv}]")
            S = y[7:].reshape(6, 4)
            J = S[:3, :3]
            self.J.append(J)
            if not k:
                self.A.append(np.zeros((3, 0)))
                self.dJ.append(np.zeros((0, 3, 3)))
                continue
            table, target = self.table(kv, values, cols, n)
            base, _ = self.table(kv, base_values, base_cols, 1)
            dtheta = (table[0::2] - table[1::2]) / (2 * h[:, None])
            dT = (target[0::2] - target[1::2]) / (2 * h[:, None])
            x0_, y0_ = base[0, names.index("x")], base[0, names.index("y")]
            spsi = np.array(
                _door.plain().rest_heading_sensitivity(x0_, y0_, y[0], y[1], p[0], p[1], *J[:, :2].ravel())
            )
            dR = (
                np.outer(dtheta[:, names.index("mu")], S[:3, 3])
                + np.outer(dtheta[:, names.index("x")], [1.0, 0.0, 0.0])
                + np.outer(dtheta[:, names.index("y")], [0.0, 1.0, 0.0])
                + np.outer(dtheta[:, names.index("psi")], spsi)
            )
            dR += self._other_sensitivities(base[0], p, dtheta, h, other)
            if vehicle.marks or vehicle.via:  # least squares over the rest pose and the evidence
                self.A.append(self._least_squares_slopes(kv, dR - dT, table, target, values, h))
            else:
                self.A.append(np.linalg.solve(J, (dT - dR).T))
            self.dJ.append(self._jacobian_slopes(vehicle, base[0], p, self.A[-1], dtheta, h))

    def _least_squares_slopes(self, k, dr, table, target, values, h) -> np.ndarray:
        """(3, inputs): dp/dx of vehicle k's least-squares fit over its rest pose,
        tyre marks and intermediate poses, -pinv(Jr) dr/dx to first order (the
        fit's `determination` rule), Jr the Jacobian of fit.py's weighted
        residual at the nominal state (`evaluate`, tolerance SENS_TOL) and dr/dx
        its change with each input: `dr` (inputs, 3) for the rest pose, central
        differences of the evidence rows over the rows of `table` (each input
        moved by +-h, the evidence's own values with it; run-outs at FD_TOL) for
        the rest."""
        vehicle, p, names = self.runout.vehicles[k], self.p[k], columns()
        weight = np.array([1.0, 1.0, heading_scale(vehicle.row)])
        _, Jr = evaluate(vehicle, names, p, SENS_TOL)
        evidence = self.evidence(k, values, table.shape[0])
        rows = []
        for i in range(table.shape[0]):
            r, _ = evaluate(variant(vehicle, table[i], target[i], *evidence.row(i)), names, p, FD_TOL)
            if r is None:
                raise SceneError(
                    "a run-out near the nominal fitted state failed (linear method)", f"vehicles[{k}]"
                )
            rows.append(r[3:])
        rows = np.array(rows)
        de = (rows[0::2] - rows[1::2]) / (2 * h[:, None])
        return -np.linalg.pinv(Jr) @ np.hstack([dr * weight, de]).T

    def _jacobian_slopes(self, vehicle, base, p, A, dtheta, h) -> np.ndarray:
        """(inputs, 3, 3): dJ/dx_j along the linear prediction (the separation
        state moved by A_j, the run-out columns by dtheta_j), by central
        differences of the integrated sensitivities: each draw's first Jacobian
        in drawfit.py is J + sum_j dJ/dx_j dx_j (a chord step with the nominal J
        alone leaves about a tenth of the miss)."""
        names = columns()
        slopes = np.zeros((len(h), 3, 3))
        for j in range(len(h)):
            if not (np.any(A[:, j]) or np.any(dtheta[j])):
                continue  # the input does not move this run-out (the other car's, a wheel choice): no slope
            ends = []
            for sign in (1.0, -1.0):
                row = base + sign * h[j] * dtheta[j]
                row[[names.index(c) for c in ("vx", "vy", "w")]] = p + sign * h[j] * A[:, j]
                y, _, status, _, _ = run_row(row, tol=SENS_TOL, sens=True)
                ends.append(y[7:].reshape(6, 4)[:3, :3] if status == 0 else np.full((3, 3), np.nan))
            slopes[j] = (ends[0] - ends[1]) / (2 * h[j])
        return np.nan_to_num(slopes)  # a failed run-out: no slope, the nominal J

    def _other_sensitivities(self, base, p, dtheta, h, other) -> np.ndarray:
        """(inputs, 3): dR/dx_j through the run-out columns without kernel
        sensitivities, by central differences of forward run-outs."""
        out = np.zeros((len(h), 3))
        moving = [j for j in range(len(h)) if np.any(dtheta[j, other] != 0.0)]
        if not moving:
            return out
        names = columns()
        rows = np.repeat(base[None, :], 2 * len(moving), axis=0)
        for i, j in enumerate(moving):
            rows[2 * i, other] += h[j] * dtheta[j, other]
            rows[2 * i + 1, other] -= h[j] * dtheta[j, other]
        cols = {c: rows[:, i] for i, c in enumerate(names)}
        cols["vx"], cols["vy"], cols["w"] = p[0], p[1], p[2]
        res = runout_batch(cols, tol=FD_TOL)
        if np.any(res["status"] != 0):
            raise SceneError("a run-out near the nominal fitted state failed (linear method)", "runout")
        rest = np.column_stack([res["x_rest"], res["y_rest"], res["psi_rest"]])
        for i, j in enumerate(moving):
            out[j] = (rest[2 * i] - rest[2 * i + 1]) / (2 * h[j])
        return out


def _outputs(c: Mapping, o: Mapping) -> dict:
    """The reconstruct outputs and each vehicle's fitted separation motion (complex-safe)."""
    out = RECONSTRUCT.outputs(c, o)
    for i in (1, 2):
        p = f"vehicles[{i - 1}].runout.separation"
        vx, vy = c[f"V{i}x"], c[f"V{i}y"]
        out[f"{p}.velocity[0]"], out[f"{p}.velocity[1]"] = vx, vy
        out[f"{p}.speed"], out[f"{p}.yaw_rate"] = np.sqrt(vx * vx + vy * vy), c[f"W{i}"]
    return out


def load_chained(scene) -> Chained:
    """Read a reconstruct-from-rest scene with distributions; fit and linearise
    the nominal run-outs. One-line SceneError for a bad scene."""
    data, leaves, impact = nominal_data(scene)
    result = reconstruct_from_rest(data)
    finals = [
        (*e["runout"]["separation"]["velocity"], e["runout"]["separation"]["yaw_rate"])
        for e in result["vehicles"]
    ]
    ro = copy.deepcopy(data)
    for v in ro["vehicles"]:
        v.get("separation", {}).pop("velocity", None)
        v.get("separation", {}).pop("yaw_rate", None)
    runout_scene = load_runout(ro)
    length = runout_scene.length()
    impact_scene = load_scene(with_final(impact, finals), kind="reconstruct")
    everything = {**impact_scene.leaves, **leaves}
    uncertain = [leaf for leaf in everything.values() if leaf.kind is not None]
    inputs = tuple(Input(leaf.path, leaf.kind, tuple(leaf.params)) for leaf in uncertain)
    raw = scene_data(scene)
    correlations = parse_correlations(raw["correlations"], everything) if "correlations" in raw else ()
    p = [np.array([vx * length, vy * length, w]) for vx, vy, w in finals]
    chained = Chained(result, impact_scene, runout_scene, leaves, inputs, tuple(correlations), p)
    chained.linearise()
    return chained


def chained_uncertainty(scene, draws: int = 10_000, seed: int | None = None, sobol: bool = False):
    """(Chained, Uncertainty) of a reconstruct-from-rest scene (module docstring)."""
    chained = load_chained(scene)
    exact = Source(
        Command("reconstruct", RECONSTRUCT.run, lambda c: (None, {}), _outputs),
        chained.inputs,
        chained.exact_columns,
        chained.correlations,
    )
    u = propagate(exact, draws=draws, seed=seed, sobol=sobol)
    linear = Source(
        Command("reconstruct", RECONSTRUCT.run, RECONSTRUCT.jacobian_kernel, _outputs),
        chained.inputs,
        chained.linear_columns,
        chained.correlations,
    )
    first_order = linear_method(linear)
    for path, stats in u.outputs.items():
        stats["sd_linear"], u.budget[path] = first_order.get(path, (math.nan, {}))
    # propagate's own sd_linear is NaN here (the exact Source has no Jacobian kernel): noted once, now
    u.notes += linearity_notes(u.outputs, u.accepted, u.n_draws)
    choices = [x.path for x in chained.inputs if x.discrete]
    if choices:
        u.notes.append(
            f"the linear method holds {', '.join(choices)} at the more probable state: sd_linear and the "
            "budget leave the wheel states out; the Monte Carlo draws them (and --sobol's indices weigh them)"
        )
    return chained, u


def reconstruct_uncertainty(scene, draws: int = 10_000, seed: int | None = None, sobol: bool = False) -> dict:
    """``impactsym reconstruct SCENE --uncertainty --json`` of a scene with rest
    poses: the chained reconstruction's JSON plus ``"uncertainty"``."""
    return uncertainty_json(*chained_uncertainty(scene, draws, seed, sobol))


def uncertainty_json(chained: Chained, u) -> dict:
    """The chained reconstruction's JSON with ``"uncertainty"`` (rounding residue shown as 0)."""
    return without_json_residue({**chained.result, "uncertainty": u.to_json_dict()})
