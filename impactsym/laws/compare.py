"""The laws in `impactsym.compare`: which law rows a scene gets, and the data the seed's models read.

* A law scene (``"model": "kudlich_slibar"`` or ``"coulomb"``) gets a row per law
  its data allow: K–S full (always), K–S sliding and the three Coulomb laws when
  it gives ``impact.friction``. The seed's models then run on its geometry with
  e = the scene's restitution and μ = the impulse ratio of the scene's own law
  (so the brach row reproduces a K–S or Coulomb–Newton impulse exactly: a PC-Crash
  case read in Brach's terms).
* Other scenes get no law rows (their model list is the seed's).

Each law row's assumptions end with the Brach (e, μ) that gives the same impulse.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..scene import scene_data
from .scene import LAW_KEYS, LawScene, is_law_scene, load_law_scene
from .single import LawResult, solve_law

ASSUMPTIONS = {
    ("kudlich_slibar", "full"): "Kudlich-Slibar (PC-Crash), full contact: both components of the relative "
    "velocity vanish at the end of compression; Poisson restitution eps; point impulse.",
    ("kudlich_slibar", "sliding"): "Kudlich-Slibar, sliding contact: the full impact unless it needs "
    "|Pt| > friction |Pn|, then |Pt| = friction |Pn| against the slip; point impulse.",
    ("coulomb", "newton"): "Coulomb friction at the impact centre, slip may stop or reverse; Newton "
    "(kinematic) restitution e; point impulse.",
    ("coulomb", "poisson"): "Coulomb friction at the impact centre; Poisson (kinetic) restitution e.",
    ("coulomb", "energetic"): "Coulomb friction at the impact centre; energetic (Stronge) restitution e: "
    "never creates energy.",
}


def comparison_input(scene: Any) -> tuple[Mapping, list[tuple[str, str, LawResult]]]:
    """(data the seed's models read, [(row name, assumptions, result)] of the law rows)."""
    if is_law_scene(scene):
        law_scene = load_law_scene(scene)
        rows = _rows(law_scene)
        own = next(r for name, _, r in rows if name == _name(law_scene.model, law_scene.law))
        data = scene_data(scene)
        impact = {k: v for k, v in data["impact"].items() if k not in LAW_KEYS}
        impact.update(impulse_ratio=own.mu)
        return {**data, "model": "rigid", "impact": impact}, rows
    return scene_data(scene), []


def _name(model: str, law: str) -> str:
    return f"{model} ({law})"


def _rows(law_scene: LawScene, laws=None) -> list[tuple[str, str, LawResult]]:
    """Each applicable law solved on the scene (a law that cannot solve it is left out)."""
    if laws is None:
        laws = [("kudlich_slibar", "full")]
        if law_scene.friction is not None:
            laws += [
                ("kudlich_slibar", "sliding"),
                ("coulomb", "newton"),
                ("coulomb", "poisson"),
                ("coulomb", "energetic"),
            ]
    out = []
    for model, law in laws:
        friction = None if (model, law) == ("kudlich_slibar", "full") else law_scene.friction
        variant = LawScene(law_scene.scene, model, law, friction, law_scene.warnings)
        result = solve_law(variant)
        text = (
            f"{ASSUMPTIONS[(model, law)]} Same impulse as Brach at e = {law_scene.scene.impact.restitution:g}, "
            f"mu = {result.mu:.6g}"
            + (
                "."
                if (model == "kudlich_slibar" or law == "newton")
                else " only while the slip does not stop or reverse."
            )
        )
        out.append((_name(model, law), text, result))
    return out
