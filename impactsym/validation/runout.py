"""RICSAC 2, 3, 6, 10: the run-out against the rest positions Day published
(SAE 2004-01-1207, Table 7: measured, SIMON, EDSMAC4; his VC-7, VC-3, VC-8, VC-11).

Two directions through :func:`impactsym.runout.runout`:

- forward: from the separation pose read from Day's Figures 9-12 and the
  separation velocity Vossou & Koulocheris published (measured, contaminated),
  the rest pose, against the measured one (and SIMON's and EDSMAC4's beside);
- fitted: the separation velocity and yaw rate that reach the measured rest pose
  from the same separation pose, against Vossou's measured velocity.

Every input that is not in the data is an assumption, stated in ``ASSUMPTIONS``
(report.py) from ``ASSUMED`` here. Day's frame is SAE (X forward, Y right,
heading clockwise); the scene's has y left and heading counter-clockwise:
x = X, y = -Y, psi = -Psi. Vossou's frame has vehicle 1 moving in -x; his
velocities are turned by 180 degrees into Day's scene (the mapping that makes
his post-impact velocities point the way Day's paths go, checked on all six
vehicles); his yaw-rate signs disagree with Day's figures on three of the six
vehicles, so only his magnitudes are used, with the sense of rotation read from
the figures.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

from ..errors import SceneError
from ..runout import runout
from .common import read, wrap
from .ricsac import _vehicles, _vossou

FT = 0.3048  # m
INCH = 0.0254  # m
G = 9.80665  # m/s²
MU = 0.87  # ASTM skid number 87 (Day, every test) / 100
CG_SHARE = {"Rabbit": 0.40, "Honda": 0.40}  # a/L of the front-drive cars; 0.45 for the others
TRACK_IN = {86.6: 51.1, 94.2: 51.1, 94.5: 51.1, 112.0: 61.8, 114.0: 61.8}  # CRASH3 class track by wheelbase
ASSUMED = (
    "Separation pose: SIMON's simulated pose at the end of the collision pulse (t_sep 0.15 s; "
    "0.25 s for VC-7), read by eye from Day's Figures 9-12 (time histories rendered at 220 dpi; "
    "about 0.5 ft and 2 deg, 1 ft and 3 deg on vehicle 2's coarser axes); not a measurement. "
    "Separation velocity: Vossou & Koulocheris 2018 (measured, momentum off by up to 17 %), "
    "turned 180 deg into Day's frame; |yaw rate| from Vossou, its sense from Day's heading "
    "curves (Vossou's sign disagrees on RICSAC 3 both cars and RICSAC 10 Torino); RICSAC 2 "
    "has no published separation velocity (fit only). Wheels: all rolling, no steer, no "
    "brake (Day: 'moved freely ... no driver steering, braking or throttle'; damaged wheels "
    "not modelled). mu = skid number 87 / 100 = 0.87, alpha_max = 10 deg, f_r = 0.01 (the "
    "contract's defaults; the cars rolled in high gear, engine drag not modelled). Mass and "
    "yaw inertia: ricsac_vehicles.csv. Wheelbase: nominal manufacturer values (Torino 114, "
    "Chevelle 112, Pinto 94.2, Rabbit 94.5, Civic 86.6 in); CG at 0.45 L behind the front "
    "axle (0.40 L for the front-drive Rabbit and Civic); track the CRASH3 class default by "
    "wheelbase. Rest heading as printed is the total heading (rotation = printed - "
    "separation); forward headings are compared wrapped. VC-11's Torino struck a "
    "transformer box at Y = 99.5 ft: shown, not judged."
)


def _separations() -> list[dict[str, str]]:
    return list(read("ricsac_separation_day2004_figures"))


def _rest(test: str, method: str) -> dict[str, str]:
    (row,) = [r for r in read("ricsac_rest_positions_day2004") if r["test"] == test and r["method"] == method]
    return row


def _pose(row: dict[str, str], vehicle: str) -> tuple[float, float, float]:
    return tuple(float(row[f"v{vehicle}_{k}"]) for k in ("x_ft", "y_ft", "psi_deg"))


def _measured_velocity(sep: dict[str, str]) -> tuple[float, float, float] | None:
    """Vossou's separation velocity in the scene frame (m/s) and yaw rate (rad/s)."""
    data = _vossou().get(int(sep["ricsac"]))
    if data is None:
        return None
    i = sep["vehicle"]
    vx, vy = float(data[f"V{i}x_mps"]), float(data[f"V{i}y_mps"])
    w = abs(float(data[f"W{i}_final_radps"]))
    return -vx, -vy, -int(sep["yaw_sign"]) * w  # 180 deg turn; Day's clockwise -> scene's negative


def _scene(sep: dict[str, str], velocity=None, rest=None, wheels: str = "rolling") -> dict[str, Any]:
    """A one-vehicle SI run-out scene in the scene frame (x = X, y = -Y, psi = -Psi)."""
    car = _vehicles()[sep["vehicle_row"]]
    wheelbase = float(sep["wheelbase_in"]) * INCH
    separation: dict[str, Any] = {"position": [float(sep["X_ft"]) * FT, -float(sep["Y_ft"]) * FT]}
    if velocity is not None:
        separation |= {"velocity": list(velocity[:2]), "yaw_rate": velocity[2]}
    vehicle = {
        "name": sep["name"],
        "mass": float(car["mass_kg"]),
        "yaw_inertia": float(car["yaw_inertia_kgm2"]),
        "heading": -float(sep["psi_deg"]),
        "wheelbase": wheelbase,
        "cg_to_front_axle": CG_SHARE.get(sep["name"], 0.45) * wheelbase,
        "track": TRACK_IN[float(sep["wheelbase_in"])] * INCH,
        "wheels": wheels,
        "separation": separation,
    }
    if rest is not None:
        vehicle["rest"] = {"position": [rest[0] * FT, -rest[1] * FT], "heading": -rest[2]}
    return {"units": "SI", "runout": {"friction": MU}, "vehicles": [vehicle]}


def _day(entry: dict[str, Any]) -> tuple[float, float, float]:
    """A run-out entry's rest pose in Day's frame (ft, deg)."""
    x, y = entry["rest"]["position"]
    return x / FT, -y / FT, -entry["rest"]["heading"]


def _path(entry: dict[str, Any], points: int = 400) -> tuple[tuple[float, float], ...]:
    """The CG path of a run-out entry in Day's frame (ft), thinned to about `points`."""
    path = entry["path"]
    step = max(1, len(path) // points)
    return tuple((p[1] / FT, -p[2] / FT) for p in [*path[::step], path[-1]])


def _errors(pose, measured, separation) -> dict[str, float]:
    return {
        "position_error_ft": math.hypot(pose[0] - measured[0], pose[1] - measured[1]),
        "heading_error_deg": wrap(pose[2] - measured[2]),
        "distance_ft": math.hypot(pose[0] - separation[0], pose[1] - separation[1]),
    }


@cache
def ricsac_runout_table() -> tuple[dict[str, Any], ...]:
    """One row per vehicle: separation pose, measured, SIMON and EDSMAC4 rest (Day's frame)."""
    rows = []
    for sep in _separations():
        label, i = f"{sep['test']}.{sep['vehicle']}", sep["vehicle"]
        row: dict[str, Any] = {"label": label, "ricsac": int(sep["ricsac"]), "name": sep["name"]}
        row |= {
            f"separation {k}": float(sep[c]) for k, c in (("X", "X_ft"), ("Y", "Y_ft"), ("psi", "psi_deg"))
        }
        separation = (row["separation X"], row["separation Y"], row["separation psi"])
        measured = _pose(_rest(sep["test"], "experiment"), i)
        row["free"] = not (sep["test"] == "VC-11" and i == "2")
        row["runout_distance_ft"] = math.hypot(measured[0] - separation[0], measured[1] - separation[1])
        for source in ("measured", "SIMON", "EDSMAC4"):
            pose = measured if source == "measured" else _pose(_rest(sep["test"], source), i)
            row |= {f"{source} {k}": v for k, v in zip(("X", "Y", "psi"), pose)}
            if source != "measured":
                errs = _errors(pose, measured, separation)
                row |= {f"{source} {k}": v for k, v in errs.items()}
        rows.append(row)
    return tuple(rows)


def _separation_of(row: dict[str, Any]) -> dict[str, str]:
    (sep,) = [s for s in _separations() if f"{s['test']}.{s['vehicle']}" == row["label"]]
    return sep


@cache
def _forward() -> tuple[dict[str, Any], ...]:
    out = []
    for row in ricsac_runout_table():
        sep = _separation_of(row)
        velocity = _measured_velocity(sep)
        if velocity is None:
            continue
        entry = runout(_scene(sep, velocity), path=True)["vehicles"][0]
        pose = _day(entry)
        measured = (row["measured X"], row["measured Y"], row["measured psi"])
        separation = (row["separation X"], row["separation Y"], row["separation psi"])
        # the other end of the wheel states: every wheel locked (a bracket, not a fit)
        locked_entry = runout(_scene(sep, velocity, wheels="locked"), path=True)["vehicles"][0]
        locked = _errors(_day(locked_entry), measured, separation)
        out.append(
            {
                **row,
                **{f"locked {k}": v for k, v in locked.items()},
                "path": _path(entry),
                "locked path": _path(locked_entry),
                "X": pose[0],
                "Y": pose[1],
                "psi": pose[2],
                "time_s": entry["time"],
                "speed_mps": math.hypot(*velocity[:2]),
                "yaw_rate": velocity[2],
                # the rolling drag a straight roll from the measured speed to the measured rest needs
                "drag_needed": math.hypot(*velocity[:2]) ** 2 / (2 * G * row["runout_distance_ft"] * FT),
                **_errors(pose, measured, separation),
            }
        )
    return tuple(out)


def ricsac_runout_forward() -> list[dict[str, Any]]:
    """Forward run-outs from Vossou's measured separation velocities (RICSAC 3, 6, 10),
    every wheel rolling (the assumption) and, as a bracket, every wheel locked."""
    return [dict(r) for r in _forward()]


@cache
def _fit() -> tuple[dict[str, Any], ...]:
    out = []
    for row in ricsac_runout_table():
        if not row["free"]:
            continue
        sep = _separation_of(row)
        measured = _measured_velocity(sep)
        rest = (row["measured X"], row["measured Y"], row["measured psi"])
        r: dict[str, Any] = {"label": row["label"], "ricsac": row["ricsac"], "name": row["name"]}
        r |= dict.fromkeys(("speed", "speed_measured", "direction_measured_deg", "yaw_rate_measured"))
        try:
            entry = runout(_scene(sep, rest=rest))["vehicles"][0]
        except SceneError as exc:  # a fit that fails is a row of the table, not a crash
            out.append(r | {"converged": False, "error": str(exc)})
            continue
        (vx, vy), w = entry["separation"]["velocity"], entry["separation"]["yaw_rate"]
        fit = entry["fit"]
        r |= {
            "converged": fit["converged"],
            "iterations": fit["iterations"],
            "residual_ft": fit["residual"]["position"] / FT,
            "residual_deg": fit["residual"]["heading"],
            "speed": math.hypot(vx, vy),
            "direction_deg": math.degrees(math.atan2(vy, vx)),
            "yaw_rate": w,
        }
        if measured is not None:
            r |= {
                "speed_measured": math.hypot(*measured[:2]),
                "direction_measured_deg": math.degrees(math.atan2(measured[1], measured[0])),
                "yaw_rate_measured": measured[2],
            }
            r["speed_pct"] = 100.0 * (r["speed"] - r["speed_measured"]) / r["speed_measured"]
            r["direction_error_deg"] = wrap(r["direction_deg"] - r["direction_measured_deg"])
        out.append(r)
    return tuple(out)


def ricsac_runout_fit() -> list[dict[str, Any]]:
    """Separation states fitted to the measured rest poses, against Vossou's measured ones."""
    return [dict(r) for r in _fit()]
