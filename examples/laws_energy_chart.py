"""Energy loss against friction for the impact laws on one eccentric scene (docs/models.md).

``python examples/laws_energy_chart.py [OUT.png]`` (default docs/laws_energy.png): the
Coulomb process under Newton, Poisson and energetic restitution, Kudlich–Slibar full
and sliding, and Brach's model at mu = the friction (signed against the slip), on
examples/corner_barrier_coulomb.json with friction 0..1.2. Prints the values it draws.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import impactsym  # noqa: E402
from impactsym.laws.scene import load_law_scene  # noqa: E402

HERE = Path(__file__).resolve().parent
SCENE = HERE / "corner_barrier_coulomb.json"


def curves(mu):
    base = load_law_scene(SCENE).inputs()
    cols = {k: np.full(len(mu), v) for k, v in base.items()}
    cols["mu_f"] = mu
    out = {}
    for law in ("newton", "poisson", "energetic"):
        out[f"Coulomb, {law}"] = impactsym.solve_batch(cols, model=f"coulomb:{law}")
    out["K-S sliding"] = impactsym.solve_batch(cols, model="kudlich_slibar:sliding")
    full = impactsym.solve_batch({k: v for k, v in cols.items() if k != "mu_f"}, model="kudlich_slibar")
    out["K-S full"] = full
    sign = np.sign(out["Coulomb, newton"]["Pt"][1:2])  # the sign of Pt against the slip
    rigid = {k: v for k, v in cols.items() if k != "mu_f"}
    out["Brach, mu = friction"] = impactsym.solve_batch(dict(rigid, mu=sign * mu, e_m=1.0), model="rigid")
    return out


def main(path: str) -> None:
    mu = np.linspace(0.0, 1.2, 49)
    out = curves(mu)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    rev = out["Coulomb, newton"]["slip_class"] == 2
    for ax, names in zip(axes, (list(out), [n for n in out if not n.startswith("Brach")])):
        for name in names:
            style = "--" if name.startswith("K-S") else (":" if name.startswith("Brach") else "-")
            ax.plot(mu, out[name]["TL"] / 1e3, style, label=name)
        if rev.any():
            ax.axvspan(mu[rev].min(), mu[rev].max(), color="0.9", zorder=0, label="Coulomb: slip reverses")
        ax.set_xlabel("friction coefficient at the impact centre")
        ax.set_ylabel("energy loss T_L [kJ]")
    axes[0].set_title("corner_barrier_coulomb.json", fontsize=10)
    axes[1].set_title("the laws alone (zoom)", fontsize=10)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print("mu     " + "  ".join(f"{name:>20}" for name in out))
    for i in range(0, len(mu), 6):
        print(f"{mu[i]:.2f}  " + "  ".join(f"{res['TL'][i]:>20.1f}" for res in out.values()))
    for name, res in out.items():
        print(f"{name}: flags {sorted(set(res['flags'].tolist()))}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else str(HERE.parent / "docs" / "laws_energy.png"))
