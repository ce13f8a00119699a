"""For people: the table of a fit and its residual chart."""

from __future__ import annotations

from ..result import UNIT_LABELS, table_cell


def table(result) -> str:
    """Estimates with 90 % intervals and a determined column, then the residuals."""
    labels = UNIT_LABELS[result.units]
    width = max(38, *(len(_label(p, result.names)) + 2 for p in result.estimates))
    lines = [
        f"fit to evidence, {result.units} units (speeds {labels['velocity']}, energy {labels['energy']}, "
        f"yaw rates rad/s); method: {result.info['method']}",
        "",
        f"{'quantity':<{width}}{'estimate':>14}{'90 % interval':>30}  determined",
    ]
    for path, est in result.estimates.items():
        if est.determined and est.interval is not None and est.sd == 0:
            continue  # known inputs (a yaw rate of 0 given), not estimates
        label = _label(path, result.names)
        if est.determined:
            low, high = est.interval or ("", "")
            ends = ["unbounded" if v is None else table_cell(v) for v in (low, high)]
            span = f"[{ends[0]}, {ends[1]}]" if est.interval else ""
            lines.append(f"{label:<{width}}{table_cell(est.value):>14}{span:>30}  yes")
        else:
            lines.append(f"{label:<{width}}{'-':>14}{'':>30}  no")
    lines += ["", f"rank {result.rank} of {len(result.unknowns)} unknowns ({', '.join(result.unknowns)})"]
    for path, est in result.estimates.items():
        if not est.determined and path in result.unknowns:
            lines.append(f"  {path}: {est.why}")
    lines += ["", f"{'evidence':<10}{'item':<38}{'value':>14}{'fitted':>14}{'z':>9}"]
    for r in result.residuals:
        lines.append(
            f"{r['evidence']:<10}{r['label']:<38}{table_cell(r['value']):>14}{table_cell(r['fitted']):>14}"
            f"{_z(r['z']):>9}"
        )
    lines += (
        ["", "warnings:"] + [f"  - {w}" for w in result.warnings]
        if result.warnings
        else ["", "warnings: none"]
    )
    return "\n".join(lines)


def _z(z) -> str:
    return "-" if z is None else f"{0.0 if abs(z) < 5e-7 else z:.3g}"


def _label(path: str, names) -> str:
    for i, name in enumerate(names):
        path = path.replace(f"vehicles[{i}].", f"{name}: ")
    return path


def residual_chart(result, out: str) -> None:
    """Normalised residual z of every observation, ±1 and ±2 bands."""
    from .._util import require

    require("matplotlib", extra="plot", what="a residual chart")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = result.residuals
    fig, ax = plt.subplots(figsize=(7, 0.45 * len(rows) + 1.5))
    z = [r["z"] or 0.0 for r in rows]
    names = [f"[{r['evidence']}] {_label(r['label'], result.names)}" for r in rows]
    ax.axvspan(-2, 2, color="0.92")
    ax.axvspan(-1, 1, color="0.85")
    ax.barh(range(len(rows)), z, color=["tab:red" if abs(v) > 2 else "tab:blue" for v in z])
    ax.set_yticks(range(len(rows)), names)
    ax.invert_yaxis()
    ax.axvline(0, color="k", lw=0.8)
    ax.set_xlabel("normalised residual z = (fitted - value) / sd")
    ax.set_title("fit residuals per evidence item")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    plt.close(fig)
