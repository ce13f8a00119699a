"""Scenes of the other impact laws: ``"model": "kudlich_slibar"`` and ``"coulomb"``.

conventions.md, "Other impact laws". A law scene is a rigid scene whose
``impact`` block holds the law's keys: ``restitution`` (K–S: Poisson's ε;
Coulomb: the law's e), ``normal_angle``, and

* ``kudlich_slibar``: ``contact`` ("full", the default, or "sliding") and, for
  a sliding contact, ``friction`` μ (≥ 0);
* ``coulomb``: ``friction`` μ (≥ 0, required) and ``restitution_law``
  ("newton", the default, "poisson" or "energetic").

``moment_restitution`` and ``impulse_ratio`` are accepted and reported as not
used (a point impulse; the law sets the ratio). Everything else (units, unit
strings, vehicles, fixed bodies, the sense of the normal) is read by
:func:`impactsym.scene.load_scene` as for a rigid scene.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import SceneError, show_value
from ..scene import Scene, load_scene, scene_columns
from ..scene.casefile import Leaf, LeafReader
from ..scene.reader import read_file
from .kernels import DEFAULT_LAW, LAWS

LAW_MODELS = tuple(LAWS)
#: The impact keys only the laws read (taken out before the rigid reading).
LAW_KEYS = ("contact", "friction", "restitution_law")
_NOT_USED = ("moment_restitution", "impulse_ratio")


@dataclass(frozen=True)
class LawScene:
    """A validated law scene: the rigid reading of its vehicles and impact
    geometry (`scene`), the law's model, its law (K–S contact or Coulomb
    restitution law), friction μ (None where not used) and warnings."""

    scene: Scene
    model: str
    law: str
    friction: float | None
    warnings: tuple[str, ...]
    friction_leaf: Leaf | None = None

    @property
    def uncertain(self) -> tuple[tuple[str, str, tuple[float, ...]], ...]:
        """The scene's uncertain leaves, ``impact.friction`` included when it is a
        distribution (as :attr:`impactsym.scene.Scene.uncertain`)."""
        leaf = self.friction_leaf
        own = () if leaf is None or leaf.kind is None else ((leaf.path, leaf.kind, leaf.params),)
        return self.scene.uncertain + own

    def inputs(self) -> dict[str, float]:
        """The law kernel's inputs (batch names; gamma in radians)."""
        _, _, values = self.scene.to_inputs()
        values = {k: v for k, v in values.items() if k not in ("mu", "e_m")}
        if self.friction is not None:
            values["mu_f"] = self.friction
        return values


def raw_data(source: Any) -> Any:
    """The scene's data as given (a mapping, or a file's parsed content), or
    None for a source that is not a law scene's (a Scene object)."""
    if isinstance(source, Mapping):
        return source
    if isinstance(source, (str, Path)):
        return read_file(Path(source))
    return None


def is_law_scene(source: Any) -> bool:
    """True when `source` (a mapping or a scene file) names one of the laws' models."""
    if isinstance(source, Scene):
        return False
    data = raw_data(source)
    return isinstance(data, Mapping) and data.get("model") in LAW_MODELS


def load_law_scene(source: Any) -> LawScene:
    """Read and validate a law scene (mapping or file); SceneError naming the field."""
    data = raw_data(source)
    model = data["model"]
    impact = data.get("impact")
    if not isinstance(impact, Mapping):
        raise SceneError("required (a table with normal_angle and restitution)", "impact")
    impact = dict(impact)
    own = {key: impact.pop(key) for key in LAW_KEYS if key in impact}
    warnings = [
        f"impact.{key} = {show_value(impact[key])} is not used by the {model} model (a point impulse"
        + ("; the law sets the impulse ratio)" if key == "impulse_ratio" else ", M = 0)")
        for key in _NOT_USED
        if key in impact
    ]
    if "restitution" not in impact:
        raise SceneError("required", "impact.restitution")
    impact.update(impulse_ratio=0.0, moment_restitution=1.0)
    scene = load_scene(dict(data, model="rigid", impact=impact))
    law, leaf = _law(model, own, scene.units)
    friction = None if leaf is None else leaf.nominal
    return LawScene(scene, model, law, friction, tuple(warnings), leaf)


def _law(model: str, own: Mapping, units: str) -> tuple[str, Leaf | None]:
    """(law, friction leaf) of the scene's law keys."""
    if model == "kudlich_slibar":
        if "restitution_law" in own:
            raise SceneError(
                "unknown key for the kudlich_slibar model (its restitution is Poisson's)",
                "impact.restitution_law",
            )
        law = _choice(own.get("contact", DEFAULT_LAW[model]), "impact.contact", LAWS[model])
        if law == "full":
            if "friction" in own:
                raise SceneError(
                    'not used by a "full" contact (give "contact": "sliding")', "impact.friction"
                )
            return law, None
        return law, _friction(own, units)
    if "contact" in own:
        raise SceneError("unknown key for the coulomb model", "impact.contact")
    law = _choice(own.get("restitution_law", DEFAULT_LAW[model]), "impact.restitution_law", LAWS[model])
    return law, _friction(own, units)


def _choice(value: Any, path: str, allowed: tuple[str, ...]) -> str:
    if value not in allowed:
        raise SceneError(f"must be one of {', '.join(allowed)}, got {show_value(value)}", path)
    return value


def _friction(own: Mapping, units: str) -> Leaf:
    """impact.friction: a plain number ≥ 0 (or a distribution of one, as any
    numeric leaf), read as a case-file leaf; required."""
    if "friction" not in own:
        raise SceneError(
            "required (the friction coefficient at the impact centre)",
            "impact.friction",
        )
    reader = LeafReader(units)
    reader.number(own["friction"], "impact.friction", "number", "nonnegative")
    return reader.leaves["impact.friction"]


def law_columns(law_scene: LawScene, overrides: Mapping[str, Any]) -> tuple[dict, Any]:
    """Kernel columns of a law scene with leaves overridden (path → arrays, as
    :func:`impactsym.scene.scene_columns`), ``impact.friction`` included; and
    the per-row reason a row is out of its domain ("" where it is not)."""
    import numpy as np

    rigid = {path: value for path, value in overrides.items() if path != "impact.friction"}
    sc = scene_columns(law_scene.scene, rigid)
    columns = {k: v for k, v in sc.columns.items() if k not in ("mu", "e_m")}
    if law_scene.friction is not None:
        columns["mu_f"] = overrides.get("impact.friction", law_scene.friction)
    reason = sc.reason
    if "impact.friction" in overrides:
        friction = np.asarray(overrides["impact.friction"], dtype=np.float64)
        reason = np.broadcast_to(reason, friction.shape).copy()
        reason[(friction < 0) & (reason == "")] = "impact.friction is negative"
    return columns, reason
