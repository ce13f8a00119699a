"""Solve one law scene: the object and JSON of `impactsym.solve`, plus the law's own entries."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from ..codes import describe_status
from ..errors import SceneError
from ..result import Result, json_number
from .kernels import SLIP_CLASSES, solve_one
from .scene import LawScene, load_law_scene

_HINTS = {
    3: "check impact.normal_angle and the vehicles' velocities and yaw rates",
    13: "the friction is too high for this geometry: the normal relative velocity never "
    "reaches zero while sliding (lower impact.friction or use a full contact)",
}


@dataclass(frozen=True)
class LawResult(Result):
    """A solved law scene: a :class:`Result` (M = TLm = 0; ``mu`` the realised
    Pt/Pn; ``mu_c`` Brach's critical ratio at the scene's e) plus the law
    (``contact`` of K–S or ``restitution_law`` of Coulomb), its friction, and
    ``slip`` (Coulomb: "continues", "stops" or "reverses") or ``contact_used``
    (K–S: "full" or "sliding")."""

    law: str = ""
    friction: float | None = None
    slip: str | None = None
    contact_used: str | None = None

    def to_json_dict(self) -> dict[str, Any]:
        """The object of ``solve --json`` plus the law's entries."""
        out = super().to_json_dict()
        if self.model == "kudlich_slibar":
            out["contact"] = self.law
            out["contact_used"] = self.contact_used
        else:
            out["restitution_law"] = self.law
            out["slip"] = self.slip
        out["friction"] = None if self.friction is None else json_number(self.friction)
        return out

    def table(self) -> str:
        """The table of `solve`, headed with the law."""
        text = Result.table(replace(self, model="rigid"))
        head, _, rest = text.partition("\n")
        law = f"{self.model} model ({self.law}" + (
            f", friction {self.friction:g})" if self.friction is not None else ")"
        )
        extra = f"slip: {self.slip}" if self.slip else f"contact used: {self.contact_used}"
        return (
            head.replace("rigid model", law) + "\n" + rest.replace("\nwarnings", f"\n{extra}\n\nwarnings", 1)
        )


def solve_law(source) -> LawResult:
    """Solve a law scene (mapping or file; conventions.md "Other impact laws").
    SceneError for a bad scene or one the law cannot solve."""
    law_scene = source if isinstance(source, LawScene) else load_law_scene(source)
    out = solve_one(law_scene.model, law_scene.law, law_scene.inputs())
    status = out["status"]
    if status != 0:
        reason = f"cannot solve the scene: {describe_status(status)}"
        hint = _HINTS.get(status)
        raise SceneError(f"{reason}; {hint}" if hint else reason)
    return result_of(law_scene, out)


def result_of(law_scene: LawScene, out: dict) -> LawResult:
    """A LawResult from a scene and its kernel row (status 0)."""
    base = Result.from_kernel(law_scene.scene, out)
    slip = SLIP_CLASSES[out["slip_class"]] if "slip_class" in out else None
    used = None if "sliding" not in out else ("sliding" if out["sliding"] else "full")
    fields = {name: getattr(base, name) for name in base.__dataclass_fields__}
    fields.update(model=law_scene.model, critical=False, warnings=base.warnings + list(law_scene.warnings))
    return LawResult(**fields, law=law_scene.law, friction=law_scene.friction, slip=slip, contact_used=used)
