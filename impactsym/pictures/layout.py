"""Where each body and arrow goes: the impact frame, outlines, centres of
gravity, motion before and after, the PDOF direction and the arrow scale."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..scene import Scene
from .inputs import PRE_IMPACT_KINDS, _add, _first, _norm, _num, _scale, _sub, _vec

_ARROW_LENGTH = 1.8  # the longest velocity arrow, in characteristic lengths
_PARTICLE_OFFSET = 0.35  # particle distance from the impact centre, in characteristic lengths


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
