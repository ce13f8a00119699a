"""NHTSA 4364, 4438, 4474 (car-to-SUV; Rose et al., SAE 2006-01-0908): the
rigid model on the published inputs against the published PIM results and the
measured delta-V."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from ..single import solve
from .common import num, read

G_ROSE = 32.2  # ft/s²: Rose et al. convert weights with 32.2 (README)
MPH = 5280.0 / 3600.0  # ft/s per mph


def _nhtsa_scene(rows: list[Mapping[str, str]]) -> dict:
    vehicles = []
    for row in rows:
        heading = num(row["heading_deg"])
        speed = num(row["speed_mph"]) * MPH
        angle = math.radians(heading + num(row["angle_heading_to_impact_line_deg"]))
        d = num(row["d_cg_to_impact_ft"])
        vehicles.append(
            {
                "name": row["vehicle"],
                "mass": num(row["weight_lb"]) / G_ROSE,
                "yaw_inertia": num(row["yaw_inertia_lb_ft_s2"]),
                "velocity": [
                    speed * math.cos(math.radians(heading)),
                    speed * math.sin(math.radians(heading)),
                ],
                "yaw_rate": math.radians(num(row["yaw_rate_degps"])),
                "impact_point": [d * math.cos(angle), d * math.sin(angle)],
            }
        )
    gamma = num(rows[0]["normal_angle_deg"])
    (r1x, r1y), (r2x, r2y) = vehicles[0]["impact_point"], vehicles[1]["impact_point"]
    if math.cos(math.radians(gamma)) * (r1x - r2x) + math.sin(math.radians(gamma)) * (r1y - r2y) < 0:
        gamma += 180.0
    e = 0.150 if rows[0]["nhtsa_test"] == "4474" else num(rows[0]["e"])
    return {
        "units": "US",
        "model": "rigid",
        "vehicles": vehicles,
        "impact": {
            "normal_angle": gamma,
            "restitution": e,
            "impulse_ratio": "critical",
            "moment_restitution": 1.0,
        },
    }


def nhtsa() -> list[dict[str, Any]]:
    """NHTSA 4364, 4438, 4474: one row per vehicle with the model's and the
    published energies [ft·lb], delta-V [mph] and final yaw rate [deg/s], and
    the measured delta-V."""
    by_test: dict[str, list] = {}
    for row in read("nhtsa_vehicle_to_vehicle_rose2006"):
        by_test.setdefault(row["nhtsa_test"], []).append(row)
    out = []
    for test, rows in by_test.items():
        result = solve(_nhtsa_scene(rows))
        for row, vehicle in zip(rows, result.vehicles):
            out.append(
                {
                    "test": test,
                    "vehicle": row["vehicle"],
                    "energy_loss": result.TL,
                    "energy_loss_published": num(row["published_energy_loss_ftlb"]),
                    "normal_loss": result.TLn,
                    "normal_loss_published": num(row["published_normal_loss_ftlb"]),
                    "tangential_loss": result.TLt,
                    "tangential_loss_published": num(row["published_tangential_loss_ftlb"]),
                    "dv": vehicle.delta_v_magnitude / MPH,
                    "dv_published": num(row["published_dv_mph"]),
                    "dv_measured": num(row["measured_dv_mph"]),
                    "yaw": abs(math.degrees(vehicle.yaw_rate)),
                    "yaw_published": num(row["published_final_yaw_rate_degps"]),
                    "flags": result.flags,
                }
            )
    return out
