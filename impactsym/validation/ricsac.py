"""RICSAC (12 staged car-to-car crashes, Calspan 1978): CRASH3 on the 24
vehicles' crush profiles (as published and with Neades' adjustments), and the
rigid impulse-momentum model with the impact centre approximated from the
damage centres (Vossou & Koulocheris 2018 velocities). Every function returns
rows of dicts; units are in each docstring."""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from typing import Any

from ..compare import compare
from ..crash3 import crash3
from ..scene import SceneError
from ..single import solve
from .common import num, read, wrap

MEASURED_VERSIONS = {
    "untransformed": "dv_measured_untransformed",
    "Brach & Smith 2002": "dv_measured_brach_smith_2002",
    "McHenry 1997": "dv_measured_mchenry_1997",
}
# Neades, thesis Table 5.7: per test.vehicle, the change to every crush depth
# [cm], to the damage offset D [cm], or the damage width L [cm] (README).
NEADES_DEPTH = {
    "1.2": -10,
    "2.2": -15,
    "3.1": 5,
    "4.2": -15,
    "5.2": -20,
    "6.2": -15,
    "7.2": -20,
    "9.1": -10,
    "10.2": 10,
}
NEADES_OFFSET = {"3.2": -50}
NEADES_WIDTH = {"12.1": 140, "12.2": 140}
IMPLAUSIBLE = {"7.2": "mass 771 kg is implausible for that car (README); kept as published"}
SHIFT_M = 0.2  # m: the impact-centre shift of the RICSAC sensitivity study


def _faces(configuration: str) -> tuple[str, str]:
    """The damaged faces of vehicles 1 and 2 from a RICSAC configuration."""
    if "front-to-side" in configuration:
        return "front", "side"
    if "front-to-rear" in configuration:
        return "front", "rear"
    return "front", "front"


def _alpha(face: str, pdof: float) -> float:
    """The PDOF from the inward normal of the damaged face [deg]."""
    if face == "front":
        return wrap(pdof)
    if face == "rear":
        return wrap(pdof - 180.0)
    return pdof - 90.0 if pdof >= 0.0 else pdof + 90.0


def _damage_centre(face: str, vehicle: Mapping[str, str], offset: float, pdof: float):
    """The damage centre in the SAE vehicle frame (x forward, y right) [cm]."""
    if face == "front":
        return num(vehicle["cg_to_front_cm"]), offset
    if face == "rear":
        return -num(vehicle["cg_to_rear_cm"]), offset
    side = 1.0 if pdof >= 0.0 else -1.0
    return offset, side * num(vehicle["width_cm"]) / 2.0


def _moment_arm(centre, pdof: float) -> float:
    """|r × d| [m] of the PDOF line (direction d at `pdof` clockwise from forward,
    in the SAE frame) through the damage centre r [cm]."""
    t = math.radians(pdof)
    return abs(centre[0] * math.sin(t) - centre[1] * math.cos(t)) / 100.0


def _profile(vehicle: Mapping[str, str], key: str, adjusted: bool):
    """(depths [cm], width L [cm], offset D [cm]) as published or as Neades adjusted them."""
    depths = [num(vehicle[f"c{i}_cm"]) for i in range(1, 7)]
    if key == "8.1":  # "7 9 0 0 0 0": a 2-point profile (README)
        depths = [6.9, 9.1]
    width, offset = num(vehicle["L_cm"]), num(vehicle["D_cm"])
    if adjusted:
        depths = [max(0.0, c + NEADES_DEPTH.get(key, 0)) for c in depths]
        width = NEADES_WIDTH.get(key, width)
        offset += NEADES_OFFSET.get(key, 0)
    return depths, width, offset


def _crash3_vehicle(key: str, face: str, pdof: float, adjusted: bool, arm: bool = True) -> dict:
    """The crush table (SI) of one RICSAC vehicle and its facts."""
    vehicle = _vehicles()[key]
    depths, width, offset = _profile(vehicle, key, adjusted)
    mass, inertia = num(vehicle["mass_kg"]), num(vehicle["yaw_inertia_kgm2"])
    h = _moment_arm(_damage_centre(face, vehicle, offset, pdof), pdof) if arm else 0.0
    crush = {
        "A": num(vehicle["A_N_per_cm"]) * 100.0,
        "B": num(vehicle["B_N_per_cm2"]) * 1e4,
        "width": width / 100.0,
        "depths": [c / 100.0 for c in depths],
        "pdof": _alpha(face, pdof),
        "moment_arm": h,
        "radius_of_gyration": math.sqrt(inertia / mass),
    }
    return {"name": key, "mass": mass, "crush": crush}


@lru_cache(maxsize=1)
def _vehicles() -> dict[str, dict[str, str]]:
    return {row["test_vehicle"]: row for row in read("ricsac_vehicles")}


@lru_cache(maxsize=1)
def _tests() -> dict[int, dict[str, str]]:
    return {int(row["test"]): row for row in read("ricsac_tests")}


def _crash3_test(test: int, adjusted: bool, correction: str = "crash3", arm: bool = True):
    """impactsym.crash3 on one RICSAC test (crush only: no impact block)."""
    row = _tests()[test]
    faces = _faces(row["configuration"])
    kind = "adjusted" if adjusted else "original"
    pdofs = [num(row[f"pdof_v{i}_{kind}_deg"]) for i in (1, 2)]
    scene = {
        "units": "SI",
        "vehicles": [_crash3_vehicle(f"{test}.{i + 1}", faces[i], pdofs[i], adjusted, arm) for i in range(2)],
    }
    return crash3(scene, restitution=0.0, energy="dissipated", correction=correction), faces, pdofs


def ricsac_crash3(adjusted: bool, arm: bool = True) -> list[dict[str, Any]]:
    """CRASH3 on the 24 RICSAC vehicles: one row per vehicle with the energy,
    α, γ, CG and effective-mass delta-V [m/s] and the measured versions."""
    rows = []
    for test in sorted(_tests()):
        result, faces, pdofs = _crash3_test(test, adjusted, arm=arm)
        data = _tests()[test]
        for i, vehicle in enumerate(result.vehicles):
            key = f"{test}.{i + 1}"
            rows.append(
                {
                    "vehicle": key,
                    "face": faces[i],
                    "pdof": pdofs[i],
                    "alpha": _alpha(faces[i], pdofs[i]),
                    "capped": any(f"vehicles[{i}].crush.pdof" in w for w in result.warnings),
                    "energy_J": vehicle.crush_energy,
                    "gamma": vehicle.mass_factor,
                    "dv": vehicle.delta_v_magnitude,
                    "dv_eff": vehicle.delta_v_effective_mass,
                    **{name: num(data[f"{col}_v{i + 1}_mps"]) for name, col in MEASURED_VERSIONS.items()},
                    "neades_raw_crash": num(data[f"dv_crash_raw_v{i + 1}_mps"]),
                    "note": IMPLAUSIBLE.get(key, ""),
                }
            )
    return rows


FT_LB = 4.4482216152605 * 0.3048  # J per ft·lb


ENERGY_REFERENCES = {
    "measured": "measured",
    "brach_pim": "Brach's PIM (SAE 871993)",
    "woolley_1985": "Woolley's CRASH3 (1985)",
}


def ricsac_energy() -> list[dict[str, Any]]:
    """Per test: CRASH3 total crush energy [ft·lb] (published profiles and
    Neades', CRASH3 and Woolley corrections) beside Woolley's 1985 CRASH3
    energy, Brach's PIM energy loss and the measured loss."""
    rows = []
    for test in sorted(_tests()):
        data = _tests()[test]
        if num(data["energy_loss_measured_ftlb"]) is None:
            continue
        out = {"test": test}
        for label, adjusted, correction in (
            ("published", False, "crash3"),
            ("published, woolley", False, "woolley"),
            ("neades", True, "crash3"),
        ):
            out[label] = _crash3_test(test, adjusted, correction)[0].energy_total / FT_LB
        out.update(
            {
                "woolley_1985": num(data["crash3_energy_woolley1985_ftlb"]),
                "brach_pim": num(data["brach1987_energy_loss_ftlb"]),
                "measured": num(data["energy_loss_measured_ftlb"]),
                "initial": num(data["initial_energy_ftlb"]),
            }
        )
        out["impossible"] = ", ".join(
            k for k in ("published", "published, woolley", "neades") if out[k] > out["initial"]
        )
        rows.append(out)
    return rows


# ---------------------------------------------------------------- RICSAC: impulse-momentum


@lru_cache(maxsize=1)
def _vossou() -> dict[int, dict[str, str]]:
    """Vossou & Koulocheris 2018, one dict per test (quantity → text)."""
    rows = read("ricsac_velocities_vossou2018")
    tests = [c for c in rows[0] if c != "quantity"]
    return {int(t.split("_")[1]): {row["quantity"]: row[t] for row in rows} for t in tests}


def _scene_point(centre_cm, heading_deg: float) -> list[float]:
    """An SAE vehicle-frame point [cm] in the scene frame (y left) [m]."""
    x, y = centre_cm[0] / 100.0, -centre_cm[1] / 100.0
    c, s = math.cos(math.radians(heading_deg)), math.sin(math.radians(heading_deg))
    return [c * x - s * y, s * x + c * y]


def _ricsac_pim_scene(test: int, shift: tuple[float, float] = (0.0, 0.0)) -> dict:
    """The rigid scene of a RICSAC test (module docstring, ASSUMPTIONS); `shift`
    moves each damage centre along its face [m]."""
    row, v = _tests()[test], _vossou()[test]
    faces = _faces(row["configuration"])
    vehicles = []
    for i in (1, 2):
        key = f"{test}.{i}"
        data = _vehicles()[key]
        vx, vy = num(v[f"v{i}x_mps"]), num(v[f"v{i}y_mps"])
        heading = math.degrees(math.atan2(vy, vx)) if math.hypot(vx, vy) > 0 else 170.0
        pdof = num(row[f"pdof_v{i}_original_deg"])
        _, _, offset = _profile(data, key, adjusted=False)
        face = faces[i - 1]
        centre = list(_damage_centre(face, data, offset, pdof))
        centre[1 if face != "side" else 0] += 100.0 * shift[i - 1]
        vehicles.append(
            {
                "name": key,
                "mass": num(data["mass_kg"]),
                "yaw_inertia": num(data["yaw_inertia_kgm2"]),
                "velocity": [vx, vy],
                "yaw_rate": 0.0,
                "impact_point": _scene_point(centre, heading),
            }
        )
    gamma = num(v["Gamma_deg"])
    (r1x, r1y), (r2x, r2y) = vehicles[0]["impact_point"], vehicles[1]["impact_point"]
    n = (math.cos(math.radians(gamma)), math.sin(math.radians(gamma)))
    if n[0] * (r1x - r2x) + n[1] * (r1y - r2y) < 0.0:
        gamma += 180.0
    return {
        "units": "SI",
        "model": "rigid",
        "vehicles": vehicles,
        "impact": {
            "normal_angle": gamma,
            "restitution": num(row["brach1987_e"]),
            "impulse_ratio": "critical",
            "moment_restitution": 1.0,
        },
    }


# The other impulse-momentum models of the seed on the same RICSAC scenes (via
# impactsym.compare): the common velocity (Limpert = IMPAC, e = 0) and particles.
OTHER_PIM_MODELS = {
    "limpert": "Limpert/IMPAC common velocity (approx. impact centre)",
    "particle": "particle (Brach's e, mu_c)",
}


def ricsac_pim() -> list[dict[str, Any]]:
    """Rigid model on the 11 RICSAC tests with velocities: delta-V [m/s] against
    the measured versions, energy loss [ft·lb] against Brach's and the measured,
    μ_c against Brach's μ, and the largest change of delta-V [%] when either
    impact centre moves ±0.2 m along its face."""
    rows = []
    for test in sorted(_vossou()):
        row = _tests()[test]
        try:
            base = solve(_ricsac_pim_scene(test))
        except SceneError as exc:
            rows.append({"test": test, "status": str(exc)})
            continue
        spread = 0.0
        for shift in ((SHIFT_M, 0.0), (-SHIFT_M, 0.0), (0.0, SHIFT_M), (0.0, -SHIFT_M)):
            try:
                moved = solve(_ricsac_pim_scene(test, shift))
            except SceneError:
                spread = math.inf
                continue
            spread = max(
                spread,
                *(
                    100.0 * abs(m.delta_v_magnitude / b.delta_v_magnitude - 1.0)
                    for m, b in zip(moved.vehicles, base.vehicles)
                ),
            )
        out = {
            "test": test,
            "status": "solved",
            "flags": base.flags,
            "mu_c": base.mu_c,
            "brach_mu": num(row["brach1987_mu"]),
            "energy_loss": base.TL / FT_LB,
            "brach_energy_loss": num(row["brach1987_energy_loss_ftlb"]),
            "measured_energy_loss": num(row["energy_loss_measured_ftlb"]),
            "brach_tangential": num(row["brach1987_tangential_loss_ftlb"]),
            "sensitivity_pct": spread,
        }
        others = {row.model: row for row in compare(_ricsac_pim_scene(test)).rows}
        for model in OTHER_PIM_MODELS:
            out[f"{model} energy_loss"] = others[model].energy["total"] / FT_LB
            for i, vehicle in enumerate(others[model].vehicles, start=1):
                out[f"{model} dv{i}"] = vehicle.delta_v_magnitude
        for i, vehicle in enumerate(base.vehicles, start=1):
            out[f"dv{i}"] = vehicle.delta_v_magnitude
            for name, col in MEASURED_VERSIONS.items():
                out[f"dv{i} {name}"] = num(row[f"{col}_v{i}_mps"])
            out[f"dv{i} brach_pim_2002"] = num(row[f"dv_pim_2002_v{i}_mps"])
        rows.append(out)
    return rows


def ricsac_momentum() -> list[dict[str, Any]]:
    """How far Vossou's measured separation velocities are from conserving
    linear momentum: |Δp| per axis as a percent of the initial |p|."""
    rows = []
    for test, v in sorted(_vossou().items()):
        m = [num(_vehicles()[f"{test}.{i}"]["mass_kg"]) for i in (1, 2)]
        before = [sum(m[i] * num(v[f"v{i + 1}{a}_mps"]) for i in range(2)) for a in "xy"]
        after = [sum(m[i] * num(v[f"V{i + 1}{a}_mps"]) for i in range(2)) for a in "xy"]
        size = math.hypot(*before)
        rows.append(
            {
                "test": test,
                "x_pct": 100.0 * (after[0] - before[0]) / size,
                "y_pct": 100.0 * (after[1] - before[1]) / size,
            }
        )
    return rows


# ---------------------------------------------------------------- IIHS barrier
