"""The grid search of the fit to rest (``impactsym runout --exhaustive``).

Every separation state (vx, vy, w) of a regular grid over a stated range
(|(vx, vy)| <= speed_max, |w| <= yaw_rate_max; 2 SPEED_CELLS + 1 points along
vx and vy, the disk's only, and 2 YAW_CELLS + 1 along w) runs forward at once
through the batch driver, and the grid points whose rest-pose miss is no larger
than that of any of their 26 neighbours (a local minimum of the miss on the
grid) become Newton starts for fit.py, least miss first. The fit's own starts
surround its estimate; the grid looks everywhere in the range, so a second
state far from the estimate is found if its basin is wider than the grid's
spacing. It is not found if the basin is narrower: a spinning run-out whose rest
moves by metres for 0.1 rad/s of yaw rate (docs/runout.md, "The grid search")
has basins far narrower than any grid that runs in seconds.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np

from .batch import columns, runout_batch
from .scene import RunoutVehicle, row_values

SPEED_CELLS = 15  # grid points each side of zero along vx and along vy
YAW_CELLS = 16  # grid points each side of zero along w
MAX_STARTS = 24  # local minima started from, least miss first


@dataclass
class Grid:
    """A grid search: its range (m/s, rad/s), points per axis (vx, vy, w), the
    run-outs it ran, how many local minima it found, and the Newton starts
    (vx, vy, w) it gives (at most MAX_STARTS, least miss first)."""

    speed_max: float
    yaw_rate_max: float
    shape: tuple[int, int, int]
    runouts: int
    minima: int
    starts: list

    def summary(self, length: float) -> dict:
        """The search as the run-out JSON reports it, speeds in the scene's
        units (`length` metres per unit), yaw rates in rad/s."""
        return {
            "speed_max": self.speed_max / length,
            "yaw_rate_max": self.yaw_rate_max,
            "grid": list(self.shape),
            "spacing": {
                "speed": 2 * self.speed_max / (self.shape[0] - 1) / length,
                "yaw_rate": 2 * self.yaw_rate_max / (self.shape[2] - 1),
            },
            "runouts": self.runouts,
            "minima": self.minima,
            "starts": len(self.starts),
        }


def scan(
    vehicle: RunoutVehicle,
    speed_max: float,
    yaw_rate_max: float,
    scale: float,
    tol: float,
    cells: tuple[int, int] = (SPEED_CELLS, YAW_CELLS),
) -> Grid:
    """Run the grid of `vehicle` (module docstring; `cells` the points each side
    of zero along vx and vy, and along w) at integrator tolerance `tol`; the
    miss of a point is |rest position miss|^2 + (heading miss x `scale`)^2
    (fit.py's weighting), infinite where the run-out failed."""
    axis = np.linspace(-speed_max, speed_max, 2 * cells[0] + 1)
    yaw = np.linspace(-yaw_rate_max, yaw_rate_max, 2 * cells[1] + 1)
    VX, VY, W = np.meshgrid(axis, axis, yaw, indexing="ij")
    # the disk, with room for round-off at its rim (the points on the axes)
    inside = speed_max**2 * (1 + 1e-12) >= VX**2 + VY**2
    names = columns()
    base = row_values(vehicle, names, 0.0, 0.0, 0.0)
    cols = {name: base[j] for j, name in enumerate(names)}
    cols["vx"], cols["vy"], cols["w"] = VX[inside], VY[inside], W[inside]
    out = runout_batch(cols, tol=tol)
    x_r, y_r, psi_r = vehicle.rest
    miss2 = (out["x_rest"] - x_r) ** 2 + (out["y_rest"] - y_r) ** 2 + ((out["psi_rest"] - psi_r) * scale) ** 2
    miss = np.full(VX.shape, np.inf)
    miss[inside] = np.where(out["status"] == 0, miss2, np.inf)
    minima = np.argwhere(_local_minima(miss))
    minima = minima[np.argsort(miss[tuple(minima.T)], kind="stable")]
    starts = [(float(VX[i, j, k]), float(VY[i, j, k]), float(W[i, j, k])) for i, j, k in minima[:MAX_STARTS]]
    return Grid(speed_max, yaw_rate_max, VX.shape, int(inside.sum()), len(minima), starts)


def _local_minima(miss: np.ndarray) -> np.ndarray:
    """Where a finite `miss` is no larger than at any of its 26 neighbours
    (outside the grid counts as infinite)."""
    padded = np.pad(miss, 1, constant_values=np.inf)
    n0, n1, n2 = miss.shape
    found = np.isfinite(miss)
    for d in product((-1, 0, 1), repeat=3):
        if d != (0, 0, 0):
            found &= (
                miss <= padded[1 + d[0] : 1 + d[0] + n0, 1 + d[1] : 1 + d[1] + n1, 1 + d[2] : 1 + d[2] + n2]
            )
    return found
