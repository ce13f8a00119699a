"""Independent reference for the run-out: scipy's solve_ivp on the contract's
equations, written here by hand from conventions.md ("Post-impact run-out"),
sharing no code with derive/ or generated/.

Test support, not runtime code (needs scipy). Same smoothing as the kernels
(a speed u that divides or gives a sign enters as max(|u|, eps)) and the same
stop (|v| + |w| R_max < v_stop), so that the comparison measures the
integrator alone. Inputs are one row of the batch columns as a dict (SI, rad).

Load transfer (a row's ``h`` > 0, the vehicle's cg_height) is written from the
textbook statement, not from derive's linear solve: the front axle gains
m h a_l/L of the rear's load (a_l the forward acceleration), the right wheels
m h a_s/track of the left's (a_s leftward), shared between the axles as their
static loads are; the loads are found by fixed-point iteration (loads ->
forces -> acceleration -> loads) to 1e-13 of the weight.
"""

from __future__ import annotations

import math

import numpy as np

EPS = 0.0005
V_STOP = 1e-3


def _wheels(row: dict):
    """(position, load, state, brake, steer) of fl, fr, rl, rr."""
    wb, a, half, m, g = row["L"], row["a"], row["track"] / 2, row["m"], row["g"]
    b = wb - a
    spots = [(a, half), (a, -half), (-b, half), (-b, -half)]
    loads = [m * g * b / (2 * wb)] * 2 + [m * g * a / (2 * wb)] * 2
    return [
        (np.array(spots[i]), loads[i], row[f"state_{k}"], row[f"brake_{k}"], row[f"steer_{k}"])
        for i, k in enumerate(("fl", "fr", "rl", "rr"))
    ]


def tyre_force(u: np.ndarray, load: float, state: float, brake: float, steer: float, row: dict, eps=EPS):
    """The wheel force in the vehicle frame for contact velocity u (vehicle frame)."""
    mu, amax, f_r = row["mu"], row["alpha_max"], row["f_r"]
    if state == 1.0:
        return -mu * load * u / max(np.hypot(*u), eps)
    e_l = np.array([math.cos(steer), math.sin(steer)])
    e_s = np.array([-math.sin(steer), math.cos(steer)])
    ul, us = u @ e_l, u @ e_s
    along = (brake * mu if brake > 0 else f_r) * load
    f_l = -along * ul / max(abs(ul), eps)
    alpha = math.atan2(abs(us), max(abs(ul), eps))
    cap = math.sqrt(1 - brake * brake)
    f_s = -mu * load * math.copysign(1.0, us) * min(alpha / amax, cap) if us != 0 else 0.0
    return f_l * e_l + f_s * e_s


def _body_force(vb, w, row: dict, wheels, loads, eps):
    """(force in the vehicle frame, moment) with the wheels at `loads`."""
    force, moment = np.zeros(2), 0.0
    for (r, _, state, brake, steer), load in zip(wheels, loads):
        u = vb + w * np.array([-r[1], r[0]])
        f = tyre_force(u, load, state, brake, steer, row, eps)
        force += f
        moment += r[0] * f[1] - r[1] * f[0]
    return force, moment


def transferred_loads(row: dict, wheels, accel) -> list[float]:
    """Wheel loads under quasi-static load transfer at body acceleration accel = (a_l, a_s)."""
    m, h, wb, a, track = row["m"], row.get("h", 0.0), row["L"], row["a"], row["track"]
    pitch = m * h * accel[0] / wb  # load the front axle gains from the rear when a_l < 0
    roll = m * h * accel[1] / track  # load the right wheels gain from the left
    shares = ((wb - a) / wb,) * 2 + (a / wb,) * 2  # the axles' static shares
    sides = (-1, 1, -1, 1)  # fl, fr, rl, rr: left loses, right gains
    axle = (-0.5, -0.5, 0.5, 0.5)
    return [w[1] + axle[k] * pitch + sides[k] * shares[k] * roll for k, w in enumerate(wheels)]


def rhs(t, y, row: dict, wheels, eps=EPS, guess=None):
    """d/dt (x, y, psi, vx, vy, w, distance). With load transfer, `guess` (a
    list, or None) carries the body force of the last call into the next as
    the fixed point's start (the loads move little between two calls: 10
    iterations a call instead of 14.5); the converged loads are the same."""
    psi, vx, vy, w = y[2], y[3], y[4], y[5]
    c, s = math.cos(psi), math.sin(psi)
    vb = np.array([c * vx + s * vy, -s * vx + c * vy])
    loads = [wheel[1] for wheel in wheels]
    force, moment = _body_force(vb, w, row, wheels, loads, eps)
    if row.get("h", 0.0) > 0.0:
        if guess:
            force = guess[0]
        for _ in range(200):
            loads = transferred_loads(row, wheels, force / row["m"])
            new, moment = _body_force(vb, w, row, wheels, loads, eps)
            done = np.abs(new - force).max() < 1e-13 * row["m"] * row["g"]
            force = new
            if done:
                break
        else:
            raise RuntimeError("load transfer did not converge")
        if guess is not None:
            guess[:] = [force]
    fx, fy = c * force[0] - s * force[1], s * force[0] + c * force[1]
    return [vx, vy, w, fx / row["m"], fy / row["m"], moment / row["I"], math.hypot(vx, vy)]


def reference_runout(
    row: dict, rtol: float = 1e-10, atol: float = 1e-12, method: str = "DOP853", eps=EPS, dense: bool = False
):
    """(x_rest, y_rest, psi_rest, t, distance) by solve_ivp to the stop event."""
    from scipy.integrate import solve_ivp

    wheels = _wheels(row)
    radius = max(np.hypot(*w[0]) for w in wheels)

    def stopped(t, y, *args):
        return math.hypot(y[3], y[4]) + abs(y[5]) * radius - V_STOP

    stopped.terminal = True
    stopped.direction = -1
    y0 = [row["x"], row["y"], row["psi"], row["vx"], row["vy"], row["w"], 0.0]
    sol = solve_ivp(
        rhs,
        (0.0, 600.0),
        y0,
        method=method,
        rtol=rtol,
        atol=atol,
        events=stopped,
        args=(row, wheels, eps, []),
        dense_output=dense,
    )
    y = sol.y[:, -1]
    return (y[0], y[1], y[2], sol.t[-1], y[6]) + ((sol,) if dense else ())
