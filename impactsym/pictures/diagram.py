"""Scene diagrams with matplotlib: geometry, velocities, delta-V, PDOF, yaw.

:func:`scene` draws one scene, or one solved scene, in the scene frame with
equal axes:

- each vehicle as an outline (a rectangle from the optional ``length``,
  ``width`` and ``heading`` of its scene entry; a dot where they are absent)
  with its centre of gravity; a fixed body as a hatched barrier along the crush
  surface;
- the impact centre, the crush surface (the line through the impact centre
  along ``t``) and the normal ``n`` (from vehicle 1 toward vehicle 2);
- the pre-impact velocities and, for a result, the post-impact ones, the
  delta-V (drawn from the tip of the pre-impact arrow to the tip of the
  post-impact one) and the principal direction of force (PDOF, the direction
  of the impulse on the vehicle: ``P`` on vehicle 1, ``-P`` on vehicle 2);
- yaw rates as curved arrows around the centre of gravity (counter-clockwise
  positive), before dashed, after solid;
- a legend with units.

Labels (vehicle names, ``n``, |ΔV|, PDOF, yaw rates) are placed once the
figure is laid out: each takes the nearest position around its anchor whose
box stays inside the axes and touches no other label, arrow, outline, line or
marker (a label placed far from its anchor gets a thin leader line). The PDOF
label has one style: where the impulse comes from, degrees clockwise from
straight ahead and the clock position (straight ahead: the ``heading``, else
the direction of travel). A CRASH3 result is drawn by
:mod:`impactsym.pictures.crash3` instead (:func:`save_plot` dispatches).

Placement: a scene file gives only ``r_i``, the vector from each centre of
gravity to the impact centre. The impact centre is put at the origin (or at
``impact.position`` when the scene data carry one) and each centre of gravity
at ``impact centre - r_i``. Particles have no impact point: they are drawn a
small distance either side of the impact centre along ``n``.

All numbers come from the scene and from the result (``solve()``); this module
only draws them. matplotlib is imported inside the functions, so
``import impactsym`` neither needs nor loads it (``pip install 'impactsym[plot]'``).

Results are duck-typed, so other kinds of result (inverse, reconstruction)
can be drawn as long as they provide:

- ``vehicles``: two entries with ``velocity`` and ``delta_v`` (and
  ``yaw_rate`` for the rigid model). For a :class:`~impactsym.result.Result`
  ``velocity``/``yaw_rate`` are the *final* motion and the initial motion is
  read from the scene. A result whose ``kind`` attribute is ``"invert"`` or
  ``"reconstruct"`` has the *initial* motion in ``velocity``/``yaw_rate``;
  its final motion is the scene's ``final_velocity``/``final_yaw_rate``, or
  ``velocity + delta_v``. Explicit ``initial_velocity``, ``final_velocity``,
  ``initial_yaw_rate`` and ``final_yaw_rate`` attributes take precedence.
- optionally ``Pn`` and ``Pt`` (impulse on vehicle 1 in the impact frame) for
  the PDOF (otherwise the direction of delta-V is used), and ``mu``, ``mu_c``,
  ``TL``, ``flags``, ``units`` for the title.

The scene itself comes from ``scene=`` or from a ``scene`` attribute of the
result.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from .._util import require
from ..codes import FLAG_ENERGY_CREATED, FLAG_MU_BEYOND_CRITICAL, FLAG_TENSILE_IMPULSE
from ..crash3 import Crash3Result
from ..residue import drop_residue, quantity_scales
from ..result import UNIT_LABELS
from ..scene import Scene
from .canvas import _angle, _Canvas
from .crash3 import save_crash3
from .glyphs import one_glyph_warning
from .inputs import SceneLike, _add, _norm, _num, _resolve, _scale, _sub
from .labels import place_labels
from .layout import _auto_scale, _bodies, _Body, _characteristic_length, _frame

LENGTH_UNITS = {"SI": "m", "US": "ft"}

_COLOR = {
    "before": "tab:blue",
    "after": "tab:green",
    "delta_v": "tab:orange",
    "pdof": "tab:purple",
    "normal": "black",
    "surface": "tab:brown",
}
_FILL = ("#c6dbef", "#fdd0a2")
_EDGE = ("#08519c", "#a63603")
_FLAG_SHORT = {
    FLAG_ENERGY_CREATED: "energy created",
    FLAG_TENSILE_IMPULSE: "tensile normal impulse",
    FLAG_MU_BEYOND_CRITICAL: "μ not between 0 and μ_c",
}


# --------------------------------------------------------------------------- public


def scene(
    scene_or_result: Any,
    ax=None,
    *,
    scene: SceneLike | None = None,
    result: Any = None,
    velocity_scale: float | None = None,
    legend: bool = True,
    title: str | None = None,
):
    """Draw a scene, or a solved scene, on ``ax`` (a new figure when ``None``).

    ``scene_or_result`` is a scene (a :class:`~impactsym.scene.Scene`, a
    mapping in scene-file form or a file path) or a result (a
    :class:`~impactsym.result.Result` or a duck-typed look-alike, see the
    module docstring). A scene may be given its ``result=``; a result needs its
    ``scene=`` unless it has a ``scene`` attribute.

    ``velocity_scale`` is the drawn length (scene length unit) of one velocity
    unit; by default the longest arrow is about twice the vehicles' size.
    Returns the axes.
    """
    the_scene, the_result, position = _resolve(scene_or_result, scene, result)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(9.0, 6.5), layout="constrained")
    with one_glyph_warning():
        _draw(ax, the_scene, the_result, position, velocity_scale, legend, title)
    return ax


def save_plot(
    scene_or_result: Any,
    path: str | Path,
    *,
    scene: SceneLike | None = None,
    result: Any = None,
    dpi: int = 120,
    **options,
) -> Path:
    """Draw like :func:`scene` and write the figure to ``path``.

    The format follows the suffix (``.png``, ``.svg``, ``.pdf``, ...). Uses a
    plain Agg canvas (no pyplot, no display needed). Returns the path. A
    CRASH3 result (:func:`impactsym.crash3`, with ``scene=``) is drawn as its
    CRASH3 diagram (:mod:`impactsym.pictures.crash3`).
    Raises :class:`ImportError` (with the install command) without matplotlib
    and :class:`OSError` when the file cannot be written.
    """
    if isinstance(scene_or_result, Crash3Result):  # crush profiles and PDOFs, not a scene diagram
        if scene is None or result is not None or options:
            raise TypeError("save_plot: a CRASH3 result takes only scene= (the scene it was computed from)")
        return save_crash3(scene_or_result, path, scene, dpi=dpi)
    the_scene, the_result, position = _resolve(scene_or_result, scene, result)
    require("matplotlib", extra="plot", what="a scene diagram", load=False)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 6.5), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    with one_glyph_warning():
        _draw(
            ax,
            the_scene,
            the_result,
            position,
            options.pop("velocity_scale", None),
            options.pop("legend", True),
            options.pop("title", None),
        )
        if options:
            raise TypeError(f"save_plot: unexpected options {', '.join(sorted(options))}")
        path = Path(path)
        fig.savefig(path, dpi=dpi, bbox_inches="tight")
    return path


def default_velocity_scale(
    scene_or_result: Any, *, scene: SceneLike | None = None, result: Any = None
) -> float:
    """The ``velocity_scale`` :func:`scene` would choose: the drawn length (scene
    length unit) of one velocity unit, so that the longest arrow is about twice
    the vehicles' size. Pass it back to keep arrows comparable between drawings."""
    the_scene, the_result, position = _resolve(scene_or_result, scene, result)
    size = _characteristic_length(the_scene)
    return _auto_scale(_bodies(the_scene, the_result, position, size), size)


def _rotated(centre, heading_deg, local):
    c, s = math.cos(math.radians(heading_deg)), math.sin(math.radians(heading_deg))
    return [(centre[0] + c * x - s * y, centre[1] + s * x + c * y) for x, y in local]


def _draw(
    ax,
    scene: Scene,
    result: Any,
    centre,
    velocity_scale,
    legend: bool,
    title: str | None,
    arrange_labels: bool = True,
):
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    units = scene.units
    speed_unit = UNIT_LABELS[units]["velocity"]
    length_unit = LENGTH_UNITS[units]
    size = _characteristic_length(scene)
    bodies = _bodies(scene, result, centre, size)
    n, t = _frame(scene)
    canvas = _Canvas(ax)
    handles = []

    # velocity scale: drawn length per velocity unit
    k = velocity_scale if velocity_scale else _auto_scale(bodies, size)
    speeds = [_norm(v) for body in bodies for v in (body.v0, body.v1) if v is not None]
    rate_scale = quantity_scales(  # rounding residue of a zero is not drawn (impactsym.residue)
        [("speed", v) for v in speeds]
        + [("yaw_rate", w) for b in bodies for w in (b.w0, b.w1) if w is not None]
    )["yaw_rate"]
    for body in bodies:
        body.w0, body.w1 = (None if w is None else drop_residue(w, rate_scale) for w in (body.w0, body.w1))
    rates = [abs(w) for body in bodies for w in (body.w0, body.w1) if w is not None]
    wmax = max(rates, default=0.0)

    # vehicles and the barrier
    reach = size
    for index, body in enumerate(bodies):
        if body.fixed:
            side = 1.0 if index == 1 else -1.0
            half = max(1.2 * size, 0.5 * body.outline[0] if body.outline else 0.0)
            depth = body.outline[1] if body.outline else 0.3 * size
            corners = [
                _add(centre, _scale(t, -half)),
                _add(centre, _scale(t, half)),
                _add(_add(centre, _scale(t, half)), _scale(n, side * depth)),
                _add(_add(centre, _scale(t, -half)), _scale(n, side * depth)),
            ]
            canvas.polygon(corners, facecolor="0.9", edgecolor="0.2", hatch="///", lw=1.2, zorder=1)
            canvas.label(
                _add(_add(centre, _scale(t, 0.75 * half)), _scale(n, side * depth)),
                body.name,
                _angle(_scale(n, side)),
                fontsize=9,
                color="0.2",
            )
            handles.append(Patch(facecolor="0.9", edgecolor="0.2", hatch="///", label="fixed barrier"))
            continue
        fill, edge = _FILL[index], _EDGE[index]
        if body.outline:
            length, width, heading = body.outline
            half_l, half_w = 0.5 * length, 0.5 * width
            canvas.polygon(
                _rotated(
                    body.cg,
                    heading,
                    [(half_l, half_w), (-half_l, half_w), (-half_l, -half_w), (half_l, -half_w)],
                ),
                facecolor=fill,
                edgecolor=edge,
                lw=1.5,
                alpha=0.9,
                zorder=1,
            )
            canvas.polygon(
                _rotated(
                    body.cg,
                    heading,
                    [(0.9 * half_l, 0.0), (0.75 * half_l, 0.25 * half_w), (0.75 * half_l, -0.25 * half_w)],
                ),
                facecolor=edge,
                edgecolor=edge,
                alpha=0.5,
                zorder=1,
            )
            reach = max(reach, half_l)
            handles.append(Patch(facecolor=fill, edgecolor=edge, label=f"{body.name} (outline, front ▶)"))
        else:
            canvas.marker(body.cg, ls="none", marker="o", ms=16, mfc=fill, mec=edge, mew=1.5, zorder=2)
            handles.append(Line2D([], [], ls="none", marker="o", ms=10, mfc=fill, mec=edge, label=body.name))
        canvas.marker(body.cg, ls="none", marker="o", ms=7, mfc="white", mec="black", mew=1.2, zorder=7)
        canvas.marker(body.cg, ls="none", marker="+", ms=7, mec="black", mew=1.2, zorder=8)
        canvas.label(body.cg, body.name, _angle(_scale(t, -1.0)), fontsize=9, color=edge)

    # crush surface, normal, impact centre
    half = 1.2 * reach
    canvas.line(
        _add(centre, _scale(t, -half)),
        _add(centre, _scale(t, half)),
        color=_COLOR["surface"],
        lw=2.5,
        zorder=3,
    )
    tip = _add(centre, _scale(n, 0.6 * size))
    canvas.arrow(centre, tip, _COLOR["normal"], lw=1.5, zorder=6)
    canvas.label(tip, "n", _angle(n), fontsize=11, fontweight="bold")
    canvas.marker(centre, ls="none", marker="X", ms=10, mfc="black", mec="white", zorder=9)

    # motion
    drawn = set()
    for index, body in enumerate(bodies):
        if body.v0 is not None:
            canvas.arrow(body.cg, _add(body.cg, _scale(body.v0, k)), _COLOR["before"], lw=2.2, alpha=0.85)
            drawn.add("before")
        if body.v1 is not None:
            canvas.arrow(body.cg, _add(body.cg, _scale(body.v1, k)), _COLOR["after"], lw=2.2)
            drawn.add("after")
        if body.dv is not None and _norm(body.dv) > 0:
            tail = _add(body.cg, _scale(body.v0, k)) if body.v0 is not None else body.cg
            head = _add(tail, _scale(body.dv, k))
            canvas.arrow(tail, head, _COLOR["delta_v"], lw=2.0, ls="--", zorder=5)
            canvas.label(
                _scale(_add(tail, head), 0.5),
                f"|ΔV| {_norm(body.dv):.3g}",
                _angle((-body.dv[1], body.dv[0])),
                fontsize=8,
                color=_COLOR["delta_v"],
            )
            drawn.add("delta_v")
        if body.force is not None and not body.fixed:
            tail = _sub(body.cg, _scale(body.force, 0.75 * size))
            canvas.arrow(tail, body.cg, _COLOR["pdof"], lw=1.8, ls="-.", zorder=6, scale=12)
            canvas.label(
                tail,
                f"{body.name}: {_pdof_label(body)}",
                _angle(_scale(body.force, -1.0)),
                wrapped=f"{body.name}:\n{_pdof_label(body)}",
                fontsize=8,
                color=_COLOR["pdof"],
            )
            drawn.add("pdof")
        for rate, radius, ls, key in ((body.w0, 0.28, "--", "yaw_before"), (body.w1, 0.4, "-", "yaw_after")):
            if rate is None or wmax <= 0 or abs(rate) <= 1e-9 * wmax:
                continue
            span = math.copysign(40.0 + 180.0 * abs(rate) / wmax, rate)
            start = 100.0 if index == 0 else -80.0
            color = _COLOR["before"] if key == "yaw_before" else _COLOR["after"]
            end = canvas.arc(body.cg, radius * size, start, span, color, ls)
            canvas.label(end, f"{rate:+.3g}", _angle(_sub(end, body.cg)), fontsize=8, color=color)
            drawn.add(key)

    handles += [
        Line2D([], [], ls="none", marker="o", ms=7, mfc="white", mec="black", label="centre of gravity"),
        Line2D([], [], ls="none", marker="X", ms=9, mfc="black", mec="white", label="impact centre"),
        Line2D([], [], color=_COLOR["surface"], lw=2.5, label="crush surface (along t)"),
        Line2D([], [], color=_COLOR["normal"], lw=1.5, marker=">", ms=5, label="normal n (vehicle 1 → 2)"),
    ]
    legend_lines = {
        "before": (dict(color=_COLOR["before"], lw=2.2), f"velocity before [{speed_unit}]"),
        "after": (dict(color=_COLOR["after"], lw=2.2), f"velocity after [{speed_unit}]"),
        "delta_v": (dict(color=_COLOR["delta_v"], lw=2.0, ls="--"), f"delta-V [{speed_unit}]"),
        "pdof": (
            dict(color=_COLOR["pdof"], lw=1.8, ls="-."),
            "PDOF: impulse on vehicle\n[° clockwise from heading]",
        ),
        "yaw_before": (dict(color=_COLOR["before"], lw=1.6, ls="--"), "yaw rate before [rad/s] (ccw +)"),
        "yaw_after": (dict(color=_COLOR["after"], lw=1.6), "yaw rate after [rad/s] (ccw +)"),
    }
    handles += [
        Line2D([], [], label=label, **style) for key, (style, label) in legend_lines.items() if key in drawn
    ]

    xlim, ylim = canvas.limits(0.15 * size)
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_aspect("equal", adjustable="box")
    ax.grid(True, lw=0.4, alpha=0.5)
    schematic = " (positions schematic)" if not scene.uses_yaw else ""
    ax.set_xlabel(f"x [{length_unit}]{schematic}")
    ax.set_ylabel(f"y [{length_unit}]")
    ax.set_title(title if title is not None else _title(scene, result), fontsize=10)
    if result is not None:
        flags = int(_num(getattr(result, "flags", 0)) or 0)
        problems = [text for bit, text in _FLAG_SHORT.items() if flags & bit]
        if problems:
            ax.text(
                0.01,
                0.01,
                "flagged: " + "; ".join(problems),
                transform=ax.transAxes,
                fontsize=9,
                color="crimson",
                ha="left",
                va="bottom",
                zorder=10,
                bbox=dict(boxstyle="round,pad=0.25", fc="white", ec="crimson", alpha=0.85),
            )
    legend_title = f"arrows: 1 {length_unit} = {1.0 / k:.3g} {speed_unit}"
    if legend:
        add_legend(ax, handles, legend_title)
    if arrange_labels:
        place_labels(ax)
    return handles, legend_title


def add_legend(ax, handles, title: str):
    """The legend, outside the axes on the right."""
    return ax.legend(
        handles=handles,
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
        title=title,
        title_fontsize=8,
        frameon=False,
    )


def render(
    ax,
    scene_or_result: Any,
    *,
    scene: SceneLike | None = None,
    velocity_scale: float | None = None,
    title: str | None = None,
):
    """Draw like :func:`scene` but without the legend and with the labels at
    their anchors; return ``(handles, legend title)`` for :func:`add_legend` (the
    explorer adds the legend only when it changes, and calls :func:`place_labels`
    once it has set the limits)."""
    the_scene, the_result, position = _resolve(scene_or_result, scene, None)
    return _draw(ax, the_scene, the_result, position, velocity_scale, False, title, arrange_labels=False)


def _pdof_label(body: _Body) -> str:
    """The PDOF as text, one style for every vehicle: the CRASH3 habit of
    :mod:`impactsym.reconstruct` (where the impulse comes from, degrees
    clockwise from straight ahead, and the clock position). Straight ahead is
    the vehicle's ``heading``; without one, its direction of travel before the
    impact (after it, for a vehicle at rest), else +x."""
    angle = _angle(body.force)
    heading = body.heading
    if heading is None:
        travel = next((v for v in (body.v0, body.v1) if v is not None and _norm(v) > 0), (1.0, 0.0))
        heading = _angle(travel)
    clockwise = (heading - angle - 180.0 + 180.0) % 360.0 - 180.0
    clock = (round(clockwise / 30.0) - 1) % 12 + 1
    return f"PDOF {round(clockwise)}° ({clock} o'clock)"  # an int: no "-0°"


def shown_beside(value: float, bounds: tuple[float, ...], digits: int = 3) -> str:
    """``value`` with ``digits`` significant digits, or as many more as it
    takes not to read as one of ``bounds`` it differs from (a flag raised for
    e_m = 1.00067 must not be captioned "e_m = 1"); then as few as show it on
    the same side of that bound."""
    for places in range(digits, 18):
        text = f"{value:.{places}g}"
        shown = float(text)
        if not any(b != value and (shown == b or (shown > b) != (value > b)) for b in bounds):
            return text
    return repr(value)


def _title(scene: Scene, result: Any) -> str:
    impact = scene.impact
    name = scene.source.name if scene.source is not None else "scene"
    mu = (
        "μ = μ_c"
        if impact.critical
        else f"slip = {impact.slip:g}"
        if impact.impulse_ratio is None
        else f"μ = {float(impact.impulse_ratio):g}"
    )
    em = f", e_m = {impact.moment_restitution:g}" if scene.uses_yaw else ""
    head = (
        f"{name}: {scene.model} model, {scene.units}; Γ = {impact.normal_angle:g}°, "
        f"e = {impact.restitution:g}, {mu}{em}"
    )
    if getattr(result, "law", None):  # impactsym.laws: the law, not its rigid reading
        friction = "" if result.friction is None else f", friction {result.friction:g}"
        head = (
            f"{name}: {result.model} ({result.law}{friction}), {scene.units}; "
            f"Γ = {impact.normal_angle:g}°, e = {impact.restitution:g}"
        )
    if getattr(result, "kind", None) == "reconstruct":
        head = (
            f"{name}: reconstruction, {scene.units}; Γ = {impact.normal_angle:g}°, implied e = "
            f"{shown_beside(result.e, (0.0, 1.0))}, e_m = {shown_beside(result.e_m, (-1.0, 1.0))}"
        )
    if result is None:
        return head
    energy = UNIT_LABELS[scene.units]["energy"]
    parts = []
    mu_value, mu_c = _num(getattr(result, "mu", None)), _num(getattr(result, "mu_c", None))
    if mu_value is not None:  # digits enough to tell μ from its bounds 0 and μ_c (flag 4)
        parts.append(f"μ = {shown_beside(mu_value, (0.0,) if mu_c is None else (0.0, mu_c))}")
    if mu_c is not None:
        parts.append(f"μ_c = {mu_c:.3g}")
    loss = _num(getattr(result, "TL", None))
    if loss is not None:
        parts.append(f"energy loss TL = {loss:.4g} {energy}")
    return head + ("\n" + ", ".join(parts) if parts else "")
