"""CRASH3: crush energy against independent integration, units, the PDOF limit and
correction, effective masses, restitution, the seed's PDOF inconsistency, the CLI."""

import copy
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import impactsym
from impactsym.cli import main
from impactsym.crash3 import INCHES_PER_FOOT
from impactsym.scene import SceneError

ROOT = Path(__file__).resolve().parents[1]
TWO_CAR = json.loads((ROOT / "examples" / "crash3_two_car_us.json").read_text())
BARRIER = json.loads((ROOT / "examples" / "crash3_barrier_si.json").read_text())

# Exact unit definitions (NIST): lbf, inch, foot, slug.
LBF, INCH, FOOT = 4.4482216152605, 0.0254, 0.3048
SLUG = LBF / FOOT


def numeric_energy(A, B, width, depths, n=200_001):
    """∫ (A + B C(w))²/(2B) dw over the profile, C piecewise linear: trapezoid rule."""
    w = np.linspace(0.0, width, n)
    C = np.interp(w, np.linspace(0.0, width, len(depths)), depths)
    f = (A + B * C) ** 2 / (2 * B)
    return float(np.sum((f[1:] + f[:-1]) * np.diff(w)) / 2)


def barrier_scene(depths, pdof=0.0, A=35000.0, B=1.0e6, width=1.5, mass=1500.0, **vehicle):
    data = copy.deepcopy(BARRIER)
    data["vehicles"][0].update(mass=mass, **vehicle)
    data["vehicles"][0]["crush"] = {"A": A, "B": B, "width": width, "depths": list(depths), "pdof": pdof}
    return data


@pytest.mark.parametrize(
    "depths",
    [[0.2, 0.5], [0.1, 0.4, 0.25, 0.0], [0.3, 0.32, 0.4, 0.1, 0.0, 0.05]],
    ids=["2 points", "4 points", "6 points"],
)
def test_crush_energy_equals_numeric_integration(depths):
    result = impactsym.crash3(barrier_scene(depths))
    expected = numeric_energy(35000.0, 1.0e6, 1.5, depths)
    assert result.vehicles[0].crush_energy_uncorrected == pytest.approx(expected, rel=1e-8)


def test_barrier_delta_v_is_the_full_energy_into_the_car():
    """Into a fixed barrier without rotation (gamma = 1): E = m dV^2 / 2."""
    result = impactsym.crash3(barrier_scene([0.3, 0.3]))
    energy = result.energy_total
    assert result.vehicles[0].delta_v_magnitude == pytest.approx(math.sqrt(2 * energy / 1500.0), rel=1e-13)
    assert result.vehicles[1].delta_v_magnitude == 0.0 and result.vehicles[1].crush_energy == 0.0


def test_pdof_correction_and_direction():
    plain = impactsym.crash3(barrier_scene([0.3, 0.3]))
    oblique = impactsym.crash3(barrier_scene([0.3, 0.3], pdof=30.0))
    car = oblique.vehicles[0]
    assert car.crush_energy == pytest.approx(plain.energy_total / math.cos(math.radians(30)) ** 2, rel=1e-13)
    # Force on vehicle 1 along Γ + 180° + α (Γ = 0): rearward and 30° clockwise from rearward.
    direction = math.degrees(math.atan2(car.delta_v[1], car.delta_v[0]))
    assert direction == pytest.approx(-150.0, abs=1e-9)


def test_pdof_beyond_90_degrees_is_an_error():
    """Past 45° the correction is capped (tests/test_crash3_options.py); at 90° or
    more the force would pull the face out: an error naming the field."""
    impactsym.crash3(barrier_scene([0.3, 0.3], pdof=89.0))
    with pytest.raises(SceneError, match=r"vehicles\[0\].crush.pdof: \|pdof\| = 90.5 must be < 90"):
        impactsym.crash3(barrier_scene([0.3, 0.3], pdof=-90.5))


@pytest.mark.parametrize(
    ("change", "text"),
    [
        ({"depths": [0.1, 0.2, 0.3]}, "depths: must be a list of 2, 4 or 6 crush depths"),
        ({"depths": [0.1, -0.2]}, "crush.depths[1]: must be >= 0 (a crush depth), got -0.2"),
        ({"B": 0.0}, "crush.B: must be > 0 (the slope of force per unit width against crush), got 0"),
        ({"A": -1.0}, "crush.A: must be >= 0"),
        ({"width": 0.0}, "crush.width: must be > 0 (the damage width)"),
        ({"A": "stiff"}, "crush.A: must be a finite number"),
    ],
)
def test_bad_crush_tables_name_their_field(change, text):
    data = barrier_scene([0.3, 0.3])
    data["vehicles"][0]["crush"].update(change)
    with pytest.raises(SceneError, match=re.escape(text)):
        impactsym.crash3(data)


def test_a_moving_vehicle_needs_a_crush_table():
    data = copy.deepcopy(TWO_CAR)
    del data["vehicles"][1]["crush"]
    with pytest.raises(SceneError, match=r"vehicles\[1\].crush: missing"):
        impactsym.crash3(data)


def test_us_crush_units_agree_with_si():
    """lb/in, lb/in², in and slug give the same delta-V as the SI conversion of the
    same car: checks the in·lb → ft·lb factor (12)."""
    us = impactsym.crash3(TWO_CAR)
    si = copy.deepcopy(TWO_CAR)
    si["units"] = "SI"
    for vehicle in si["vehicles"]:
        vehicle["mass"] *= SLUG
        vehicle["yaw_inertia"] *= SLUG * FOOT**2
        vehicle["impact_point"] = [x * FOOT for x in vehicle["impact_point"]]
        crush = vehicle["crush"]
        crush["A"] *= LBF / INCH
        crush["B"] *= LBF / INCH**2
        crush["width"] *= INCH
        crush["depths"] = [c * INCH for c in crush["depths"]]
    si = impactsym.crash3(si)
    assert si.energy_total == pytest.approx(us.energy_total * LBF * FOOT, rel=1e-12)
    for a, b in zip(us.vehicles, si.vehicles):
        assert b.delta_v_magnitude == pytest.approx(a.delta_v_magnitude * FOOT, rel=1e-12)
    assert INCHES_PER_FOOT == 12.0


def test_effective_masses_from_radius_of_gyration_and_moment_arm():
    data = copy.deepcopy(TWO_CAR)
    arms, radii = (1.5, 2.5), (4.0, 4.4)
    for vehicle, h, k in zip(data["vehicles"], arms, radii):
        vehicle["crush"].update(moment_arm=h, radius_of_gyration=k)
    result = impactsym.crash3(data)
    m = [v["mass"] for v in data["vehicles"]]
    gamma = [k * k / (k * k + h * h) for h, k in zip(arms, radii)]
    mbar = 1.0 / (1.0 / (gamma[0] * m[0]) + 1.0 / (gamma[1] * m[1]))
    impulse = math.sqrt(2 * result.energy_total * mbar)
    for i in range(2):
        assert result.vehicles[i].mass_factor == pytest.approx(gamma[i], rel=1e-14)
        assert result.vehicles[i].delta_v_magnitude == pytest.approx(impulse / m[i], rel=1e-13)


def test_effective_mass_from_yaw_inertia_and_impact_point():
    """Without the optional keys: k² = I/m and h = r × d for the PDOF direction d."""
    result = impactsym.crash3(TWO_CAR)
    assert TWO_CAR["impact"]["normal_angle"] == 0.0
    for vehicle, out in zip(TWO_CAR["vehicles"], result.vehicles):
        assert vehicle["crush"]["pdof"] == 0.0  # so the PDOF line is along x
        k2 = vehicle["yaw_inertia"] / vehicle["mass"]
        h = vehicle["impact_point"][1]  # |r × (±1, 0)| = |ry|
        assert abs(out.moment_arm) == pytest.approx(abs(h), rel=1e-14)
        assert out.mass_factor == pytest.approx(k2 / (k2 + h * h), rel=1e-14)


def test_restitution_scales_delta_v():
    plain = impactsym.crash3(TWO_CAR)
    bouncy = impactsym.crash3(TWO_CAR, restitution=0.2)
    factor = math.sqrt(1.2 / 0.8)
    for a, b in zip(plain.vehicles, bouncy.vehicles):
        assert b.delta_v_magnitude == pytest.approx(a.delta_v_magnitude * factor, rel=1e-13)
    with pytest.raises(SceneError, match="restitution: must be in"):
        impactsym.crash3(TWO_CAR, restitution=1.0)


def test_momentum_balance_and_unequal_pdofs_warning():
    result = impactsym.crash3(TWO_CAR)
    m = [v["mass"] for v in TWO_CAR["vehicles"]]
    for axis in (0, 1):
        total = sum(mi * v.delta_v[axis] for mi, v in zip(m, result.vehicles))
        assert total == pytest.approx(0.0, abs=1e-12 * m[0] * 30)
    assert result.warnings == []
    data = copy.deepcopy(TWO_CAR)
    data["vehicles"][1]["crush"]["pdof"] = 20.0
    assert any("momentum is not conserved" in w for w in impactsym.crash3(data).warnings)


def test_with_the_implied_pdof_and_energy_crash3_is_the_common_velocity_solution():
    """The seed's point, end to end: a car into a barrier with an eccentric impact
    centre. Give CRASH3 the PDOF of the common-velocity (Limpert) solution and a
    crush whose corrected energy is that solution's energy loss: it returns the same
    |delta-V|. The moment arm and radius of gyration come from the scene."""
    car = {
        "name": "car",
        "mass": 1500.0,
        "yaw_inertia": 2500.0,
        "velocity": [14.0, 3.0],
        "impact_point": [2.3, -0.4],
    }
    scene = {
        "model": "limpert",
        "units": "SI",
        "impact": {"normal_angle": 10.0},
        "vehicles": [car, {"name": "barrier", "fixed": True}],
    }
    limpert = impactsym.solve(scene)
    alpha = math.degrees(math.atan(limpert.mu))
    A, B, width = 35000.0, 1.0e6, 1.5
    target = limpert.TL * math.cos(math.radians(alpha)) ** 2 / width  # energy per unit width
    depth = (-A + math.sqrt(A * A - 2 * B * (A * A / (2 * B) - target))) / B  # A C + B C²/2 + G = target
    crushed = {**car, "crush": {"A": A, "B": B, "width": width, "depths": [depth, depth], "pdof": alpha}}
    result = impactsym.crash3({**scene, "vehicles": [crushed, scene["vehicles"][1]]})
    assert result.energy_total == pytest.approx(limpert.TL, rel=1e-12)
    assert result.vehicles[0].delta_v_magnitude == pytest.approx(
        limpert.vehicles[0].delta_v_magnitude, rel=1e-10
    )
    assert result.vehicles[0].pdof_implied == pytest.approx(alpha, abs=1e-9)
    assert not any("implies" in w for w in result.warnings)


def test_entered_pdof_against_the_implied_one_is_reported():
    data = json.loads((ROOT / "examples" / "models_two_car_us.json").read_text())
    result = impactsym.crash3(data)
    implied = result.vehicles[0].pdof_implied
    assert implied == pytest.approx(
        math.degrees(math.atan(impactsym.solve({**data, "model": "limpert"}).mu_c)), abs=1e-9
    )
    assert sum("CRASH3 takes |delta-V| from mu = mu_max" in w for w in result.warnings) == 2
    assert impactsym.crash3(TWO_CAR).vehicles[0].pdof_implied is None  # no velocities


def test_cli_crash3_json_and_table(capsys):
    assert main(["crash3", str(ROOT / "examples" / "crash3_two_car_us.json"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"vehicles", "energy_total", "warnings"} <= set(out)
    assert all({"crush_energy", "delta_v_magnitude"} <= set(v) for v in out["vehicles"])
    assert out["energy_total"] == pytest.approx(sum(v["crush_energy"] for v in out["vehicles"]))
    assert main(["crash3", str(ROOT / "examples" / "crash3_barrier_si.json"), "--restitution", "0.1"]) == 0
    assert "restitution e = 0.1" in capsys.readouterr().out


def test_cli_crash3_bad_scene_is_one_line(capsys, tmp_path):
    data = copy.deepcopy(TWO_CAR)
    data["vehicles"][0]["crush"]["pdof"] = 95
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    assert main(["crash3", str(path)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "vehicles[0].crush.pdof" in err


def test_a_wrong_effective_mass_fails_its_proof(monkeypatch):
    """The CRASH3 proofs are not vacuous: double the moment arm in 1/(γ m) and the
    common-velocity claim fails."""
    import dataclasses

    from derive import crash3 as derive_crash3
    from derive.kernel import Block

    knl = derive_crash3.KERNELS[3]
    wrong = {derive_crash3.h1: 2 * derive_crash3.h1}
    blocks = tuple(
        Block(
            tuple((s, x.xreplace(wrong) if s == derive_crash3.ke1 else x) for s, x in block.assigns),
            block.guard,
        )
        for block in knl.blocks
    )
    bad = dataclasses.replace(knl, blocks=blocks)
    monkeypatch.setattr(
        derive_crash3, "KERNELS", derive_crash3.KERNELS[:3] + (bad,) + derive_crash3.KERNELS[4:]
    )
    results = dict(derive_crash3._delta_v_claims())
    assert not results[
        "crash3_delta_v: given the common-velocity rigid solution's PDOF and "
        "energy loss it returns that solution's |P| exactly"
    ]
