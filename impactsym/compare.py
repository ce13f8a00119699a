"""Every model of the seed on one scene, side by side (the seed's Tables 5-8).

:func:`compare` runs a forward scene through each model its data allow:

- ``brach`` (the general model) and ``macmillan`` (e_m = 1) need the scene's
  restitution and impulse ratio; ``particle`` too (it ignores yaw and lever arms);
- ``limpert`` and ``impac`` (common velocity) need only the geometry; they
  coincide by construction (seed Table 7);
- ``impac_sideswipe`` runs when the scene gives ``impact.slip`` (at slip = 0 it
  is ``impac``);
- ``crash3`` runs when every moving vehicle carries a ``crush`` table, with the
  scene's ``"crash3"`` options (default restitution 0: common velocity). A
  crush-only scene (no velocities or no impact block) gives the CRASH3 row
  alone, without final velocities or energy percentages, and lists every
  impulse-momentum model as skipped with the reason.

Each row gives the final velocity of each vehicle as speed and direction
(degrees counter-clockwise from +x), the final yaw rate, delta-V, and the energy
loss with its normal, tangential and moment parts, also as a percent of the
initial kinetic energy (translational plus yaw). CRASH3 has no yaw rates and
no energy parts (crush measures the normal deformation only); its final
velocities are the initial ones plus its delta-V along the entered PDOFs.
A model the data do not allow is listed in ``skipped`` with the reason.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from . import _kernels
from ._kernels import PRESETS
from ._util import require
from .crash3 import crash3
from .laws.compare import comparison_input
from .residue import drop_residue, quantity_scales
from .result import UNIT_LABELS, Result
from .scene import Scene, SceneError, load_scene, uses_yaw
from .scene.fields import as_mapping
from .single import solve

__all__ = ["compare", "Comparison", "ModelRow", "COMPARED_MODELS"]

COMPARED_MODELS = ("brach", "macmillan", "limpert", "impac", "impac_sideswipe", "particle", "crash3")
CRASH3_ASSUMPTIONS = (
    "CRASH3 (McHenry): |delta-V| from the crush energy with a common velocity "
    "at the impact centre (e = 0, mu = mu_max); its direction from the entered "
    "PDOF; no yaw."
)
_ENERGY_PARTS = ("total", "normal", "tangential", "moment")


@dataclass(frozen=True)
class VehicleRow:
    """One vehicle in one model: final velocity [m/s | ft/s] and its speed and
    direction [deg], final yaw rate [rad/s] (None: the model has none), delta-V."""

    velocity: tuple[float, float] | None
    speed: float | None
    direction: float | None
    yaw_rate: float | None
    delta_v: tuple[float, float]
    delta_v_magnitude: float

    def to_json_dict(self) -> dict[str, Any]:
        """The vehicle entry of a model in ``compare --json``."""
        return {
            "velocity": None if self.velocity is None else list(self.velocity),
            "speed": self.speed,
            "direction": self.direction,
            "yaw_rate": self.yaw_rate,
            "delta_v": None if self.delta_v is None else list(self.delta_v),
            "delta_v_magnitude": self.delta_v_magnitude,
        }


@dataclass(frozen=True)
class ModelRow:
    """One model's outcome: vehicles, energy loss [J | ft·lb] by part (None for
    a part the model does not have) and as a percent of the initial kinetic
    energy, the impulse ratio used and the critical one (None for CRASH3)."""

    model: str
    assumptions: str
    vehicles: tuple[VehicleRow, VehicleRow]
    energy: dict[str, float | None]
    energy_percent: dict[str, float | None]
    mu: float | None
    mu_c: float | None
    warnings: list[str] = field(default_factory=list)

    def to_json_dict(self) -> dict[str, Any]:
        """One model's entry in ``compare --json``."""
        return {
            "model": self.model,
            "assumptions": self.assumptions,
            "vehicles": [v.to_json_dict() for v in self.vehicles],
            "energy_loss": dict(self.energy),
            "energy_loss_percent": dict(self.energy_percent),
            "impulse_ratio": self.mu,
            "critical_impulse_ratio": self.mu_c,
            "warnings": list(self.warnings),
        }


@dataclass(frozen=True)
class Comparison:
    """Every model the scene allows, with the initial kinetic energy [J | ft·lb]
    (None for a crush-only scene)."""

    units: str
    names: tuple[str, str]
    initial_kinetic_energy: float | None
    rows: tuple[ModelRow, ...]
    skipped: dict[str, str]
    scene_name: str | None = None  # the scene file's name, for the plot's title

    def to_json_dict(self) -> dict[str, Any]:
        """The object printed by ``impactsym compare --json``."""
        return {
            "units": self.units,
            "vehicle_names": list(self.names),
            "initial_kinetic_energy": self.initial_kinetic_energy,
            "models": [row.to_json_dict() for row in self.rows],
            "skipped": dict(self.skipped),
        }

    def _cells(self) -> tuple[list[str], list[list[str]]]:
        """Column headers and one list of cells per model."""
        labels = UNIT_LABELS[self.units]
        v, w = labels["velocity"], labels["yaw_rate"]
        headers = ["model"]
        for name in self.names:
            headers += [f"{name}: V [{v}] / dir", f"W [{w}]", f"|dV| [{v}]"]
        headers += ["TL %", "TLn %", "TLt %", "TLm %"]
        body = []
        motion = [v for row in self.rows for v in row.vehicles]
        rate = quantity_scales(  # rounding residue of a zero yaw rate shown as 0 (impactsym.residue)
            [("speed", v.speed or 0.0) for v in motion] + [("yaw_rate", v.yaw_rate or 0.0) for v in motion]
        )["yaw_rate"]
        for row in self.rows:
            cells = [row.model]
            for veh in row.vehicles:
                speed = "n/a" if veh.speed is None else f"{veh.speed:.2f} / {veh.direction:.1f}°"
                yaw = None if veh.yaw_rate is None else drop_residue(veh.yaw_rate, rate)
                cells += [speed, _cell(yaw, ".2f"), _cell(veh.delta_v_magnitude, ".2f")]
            cells += [_cell(row.energy_percent[part], ".1f") for part in _ENERGY_PARTS]
            body.append(cells)
        return headers, body

    def table(self) -> str:
        """A plain-text table for people (like the seed's Tables 5-8)."""
        headers, body = self._cells()
        widths = [max(len(h), *(len(r[i]) for r in body)) for i, h in enumerate(headers)]
        initial = (
            "unknown (no pre-impact motion)"
            if self.initial_kinetic_energy is None
            else f"{self.initial_kinetic_energy:.6g} {UNIT_LABELS[self.units]['energy']}"
        )
        lines = [
            f"model comparison, {self.units} units; energy as % of the initial kinetic energy {initial}",
            "",
        ]
        for cells in [headers] + body:
            lines.append(
                "  ".join(c.rjust(wd) if i else c.ljust(wd) for i, (c, wd) in enumerate(zip(cells, widths)))
            )
        lines += [""] + [f"skipped {name}: {reason}" for name, reason in self.skipped.items()]
        for row in self.rows:
            lines += [f"{row.model}: {warning}" for warning in row.warnings]
        return "\n".join(lines).rstrip("\n")

    def markdown(self) -> str:
        """The same table as GitHub markdown, with the same notes as the text
        table: the models skipped and why, and each model's warnings."""
        headers, body = self._cells()
        lines = ["| " + " | ".join(_escape(headers)) + " |", "|" + "---|" * len(headers)]
        lines += ["| " + " | ".join(_escape(cells)) + " |" for cells in body]
        lines += [""] + [f"- skipped `{n}`: {reason}" for n, reason in self.skipped.items()]
        lines += [f"- `{row.model}`: {warning}" for row in self.rows for warning in row.warnings]
        return "\n".join(lines).rstrip("\n")

    def plot(self, path: str | Path) -> None:
        """Save :meth:`figure` to `path` (the format follows the suffix; needs
        matplotlib: ``pip install 'impactsym[plot]'``)."""
        self.figure().savefig(path, dpi=120)

    def figure(self):
        """Bar charts of |delta-V| per vehicle and of the energy loss (% of the
        initial kinetic energy, stacked normal/tangential/moment; CRASH3's crush
        energy hatched) by model, on a plain Agg figure (no pyplot): titled with
        the scene's name, each legend outside its axes, headroom above the bars."""
        require("matplotlib", extra="plot", what="compare --plot", load=False)
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=(12.0, 4.8), layout="constrained")
        FigureCanvasAgg(fig)
        ax_dv, ax_e = fig.subplots(1, 2)
        names = [row.model for row in self.rows]
        x = list(range(len(names)))
        for k, label in enumerate(self.names):
            ax_dv.bar(
                [i + (k - 0.5) * 0.38 for i in x],
                [row.vehicles[k].delta_v_magnitude for row in self.rows],
                0.38,
                label=label,
            )
        ax_dv.set_ylabel(f"|delta-V| [{UNIT_LABELS[self.units]['velocity']}]")
        ax_dv.set_title("|delta-V| by vehicle", fontsize=10)
        bottom = [0.0] * len(names)
        for part in ("normal", "tangential", "moment"):
            heights = [row.energy_percent[part] or 0.0 for row in self.rows]
            ax_e.bar(x, heights, 0.6, bottom=bottom, label=part)
            bottom = [b + h for b, h in zip(bottom, heights)]
        crash = [
            (row.energy_percent["total"] or 0.0) if row.energy_percent["normal"] is None else 0.0
            for row in self.rows
        ]
        ax_e.bar(x, crash, 0.6, label="crush energy (CRASH3)", hatch="//")
        ax_e.set_ylabel("energy loss [% of initial kinetic energy]")
        ax_e.set_title("energy loss by part", fontsize=10)
        energy_known = self.initial_kinetic_energy is not None
        if not energy_known:
            ax_e.text(
                0.5,
                0.5,
                "not known for a crush-only scene\n(no initial kinetic energy)",
                transform=ax_e.transAxes,
                ha="center",
                va="center",
                color="0.3",
            )
            ax_e.set_yticks([])
        for ax in (ax_dv, ax_e):
            ax.set_xticks(x)
            ax.set_xticklabels(names, rotation=30, ha="right")
            ax.axhline(0.0, color="0.3", lw=0.8)
            _headroom(ax)
            if ax is ax_dv or energy_known:
                ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
        fig.suptitle(f"{self.scene_name or 'scene'}: model comparison ({self.units} units)")
        return fig


def _headroom(ax, fraction: float = 0.12) -> None:
    """y limits with ``fraction`` of the bars' span free above the highest bar
    (and below the lowest, when a bar is negative), zero always shown."""
    tops = [v for bar in ax.patches for v in (bar.get_y(), bar.get_y() + bar.get_height())]
    low, high = min(tops + [0.0]), max(tops + [0.0])
    span = (high - low) or 1.0
    ax.set_ylim(low - fraction * span if low < 0 else 0.0, high + fraction * span)


def _scene_name(scene: Scene | Mapping | str | Path) -> str | None:
    """The scene file's name (None for a mapping, or a Scene read from none)."""
    if isinstance(scene, Scene):
        return scene.source.name if scene.source is not None else None
    return None if isinstance(scene, Mapping) else Path(scene).name


def compare(scene: Scene | Mapping | str | Path) -> Comparison:
    """Run a forward scene through every model its data allow (see the module
    docstring); a crush-only scene gives the CRASH3 row alone. Raises
    :class:`SceneError` when the scene is neither a valid forward scene nor a
    CRASH3 scene, or no model can solve it."""
    data, law_rows = comparison_input(scene)  # impactsym.laws: law scenes, and K-S rows
    try:
        base = _base_scene(data)
    except SceneError as exc:
        return replace(_crush_only(data, exc), scene_name=_scene_name(scene))
    # every model sees the normal in the sense the geometry chose (the particle
    # model has no impact points to choose it by)
    data = {**data, "impact": {**data["impact"], "normal_angle": base.impact.normal_angle}}
    initial = _initial_kinetic_energy(base)
    rows, skipped = [], {}
    for name in COMPARED_MODELS:
        try:
            rows.append(
                _crash3_row(data, base, initial) if name == "crash3" else _model_row(data, name, initial)
            )
        except SceneError as exc:
            skipped[name] = str(exc)
    rows += [_law_row(name, text, result, initial) for name, text, result in law_rows]
    if not rows:
        raise SceneError(
            "no model can solve this scene: " + "; ".join(f"{n}: {r}" for n, r in skipped.items())
        )
    names = (base.vehicles[0].name, base.vehicles[1].name)
    return Comparison(base.units, names, initial, tuple(rows), skipped, _scene_name(scene))


def _crush_only(data: Mapping, forward_error: SceneError) -> Comparison:
    """A scene that is not a forward scene: the CRASH3 row alone when it is a
    CRASH3 scene (the forward error is re-raised when it is not)."""
    try:
        scene = load_scene(data, kind="crash3")
    except SceneError:
        raise forward_error from None
    result = crash3(data)
    rows = (
        ModelRow(
            "crash3",
            CRASH3_ASSUMPTIONS,
            tuple(_vehicle_row(None, None, c.delta_v, c.delta_v_magnitude) for c in result.vehicles),
            _crash3_energy(result),
            _percent(_crash3_energy(result), None),
            None,
            None,
            [w for w in result.warnings if w not in scene.warnings],
        ),
    )
    skipped = {name: _needs(data, name) for name in COMPARED_MODELS if name != "crash3"}
    names = (scene.vehicles[0].name, scene.vehicles[1].name)
    return Comparison(scene.units, names, None, rows, skipped)


def _needs(data: Mapping, model: str) -> str:
    """Why a crush-only scene cannot run ``model``: what the model itself needs
    and the scene lacks (the pre-impact motion; its preset's coefficients)."""
    impact = data.get("impact", {}) if isinstance(data.get("impact"), Mapping) else {}
    vehicles = data.get("vehicles", [])
    motion = [
        f"vehicles[{i}].velocity"
        for i, v in enumerate(vehicles)
        if isinstance(v, Mapping) and "velocity" not in v and not v.get("fixed")
    ]
    coefficients = [f"impact.{key}" for key in PRESETS[model]["required"] if key not in impact]
    needs = ([", ".join(motion) + " (the pre-impact motion)"] if motion else []) + (
        [", ".join(coefficients)] if coefficients else []
    )
    return "needs " + " and ".join(needs) if needs else "needs a forward scene"


def _crash3_energy(result) -> dict[str, float | None]:
    """CRASH3's energy: the crush energy total, no parts."""
    return {"total": result.energy_total, "normal": None, "tangential": None, "moment": None}


def _base_scene(data: Mapping) -> Scene:
    """The scene as given or, when its own model lacks coefficients the other
    models do not need, as the common-velocity (impac) model reads it."""
    try:
        return load_scene(data)
    except SceneError as exc:
        try:
            return load_scene(_variant(data, "impac"))
        except SceneError:
            raise exc from None


def _variant(data: Mapping, model: str) -> dict:
    """The scene as the given model reads it: the impact coefficients the model
    fixes or does not use are left out (so they raise no warnings)."""
    preset = PRESETS[model]
    used = ("normal_angle", *preset["required"], *preset["optional"])
    impact = {k: v for k, v in as_mapping(data.get("impact", {}), "impact").items() if k in used}
    return {**data, "model": model, "impact": impact}


def _model_row(data: Mapping, model: str, initial: float) -> ModelRow:
    """One impulse-momentum model's row."""
    if model == "impac_sideswipe" and "slip" not in data["impact"]:
        raise SceneError("no impact.slip given (at slip = 0 it is the impac row)")
    scene = load_scene(_variant(data, model))
    result: Result = solve(scene)
    yaw = uses_yaw(model)
    vehicles = tuple(
        _vehicle_row(v.velocity, v.yaw_rate if yaw else None, v.delta_v, v.delta_v_magnitude)
        for v in result.vehicles
    )
    energy = {
        "total": result.TL,
        "normal": result.TLn,
        "tangential": result.TLt,
        "moment": result.TLm if yaw else None,
    }
    return ModelRow(
        model,
        PRESETS[model]["assumptions"],
        vehicles,
        energy,
        _percent(energy, initial),
        result.mu,
        result.mu_c,
        [w for w in result.warnings if w not in scene.warnings],
    )


def _law_row(name: str, assumptions: str, result: Result, initial: float) -> ModelRow:
    """An impact law's row (impactsym.laws): a point impulse, no moment part."""
    vehicles = tuple(
        _vehicle_row(v.velocity, v.yaw_rate, v.delta_v, v.delta_v_magnitude) for v in result.vehicles
    )
    energy = {"total": result.TL, "normal": result.TLn, "tangential": result.TLt, "moment": None}
    extra = [f"slip {result.slip}"] if getattr(result, "slip", None) else []
    warnings = extra + [w for w in result.warnings if "not used" not in w]
    return ModelRow(
        name, assumptions, vehicles, energy, _percent(energy, initial), result.mu, result.mu_c, warnings
    )


def _crash3_row(data: Mapping, base: Scene, initial: float) -> ModelRow:
    """CRASH3's row: delta-V from crush, final velocity = initial + delta-V."""
    missing = [v.name for v in base.vehicles if not v.fixed and "crush" not in v.extra]
    if missing:
        raise SceneError(f"no crush table for {', '.join(missing)}")
    result = crash3(data)
    vehicles = tuple(
        _vehicle_row(
            (v.velocity[0] + c.delta_v[0], v.velocity[1] + c.delta_v[1]), None, c.delta_v, c.delta_v_magnitude
        )
        for v, c in zip(base.vehicles, result.vehicles)
    )
    energy = _crash3_energy(result)
    return ModelRow(
        "crash3",
        CRASH3_ASSUMPTIONS,
        vehicles,
        energy,
        _percent(energy, initial),
        None,
        None,
        [w for w in result.warnings if w not in base.warnings],
    )


def _vehicle_row(velocity, yaw_rate, delta_v, magnitude) -> VehicleRow:
    """Final velocity also as speed and direction (degrees from +x); None
    without a final velocity (crush-only CRASH3)."""
    if velocity is None:
        return VehicleRow(None, None, None, yaw_rate, None if delta_v is None else tuple(delta_v), magnitude)
    return VehicleRow(
        velocity=tuple(velocity),
        speed=math.hypot(*velocity),
        direction=math.degrees(math.atan2(velocity[1], velocity[0])),
        yaw_rate=yaw_rate,
        delta_v=tuple(delta_v),
        delta_v_magnitude=magnitude,
    )


def _initial_kinetic_energy(scene: Scene) -> float:
    """Kinetic energy of the pair before impact (generated report kernel)."""
    values = {}
    for number, vehicle in enumerate(scene.vehicles, start=1):
        values[f"m{number}"] = math.inf if vehicle.fixed else vehicle.mass
        values[f"I{number}"] = math.inf if vehicle.fixed else (vehicle.yaw_inertia or 0.0)
        values[f"v{number}x"], values[f"v{number}y"] = vehicle.velocity
        values[f"w{number}"] = vehicle.yaw_rate if vehicle.yaw_inertia else 0.0
    ks = _kernels.KINETIC_ENERGY
    out = _kernels.run_one(ks, values, ks.outputs)
    if out["status"]:
        raise SceneError("cannot compute the initial kinetic energy")
    return out["T"]


def _percent(energy: Mapping[str, float | None], initial: float | None) -> dict[str, float | None]:
    """Each energy as a percent of the initial kinetic energy (None stays None;
    all None without an initial kinetic energy)."""
    return {
        k: None if v is None or initial is None or initial <= 0.0 else 100.0 * v / initial
        for k, v in energy.items()
    }


def _escape(cells: list[str]) -> list[str]:
    """Markdown table cells with their pipes escaped (|dV| in a header)."""
    return [c.replace("|", "\\|") for c in cells]


def _cell(value: float | None, fmt: str) -> str:
    """A table cell in format `fmt`, or n/a for a quantity the model does not have."""
    return "n/a" if value is None else format(value + 0.0, fmt)
