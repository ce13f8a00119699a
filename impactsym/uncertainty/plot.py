"""Figures of an uncertainty result: histograms of the main outputs and a tornado budget.

Needs matplotlib (the ``plot`` or ``uncertainty`` extra). Drawn on the Agg
backend into a file; nothing is shown on screen.
"""

from __future__ import annotations

import numpy as np

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


def main_outputs(result, count: int = 4) -> list[str]:
    """The outputs drawn: the MAIN ones the result has, in that order."""
    chosen = [p for p in MAIN if p in result.outputs and p in result.draws]
    return chosen[:count] or [p for p in result.outputs if p in result.draws][:count]


def save_uncertainty_plot(result, path, bins: int = 60) -> None:
    """Histograms of the main outputs (accepted draws) with the 90 % interval
    shaded and the nominal value marked, and a tornado chart of the first
    output's variance budget; written to `path`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    outputs = main_outputs(result)
    fig, axes = plt.subplots(1, len(outputs) + 1, figsize=(4 * (len(outputs) + 1), 3.6))
    for ax, name in zip(axes, outputs):
        o = result.outputs[name]
        ax.hist(np.asarray(result.draws[name]), bins=bins, color="0.6")
        ax.axvspan(o["p5"], o["p95"], color="tab:blue", alpha=0.2, label="90 % interval")
        ax.axvline(o["nominal"], color="tab:red", label="nominal")
        ax.set_title(name, fontsize=9)
        ax.set_yticks([])
    axes[0].legend(fontsize=8)
    _tornado(axes[-1], result, outputs[0] if outputs else next(iter(result.outputs)))
    fig.suptitle(f"{result.command}: {result.accepted} of {result.n_draws} draws accepted", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _tornado(ax, result, output: str, count: int = 8) -> None:
    """The largest budget shares of one output as horizontal bars."""
    shares = sorted(result.budget.get(output, {}).items(), key=lambda kv: abs(kv[1]))[-count:]
    names = [n for n, _ in shares]
    ax.barh(range(len(shares)), [s for _, s in shares], color="tab:orange")
    ax.set_yticks(range(len(shares)), names, fontsize=7)
    ax.set_xlabel("share of variance (linear)")
    ax.set_title(f"budget: {output}", fontsize=9)
    if not shares:
        ax.text(0.5, 0.5, "no linear budget", ha="center", transform=ax.transAxes)
    ax.set_xlim(
        min(0.0, *(s for _, s in shares)) if shares else 0.0,
        max(1.0, *(s for _, s in shares)) if shares else 1.0,
    )
