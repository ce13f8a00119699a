"""Scene files: reading, validation and conversion to kernel inputs.

A scene describes one planar two-vehicle impact in the format of
``conventions.md`` (JSON or TOML, same structure).  Frame: x, y in the scene
plane, angles counter-clockwise from +x.  ``impact.normal_angle`` is Γ in
degrees; the normal ``n = (cos Γ, sin Γ)`` points from vehicle 1 toward
vehicle 2 (given in the other sense, it is turned round: see
:func:`impactsym.scene.casefile.used_normal_angle`).  ``impact_point`` is the vector
from a vehicle's centre of gravity to the impact centre, in the scene frame
(or ``{forward, left}`` in the vehicle frame).

Units are consistent sets: ``"SI"`` (kg, m, kg·m², m/s, rad/s) or ``"US"``
(slug, ft, slug·ft², ft/s, rad/s).  Any number may instead be a unit string
or a distribution (:mod:`impactsym.scene.casefile`, docs/casefile.md); a
:class:`Scene` holds everything in its system's units.

Validation is strict about values and keys: a bad value or an unknown key
raises :class:`SceneError` with one line naming the field path
(``vehicles[1].mass: must be a positive finite number, got -5``,
``impact.restitusion: unknown key; did you mean "restitution"?``); a known key
the command does not use is reported in :attr:`Scene.warnings`.
"""

from ..errors import SceneError, show_value
from .columns import SceneColumns, scene_columns
from .model import CRITICAL, KINDS, MODELS, UNITS, Impact, Scene, Vehicle, uses_yaw
from .reader import load_scene, scene_data

__all__ = [
    "CRITICAL",
    "KINDS",
    "MODELS",
    "UNITS",
    "Impact",
    "Scene",
    "SceneColumns",
    "SceneError",
    "Vehicle",
    "load_scene",
    "scene_columns",
    "scene_data",
    "show_value",
    "uses_yaw",
]
