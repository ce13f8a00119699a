"""`--plot`: the run-out paths with vehicle outlines at intervals, tyre marks
as the traces of the locked wheels, the separation and rest poses, and the
measured rest pose and intermediate poses when the scene gives them
(matplotlib, imported here only)."""

from __future__ import annotations

import math

import numpy as np

from .scene import RunoutScene

OUTLINES = 8  # outlines drawn along each path


def _outline(row: dict, x: float, y: float, psi: float, length: float) -> np.ndarray:
    """Corners of the wheel rectangle (wheelbase x track, plus 0.8 m overhangs) in scene units."""
    a, b, half = row["a"] + 0.8, row["L"] - row["a"] + 0.8, row["track"] / 2 + 0.15
    corners = np.array([[a, half], [-b, half], [-b, -half], [a, -half], [a, half]])
    c, s = math.cos(psi), math.sin(psi)
    rot = np.array([[c, -s], [s, c]])
    return (corners @ rot.T) / length + [x, y]


def plot_runout(scene: RunoutScene, result: dict, out: str) -> None:
    """Draw `result` (with paths) of `scene` into the image file `out`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    length = scene.length()
    fig, ax = plt.subplots(figsize=(8, 7))
    for k, (veh, entry) in enumerate(zip(scene.vehicles, result["vehicles"])):
        color = f"C{k}"
        path = np.array(entry["path"])
        t, x, y, psi = path[:, 0], path[:, 1], path[:, 2], np.radians(path[:, 3])
        ax.plot(x, y, color=color, lw=1.5, label=f"{entry['name']} (centre of gravity)")
        for i in np.linspace(0, len(t) - 1, OUTLINES).astype(int):
            pts = _outline(veh.row, x[i], y[i], psi[i], length)
            ax.plot(pts[:, 0], pts[:, 1], color=color, lw=0.6, alpha=0.5)
        for end, style in ((0, "-"), (len(t) - 1, "-")):
            pts = _outline(veh.row, x[end], y[end], psi[end], length)
            ax.plot(pts[:, 0], pts[:, 1], color=color, lw=2, ls=style)
        _tyre_marks(ax, veh, x, y, psi, length)
        if veh.rest is not None:
            pts = _outline(veh.row, veh.rest[0] / length, veh.rest[1] / length, veh.rest[2], length)
            ax.plot(pts[:, 0], pts[:, 1], color="k", lw=1, ls="--", label=f"{entry['name']} measured rest")
        _intermediate(ax, veh, entry["name"], length)
    unit = "ft" if scene.units == "US" else "m"
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    ax.set_aspect("equal")
    ax.legend(fontsize=8)
    ax.set_title("Run-out: paths, outlines, tyre marks of locked wheels")
    fig.savefig(out, dpi=120, bbox_inches="tight")
    plt.close(fig)


def _tyre_marks(ax, veh, x, y, psi, length) -> None:
    """Traces of the locked wheels."""
    row = veh.row
    spots = {
        "fl": (row["a"], row["track"] / 2),
        "fr": (row["a"], -row["track"] / 2),
        "rl": (row["a"] - row["L"], row["track"] / 2),
        "rr": (row["a"] - row["L"], -row["track"] / 2),
    }
    for k, (px, py) in spots.items():
        if row[f"state_{k}"] == 1.0:
            wx = x + (np.cos(psi) * px - np.sin(psi) * py) / length
            wy = y + (np.sin(psi) * px + np.cos(psi) * py) / length
            ax.plot(wx, wy, color="0.2", lw=2.5, alpha=0.6)


def _intermediate(ax, veh, name: str, length: float) -> None:
    """The given intermediate poses: a cross at each position, the outline
    where a heading is given."""
    for i, (x, y, psi) in enumerate(veh.via):
        label = f"{name} intermediate poses" if i == 0 else None
        ax.plot(x / length, y / length, "kx", ms=8, label=label)
        if psi is not None:
            pts = _outline(veh.row, x / length, y / length, psi, length)
            ax.plot(pts[:, 0], pts[:, 1], color="k", lw=0.8, ls=":")
