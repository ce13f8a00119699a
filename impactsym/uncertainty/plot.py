"""Figures of an uncertainty result: histograms of the main outputs and a tornado budget.

Needs matplotlib (the ``plot`` or ``uncertainty`` extra). Drawn on the Agg
backend into a file; nothing is shown on screen. Labelled for people: each
panel names the vehicle and the quantity with its unit (the scene's), inputs
are named in words, not as JSON paths, and ticks are few enough to read.
"""

from __future__ import annotations

import re

import numpy as np

from ..result import UNIT_LABELS

#: Outputs drawn first when present (the answers a reconstructionist reports).
MAIN = (
    "vehicles[0].speed",
    "vehicles[1].speed",
    "vehicles[0].delta_v_magnitude",
    "vehicles[1].delta_v_magnitude",
    "energy_loss.total",
    "energy_total",
    "vehicles[0].crush_energy",
    "vehicles[1].crush_energy",
)

#: The last words of a path -> (what it is for people, its unit's key in UNIT_LABELS or a unit).
_WORDS = {
    "speed": ("pre-impact speed", "velocity"),
    "delta_v_magnitude": ("|ΔV|", "velocity"),
    "delta_v_magnitude_impulse_momentum": ("|ΔV| (impulse-momentum)", "velocity"),
    "delta_v[0]": ("ΔV x", "velocity"),
    "delta_v[1]": ("ΔV y", "velocity"),
    "velocity[0]": ("velocity x", "velocity"),
    "velocity[1]": ("velocity y", "velocity"),
    "yaw_rate": ("yaw rate", "yaw_rate"),
    "pdof_deg": ("PDOF", "deg"),
    "crush_energy": ("crush energy", "energy"),
    "energy_total": ("total crush energy", "energy"),
    "energy_loss.total": ("energy loss", "energy"),
    "energy_loss.normal": ("energy loss, normal", "energy"),
    "energy_loss.tangential": ("energy loss, tangential", "energy"),
    "energy_loss.moment": ("energy loss, moment", "energy"),
    "impulse.normal": ("normal impulse", "impulse"),
    "impulse.tangential": ("tangential impulse", "impulse"),
    "impulse.moment": ("moment impulse", "moment"),
    "normal_angle": ("normal angle Γ", "deg"),
    "restitution": ("restitution e", "-"),
    "impulse_ratio": ("impulse ratio μ", "-"),
    "moment_restitution": ("moment restitution", "-"),
}


def main_outputs(result, count: int = 4) -> list[str]:
    """The outputs drawn: the MAIN ones the result has, in that order."""
    chosen = [p for p in MAIN if p in result.outputs and p in result.draws]
    return chosen[:count] or [p for p in result.outputs if p in result.draws][:count]


def describe(path: str, names=None, units: str | None = None) -> tuple[str, str]:
    """(words, unit) of an output or input path: ``vehicles[0].speed`` ->
    ("car 1: pre-impact speed", "m/s"); unknown paths in words."""
    match = re.match(r"vehicles\[(\d+)\]\.(.*)", path)
    who, rest = (None, path) if not match else (int(match.group(1)), match.group(2))
    rest = rest.removeprefix("impact.").removeprefix("crash3.")
    words, unit = _WORDS.get(rest, (None, None))
    if words is None:
        words = re.sub(r"\[(\d+)\]", lambda m: f" {int(m.group(1)) + 1}", rest)
        words = words.replace("final_velocity.", "final ").replace("velocity.", "").replace("_", " ")
        words = words.replace(".", " ")
    labels = UNIT_LABELS.get(units or "", {})
    unit = labels.get(unit, unit) if units else ("scene units" if unit in UNIT_LABELS["SI"] else unit)
    if who is not None:
        name = names[who] if names and who < len(names) else f"vehicle {who + 1}"
        words = f"{name}: {words}"
    return words, unit or ""


def uncertainty_figure(result, bins: int = 60, names=None, units: str | None = None):
    """The figure (matplotlib Figure on an Agg canvas) of :func:`save_uncertainty_plot`."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter, MaxNLocator

    outputs = main_outputs(result)
    fig = Figure(figsize=(4.2 * (len(outputs) + 1), 3.9), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(outputs) + 1, squeeze=False)[0]
    for ax, name in zip(axes, outputs):
        o = result.outputs[name]
        words, unit = describe(name, names, units)
        ax.hist(np.asarray(result.draws[name]), bins=bins, color="0.6")
        ax.axvspan(o["p5"], o["p95"], color="tab:blue", alpha=0.2, label="90 % interval")
        ax.axvline(o["nominal"], color="tab:red", label="nominal")
        ax.set_title(words, fontsize=9)
        ax.set_xlabel(f"{words.split(': ')[-1]} [{unit}]", fontsize=8)
        ax.set_ylabel("accepted draws", fontsize=8)
        ax.xaxis.set_major_locator(MaxNLocator(nbins=4))
        ax.xaxis.set_major_formatter(FuncFormatter(_tick))
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=7)
    _tornado(axes[-1], result, outputs[0] if outputs else next(iter(result.outputs)), names, units)
    fig.suptitle(f"{result.command}: {result.accepted} of {result.n_draws} draws accepted", fontsize=10)
    return fig


def save_uncertainty_plot(result, path, bins: int = 60, names=None, units: str | None = None) -> None:
    """Histograms of the main outputs (accepted draws) with the 90 % interval
    shaded and the nominal value marked, and a tornado chart of the first
    output's variance budget; written to `path`. ``names`` (the vehicles')
    and ``units`` (the scene's) label the panels."""
    uncertainty_figure(result, bins, names, units).savefig(path, dpi=110)


def _tick(value: float, _position=None) -> str:
    """A tick label: thousands separated (40,000 not 4e+04), else 4 digits."""
    return f"{value:,.0f}" if abs(value) >= 1e4 else f"{value:.4g}"


def _tornado(ax, result, output: str, names, units, count: int = 8) -> None:
    """The largest budget shares of one output as horizontal bars."""
    shares = sorted(result.budget.get(output, {}).items(), key=lambda kv: abs(kv[1]))[-count:]
    labels = [describe(n, names, units)[0] for n, _ in shares]
    ax.barh(range(len(shares)), [s for _, s in shares], color="tab:orange")
    ax.set_yticks(range(len(shares)), labels, fontsize=7)
    ax.set_xlabel("share of the variance (linearised)", fontsize=8)
    ax.set_title(f"what drives {describe(output, names, units)[0]}", fontsize=9)
    ax.tick_params(axis="x", labelsize=7)
    if not shares:
        ax.text(0.5, 0.5, "no linear budget", ha="center", transform=ax.transAxes)
    ax.set_xlim(
        min(0.0, *(s for _, s in shares)) if shares else 0.0,
        max(1.0, *(s for _, s in shares)) if shares else 1.0,
    )
