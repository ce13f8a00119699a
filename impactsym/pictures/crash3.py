"""CRASH3 diagrams with matplotlib: each vehicle's crush profile, its depths and its PDOF.

One panel per vehicle with a crush table (a fixed barrier has none): the
undeformed damaged face as a line across the damage width L, the crush profile
C1..CN below it (equally spaced across L, piecewise linear, as CRASH3
integrates it) with each depth written under its point, and the principal
direction of force as an arrow pushing the face in, at the PDOF α from the
face's inward normal (counter-clockwise positive, as in the scene file). The
panel is drawn in the face's own frame: the inward normal points down, so the
picture keeps the scene's sense of rotation. Each panel's title gives the
vehicle's crush energy and |delta-V|; the figure's title the scene and the
CRASH3 options. Lengths in the crush table's unit (in for US scenes, m for SI).

All numbers come from the scene's crush tables and the result (:func:`impactsym.crash3`);
this module only draws them. matplotlib is imported inside the functions.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from .._util import require
from ..crash3 import Crash3Result, crush_tables
from ..result import UNIT_LABELS

__all__ = ["crash3_figure", "save_crash3"]

#: Crush-table length unit by unit system (CRASH3's inches in US scenes).
CRUSH_LENGTH = {"SI": "m", "US": "in"}
_FILL, _EDGE, _PDOF = "#fdd0a2", "#a63603", "tab:purple"


def crash3_figure(result: Crash3Result, scene: Any):
    """The CRASH3 diagram of ``result`` (from :func:`impactsym.crash3`) and the
    ``scene`` it was computed from (a path, mapping or Scene), on a plain Agg
    figure (no pyplot). Returns the figure."""
    require("matplotlib", extra="plot", what="a CRASH3 diagram", load=False)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    tables = crush_tables(scene)
    drawn = [(vehicle, table) for vehicle, table in zip(result.vehicles, tables) if table is not None]
    fig = Figure(figsize=(max(7.0, 5.0 * len(drawn) + 1.0), 5.0), layout="constrained")
    FigureCanvasAgg(fig)
    for ax, (vehicle, table) in zip(fig.subplots(1, len(drawn), squeeze=False)[0], drawn):
        _panel(ax, vehicle, table, result.units)
    name = Path(scene).name if isinstance(scene, (str, Path)) else "scene"
    options = result.options
    fixed = [vehicle.name for vehicle, table in zip(result.vehicles, tables) if table is None]
    against = f", against {', '.join(fixed)} (fixed, no crush)" if fixed else ""
    fig.suptitle(
        f"{name}: CRASH3, {result.units}{against}\ne = {options.restitution:g}, crush energy "
        f"{options.energy}, {options.correction} correction",
        fontsize=11,
    )
    return fig


def save_crash3(result: Crash3Result, path: str | Path, scene: Any, dpi: int = 120) -> Path:
    """Draw :func:`crash3_figure` and write it to ``path`` (format from the suffix)."""
    path = Path(path)
    crash3_figure(result, scene).savefig(path, dpi=dpi)
    return path


def _panel(ax, vehicle, table, units: str) -> None:
    """One vehicle: face, crush profile with its depths, PDOF arrow, title."""
    length = CRUSH_LENGTH[units]
    width, depths = table.width, table.depths
    xs = [-0.5 * width + width * i / (len(depths) - 1) for i in range(len(depths))]
    deepest = max(depths)
    ax.fill(
        [*xs, xs[-1], xs[0]],
        [*(-c for c in depths), 0.0, 0.0],
        facecolor=_FILL,
        edgecolor=_EDGE,
        lw=1.5,
        gid="crush",
        label="crushed region",
    )
    ax.plot(xs, [-c for c in depths], ls="none", marker="o", ms=5, color=_EDGE, gid="profile")
    ax.plot([-0.5 * width, 0.5 * width], [0.0, 0.0], color="black", lw=2.0, gid="face")
    gap = 0.03 * width  # between a point and its depth
    for i, (x, c) in enumerate(zip(xs, depths)):
        ax.text(x, -c - gap, f"C{i + 1}\n{c:g}", ha="center", va="top", fontsize=8, color=_EDGE)
    # the force on the vehicle: the inward normal (down) turned by α counter-clockwise
    alpha = math.radians(table.pdof)
    direction = (math.sin(alpha), -math.cos(alpha))
    arrow = 0.25 * width
    tail = (-direction[0] * arrow, -direction[1] * arrow)
    ax.annotate(
        "",
        (0.0, 0.0),
        tail,
        arrowprops=dict(arrowstyle="-|>", color=_PDOF, lw=2.2, mutation_scale=16, shrinkA=0, shrinkB=0),
        gid="pdof",
    )
    side = "left" if direction[0] <= 0 else "right"  # the label beside the tail, away from the arrow
    ax.text(
        tail[0] + (0.03 if side == "left" else -0.03) * width,
        tail[1],
        f"PDOF {table.pdof:g}°",
        ha=side,
        va="center",
        fontsize=9,
        color=_PDOF,
    )
    ax.text(0.5 * width, 0.02 * width, f"L = {width:g} {length}", ha="right", va="bottom", fontsize=8)
    ax.set_aspect("equal", adjustable="box")  # true shape: depths against width
    top = max(tail[1], 0.0) + 0.1 * width
    ax.set_ylim(-deepest - 0.25 * width, top)
    ax.set_xlim(-0.6 * width, 0.6 * width)
    ax.yaxis.set_major_formatter(lambda y, _: f"{0.0 - y:g}" if y <= 0 else "")  # depths, down from the face
    ax.set_xlabel(f"across the damaged face [{length}]")
    ax.set_ylabel(f"crush depth [{length}]")
    labels = UNIT_LABELS[units]
    ax.set_title(
        f"{vehicle.name}: crush energy {vehicle.crush_energy:.4g} {labels['energy']}\n"
        f"|ΔV| {vehicle.delta_v_magnitude:.3g} {labels['velocity']}",
        fontsize=10,
    )
    ax.grid(True, lw=0.4, alpha=0.5)
