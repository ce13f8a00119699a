"""Parameter-sweep plots with matplotlib: heatmaps and lines with the impossible region.

:func:`sweep` draws a parameter sweep (a tidy frame, one row per grid point,
as ``impactsym.sweep`` returns): over two varied parameters a heatmap of one
output with the physically impossible cells (energy created, tensile normal
impulse, μ beyond μ_c) hatched over their colour, rows not solved dark grey
and the line μ = μ_c; over one, lines with the impossible points crossed out.
:func:`save_sweep` writes it to a file. Scene diagrams are in
:mod:`impactsym.plot`. matplotlib is imported inside the functions
(``pip install 'impactsym[plot]'``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import _kernels
from .._util import require
from ..codes import FLAG_ENERGY_CREATED, FLAG_MU_BEYOND_CRITICAL, FLAG_TENSILE_IMPULSE
from ..result import UNIT_LABELS

__all__ = [
    "sweep",
    "save_sweep",
    "SWEEP_OUTPUTS",
    "IMPOSSIBLE_FLAGS",
    "IMPOSSIBLE_LABEL",
    "NOT_SOLVED_LABEL",
    "MU_C_LABEL",
]

#: Output columns of a sweep frame (as ``solve_batch`` names them); ``mu`` is also an input.
SWEEP_OUTPUTS = _kernels.OUTPUTS
#: Flag bits that make a solved row physically impossible on a sweep plot.
IMPOSSIBLE_FLAGS = FLAG_ENERGY_CREATED | FLAG_TENSILE_IMPULSE | FLAG_MU_BEYOND_CRITICAL
IMPOSSIBLE_LABEL = "physically impossible (energy created, tensile impulse or μ beyond μ_c)"
NOT_SOLVED_LABEL = "not solved (status ≠ 0)"
MU_C_LABEL = "μ = μ_c"

_RESULT_COLUMNS = frozenset(SWEEP_OUTPUTS) - {"mu"} | {"status", "flags"}
_SYSTEM_UNITS = {
    "SI": {**UNIT_LABELS["SI"], "mass": "kg", "inertia": "kg·m²", "length": "m"},
    "US": {**UNIT_LABELS["US"], "mass": "slug", "inertia": "slug·ft²", "length": "ft"},
}
_FIXED_UNITS = {"deg": "°", "rad": "rad", "yaw_rate": "rad/s"}  # the same in both systems
_QUANTITIES = {
    "e": ("restitution e", None),
    "mu": ("impulse ratio μ", None),
    "e_m": ("moment restitution e_m", None),
    "normal_angle": ("normal angle Γ", "deg"),
    "gamma": ("normal angle Γ", "rad"),
    "slip": ("slip", None),
    "mu_c": ("critical impulse ratio μ_c", None),
    "Pn": ("normal impulse Pn", "impulse"),
    "Pt": ("tangential impulse Pt", "impulse"),
    "M": ("moment impulse M", "moment"),
    "TL": ("energy loss TL", "energy"),
    "TLn": ("normal energy loss TLn", "energy"),
    "TLt": ("tangential energy loss TLt", "energy"),
    "TLm": ("moment energy loss TLm", "energy"),
    **{f"m{i}": (f"mass m{i}", "mass") for i in "12"},
    **{f"I{i}": (f"yaw inertia I{i}", "inertia") for i in "12"},
    **{f"w{i}": (f"initial yaw rate w{i}", "yaw_rate") for i in "12"},
    **{f"W{i}": (f"final yaw rate W{i}", "yaw_rate") for i in "12"},
    **{f"dV{i}": (f"delta-V dV{i}", "velocity") for i in "12"},
    **{f"v{i}{c}": (f"initial velocity v{i}{c}", "velocity") for i in "12" for c in "xy"},
    **{f"V{i}{c}": (f"final velocity V{i}{c}", "velocity") for i in "12" for c in "xy"},
    **{f"r{i}{c}": (f"impact point r{i}{c}", "length") for i in "12" for c in "xy"},
}
_MASK_STYLE = {
    # translucent: the cell's colour (on the colour scale) shows through the hatch
    "impossible": dict(facecolor=(1.0, 1.0, 1.0, 0.45), edgecolor="0.15", hatch="///", lw=0.0),
    "not_solved": dict(facecolor="0.3", edgecolor="0.3", lw=0.0),
}


def sweep(df, x: str, y: str | None = None, color=None, ax=None, units: str | None = None):
    """Draw a parameter sweep on ``ax`` (a new pyplot figure when ``None``); return the axes.

    ``df`` is a sweep frame (a pandas DataFrame, or a mapping of equal-length
    columns): the varied parameters first (``e``, ``mu``, ``e_m``,
    ``normal_angle`` in degrees, ``m1``, ``r1x``, ...), then outputs named as in
    :data:`SWEEP_OUTPUTS`, then ``status`` and ``flags`` (see
    :mod:`impactsym.codes`; absent means 0). The varied parameters are the
    columns before the first output, ``status`` or ``flags`` column; every one
    not drawn on an axis must hold a single value, otherwise filter the frame
    first. Row order does not matter.

    - 2-D (``x`` and ``y``): a heatmap of ``color`` (one column, default
      ``TL``) over the full grid of ``x`` × ``y`` values, one cell per row,
      cell edges halfway between neighbouring values (so non-uniform spacing
      works; a single value gets a cell of ±10 %, ±0.5 at zero), with a
      colourbar. Solved rows with ``flags & IMPOSSIBLE_FLAGS`` (energy created,
      tensile normal impulse, μ not between 0 and μ_c) keep their colour under
      a translucent hatched mask; rows not solved are covered by a dark grey
      one. With ``mu`` on an axis and a ``mu_c`` column the line μ = μ_c (μ_c
      against the other parameter) is drawn. The colour scale spans every
      solved cell, physically possible or not.
    - 1-D (``y`` None): ``color`` (a column or a list of columns, default
      ``TL``) against ``x``, impossible points marked with red crosses, rows not
      solved shaded grey; with ``x == "mu"`` a vertical line at μ_c.

    ``units`` (``"SI"`` or ``"US"``) adds units to the labels (J or ft·lb, m/s
    or ft/s, N·s or lb·s, ...); ``normal_angle`` is always in degrees and yaw
    rates in rad/s. The drawn artists carry ``gid`` ``"values"``,
    ``"impossible"``, ``"not_solved"`` and ``"mu_c"``. Raises
    :class:`ValueError` (one line) for an unknown column, a parameter varied
    but not drawn, or axes that do not form a full grid, and
    :class:`ImportError` without matplotlib.
    """
    columns = _color_columns(color, two_d=y is not None)
    _check_sweep(df, x, y, columns, units)
    require("matplotlib", extra="plot", what="a sweep plot", load=False)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(9.0, 6.5), layout="constrained")
    if y is None:
        _sweep_line(ax, df, x, columns, units)
    else:
        _sweep_map(ax, df, x, y, columns[0], units)
    return ax


def save_sweep(
    df, path: str | Path, x: str, y: str | None = None, color=None, units: str | None = None
) -> Path:
    """Draw like :func:`sweep` on a fresh Agg figure (no pyplot, no display
    needed) and write it to ``path`` (PNG for ``.png``; the format follows the
    suffix as in :func:`save_plot`). Returns the path."""
    require("matplotlib", extra="plot", what="a sweep plot", load=False)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 6.5), layout="constrained")
    FigureCanvasAgg(fig)
    sweep(df, x, y, color=color, ax=fig.add_subplot(), units=units)
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path


def _color_columns(color, two_d: bool) -> list[str]:
    """The drawn output columns: ``TL`` by default; a heatmap shows one."""
    columns = ["TL"] if color is None else [color] if isinstance(color, str) else list(color)
    if not columns or (two_d and len(columns) != 1):
        raise ValueError(
            f"color: a {'heatmap shows one column' if two_d else 'line plot needs a column'}, got {color!r}"
        )
    return columns


def _check_sweep(df, x: str, y: str | None, columns: list[str], units: str | None) -> None:
    """Unknown columns or units, a parameter varied but not drawn: ValueError (one line)."""
    if units is not None and units not in _SYSTEM_UNITS:
        raise ValueError(f"units: expected 'SI' or 'US', got {units!r}")
    names = list(df.keys())
    axes = [x] if y is None else [x, y]
    if y is not None and x == y:
        raise ValueError(f"y: the same column as x ({x})")
    for name in axes + columns:
        if name not in names:
            raise ValueError(f"{name}: no such column in the sweep (columns: {', '.join(map(str, names))})")
    extra = [
        name
        for name in _parameters(names)
        if name not in axes and name not in columns and len(np.unique(np.asarray(df[name]))) > 1
    ]
    if extra:
        raise ValueError(
            f"the sweep also varies {', '.join(extra)}, which the plot's axes do not use; "
            f"filter it to one value each first (e.g. df[df[{extra[0]!r}] == value])"
        )


def _parameters(names: list[str]) -> list[str]:
    """The varied-parameter columns: those before the first output, ``status`` or ``flags``."""
    first = next((i for i, name in enumerate(names) if name in _RESULT_COLUMNS), len(names))
    return names[:first]


def _unit(name: str, units: str | None) -> str | None:
    """The unit of a column in ``units`` ("SI", "US" or None: only the units
    both systems share); None for a pure number or an unknown column."""
    key = _QUANTITIES.get(name, (name, None))[1]
    return _FIXED_UNITS.get(key) or (_SYSTEM_UNITS[units].get(key) if units and key else None)


def _label(name: str, units: str | None) -> str:
    """``"energy loss TL [J]"``: the quantity's name, and its unit when known."""
    text, unit = _QUANTITIES.get(name, (name, None))[0], _unit(name, units)
    return f"{text} [{unit}]" if unit else text


def _lines_label(columns: list[str], units: str | None) -> str:
    """The y label of a line plot: one column's label, or the names with their
    common unit (``"dV1, dV2 [m/s]"``)."""
    if len(columns) == 1:
        return _label(columns[0], units)
    common = {_unit(column, units) for column in columns}
    unit = common.pop() if len(common) == 1 else None
    return ", ".join(columns) + (f" [{unit}]" if unit else "")


def _status_flags(df, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(solved, impossible) row masks from ``status`` and ``flags`` (absent: 0)."""
    status = np.asarray(df["status"]) if "status" in df else np.zeros(n, dtype=np.int32)
    flags = np.asarray(df["flags"]) if "flags" in df else np.zeros(n, dtype=np.int32)
    solved = status == 0
    return solved, solved & ((flags.astype(np.int64) & IMPOSSIBLE_FLAGS) != 0)


def _axis_values(df, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Sorted distinct values of a parameter column and each row's index into them."""
    values = np.asarray(df[name], dtype=np.float64)
    if not np.isfinite(values).all():
        raise ValueError(f"{name}: the axis values must be finite numbers")
    return np.unique(values, return_inverse=True)


def _grid(df, x: str, y: str):
    """``(xs, ys, iy, ix)``: the grid values and each row's cell; every
    (x, y) pair must occur exactly once."""
    xs, ix = _axis_values(df, x)
    ys, iy = _axis_values(df, y)
    counts = np.zeros((len(ys), len(xs)), dtype=np.int64)
    np.add.at(counts, (iy, ix), 1)
    if (counts != 1).any():
        raise ValueError(
            f"{x} × {y}: not a full grid ({len(ix)} rows for {len(xs)} × {len(ys)} values, "
            f"{int((counts == 0).sum())} missing, {int((counts > 1).sum())} repeated)"
        )
    return xs, ys, iy, ix


def _on_grid(values: np.ndarray, iy, ix, shape, fill=np.nan) -> np.ndarray:
    """Row values placed in a (len(ys), len(xs)) array, ``fill`` elsewhere."""
    out = np.full(shape, fill, dtype=np.result_type(values, fill))
    out[iy, ix] = values
    return out


def _edges(values: np.ndarray) -> np.ndarray:
    """Cell edges around sorted grid values: halfway between neighbours, the
    outer cells as wide as their neighbour's half; a single value gets ±10 %
    (±0.5 at zero)."""
    if len(values) == 1:
        half = 0.1 * abs(values[0]) or 0.5
        return np.array([values[0] - half, values[0] + half])
    middle = 0.5 * (values[1:] + values[:-1])
    return np.concatenate([[2.0 * values[0] - middle[0]], middle, [2.0 * values[-1] - middle[-1]]])


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """``[start, stop)`` index ranges of the consecutive True entries of a 1-D mask."""
    padded = np.concatenate([[False], mask, [False]]).astype(np.int8)
    changes = np.flatnonzero(np.diff(padded))
    return list(zip(changes[::2].tolist(), changes[1::2].tolist()))


def _cell_mask(ax, mask: np.ndarray, xedges, yedges, gid: str, label: str) -> None:
    """Draw the cells where ``mask`` (shape (ny, nx)) is True as one collection of
    rectangles (runs along x merged), styled by ``_MASK_STYLE[gid]``."""
    from matplotlib.collections import PolyCollection

    boxes = [
        [
            (xedges[a], yedges[j]),
            (xedges[b], yedges[j]),
            (xedges[b], yedges[j + 1]),
            (xedges[a], yedges[j + 1]),
        ]
        for j, row in enumerate(mask)
        for a, b in _runs(row)
    ]
    ax.add_collection(
        PolyCollection(boxes, gid=gid, label=label, zorder=2, **_MASK_STYLE[gid]), autolim=False
    )


def _finite_mean(values: np.ndarray, axis: int) -> np.ndarray:
    """Mean of the finite entries along ``axis``; NaN where there are none."""
    finite = np.isfinite(values)
    count = finite.sum(axis=axis)
    total = np.where(finite, values, 0.0).sum(axis=axis)
    return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def _mu_c_line(ax, mu_c: np.ndarray, x: str, xs, ys, xedges, yedges):
    """μ = μ_c on a heatmap with ``mu`` on one axis: μ_c (constant along μ) against
    the other parameter; ``None`` when no μ_c is known."""
    along_x = x == "mu"
    boundary = _finite_mean(mu_c, axis=1 if along_x else 0)
    other, edges = (ys, yedges) if along_x else (xs, xedges)
    if not np.isfinite(boundary).any():
        return None
    if len(other) == 1:
        other, boundary = edges, np.repeat(boundary, 2)
    points = (boundary, other) if along_x else (other, boundary)
    (line,) = ax.plot(*points, color="crimson", lw=2.2, gid="mu_c", label=MU_C_LABEL, zorder=4)
    return line


def _sweep_map(ax, df, x: str, y: str, column: str, units: str | None) -> None:
    """The 2-D heatmap of :func:`sweep`."""
    from matplotlib.patches import Patch

    xs, ys, iy, ix = _grid(df, x, y)
    shape = (len(ys), len(xs))
    solved, impossible = _status_flags(df, len(ix))
    values = _on_grid(np.where(solved, np.asarray(df[column], dtype=np.float64), np.nan), iy, ix, shape)
    xedges, yedges = _edges(xs), _edges(ys)
    mesh = ax.pcolormesh(xedges, yedges, np.ma.masked_invalid(values), cmap="viridis", gid="values", zorder=1)
    ax.figure.colorbar(mesh, ax=ax, label=_label(column, units))
    handles = []
    for gid, label, rows in (
        ("impossible", IMPOSSIBLE_LABEL, impossible),
        ("not_solved", NOT_SOLVED_LABEL, ~solved),
    ):
        if rows.any():
            _cell_mask(ax, _on_grid(rows, iy, ix, shape, fill=False), xedges, yedges, gid, label)
            handles.append(Patch(label=label, **_MASK_STYLE[gid]))
    if "mu" in (x, y) and "mu_c" in df:
        mu_c = _on_grid(np.where(solved, np.asarray(df["mu_c"], dtype=np.float64), np.nan), iy, ix, shape)
        line = _mu_c_line(ax, mu_c, x, xs, ys, xedges, yedges)
        handles += [line] if line is not None else []
    ax.set_xlim(xedges[0], xedges[-1])
    ax.set_ylim(yedges[0], yedges[-1])
    _finish(ax, _label(x, units), _label(y, units), _label(column, units), solved, impossible, handles)


def _sweep_line(ax, df, x: str, columns: list[str], units: str | None) -> None:
    """The 1-D line plot of :func:`sweep`."""
    xs, index = _axis_values(df, x)
    if len(xs) != len(index):
        raise ValueError(
            f"{x}: repeated values ({len(index)} rows for {len(xs)} values); "
            "filter the other varied parameters first"
        )
    solved_rows, impossible_rows = _status_flags(df, len(index))
    order = np.argsort(index)
    solved, impossible = solved_rows[order], impossible_rows[order]
    handles = []
    for column in columns:
        values = np.asarray(df[column], dtype=np.float64)[order]
        handles += ax.plot(
            xs, values, marker=".", lw=1.8, gid="values", label=_label(column, units), zorder=3
        )
        crosses = ax.plot(
            xs[impossible],
            values[impossible],
            ls="none",
            marker="x",
            ms=8,
            mew=2.0,
            color="crimson",
            gid="impossible",
            label=IMPOSSIBLE_LABEL,
            zorder=4,
        )
    handles += crosses if impossible.any() else []
    edges = _edges(xs)
    spans = [
        ax.axvspan(
            edges[a], edges[b], color="0.3", alpha=0.35, lw=0, gid="not_solved", label=NOT_SOLVED_LABEL
        )
        for a, b in _runs(~solved)
    ]
    handles += spans[:1]
    if x == "mu" and "mu_c" in df:
        mu_c = _finite_mean(np.asarray(df["mu_c"], dtype=np.float64)[solved_rows], axis=0)
        if np.isfinite(mu_c):
            handles.append(
                ax.axvline(float(mu_c), color="crimson", lw=1.5, ls="--", gid="mu_c", label=MU_C_LABEL)
            )
    ylabel = _lines_label(columns, units)
    _finish(ax, _label(x, units), ylabel, ylabel, solved, impossible, handles)


def _finish(ax, xlabel: str, ylabel: str, quantity: str, solved, impossible, handles) -> None:
    """Axis labels, a title that counts the impossible and unsolved rows, the
    legend below the axes, off the data (a figure legend: constrained layout,
    as :func:`sweep` and :func:`save_sweep` use, makes room for it)."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(
        f"{quantity}\nphysically impossible: {int(impossible.sum())} of {int(solved.sum())} solved "
        f"points; not solved: {int((~solved).sum())}",
        fontsize=10,
    )
    ax.grid(True, lw=0.4, alpha=0.5)
    if handles:
        ax.figure.legend(
            handles=handles, loc="outside lower center", ncols=min(2, len(handles)), fontsize=8, frameon=False
        )
