"""For people: the table of a fit and its residual chart."""

from __future__ import annotations

from ..result import UNIT_LABELS, table_cell
from .law import law_line


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
    if result.law is not None:
        lines += ["", law_line(result.law)]
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

    require("matplotlib", extra="plot", what="a residual chart", load=False)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    rows = result.residuals
    fig = Figure(figsize=(7, 0.45 * len(rows) + 1.5), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
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
    fig.savefig(out, dpi=120)


def scene_picture(result, scene, out: str) -> None:
    """The scene drawn with the fitted motion (impactsym.plot) and the departure
    directions of the evidence as dashed rays from the centres of gravity. A
    vehicle whose speed the evidence does not determine is drawn at rest and
    said so in the title."""
    import math
    from types import SimpleNamespace

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from .. import plot
    from .case import read_case

    case = read_case(scene)
    data = result.to_json_dict()
    vehicles, drawn = [], []
    for i, fitted in enumerate(data["vehicles"]):
        n = i + 1
        entry = {"name": fitted["name"], "impact_point": [case.params[f"r{n}x"], case.params[f"r{n}y"]]}
        if case.fixed[i]:
            entry["fixed"] = True
        else:
            known = None not in fitted["velocity"]
            entry.update(
                mass=case.params[f"m{n}"],
                yaw_inertia=case.params[f"I{n}"],
                heading=math.degrees(case.headings[i]),
                velocity=fitted["velocity"] if known else [0.0, 0.0],
                yaw_rate=fitted["yaw_rate"] or 0.0,
            )
            if not known:
                drawn.append(fitted["name"])
        vehicles.append(entry)
    gamma = math.degrees(case.params["gamma"])
    forward = {"units": case.units, "impact": {"normal_angle": gamma, "restitution": 0.0, "impulse_ratio": 0.0},
               "vehicles": vehicles}  # fmt: skip
    look = SimpleNamespace(
        kind="solve",
        units=case.units,
        vehicles=[
            SimpleNamespace(
                velocity=v["final_velocity"] if None not in v["final_velocity"] else None,
                yaw_rate=v["final_yaw_rate"],
                delta_v=v["delta_v"] if None not in v["delta_v"] else None,
            )
            for v in data["vehicles"]
        ],
    )
    fig = Figure(figsize=(9.0, 6.5), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    title = "fitted motion" + (f" ({', '.join(drawn)}: speed not determined, drawn at rest)" if drawn else "")
    plot.scene(forward, result=look, ax=ax, title=title)
    span = max(abs(c) for c in (*ax.get_xlim(), *ax.get_ylim()))
    for obs in case.observations:
        if obs.how[0] != "direction":
            continue
        n = int(obs.how[1][0][1])
        cg = (-case.params[f"r{n}x"], -case.params[f"r{n}y"])
        for angle, style in (
            (obs.value, "-"),
            (obs.value - 1.645 * obs.sd, ":"),
            (obs.value + 1.645 * obs.sd, ":"),
        ):
            end = (cg[0] + span * math.cos(angle), cg[1] + span * math.sin(angle))
            ax.plot([cg[0], end[0]], [cg[1], end[1]], style, color="tab:olive", lw=1.0)
    ax.text(0.01, 0.01, "olive: departure directions of the evidence (dotted: 90 % band)", color="tab:olive",
            transform=ax.transAxes, fontsize=8, va="bottom")  # fmt: skip
    fig.savefig(out, dpi=120, bbox_inches="tight")
