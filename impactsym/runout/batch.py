"""`runout_batch(columns)`: one run-out per row, separation to rest (SI, radians).

Columns (conventions.md, "Post-impact run-out"): ``m I L a track mu alpha_max f_r g
x y psi vx vy w`` and per wheel k in ``fl fr rl rr``: ``state_k`` (0 rolling, 1
locked), ``brake_k`` (0..1), ``steer_k`` (rad). ``alpha_max`` (default 10 deg in
rad), ``f_r`` (0.01), ``g`` (9.80665), ``h`` (the centre of gravity's height [m];
0: the contract's static wheel loads, > 0: quasi-static load transfer) and the
wheel columns (0) may be left out: the documented defaults of a scene file.
Outputs ``x_rest y_rest psi_rest`` (psi unwrapped) ``t distance status steps``;
a row with ``status != 0`` has NaN outputs (codes: :data:`STATUS_TEXT`) and the
other rows are unaffected.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError
from . import _door, prime, threads

DEFAULTS = {"alpha_max": math.radians(10.0), "f_r": 0.01, "g": 9.80665, "h": 0.0}
WHEEL_DEFAULT = 0.0
# Rows per task on the threads: at least CHUNK, and at most TASKS tasks per
# thread. 32 rows ran as many run-outs per second on two threads as numba's
# prange loop did (9,170-9,240 against 9,100-9,290 a second on 2,000 random
# rows; 8 and 128 about 1 % fewer; a run-out's cost varies by ten times, so
# small tasks share the load); on 200,000 cheap rows (the locked Monte Carlo
# of docs/runout.md) 6,250 tasks of 32 cost 10 % in submitting them.
CHUNK = 32
TASKS = 32


def columns() -> tuple[str, ...]:
    """The input columns, in the kernel's order."""
    return _door.plain().COLUMNS


def status_text(code: int) -> str:
    """What a row status means."""
    return "solved" if code == 0 else _door.plain().STATUS_TEXT.get(int(code), f"status {code}")


def input_table(cols) -> np.ndarray:
    """The (rows, COLUMNS) float64 table of a mapping of columns (arrays or scalars)."""
    names = columns()
    known = set(names)
    for key in cols:
        if key not in known:
            raise SceneError(f"unknown column (known: {', '.join(names)})", str(key))
    values, n = [], None
    for name in names:
        if name in cols:
            value = np.asarray(cols[name], dtype=np.float64)
        elif name in DEFAULTS:
            value = np.float64(DEFAULTS[name])
        elif name.startswith(("state_", "brake_", "steer_")):
            value = np.float64(WHEEL_DEFAULT)
        else:
            raise SceneError("missing column", name)
        if value.ndim > 1:
            raise SceneError(f"must be a scalar or a 1-D array, got shape {value.shape}", name)
        if value.ndim == 1:
            if n is not None and value.shape[0] != n:
                raise SceneError(f"has {value.shape[0]} rows, other columns {n}", name)
            n = value.shape[0]
        values.append(value)
    n = 1 if n is None else n
    return np.ascontiguousarray(np.stack([np.broadcast_to(v, (n,)) for v in values], axis=1))


def runout_batch(cols, tol: float | None = None, parallel: bool | None = None) -> dict:
    """Run every row to rest; returns a dict of output arrays (see the module doc).

    `tol` is the integrator's local error tolerance per step (SI, absolute;
    default generated TOL, measured in docs/runout.md). Rows run in chunks
    (CHUNK, TASKS) on the room's threads (threads.py) when `parallel`
    (default: more than CHUNK rows), else in the calling thread."""
    table = input_table(cols)
    n = table.shape[0]
    plain = _door.plain()
    tol = plain.TOL if tol is None else float(tol)
    out = {name: np.empty(n) for name in ("x_rest", "y_rest", "psi_rest", "t", "distance")}
    out |= {name: np.empty(n, dtype=np.int64) for name in ("status", "steps")}
    transfer = _transferring(table)
    for driver, rows in (("runout_batch", ~transfer), ("runout_batch_lt", transfer)):
        if rows.all():
            _drive(driver, table, out, tol, parallel)
        elif rows.any():
            part = {name: np.empty(int(rows.sum()), dtype=a.dtype) for name, a in out.items()}
            _drive(driver, np.ascontiguousarray(table[rows]), part, tol, parallel)
            for name, a in part.items():
                out[name][rows] = a
    return out


def _transferring(table: np.ndarray) -> np.ndarray:
    """Rows with quasi-static load transfer (column h > 0): they run through the
    kernel's _lt drivers, which numba compiles only when such a row comes."""
    return table[:, columns().index("h")] > 0.0


def _drive(driver: str, table: np.ndarray, out: dict, tol: float, parallel: bool | None) -> None:
    """All rows of `table` through the batch driver `driver`, into the arrays of `out`."""
    n = table.shape[0]
    plain, jit = _door.plain(), _door.jit()
    kernel = getattr(jit, driver)
    prime.ahead()
    names = ("x_rest", "y_rest", "psi_rest", "t", "distance", "status", "steps")
    arrays = tuple(out[name] for name in names)
    workers = threads.workers()
    if (parallel if parallel is not None else n > CHUNK) and workers > 1:
        size = max(CHUNK, -(-n // (TASKS * workers)))
        chunks = [
            threads.pool().submit(kernel, table, lo, min(lo + size, n), *arrays, tol, plain.EPS)
            for lo in range(0, n, size)
        ]
        for chunk in chunks:
            chunk.result()
    else:
        kernel(table, 0, n, *arrays, tol, plain.EPS)


def run_row(
    values: np.ndarray,
    tol: float | None = None,
    sens: bool = False,
    path_points: int = 0,
    eps: float | None = None,
    path_columns: int = 4,
):
    """One row (the COLUMNS values): (y, t, status, steps, path). y = (x, y, psi,
    vx, vy, w, distance) at rest, then with `sens` d y_i/d(vx, vy, w, mu) at
    y[7 + 4 i + j]; `path` is (points, path_columns) when asked: t, then the
    first path_columns - 1 entries of the state at each accepted step (t, x, y,
    psi by default; 32 for the whole state with its sensitivities, as via.py
    reads it).

    Every single run-out of a scene (forward, fitted, drawn) goes through the
    one row function with sensitivities, `sens` only choosing what is returned:
    a scene's first use then compiles one integrator, not two (a first fit
    scene on an empty cache 5.3 s instead of 7.6 s, docs/runout.md). Its
    forward part is the forward kernel's model; the sensitivities' own error
    control gives it other steps, so the two differ by their integration
    errors (worst 0.14 mm over 300 random run-outs at the default tolerance).
    Batches use the forward drivers (`runout_batch`)."""
    plain, jit = _door.plain(), _door.jit()
    buffer = np.empty((path_points, path_columns))
    values = np.ascontiguousarray(values, dtype=np.float64)
    row = jit.runout_row_sens_lt if _transferring(values[None])[0] else jit.runout_row_sens
    prime.ahead()
    y, t, status, steps, points = row(
        values,
        plain.TOL if tol is None else float(tol),
        plain.EPS if eps is None else float(eps),
        buffer,
    )
    return (y if sens else y[:7]), t, int(status), int(steps), buffer[:points]


def compile_drivers() -> int:
    """Compile (or load from numba's cache) every run-out driver: the batch
    driver and the row function with sensitivities (`run_row`'s), each with
    static loads and with load transfer, by running one locked slide through
    each (``impactsym compile``). Returns how many."""
    row = {"m": 1500.0, "I": 2500.0, "L": 2.7, "a": 1.2, "track": 1.5, "mu": 0.7}
    row |= {"x": 0.0, "y": 0.0, "psi": 0.0, "vx": 10.0, "vy": 0.0, "w": 0.0}
    row |= {f"state_{k}": 1.0 for k in ("fl", "fr", "rl", "rr")}
    for h in (0.0, 0.5):  # static loads, then load transfer (the _lt drivers)
        runout_batch(row | {"h": h})
        run_row(input_table(row | {"h": h})[0], sens=True)
    return 4
