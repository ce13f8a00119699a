"""Predicted-versus-measured plots of the validation report (needs matplotlib)."""

from __future__ import annotations

from pathlib import Path

from .common import Comparison, Dataset
from .iihs import V2V_MODEL
from .ricsac import OTHER_PIM_MODELS

# Per dataset, the plots: (panel title, reference, [(model, quantity), ...]).
PLOTS = {
    "ricsac": [
        (
            "delta-V [m/s] vs measured (Brach & Smith 2002)",
            "measured, Brach & Smith 2002",
            [
                ("CRASH3 (published profiles)", "delta-V"),
                ("CRASH3 (Neades' adjustments)", "delta-V"),
                ("rigid PIM (approx. impact centre)", "delta-V"),
                (OTHER_PIM_MODELS["limpert"], "delta-V"),
            ],
        ),
        (
            "energy loss [ft lb] vs measured",
            None,
            [
                ("CRASH3 (published profiles)", "energy loss", "measured"),
                ("CRASH3 (Neades' adjustments)", "energy loss", "measured"),
                ("rigid PIM (approx. impact centre)", "energy loss", "measured"),
            ],
        ),
    ],
    "ricsac_runout": [
        (
            "rest distance from separation [ft] vs measured",
            "measured",
            [
                ("run-out, wheels rolling (forward)", "rest distance from separation"),
                ("run-out, wheels locked (bracket)", "rest distance from separation"),
                ("SIMON (Day 2004)", "rest distance from separation"),
                ("EDSMAC4 (Day 2004)", "rest distance from separation"),
            ],
        ),
        (
            "separation speed [m/s] fitted to rest vs measured",
            "measured (Vossou 2018)",
            [("run-out fit to rest", "separation speed")],
        ),
    ],
    "iihs": [
        ("delta-V [ft/s] vs measured", "measured", [("rigid PIM (Brach's fits)", "delta-V")]),
        (
            "yaw-rate change [deg/s] vs measured",
            "measured",
            [("rigid PIM (Brach's fits)", "yaw-rate change")],
        ),
    ],
    "iihs_v2v": [
        (
            "|delta-V| [ft/s] vs measured",
            None,
            [(V2V_MODEL, "delta-V", f"measured, {kind}") for kind in ("sideswipe", "non-sideswipe")],
        ),
        (
            "yaw-rate change [deg/s] vs measured",
            None,
            [(V2V_MODEL, "yaw-rate change", f"measured, {kind}") for kind in ("sideswipe", "non-sideswipe")],
        ),
    ],
    "nhtsa": [
        (
            "delta-V [mph]",
            None,
            [("rigid PIM", "delta-V", "published PIM"), ("rigid PIM", "delta-V", "measured")],
        ),
        ("final yaw rate [deg/s] vs published PIM", "published PIM", [("rigid PIM", "final yaw rate")]),
        (
            "energy loss [ft lb] vs published PIM",
            "published PIM",
            [
                ("rigid PIM", "energy loss"),
                ("rigid PIM", "normal energy loss"),
                ("rigid PIM", "tangential energy loss"),
            ],
        ),
    ],
}


def _find(ds: Dataset, model: str, quantity: str, reference: str) -> Comparison:
    return next(
        c for c in ds.comparisons if (c.model, c.quantity, c.reference) == (model, quantity, reference)
    )


def plot(datasets: list[Dataset], directory: Path | str) -> list[Path]:
    """Predicted-versus-measured plots with the 1:1 line, one PNG per dataset
    saved in `directory` (needs matplotlib); returns the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for ds in datasets:
        drawings = {ds.name: figure(ds, plt)}
        if ds.name == "ricsac_runout":
            drawings[f"{ds.name}_plan"] = runout_plan(ds, plt)
        for name, fig in drawings.items():
            path = directory / f"{name}.png"
            fig.savefig(path, dpi=110, bbox_inches="tight")
            plt.close(fig)
            paths.append(path)
    return paths


def figure(ds: Dataset, plt):
    """The predicted-versus-measured figure of one dataset (pyplot `plt`); each
    panel's legend below its axes, where it covers no point."""
    panels = PLOTS[ds.name]
    fig, axes = plt.subplots(1, len(panels), figsize=(5.2 * len(panels), 4.6), squeeze=False)
    for ax, (title, reference, series) in zip(axes[0], panels):
        top = 0.0
        comps = [_find(ds, e[0], e[1], e[2] if len(e) > 2 else reference) for e in series]
        mixed_q = len({c.quantity for c in comps}) > 1
        mixed_r = len({c.reference for c in comps}) > 1
        # One model against several references: the model in the title, the
        # references in the legend.
        by_reference = mixed_r and not mixed_q and len({c.model for c in comps}) == 1
        if by_reference:
            title = f"{title}\n{comps[0].model}"
        for comp in comps:
            xs, ys = [r for _, _, r in comp.rows], [m for _, m, _ in comp.rows]
            label = (
                comp.reference
                if by_reference
                else comp.model
                + (f", {comp.quantity}" if mixed_q else "")
                + (f" vs {comp.reference}" if mixed_r else "")
            )
            ax.scatter(
                xs, ys, s=22, alpha=0.8, label=f"{label} (median |err| {comp.stats()['median']:.1f} %)"
            )
            top = max(top, *xs, *ys)
        ax.ticklabel_format(style="sci", scilimits=(-3, 4))
        ax.plot([0, top * 1.05], [0, top * 1.05], "k--", lw=1, label="1:1")
        ax.set_xlabel("reference")
        ax.set_ylabel("model")
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14))
        ax.set_aspect("equal", adjustable="box")
    fig.suptitle(ds.title, fontsize=11)
    fig.tight_layout()
    return fig


# markers of the rest poses in the plan view: source -> (marker, colour)
REST_MARKS = {"measured": ("*", "k"), "SIMON": ("^", "tab:orange"), "EDSMAC4": ("s", "tab:green")}


def runout_plan(ds: Dataset, plt):
    """Plan view per RICSAC test (Day's frame: X right, Y down the page as in the
    SAE frame): separation, measured, SIMON and EDSMAC4 rest positions, and the
    run-out paths with every wheel rolling and every wheel locked; the frame is
    fitted to the published positions, so a path that rolls far past them leaves it."""
    table, forward = ds.tables["table"], {r["label"]: r for r in ds.tables["forward"]}
    tests = sorted({r["label"].split(".")[0] for r in table}, key=lambda t: int(t.split("-")[1]))
    fig, axes = plt.subplots(1, len(tests), figsize=(4.4 * len(tests), 4.6), squeeze=False)
    for ax, test in zip(axes[0], tests):
        rows = [r for r in table if r["label"].split(".")[0] == test]
        xs, ys = [], []
        for r in rows:
            sx, sy = r["separation X"], r["separation Y"]
            ax.plot(sx, sy, "o", mfc="none", color="tab:blue")
            ax.annotate(r["name"], (sx, sy), fontsize=7, xytext=(3, 3), textcoords="offset points")
            xs.append(sx)
            ys.append(sy)
            for source, (marker, colour) in REST_MARKS.items():
                x, y = r[f"{source} X"], r[f"{source} Y"]
                ax.plot(x, y, marker, color=colour, ms=9 if source == "measured" else 6)
                xs.append(x)
                ys.append(y)
            run = forward.get(r["label"])
            if run is not None:
                for key, style in (("path", "-"), ("locked path", "--")):
                    ax.plot(*zip(*run[key]), style, color="tab:blue", lw=1)
        pad = 0.15 * max(max(xs) - min(xs), max(ys) - min(ys), 10.0)
        ax.set_xlim(min(xs) - pad, max(xs) + pad)
        ax.set_ylim(max(ys) + pad, min(ys) - pad)  # Y to the right of X: down the page
        ax.set_aspect("equal", adjustable="box")
        ax.set_title(f"{test} (RICSAC {rows[0]['ricsac']})", fontsize=10)
        ax.set_xlabel("X [ft]")
        ax.set_ylabel("Y [ft]")
    handles = [
        plt.Line2D([], [], marker="o", mfc="none", ls="", color="tab:blue", label="separation (read)"),
        *(
            plt.Line2D([], [], marker=m, ls="", color=c, label=f"rest, {s}")
            for s, (m, c) in REST_MARKS.items()
        ),
        plt.Line2D([], [], ls="-", color="tab:blue", label="run-out, wheels rolling"),
        plt.Line2D([], [], ls="--", color="tab:blue", label="run-out, wheels locked"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=6, fontsize=8, bbox_to_anchor=(0.5, -0.04))
    fig.suptitle(ds.title, fontsize=11)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return fig
