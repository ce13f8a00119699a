"""What a diagram draws from: the scene and result of a call (duck-typed
results, see :mod:`impactsym.pictures.diagram`), the impact-centre position,
and the small vector helpers of the drawing (scene frame, scene units)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..laws.scene import is_law_scene, load_law_scene
from ..scene import Scene, SceneError, load_scene
from ..scene.reader import read_file

#: Result kinds whose ``velocity``/``yaw_rate`` are the pre-impact motion.
PRE_IMPACT_KINDS = ("invert", "inverse", "reconstruct", "reconstruction")

SceneLike = Scene | Mapping | str | Path


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
        if hasattr(obj, "figure") and hasattr(obj, "get_xlim"):  # matplotlib Axes, not a result
            raise TypeError(
                "plot: got matplotlib Axes; save_plot draws a scene diagram from a result or a scene. "
                "To save a picture already drawn (a sweep plot, say), use ax.figure.savefig(path), "
                "or impactsym.plot.save_sweep(frame, path, x=...)"
            )
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
                raw = read_file(source.source)
            except (OSError, SceneError):
                raw = None
            position = _raw_position(raw)
    elif isinstance(source, Mapping):
        position = _raw_position(source)
    else:
        try:
            position = _raw_position(read_file(Path(source)))
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
