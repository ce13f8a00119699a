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
:mod:`impactsym.plot_crash3` instead (:func:`save_plot` dispatches).

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

:func:`sweep` and :func:`save_sweep` (parameter sweeps) live in
:mod:`impactsym.plot_sweep` and are re-exported here.
"""

from __future__ import annotations

import argparse
import math
import weakref
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ._util import require
from .codes import FLAG_ENERGY_CREATED, FLAG_MU_BEYOND_CRITICAL, FLAG_TENSILE_IMPULSE
from .crash3 import Crash3Result
from .laws.scene import is_law_scene, load_law_scene
from .plot_crash3 import save_crash3
from .plot_sweep import save_sweep, sweep
from .result import UNIT_LABELS
from .scene import Scene, SceneError, _read_file, load_scene

__all__ = [
    "scene",
    "save_plot",
    "sweep",
    "save_sweep",
    "add_plot_argument",
    "default_velocity_scale",
    "PRE_IMPACT_KINDS",
]

#: Result kinds whose ``velocity``/``yaw_rate`` are the pre-impact motion.
PRE_IMPACT_KINDS = ("invert", "inverse", "reconstruct", "reconstruction")

LENGTH_UNITS = {"SI": "m", "US": "ft"}

_ARROW_LENGTH = 1.8  # the longest velocity arrow, in characteristic lengths
_PARTICLE_OFFSET = 0.35  # particle distance from the impact centre, in characteristic lengths
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

SceneLike = Scene | Mapping | str | Path


@dataclass
class _Body:
    """What is drawn for one vehicle (scene frame, scene units)."""

    name: str
    fixed: bool
    cg: tuple[float, float]
    outline: tuple[float, float, float] | None = None  # length, width, heading [deg]
    v0: tuple[float, float] | None = None  # pre-impact velocity
    v1: tuple[float, float] | None = None  # post-impact velocity
    dv: tuple[float, float] | None = None  # delta-V
    w0: float | None = None  # pre-impact yaw rate
    w1: float | None = None  # post-impact yaw rate
    force: tuple[float, float] | None = None  # direction of the impulse on the body (unit)
    heading: float | None = None  # the scene's ``heading`` [deg], for the PDOF label


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
    CRASH3 diagram (:mod:`impactsym.plot_crash3`).
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


def add_plot_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--plot PATH`` to a command's parser (``impactsym solve SCENE --plot out.png``).

    The value is checked when parsed: matplotlib must be installed and the
    suffix must be an image format matplotlib writes; otherwise argparse
    reports a usage error (one line, exit code 2 in the CLI).
    """
    parser.add_argument(
        "--plot",
        metavar="PATH",
        type=_plot_path,
        default=None,
        help="also draw the scene diagram to PATH (.png, .svg, .pdf; needs matplotlib)",
    )


def default_velocity_scale(
    scene_or_result: Any, *, scene: SceneLike | None = None, result: Any = None
) -> float:
    """The ``velocity_scale`` :func:`scene` would choose: the drawn length (scene
    length unit) of one velocity unit, so that the longest arrow is about twice
    the vehicles' size. Pass it back to keep arrows comparable between drawings."""
    the_scene, the_result, position = _resolve(scene_or_result, scene, result)
    size = _characteristic_length(the_scene)
    return _auto_scale(_bodies(the_scene, the_result, position, size), size)


# --------------------------------------------------------------------------- inputs


_FORMATS = (".png", ".svg", ".pdf", ".jpg", ".jpeg", ".eps", ".ps", ".webp", ".tif", ".tiff")


def _plot_path(text: str) -> Path:
    """``--plot`` argument type: a path with an image suffix, matplotlib installed."""
    path = Path(text)
    if path.suffix.lower() not in _FORMATS:
        raise argparse.ArgumentTypeError(
            f"--plot {text}: unknown image type {path.suffix or '(none)'!r} (use .png, .svg or .pdf)"
        )
    try:
        require("matplotlib", extra="plot", what="--plot", load=False)
    except ImportError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return path


def _is_scene_like(obj: Any) -> bool:
    return isinstance(obj, (Scene, Mapping, str, Path))


def _resolve(obj: Any, scene: SceneLike | None, result: Any) -> tuple[Scene, Any, tuple[float, float]]:
    """The scene, the result (or ``None``) and the impact-centre position."""
    if _is_scene_like(obj):
        if scene is not None:
            raise TypeError("plot: give the scene once (positionally or as scene=)")
        scene = obj
    else:
        if result is not None:
            raise TypeError("plot: give the result once (positionally or as result=)")
        result = obj
        if scene is None:
            scene = getattr(result, "scene", None)
        if scene is None:
            raise TypeError(
                f"plot: a {type(result).__name__} does not carry its scene; pass scene=... "
                "(the scene file or Scene it was solved from)"
            )
    if result is not None and not hasattr(result, "vehicles"):
        raise TypeError(f"plot: expected a result with vehicles, got {type(result).__name__}")
    kind = _SCENE_KINDS.get(str(getattr(result, "kind", "solve")), "forward")
    if is_law_scene(scene):  # impactsym.laws: drawn as its rigid reading
        return load_law_scene(scene).scene, result, _impact_position(scene)
    return load_scene(scene, kind=kind), result, _impact_position(scene)


#: Which scene kind (load_scene) a result kind was solved from.
_SCENE_KINDS = {"solve": "forward", "invert": "inverse", "reconstruct": "reconstruct"}


def _impact_position(source: SceneLike) -> tuple[float, float]:
    """``impact.position`` of the scene data when present, else the origin."""
    if isinstance(source, Scene):
        position = getattr(source.impact, "position", None)
        if position is None:
            position = (getattr(source.impact, "extra", None) or {}).get("position")
        if position is None:
            position = source.extra.get("impact_position")
        if position is None and source.source is not None:
            try:
                raw = _read_file(source.source)
            except (OSError, SceneError):
                raw = None
            position = _raw_position(raw)
    elif isinstance(source, Mapping):
        position = _raw_position(source)
    else:
        try:
            position = _raw_position(_read_file(Path(source)))
        except (OSError, SceneError):
            position = None
    if position is None:
        return (0.0, 0.0)
    try:
        x, y = (float(value) for value in position)
    except (TypeError, ValueError):
        raise SceneError(f"must be a list of 2 finite numbers, got {position!r}", "impact.position") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise SceneError(f"must be a list of 2 finite numbers, got {position!r}", "impact.position")
    return (x, y)


def _raw_position(raw: Any):
    if isinstance(raw, Mapping):
        impact = raw.get("impact")
        if isinstance(impact, Mapping) and "position" in impact:
            return impact["position"]
        return raw.get("impact_position")
    return None


def _vec(value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        x, y = (float(item) for item in value)
    except (TypeError, ValueError):
        return None
    return (x, y) if math.isfinite(x) and math.isfinite(y) else None


def _num(value: Any) -> float | None:
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) else None


def _first(*values):
    for value in values:
        if value is not None:
            return value
    return None


def _add(a, b):
    return (a[0] + b[0], a[1] + b[1])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def _scale(a, k):
    return (a[0] * k, a[1] * k)


def _norm(a) -> float:
    return math.hypot(a[0], a[1])


# --------------------------------------------------------------------------- layout


def _frame(scene: Scene):
    gamma = math.radians(scene.impact.normal_angle)
    n = (math.cos(gamma), math.sin(gamma))
    t = (-math.sin(gamma), math.cos(gamma))
    return n, t


def _outline(vehicle, velocity) -> tuple[float, float, float] | None:
    """(length, width, heading) when the scene entry gives length and width."""
    length, width = _num(vehicle.extra.get("length")), _num(vehicle.extra.get("width"))
    if length is None or width is None:
        return None
    heading = _num(vehicle.extra.get("heading"))
    if heading is None:
        heading = (
            math.degrees(math.atan2(velocity[1], velocity[0])) if velocity and _norm(velocity) > 0 else 0.0
        )
    return (length, width, heading)


def _characteristic_length(scene: Scene) -> float:
    sizes = []
    for vehicle in scene.vehicles:
        if vehicle.fixed:
            continue
        if scene.uses_yaw:
            sizes.append(_norm(vehicle.impact_point))
        for key in ("length", "width"):
            size = _num(vehicle.extra.get(key))
            if size is not None:
                sizes.append(0.5 * size)
    size = max(sizes, default=0.0)
    return size if size > 0 else 1.0


def _bodies(scene: Scene, result: Any, centre, size: float) -> list[_Body]:
    """Placement and motion of both bodies."""
    n, t = _frame(scene)
    kind = str(getattr(result, "kind", "solve") or "solve").lower() if result is not None else None
    rigid = scene.uses_yaw
    bodies = []
    for index, vehicle in enumerate(scene.vehicles):
        entry = result.vehicles[index] if result is not None else None
        v0, v1, dv, w0, w1 = _motion(vehicle, entry, kind, rigid)
        outline = _outline(vehicle, _first(v0, v1))
        if rigid:
            cg = _sub(centre, vehicle.impact_point)
        else:
            offset = 0.5 * outline[0] if outline else _PARTICLE_OFFSET * size
            cg = _add(centre, _scale(n, offset if index else -offset))
        bodies.append(
            _Body(
                vehicle.name,
                vehicle.fixed,
                cg,
                outline,
                v0,
                v1,
                dv,
                w0,
                w1,
                heading=_num(vehicle.extra.get("heading")),
            )
        )
    _set_forces(bodies, result, n, t)
    return bodies


def _motion(vehicle, entry, kind, rigid):
    """(v0, v1, dv, w0, w1) of one vehicle; ``None`` where unknown or not drawn."""
    if vehicle.fixed:
        return None, None, None, None, None
    scene_v0 = _vec(vehicle.velocity)
    scene_w0 = _num(vehicle.yaw_rate)
    scene_v1 = _vec(vehicle.extra.get("final_velocity"))
    scene_w1 = _num(vehicle.extra.get("final_yaw_rate"))
    if entry is None:
        v0, v1, dv, w0, w1 = scene_v0, scene_v1, None, scene_w0, scene_w1
    else:
        velocity, rate = _vec(getattr(entry, "velocity", None)), _num(getattr(entry, "yaw_rate", None))
        if kind in PRE_IMPACT_KINDS:
            v0, w0 = _first(velocity, scene_v0), _first(rate, scene_w0)
            v1, w1 = scene_v1, scene_w1
        else:
            v0, w0 = scene_v0, scene_w0
            v1, w1 = velocity, rate
        v0 = _first(_vec(getattr(entry, "initial_velocity", None)), v0)
        v1 = _first(_vec(getattr(entry, "final_velocity", None)), v1)
        w0 = _first(_num(getattr(entry, "initial_yaw_rate", None)), w0)
        w1 = _first(_num(getattr(entry, "final_yaw_rate", None)), w1)
        dv = _vec(getattr(entry, "delta_v", None))
        if dv is not None and v1 is None and v0 is not None:
            v1 = _add(v0, dv)
        if dv is not None and v0 is None and v1 is not None:
            v0 = _sub(v1, dv)
        if dv is None and v0 is not None and v1 is not None:
            dv = _sub(v1, v0)
    if not rigid:
        w0 = w1 = None
    return v0, v1, dv, w0, w1


def _set_forces(bodies: list[_Body], result: Any, n, t) -> None:
    """PDOF: P = Pn·n + Pt·t on vehicle 1, -P on vehicle 2; else the delta-V direction."""
    if result is None:
        return
    pn, pt = _num(getattr(result, "Pn", None)), _num(getattr(result, "Pt", None))
    impulse = _add(_scale(n, pn), _scale(t, pt)) if pn is not None and pt is not None else None
    for index, body in enumerate(bodies):
        direction = None
        if impulse is not None:
            direction = impulse if index == 0 else _scale(impulse, -1.0)
        elif body.dv is not None:
            direction = body.dv
        if direction is not None and _norm(direction) > 0:
            body.force = _scale(direction, 1.0 / _norm(direction))


def _auto_scale(bodies: list[_Body], size: float) -> float:
    """Drawn length per velocity unit: the longest velocity or delta-V arrow is
    ``_ARROW_LENGTH`` characteristic lengths."""
    vectors = [v for body in bodies for v in (body.v0, body.v1, body.dv) if v is not None]
    vmax = max((_norm(v) for v in vectors), default=0.0)
    return _ARROW_LENGTH * size / vmax if vmax > 0 else 1.0


# --------------------------------------------------------------------------- drawing


class _Canvas:
    """Draws on an axes and remembers every point, for the limits."""

    def __init__(self, ax):
        from matplotlib.patches import FancyArrowPatch, Polygon
        from matplotlib.path import Path as MplPath

        self.ax = ax
        self.points: list[tuple[float, float]] = []
        self._arrow, self._polygon, self._path = FancyArrowPatch, Polygon, MplPath

    def arrow(self, tail, head, color, lw=2.0, ls="-", alpha=1.0, zorder=4, scale=14):
        if _norm(_sub(head, tail)) <= 0:
            return
        self.ax.add_patch(
            self._arrow(
                tail,
                head,
                arrowstyle="-|>",
                mutation_scale=scale,
                color=color,
                lw=lw,
                linestyle=ls,
                alpha=alpha,
                shrinkA=0,
                shrinkB=0,
                zorder=zorder,
            )
        )
        self.points += [tail, head]

    def arc(self, centre, radius, start_deg, sweep_deg, color, ls, zorder=5):
        steps = max(8, int(abs(sweep_deg) / 6))
        points = []
        for step in range(steps + 1):
            angle = math.radians(start_deg + sweep_deg * step / steps)
            points.append((centre[0] + radius * math.cos(angle), centre[1] + radius * math.sin(angle)))
        self.ax.add_patch(
            self._arrow(
                path=self._path(points),
                arrowstyle="-|>",
                mutation_scale=11,
                color=color,
                lw=1.6,
                linestyle=ls,
                zorder=zorder,
            )
        )
        self.points += points
        return points[-1]

    def polygon(self, corners, **style):
        self.ax.add_patch(self._polygon(corners, closed=True, **style))
        self.points += list(corners)

    def line(self, a, b, **style):
        self.ax.plot([a[0], b[0]], [a[1], b[1]], **style)
        self.points += [a, b]

    def marker(self, point, **style):
        self.ax.plot([point[0]], [point[1]], **style)
        self.points.append(point)

    def label(self, anchor, text, prefer_deg: float, wrapped: str | None = None, **style):
        """A label near ``anchor`` (data coordinates); :func:`_place_labels` later
        moves it around the anchor, trying the screen direction ``prefer_deg`` first
        and the text ``wrapped`` (on two lines) when the one line finds no free place."""
        label = self.ax.annotate(
            text,
            anchor,
            xytext=(0.0, 0.0),
            textcoords="offset points",
            ha="center",
            va="center",
            zorder=6,
            annotation_clip=False,
            bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.75),
            **style,
        )
        label.set_in_layout(False)  # kept inside the axes by _place_labels; must not move the layout
        _PREFERRED[label] = (prefer_deg, wrapped)
        self.points.append(anchor)

    def limits(self, pad: float):
        xs = [p[0] for p in self.points]
        ys = [p[1] for p in self.points]
        return (min(xs) - pad, max(xs) + pad), (min(ys) - pad, max(ys) + pad)


def _angle(vector) -> float:
    """Direction of a vector, degrees counter-clockwise from +x (the screen
    direction too: the axes have equal aspect)."""
    return math.degrees(math.atan2(vector[1], vector[0]))


# --------------------------------------------------------------------------- label placement

#: Scene labels (annotations made by ``_Canvas.label``): the screen direction tried
#: first and the label on two lines (or None).
_PREFERRED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_RADII = (
    2.0,
    6.0,
    11.0,
    17.0,
    24.0,
    32.0,
    42.0,
    54.0,
    68.0,
    84.0,
    102.0,
    122.0,
    145.0,
)  # label distance from its anchor [points]
_DIRECTIONS = 24
_LEADER_FROM = 14.0  # labels further than this from their anchor [points] get a leader line


def _candidates(prefer_deg: float):
    """``(offset in points, ha, va)`` around an anchor: nearest first, and at each
    distance the directions closest to ``prefer_deg`` first. The alignment puts
    the side of the text facing the anchor at the offset."""
    angles = sorted(
        (360.0 * i / _DIRECTIONS for i in range(_DIRECTIONS)),
        key=lambda a: abs((a - prefer_deg + 180.0) % 360.0 - 180.0),
    )
    for radius in _RADII:
        for angle in angles:
            c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
            ha = "left" if c > 0.38 else "right" if c < -0.38 else "center"
            va = "bottom" if s > 0.38 else "top" if s < -0.38 else "center"
            yield (radius * c, radius * s), ha, va


def _renderer(fig):
    canvas = fig.canvas
    return canvas.get_renderer() if hasattr(canvas, "get_renderer") else fig._get_renderer()


def _obstacles(ax, renderer, labels) -> tuple[list, list]:
    """What a label must not cover, in display coordinates: ``(paths, boxes)``;
    paths as ``(path, filled, pad)`` (arrows, outlines and lines by their stroke,
    a hatched barrier or a small filled mark as an area; ``pad`` half the line
    width), boxes ``(x0, y0, x1, y1)`` for markers and fixed texts."""
    from matplotlib.patches import FancyArrowPatch

    points = renderer.points_to_pixels(1.0)
    paths, boxes = [], []
    for patch in ax.patches:
        path = patch.get_transform().transform_path(patch.get_path())
        filled = bool(patch.get_hatch()) or (
            patch.get_facecolor()[3] > 0
            and not isinstance(patch, FancyArrowPatch)
            and len(path.vertices) <= 5
        )  # a small filled mark (the front ▶)
        paths += [(part, filled, 0.5 * patch.get_linewidth() * points) for part in _polylines(path)]
    for line in ax.lines:
        xy = line.get_xydata()
        if len(xy) == 1:  # a marker
            x, y = ax.transData.transform(xy[0])
            half = (0.5 * line.get_markersize() + line.get_markeredgewidth()) * points
            boxes.append((x - half, y - half, x + half, y + half))
        else:
            path = line.get_transform().transform_path(line.get_path())
            paths += [(part, False, 0.5 * line.get_linewidth() * points) for part in _polylines(path)]
    for text in ax.texts:
        if text not in labels and text.get_visible() and text.get_text():  # e.g. the flags box
            patch = text.get_bbox_patch()
            boxes.append(tuple((patch or text).get_window_extent(renderer).extents))
    return paths, boxes


def _polylines(path) -> list:
    """A display path as plain polylines (curves flattened, closed parts closed):
    ``Path.intersects_bbox`` would take the placeholder vertex of a CLOSEPOLY
    code (often (0, 0)) for a real point."""
    from matplotlib.path import Path as MplPath

    return [MplPath(polygon) for polygon in path.to_polygons(closed_only=False) if len(polygon) > 1]


def _place_labels(ax) -> None:
    """Move each scene label to the nearest position around its anchor where its
    box (text and background) lies inside the axes and touches no arrow, outline,
    line, marker or other text (greedy, in drawing order). A label that finds
    no free place on one line tries two (when it has a two-line form); when
    still none is free, the position running into the fewest things is kept."""
    fig = ax.figure
    if fig.get_layout_engine() is not None:
        # the final axes position: constrained layout around an equal-aspect axes
        # settles on its second pass (the first starts from the unshrunk axes)
        fig.draw_without_rendering()
        fig.draw_without_rendering()
    else:
        ax.apply_aspect()
    renderer = _renderer(fig)
    labels = [text for text in ax.texts if text in _PREFERRED]
    paths, boxes = _obstacles(ax, renderer, labels)
    obstacles = _Obstacles(ax.bbox.extents, paths, boxes)
    for label in labels:
        prefer, wrapped = _PREFERRED[label]
        best = _best_position(label, prefer, renderer, obstacles)
        if best[0] and wrapped:  # no free place: try the label on two lines
            line = label.get_text()
            label.set_text(wrapped)
            best = min(
                best + (line,),
                _best_position(label, prefer, renderer, obstacles) + (wrapped,),
                key=lambda choice: choice[0],
            )
            label.set_text(best[-1])
        _, offset, ha, va, box = best[:5]
        label.xyann = offset
        label.set_horizontalalignment(ha)
        label.set_verticalalignment(va)
        if math.hypot(*offset) > _LEADER_FROM:  # far from its anchor: a thin line says whose label it is
            start, end = _leader_segment(ax.transData.transform(label.xy), box)
            ax.plot(
                *zip(*ax.transData.inverted().transform([start, end])),
                color=label.get_color(),
                lw=0.7,
                alpha=0.7,
                zorder=label.get_zorder() - 0.5,
                gid="leader",
            )
            obstacles.add_leader(start, end)
        obstacles.boxes.append(box)


def _leader_segment(anchor, box):
    """The leader line of a label (display coordinates): from its anchor to the
    nearest point of its box."""
    x, y = anchor
    return (x, y), (min(max(x, box[0]), box[2]), min(max(y, box[1]), box[3]))


class _Obstacles:
    """The axes frame, paths and boxes a label's box is checked against
    (display coordinates). The cheap tests (frame, boxes, path extents) run on
    all candidate boxes at once; the exact path test only where a box reaches
    a path's extent."""

    def __init__(self, frame, paths, boxes):
        import numpy as np

        self.frame, self.paths, self.boxes = np.asarray(frame), paths, boxes
        self.extents = np.array([[*path.get_extents().extents] for path, _, _ in paths]).reshape(-1, 4)
        self.pads = np.array([pad for _, _, pad in paths])
        self.leaders: list = []

    def add_leader(self, start, end) -> None:
        """A leader line drawn: later labels neither cover nor cross it."""
        import numpy as np
        from matplotlib.path import Path as MplPath

        path = MplPath([start, end])
        self.paths.append((path, False, 1.0))
        self.extents = np.vstack([self.extents, path.get_extents().extents])
        self.pads = np.append(self.pads, 1.0)
        self.leaders.append(path)

    def _leader_crosses(self, anchor, box) -> bool:
        """Whether the leader line of a label at ``box`` would cross a placed
        label's box or another leader line."""
        from matplotlib.path import Path as MplPath
        from matplotlib.transforms import Bbox

        start, end = _leader_segment(anchor, box)
        leader = MplPath([start, end])
        return any(
            leader.intersects_bbox(Bbox([other[:2], other[2:]]), filled=False) for other in self.boxes
        ) or any(leader.intersects_path(other) for other in self.leaders)

    def best(self, candidates, anchor, far):
        """``(conflicts, index)`` of the first free box of ``candidates`` (an
        (N, 4) array of x0, y0, x1, y1), else of the one running into the
        fewest things (leaving the axes counts as many; a path whose extent a
        box reaches counts without the exact test). A box ``far`` from its
        ``anchor`` (display coordinates) gets a leader line, which should cross
        no placed label and no other leader: the first free box whose leader
        crosses is taken only when no box is free with its leader."""
        import numpy as np
        from matplotlib.transforms import Bbox

        x0, y0, x1, y1 = (candidates[:, i : i + 1] for i in range(4))
        fx0, fy0, fx1, fy1 = self.frame
        outside = ~((fx0 <= x0) & (x1 <= fx1) & (fy0 <= y0) & (y1 <= fy1))[:, 0]
        b = np.array(self.boxes, dtype=float).reshape(-1, 4)
        hits = ((x0 < b[:, 2]) & (b[:, 0] < x1) & (y0 < b[:, 3]) & (b[:, 1] < y1)).sum(axis=1)
        e, pad = self.extents, self.pads
        near = (x0 - pad <= e[:, 2]) & (e[:, 0] <= x1 + pad) & (y0 - pad <= e[:, 3]) & (e[:, 1] <= y1 + pad)
        cost = 100 * outside + hits + near.sum(axis=1)
        crossing = None
        for index in np.flatnonzero((~outside) & (hits == 0)):
            box = Bbox(candidates[index].reshape(2, 2))
            if any(
                self.paths[k][0].intersects_bbox(box.padded(self.pads[k]), filled=self.paths[k][1])
                for k in np.flatnonzero(near[index])
            ):
                continue
            if far[index] and self._leader_crosses(anchor, candidates[index]):
                crossing = int(index) if crossing is None else crossing
                continue
            return 0, int(index)
        if crossing is not None:  # a free box whose leader crosses: better than a box on something
            return 0, crossing
        index = int(np.argmin(cost))  # the first of the least crowded
        return int(cost[index]) or 1, index


def _best_position(label, prefer: float, renderer, obstacles: _Obstacles):
    """``(conflicts, offset, ha, va, box)``: the first free candidate position
    of ``label``, or the one running into the fewest things. The text's size
    is measured once; a candidate's box follows from its offset and alignment."""
    import numpy as np

    points = renderer.points_to_pixels(1.0)
    pad = 0.25 * label.get_fontsize() * points  # the background box around the text
    label.xyann = (0.0, 0.0)
    label.set_horizontalalignment("center")
    label.set_verticalalignment("center")
    centre = label.get_window_extent(renderer)
    half_w, half_h = 0.5 * centre.width, 0.5 * centre.height
    shift = {"left": 1.0, "right": -1.0, "center": 0.0, "bottom": 1.0, "top": -1.0}
    candidates = list(_candidates(prefer))
    middles = np.array(
        [
            (
                0.5 * (centre.x0 + centre.x1) + dx * points + shift[ha] * half_w,
                0.5 * (centre.y0 + centre.y1) + dy * points + shift[va] * half_h,
            )
            for (dx, dy), ha, va in candidates
        ]
    )
    size = np.array([half_w + pad, half_h + pad])
    boxes = np.hstack([middles - size, middles + size])
    far = np.array([math.hypot(*offset) > _LEADER_FROM for offset, _, _ in candidates])
    cost, index = obstacles.best(boxes, (0.5 * (centre.x0 + centre.x1), 0.5 * (centre.y0 + centre.y1)), far)
    offset, ha, va = candidates[index]
    return cost, offset, ha, va, tuple(boxes[index])


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
    place_labels: bool = True,
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
        _legend(ax, handles, legend_title)
    if place_labels:
        _place_labels(ax)
    return handles, legend_title


def _legend(ax, handles, title: str):
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


def _render(
    ax,
    scene_or_result: Any,
    *,
    scene: SceneLike | None = None,
    velocity_scale: float | None = None,
    title: str | None = None,
):
    """Draw like :func:`scene` but without the legend and with the labels at
    their anchors; return ``(handles, legend title)`` for :func:`_legend` (the
    explorer adds the legend only when it changes, and calls :func:`_place_labels`
    once it has set the limits)."""
    the_scene, the_result, position = _resolve(scene_or_result, scene, None)
    return _draw(ax, the_scene, the_result, position, velocity_scale, False, title, place_labels=False)


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
            f"{name}: reconstruction, {scene.units}; Γ = {impact.normal_angle:g}°, implied e = {result.e:.3g}, "
            f"e_m = {result.e_m:.3g}"
        )
    if result is None:
        return head
    energy = UNIT_LABELS[scene.units]["energy"]
    parts = []
    mu_value, mu_c = _num(getattr(result, "mu", None)), _num(getattr(result, "mu_c", None))
    if mu_value is not None:
        parts.append(f"μ = {mu_value:.3g}")
    if mu_c is not None:
        parts.append(f"μ_c = {mu_c:.3g}")
    loss = _num(getattr(result, "TL", None))
    if loss is not None:
        parts.append(f"energy loss TL = {loss:.4g} {energy}")
    return head + ("\n" + ", ".join(parts) if parts else "")
