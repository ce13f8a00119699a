"""The validation report as text: markdown (notes, error statistics, per-row
tables, figures) for the docs, and a plain statistics table for a terminal."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .common import Dataset, fmt

STATS_COLUMNS = [
    ("model", "model"),
    ("quantity", "quantity"),
    ("reference", "reference"),
    ("n", "n"),
    ("median abs err %", "median"),
    ("worst abs err %", "worst"),
    ("median signed err %", "bias"),
]

PIM_COLUMNS = [
    ("test", "test"),
    ("dV1", "dv1"),
    ("meas 1", "dv1 Brach & Smith 2002"),
    ("dV2", "dv2"),
    ("meas 2", "dv2 Brach & Smith 2002"),
    ("Limpert dV1", "limpert dv1"),
    ("Limpert dV2", "limpert dv2"),
    ("particle dV1", "particle dv1"),
    ("particle dV2", "particle dv2"),
    ("TL", "energy_loss"),
    ("Brach TL", "brach_energy_loss"),
    ("measured TL", "measured_energy_loss"),
    ("mu_c", "mu_c"),
    ("Brach mu", "brach_mu"),
    ("sens. %", "sensitivity_pct"),
]

#: Per dataset, its per-row tables: (caption, table or view, [(header, column), ...]).
DETAILS: dict[str, list[tuple[str, str, list[tuple[str, str]]]]] = {
    "ricsac": [
        (
            "CRASH3 delta-V per vehicle [m/s] (CG delta-V; 'eff' = effective-mass delta-V):",
            "crash3 merged",
            [
                ("veh", "vehicle"),
                ("face", "face"),
                ("alpha pub", "alpha"),
                ("capped", "capped"),
                ("gamma pub", "gamma"),
                ("dV pub", "dv"),
                ("alpha Neades", "alpha_neades"),
                ("gamma Neades", "gamma_neades"),
                ("dV Neades", "dv_neades"),
                ("dV eff Neades", "dv_eff_neades"),
                ("dV Neades gamma=1", "dv_nogamma"),
                ("meas untransf.", "untransformed"),
                ("meas B&S 2002", "Brach & Smith 2002"),
                ("meas McHenry", "McHenry 1997"),
                ("Neades raw CRASH", "neades_raw_crash"),
            ],
        ),
        (
            "Energy loss per test [ft lb]:",
            "energy",
            [
                ("test", "test"),
                ("CRASH3 pub", "published"),
                ("CRASH3 pub, Woolley corr.", "published, woolley"),
                ("CRASH3 Neades", "neades"),
                ("Woolley 1985 CRASH3", "woolley_1985"),
                ("Brach PIM", "brach_pim"),
                ("measured", "measured"),
                ("initial KE", "initial"),
                ("exceeds initial KE", "impossible"),
            ],
        ),
        (
            "Rigid PIM (Brach's e, mu = mu_c, e_m = 1) with the approximated impact centre, "
            "and the Limpert/IMPAC common-velocity and particle models on the same scenes "
            "(delta-V m/s, energy ft lb; sens. = largest rigid delta-V change % for a 0.2 m "
            "shift of either centre):",
            "pim",
            PIM_COLUMNS,
        ),
        (
            "Momentum balance of Vossou's measured separation velocities "
            "(change of total momentum, % of the initial):",
            "momentum",
            [("test", "test"), ("x %", "x_pct"), ("y %", "y_pct")],
        ),
    ],
    "iihs": [
        (
            "Per test (ft/s, deg/s):",
            "barrier",
            [
                ("test", "test"),
                ("vehicle", "vehicle"),
                ("kind", "kind"),
                ("dV", "dv"),
                ("dV meas", "dv_measured"),
                ("dVx", "dvx"),
                ("dVx meas", "dvx_measured"),
                ("dVy", "dvy"),
                ("dVy meas", "dvy_measured"),
                ("yaw", "yaw"),
                ("yaw meas", "yaw_measured"),
            ],
        )
    ],
    "iihs_v2v": [
        (
            "Per vehicle (d ft, mass slug, I slug ft^2, delta-V ft/s, yaw deg/s; "
            "'mb/ma meas' = measured |dV_a|/|dV_b|):",
            "v2v",
            [
                ("test", "test"),
                ("vehicle", "vehicle"),
                ("kind", "kind"),
                ("overlap", "overlap"),
                ("d (approx.)", "d"),
                ("d from", "d_source"),
                ("mass", "mass"),
                ("I", "yaw_inertia"),
                ("dV", "dv"),
                ("dV meas", "dv_measured"),
                ("yaw", "yaw"),
                ("yaw meas", "yaw_measured"),
                ("mb/ma meas", "implied_mass_ratio"),
            ],
        ),
        (
            "Sensitivity to the approximations (changes and errors in %, over the 18 vehicles):",
            "sensitivity",
            [
                ("case", "case"),
                ("value", "value"),
                ("dV change median", "dv_change_median"),
                ("dV change largest", "dv_change_worst"),
                ("yaw change median", "yaw_change_median"),
                ("yaw change largest", "yaw_change_worst"),
                ("dV median abs err", "dv_error_median"),
                ("yaw median abs err", "yaw_error_median"),
                ("median dVa/dVb", "ratio_a_to_b"),
            ],
        ),
        (
            "The two 15 deg oblique tests under the four readings of their geometry (median abs err %):",
            "oblique readings",
            [
                ("b heading", "heading_b"),
                ("Gamma frame", "gamma_frame"),
                ("used", "used"),
                ("dV", "dv_error_median"),
                ("yaw", "yaw_error_median"),
                ("tests flagged", "flagged"),
            ],
        ),
    ],
    "ricsac_runout": [
        (
            "Rest positions (Day's frame, ft and deg; VC-3 = RICSAC 3, VC-7 = 2, VC-8 = 6, VC-11 = 10):",
            "table",
            [
                ("vehicle", "label"),
                ("car", "name"),
                ("sep X", "separation X"),
                ("sep Y", "separation Y"),
                ("sep psi", "separation psi"),
                ("measured X", "measured X"),
                ("measured Y", "measured Y"),
                ("measured psi", "measured psi"),
                ("SIMON X", "SIMON X"),
                ("SIMON Y", "SIMON Y"),
                ("SIMON psi", "SIMON psi"),
                ("EDSMAC4 X", "EDSMAC4 X"),
                ("EDSMAC4 Y", "EDSMAC4 Y"),
                ("EDSMAC4 psi", "EDSMAC4 psi"),
                ("run-out ft", "runout_distance_ft"),
                ("free", "free"),
            ],
        ),
        (
            "Forward from the measured separation velocity (wheels rolling; errors in ft and deg):",
            "forward",
            [
                ("vehicle", "label"),
                ("speed m/s", "speed_mps"),
                ("yaw rad/s", "yaw_rate"),
                ("X", "X"),
                ("Y", "Y"),
                ("psi", "psi"),
                ("time s", "time_s"),
                ("pos err", "position_error_ft"),
                ("run-out", "runout_distance_ft"),
                ("psi err", "heading_error_deg"),
                ("SIMON pos err", "SIMON position_error_ft"),
                ("SIMON psi err", "SIMON heading_error_deg"),
                ("EDSMAC4 pos err", "EDSMAC4 position_error_ft"),
                ("EDSMAC4 psi err", "EDSMAC4 heading_error_deg"),
                ("drag needed g", "drag_needed"),
                ("locked dist", "locked distance_ft"),
                ("locked pos err", "locked position_error_ft"),
                ("locked psi err", "locked heading_error_deg"),
                ("free", "free"),
            ],
        ),
        (
            "Separation state fitted to the measured rest pose (scene frame: y left, angles "
            "counter-clockwise; m/s, deg, rad/s):",
            "fit",
            [
                ("vehicle", "label"),
                ("converged", "converged"),
                ("iter", "iterations"),
                ("resid ft", "residual_ft"),
                ("resid deg", "residual_deg"),
                ("speed", "speed"),
                ("speed meas", "speed_measured"),
                ("speed %", "speed_pct"),
                ("dir", "direction_deg"),
                ("dir meas", "direction_measured_deg"),
                ("dir err", "direction_error_deg"),
                ("yaw", "yaw_rate"),
                ("yaw meas", "yaw_rate_measured"),
            ],
        ),
    ],
    "nhtsa": [
        (
            "Per vehicle (energies ft lb per test, delta-V mph, yaw deg/s):",
            "nhtsa",
            [
                ("test", "test"),
                ("vehicle", "vehicle"),
                ("TL", "energy_loss"),
                ("TL pub", "energy_loss_published"),
                ("TLn", "normal_loss"),
                ("TLn pub", "normal_loss_published"),
                ("TLt", "tangential_loss"),
                ("TLt pub", "tangential_loss_published"),
                ("dV", "dv"),
                ("dV pub", "dv_published"),
                ("dV meas", "dv_measured"),
                ("yaw", "yaw"),
                ("yaw pub", "yaw_published"),
            ],
        )
    ],
}


def table(rows: list[dict], columns: list[tuple[str, str]]) -> list[str]:
    """A markdown table of `rows` with (header, key) columns."""
    lines = ["| " + " | ".join(h for h, _ in columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(fmt(r.get(k)) for _, k in columns) + " |" for r in rows]
    return lines


def statistics_rows(datasets: list[Dataset]) -> list[dict[str, Any]]:
    """One row per comparison: dataset, model, quantity, reference and its statistics."""
    return [
        {"dataset": ds.name, "model": c.model, "quantity": c.quantity, "reference": c.reference, **c.stats()}
        for ds in datasets
        for c in ds.comparisons
    ]


def _views(ds: Dataset) -> dict[str, list[dict[str, Any]]]:
    """The dataset's tables, and for RICSAC its three CRASH3 runs side by side."""
    t = ds.tables
    if ds.name != "ricsac":
        return t
    merged = [
        {
            **p,
            "dv_neades": a["dv"],
            "dv_eff_neades": a["dv_eff"],
            "alpha_neades": a["alpha"],
            "gamma_neades": a["gamma"],
            "dv_nogamma": g["dv"],
        }
        for p, a, g in zip(t["crash3 published"], t["crash3 neades"], t["crash3 neades, gamma = 1"])
    ]
    return {**t, "crash3 merged": merged}


def _detail(ds: Dataset) -> list[str]:
    """The dataset's per-row tables (DETAILS) as markdown."""
    views, lines = _views(ds), []
    for caption, name, columns in DETAILS[ds.name]:
        lines += ["", caption, "", *table(views[name], columns)]
    return lines


def markdown(datasets: list[Dataset], figures: Mapping[str, str] | None = None) -> str:
    """The report as markdown: per dataset the assumptions, the error
    statistics by model, the per-row tables and (optionally) the figure."""
    lines = [
        "Generated by `impactsym validate --markdown` (impactsym/validation/). "
        "Errors: 100 (model - reference) / reference."
    ]
    for ds in datasets:
        lines += ["", f"### {ds.title}", ""] + [f"- {note}" for note in ds.notes]
        lines += ["", "Error statistics:", ""]
        lines += table(
            [
                {"model": c.model, "quantity": c.quantity, "reference": c.reference, **c.stats()}
                for c in ds.comparisons
            ],
            STATS_COLUMNS,
        )
        if figures and ds.name in figures:
            lines += ["", f"![{ds.title}]({figures[ds.name]})"]
        lines += _detail(ds)
    return "\n".join(lines) + "\n"


def text_summary(datasets: list[Dataset]) -> str:
    """The error statistics as a plain-text table for a terminal."""
    rows = statistics_rows(datasets)
    # each text column as wide as its longest entry: names are never cut
    w = {k: max([len(k)] + [len(r[k]) for r in rows]) for k in ("dataset", "model", "quantity", "reference")}
    head = (
        f"{'dataset':{w['dataset']}} {'model':{w['model']}} {'quantity':{w['quantity']}} "
        f"{'reference':{w['reference']}} {'n':>3} {'median%':>8} {'worst%':>8} {'bias%':>8}"
    )
    body = [
        f"{r['dataset']:{w['dataset']}} {r['model']:{w['model']}} {r['quantity']:{w['quantity']}} "
        f"{r['reference']:{w['reference']}} {r['n']:3d} {r['median']:8.1f} {r['worst']:8.1f} {r['bias']:8.1f}"
        for r in rows
    ]
    return "\n".join([head, *body])
