"""IIHS small-overlap tests (Brach et al., SAE 2014-01-0469): the 41 barrier
tests with Brach's fitted parameters, and the 9 vehicle-to-vehicle tests with
his fitted e, mu, phi, Gamma and an approximated CG-to-impact distance and
assumed masses, with the sensitivity to those approximations. Units: US
(ft, slug, ft/s, deg/s)."""

from __future__ import annotations

import math
import statistics
from collections.abc import Mapping
from typing import Any

from ..single import solve
from .common import num, read, stats

G_FT = 32.174  # ft/s², standard gravity: weight [lb] → mass [slug]
FUSION_WEIGHT, FUSION_INERTIA = 3574.2, 2336.3  # lb, slug·ft² (the one car with data)


def _barrier_scene(row: Mapping[str, str], mu: float | str, k_scale: float = 1.0) -> dict:
    """The car (Fusion mass; yaw inertia scaled by k_scale² for a sensitivity
    study of the assumed radius of gyration) into the fixed barrier."""
    mass = FUSION_WEIGHT / G_FT
    d, phi = num(row["d1_ft"]), math.radians(num(row["phi_deg"]))
    return {
        "units": "US",
        "model": "rigid",
        "vehicles": [
            {
                "name": row["test_id"],
                "mass": mass,
                "yaw_inertia": FUSION_INERTIA * k_scale**2,
                "velocity": [num(row["v0_ftps"]), 0.0],
                "yaw_rate": 0.0,
                "impact_point": [d * math.cos(phi), d * math.sin(phi)],
            },
            {"name": "barrier", "fixed": True},
        ],
        "impact": {
            "normal_angle": num(row["gamma_deg"]),
            "restitution": num(row["e"]),
            "impulse_ratio": mu,
            "moment_restitution": 1.0,
        },
    }


def iihs_barrier(k_scale: float = 1.0) -> list[dict[str, Any]]:
    """The 41 IIHS small-overlap barrier tests: predicted |ΔV| [ft/s] (from
    components) and yaw-rate change [deg/s] against the measured; `k_scale`
    scales the assumed radius of gyration (sensitivity)."""
    rows = []
    for row in read("iihs_small_overlap_barrier_brach2014"):
        critical = solve(_barrier_scene(row, "critical", k_scale))
        result = solve(
            _barrier_scene(row, num(row["mu_percent_of_critical"]) / 100.0 * critical.mu_c, k_scale)
        )
        car = result.vehicles[0]
        dvx, dvy = car.velocity[0] - num(row["v0_ftps"]), car.velocity[1]
        rows.append(
            {
                "test": row["test_id"],
                "vehicle": f"{row['model_year']} {row['vehicle']}",
                "kind": row["kind"],
                "outlier": "outlier" in row["kind"],
                "dv": math.hypot(dvx, dvy),
                "dv_measured": math.hypot(num(row["dvx_ftps"]), num(row["dvy_ftps"])),
                "dvx": -dvx,
                "dvx_measured": num(row["dvx_ftps"]),
                "dvy": abs(dvy),
                "dvy_measured": num(row["dvy_ftps"]),
                "yaw": math.degrees(car.yaw_rate),
                "yaw_measured": num(row["omega_degps"]),
                "flags": result.flags,
            }
        )
    return rows


# ---------------------------------------------------------------- IIHS vehicle to vehicle

V2V_MODEL = "rigid PIM (Brach's fits, approx. d, equal masses)"
OBLIQUE_DEG = 15.0  # deg: the relative heading of the "15° oblique" tests, off head-on
V2V_MASS_SCALES = (0.85, 1.15)  # the sensitivity study's m_b / m_a
V2V_K_SCALES = (0.9, 1.1)  # and its radius-of-gyration factors


def _barrier_rows() -> list[Mapping[str, str]]:
    """Brach's barrier fits without the source's outlier."""
    return [r for r in read("iihs_small_overlap_barrier_brach2014") if "outlier" not in r["kind"]]


def _v2v_d(row: Mapping[str, str]) -> tuple[float, str]:
    """The CG-to-impact distance d [ft] assumed for a V2V vehicle (none is
    published) and its source: the median of Brach's barrier d1 for the same
    model (year dropped) and kind, else the same model, else every barrier
    test of that kind."""
    model = row["vehicle"].split(" ", 1)[1]
    barrier = _barrier_rows()
    for label, pool in (
        (
            f"barrier {model}, {row['kind']}",
            [r for r in barrier if r["vehicle"] == model and r["kind"] == row["kind"]],
        ),
        (f"barrier {model}, all kinds", [r for r in barrier if r["vehicle"] == model]),
        (f"barrier, all {row['kind']}", [r for r in barrier if r["kind"] == row["kind"]]),
    ):
        if pool:
            return statistics.median(num(r["d1_ft"]) for r in pool), f"median d1 of {len(pool)} ({label})"
    raise ValueError(f"no barrier d1 for {row['vehicle']}")  # unreachable: every kind has tests


def v2v_tests() -> dict[str, tuple[Mapping[str, str], Mapping[str, str]]]:
    """The 9 V2V tests: test id → ('a' row, 'b' row)."""
    rows = read("iihs_vehicle_to_vehicle_brach2014")
    return {a["test_vehicle"][:-1]: (a, b) for a, b in zip(rows[::2], rows[1::2])}


def _v2v_scene(
    pair,
    mu: float | str,
    d: float | None = None,
    mass_scale: float = 1.0,
    k_scale: float = 1.0,
    oblique: float = OBLIQUE_DEG,
    gamma_in_b: bool = False,
) -> dict:
    """Vehicle 'a' (frame: a's at impact, x forward, y left) and 'b' head-on, or
    at 180° + `oblique` for the oblique tests, each struck on its left front
    (r = d (cos φ, sin φ) in its own frame), Γ in a's frame (b's with
    `gamma_in_b`). Masses: the Fusion's (b's × `mass_scale`), I = k² m with the
    Fusion's k × `k_scale`; `d` [ft] overrides the approximated distances."""
    a, b = pair
    heading_b = 180.0 + (oblique if "oblique" in a["overlap"] else 0.0)
    mass = FUSION_WEIGHT / G_FT
    vehicles = []
    for row, heading, m in ((a, 0.0, mass), (b, heading_b, mass * mass_scale)):
        dist = _v2v_d(row)[0] if d is None else d
        angle, v0 = math.radians(heading + num(row["phi_deg"])), num(row["v0_ftps"])
        vehicles.append(
            {
                "name": row["test_vehicle"],
                "mass": m,
                "yaw_inertia": FUSION_INERTIA / mass * k_scale**2 * m,
                "velocity": [v0 * math.cos(math.radians(heading)), v0 * math.sin(math.radians(heading))],
                "yaw_rate": 0.0,
                "impact_point": [dist * math.cos(angle), dist * math.sin(angle)],
            }
        )
    gamma = num(a["gamma_deg"]) + (heading_b - 180.0 if gamma_in_b else 0.0)
    return {
        "units": "US",
        "model": "rigid",
        "vehicles": vehicles,
        "impact": {
            "normal_angle": gamma,  # either sense: the solver takes the one from a toward b
            "restitution": num(a["e"]),
            "impulse_ratio": mu,
            "moment_restitution": 1.0,
        },
    }


def v2v_solve(pair, **options):
    """Brach's μ as a percent of the critical one (a first, critical solve)."""
    critical = solve(_v2v_scene(pair, "critical", **options))
    percent = num(pair[0]["mu_percent_of_critical"]) / 100.0
    return solve(_v2v_scene(pair, percent * critical.mu_c, **options))


def iihs_v2v(**options) -> list[dict[str, Any]]:
    """The 9 IIHS vehicle-to-vehicle tests, one row per vehicle: predicted
    |ΔV| [ft/s] and yaw-rate change [deg/s] (counter-clockwise positive; the
    measured are magnitudes) against the measured, with the assumed d [ft],
    mass [slug] and yaw inertia [slug·ft²]; `options` go to the scene (the
    sensitivity studies)."""
    out = []
    for test, pair in v2v_tests().items():
        result = v2v_solve(pair, **options)
        scene = _v2v_scene(pair, 0.0, **options)
        for row, vehicle, given in zip(pair, result.vehicles, scene["vehicles"]):
            d, source = _v2v_d(row)
            out.append(
                {
                    "test": test,
                    "vehicle": row["test_vehicle"][-1] + ": " + row["vehicle"],
                    "kind": row["kind"],
                    "overlap": row["overlap"],
                    "d": math.hypot(*given["impact_point"]),
                    "d_source": source if options.get("d") is None else "sensitivity study",
                    "mass": given["mass"],
                    "yaw_inertia": given["yaw_inertia"],
                    "mu_c": result.mu_c,
                    "mu": result.mu,
                    "delta_v": vehicle.delta_v,
                    "dv": vehicle.delta_v_magnitude,
                    "dv_measured": num(row["dv_ftps"]),
                    "yaw": math.degrees(vehicle.yaw_rate),
                    "yaw_measured": num(row["omega_degps"]),
                    "flags": result.flags,
                }
            )
    return out


def _pct(new: float, old: float) -> float:
    return 100.0 * (new / old - 1.0)


def v2v_sensitivity() -> list[dict[str, Any]]:
    """How the V2V predictions move with the approximations: both d at the
    barrier minimum and maximum, m_b/m_a × 0.85 and × 1.15, k × 0.9 and × 1.1.
    Per case the median and largest |change| [%] of |ΔV| and of the yaw-rate
    change over the 18 vehicles, the median |error| [%] against the measured,
    and the median |ΔV_a|/|ΔV_b|."""
    base = iihs_v2v()
    d1 = [num(r["d1_ft"]) for r in _barrier_rows()]
    cases = [(f"d = barrier {name}", {"d": f(d1)}) for name, f in (("min", min), ("max", max))]
    cases += [(f"m_b x {s:g}", {"mass_scale": s}) for s in V2V_MASS_SCALES]
    cases += [(f"k x {s:g}", {"k_scale": s}) for s in V2V_K_SCALES]
    rows = []
    for case, options in cases:
        moved = iihs_v2v(**options)
        dv = [abs(_pct(m["dv"], b["dv"])) for m, b in zip(moved, base)]
        yaw = [abs(_pct(m["yaw"], b["yaw"])) for m, b in zip(moved, base)]
        rows.append(
            {
                "case": case,
                "value": options.get("d", options.get("mass_scale", options.get("k_scale"))),
                "dv_change_median": statistics.median(dv),
                "dv_change_worst": max(dv),
                "yaw_change_median": statistics.median(yaw),
                "yaw_change_worst": max(yaw),
                "dv_error_median": stats([_pct(r["dv"], r["dv_measured"]) for r in moved])["median"],
                "yaw_error_median": stats([_pct(r["yaw"], r["yaw_measured"]) for r in moved])["median"],
                "ratio_a_to_b": statistics.median(a["dv"] / b["dv"] for a, b in zip(moved[::2], moved[1::2])),
            }
        )
    return rows


def v2v_oblique_readings() -> list[dict[str, Any]]:
    """The two 15° oblique tests under the four readings of the unpublished
    geometry (b's heading 180° ± 15°; Γ in a's or b's frame): median |error| [%]
    of |ΔV| and the yaw-rate change of their 4 vehicles. Shown, not chosen from."""
    rows = []
    for oblique in (OBLIQUE_DEG, -OBLIQUE_DEG):
        for gamma_in_b in (False, True):
            moved = [r for r in iihs_v2v(oblique=oblique, gamma_in_b=gamma_in_b) if "oblique" in r["overlap"]]
            rows.append(
                {
                    "heading_b": 180.0 + oblique,
                    "gamma_frame": "b" if gamma_in_b else "a",
                    "used": oblique == OBLIQUE_DEG and not gamma_in_b,
                    "dv_error_median": stats([_pct(r["dv"], r["dv_measured"]) for r in moved])["median"],
                    "yaw_error_median": stats([_pct(r["yaw"], r["yaw_measured"]) for r in moved])["median"],
                    "flagged": sum(bool(r["flags"]) for r in moved[::2]),
                }
            )
    return rows


# ---------------------------------------------------------------- NHTSA (Rose 2006)
