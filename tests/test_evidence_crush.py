"""crush_energy evidence given as a CRASH3 crush profile: its energy through
impactsym.crash3, the energy loss when every moving vehicle's is given, a
one-sided bound (T_L at least it) when one of two is."""

from __future__ import annotations

import pytest

from impactsym.crash3 import crash3
from impactsym.evidence import fit
from impactsym.scene import SceneError

from .evidence_truth import base_scene, observed, truth

A, B, WIDTH = 35000.0, 600000.0, 1.4  # SI stiffness N/m, N/m², damage width m


def profile(depth: float, pdof: float = 0.0) -> dict:
    return {"A": A, "B": B, "width": WIDTH, "depths": [0.8 * depth, depth, depth, 0.8 * depth], "pdof": pdof}


def crash3_energy(crush: dict, options: dict | None = None) -> float:
    """The CRASH3 code's crush energy of a profile (a car against a barrier)."""
    scene = {"units": "SI", "vehicles": [{"mass": 1000.0, "crush": crush}, {"fixed": True}]}
    if options:
        scene["crash3"] = options
    return crash3(scene).vehicles[0].crush_energy


def profile_for(energy: float, pdof: float = 0.0) -> dict:
    """A profile whose CRASH3 energy is `energy`: bisection on the depth (the
    energy rises with it), through the CRASH3 code itself."""
    lo, hi = 0.0, 3.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if crash3_energy(profile(mid, pdof)) < energy else (lo, mid)
    return profile(0.5 * (lo + hi), pdof)


def scene_with_crush(t, share: float, both: bool = True, own: bool = False):
    """Truth `t`'s fit scene: vehicle 0's speed, both departure directions, and the
    crush profiles that split T_L as share : 1 - share."""
    scene = base_scene(t)
    scene["evidence"] = [
        {"vehicle": 0, "quantity": "speed", "value": observed(t, "speed", 0), "sd": 0.3},
        {"vehicle": 0, "quantity": "final_direction", "value": observed(t, "final_direction", 0), "sd": 1.0},
        {"vehicle": 1, "quantity": "final_direction", "value": observed(t, "final_direction", 1), "sd": 1.0},
    ]
    energies = [share * t["ref"]["TL"], (1 - share) * t["ref"]["TL"]]
    for i in (0, 1) if both else (0,):
        crush = profile_for(energies[i], pdof=10.0 * i)
        item = {"vehicle": i, "quantity": "crush_energy", "sd": 0.05 * energies[i]}
        if own:
            scene["vehicles"][i]["crush"] = crush
        else:
            item["crush"] = crush
        scene["evidence"].append(item)
    return scene, energies


@pytest.mark.parametrize("own", [False, True])
def test_crush_profiles_of_both_vehicles_recover_the_speeds(own):
    t = truth(19)
    scene, energies = scene_with_crush(t, 0.4, own=own)
    got = fit(scene, draws=200, seed=1).to_json_dict()
    energy = [r for r in got["residuals"] if r["label"].startswith("energy_loss.total")]
    assert len(energy) == 1 and energy[0]["value"] == pytest.approx(t["ref"]["TL"], rel=1e-6)
    for i in (0, 1):
        lo, hi = got["vehicles"][i]["speed_interval"]
        assert lo <= t["speeds"][i] <= hi
        assert got["vehicles"][i]["speed"] == pytest.approx(t["speeds"][i], rel=1e-4)


def test_one_crush_profile_of_two_is_a_lower_bound_on_the_energy_loss():
    t = truth(19)
    scene, energies = scene_with_crush(t, 0.4, both=False)
    scene["evidence"].insert(
        3, {"vehicle": 1, "quantity": "final_speed", "value": observed(t, "final_speed", 1), "sd": 0.3}
    )
    got = fit(scene, draws=0).to_json_dict()
    (bound,) = [r for r in got["residuals"] if r["label"].startswith("energy_loss.total")]
    assert "at least vehicles[0].crush_energy" in bound["label"]
    assert bound["value"] == pytest.approx(energies[0], rel=1e-6)
    assert got["energy_loss"]["total"] >= energies[0] * (1 - 1e-9)
    assert bound["z"] == pytest.approx(0.0, abs=1e-9)  # the truth is well above the bound
    bare = base_scene(t)
    bare["evidence"] = scene["evidence"][:4] + [
        {"vehicle": 0, "quantity": "crush_energy", "value": 2.0 * t["ref"]["TL"], "sd": 100.0}
    ]
    pushed = fit(bare, draws=0).to_json_dict()
    assert pushed["energy_loss"]["total"] >= 1.9 * t["ref"]["TL"]  # a bound above the truth moves the fit


def test_correction_option_changes_the_observed_energy():
    t = truth(19)
    scene, _ = scene_with_crush(t, 0.4)
    scene["evidence"][3]["crush"]["pdof"] = 30.0
    woolley = {**scene, "crash3": {"correction": "woolley"}}
    label = "energy_loss.total (sum of the crush energies)"
    a, b = (
        next(r["value"] for r in fit(s, draws=0).to_json_dict()["residuals"] if r["label"] == label)
        for s in (scene, woolley)
    )
    crushes = [scene["evidence"][j]["crush"] for j in (3, 4)]
    expected = sum(crash3_energy(c) - crash3_energy(c, {"correction": "woolley"}) for c in crushes)
    assert a - b == pytest.approx(expected, rel=1e-9)
    assert a > b


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda c: c.update(width=-1.0), "evidence[3].crush.width"),
        (lambda c: c.pop("depths"), "evidence[3].crush.depths"),
        (lambda c: c.update(depths=[0.1, 0.2, 0.3]), "evidence[3].crush.depths"),
        (lambda c: c.update(pdof=95.0), "evidence[3].crush.pdof"),
        (lambda c: c.update(stiff=1.0), "evidence[3].crush.stiff"),
        (lambda c: c.update(category=3), "evidence[3].crush.category"),
    ],
)
def test_a_bad_crush_block_is_a_one_line_error_naming_the_field(change, field):
    scene, _ = scene_with_crush(truth(19), 0.4)
    change(scene["evidence"][3]["crush"])
    with pytest.raises(SceneError) as err:
        fit(scene, draws=0)
    assert err.value.field == field and "\n" not in str(err.value)


def test_a_missing_profile_is_refused():
    t = truth(19)
    scene, _ = scene_with_crush(t, 0.4)
    del scene["evidence"][3]["crush"]
    with pytest.raises(SceneError) as err:
        fit(scene, draws=0)
    assert err.value.field == "evidence[3].value"


def absorbed_scene(t, e: float, share: float = 0.4):
    """Truth `t`'s crush scene with profiles whose CRASH3 energies, read as
    absorbed up to maximum crush with restitution e, lose T_L over the impact:
    each profile holds its share of T_L divided by (1 - e^2) (Rose et al.'s 1-D
    impact, independent of the fit's kernels)."""
    scene, energies = scene_with_crush(t, share)
    for j, i in ((3, 0), (4, 1)):
        absorbed = energies[i] / (1 - e * e)
        scene["evidence"][j]["crush"] = profile_for(absorbed, pdof=10.0 * i)
        scene["evidence"][j]["sd"] = 0.05 * absorbed
    scene["crash3"] = {"energy": "absorbed", "restitution": e}
    return scene


@pytest.mark.parametrize("e", [0.0, 0.3])
def test_absorbed_crush_energies_recover_the_speeds(e):
    t = truth(19)
    got = fit(absorbed_scene(t, e), draws=200, seed=1).to_json_dict()
    (energy,) = [r for r in got["residuals"] if r["label"].startswith("energy_loss.total")]
    assert f"absorbed energies x (1 - e^2), e = {e:g}" in energy["label"]
    assert energy["value"] == pytest.approx(t["ref"]["TL"], rel=1e-6)
    for i in (0, 1):
        lo, hi = got["vehicles"][i]["speed_interval"]
        assert lo <= t["speeds"][i] <= hi
        assert got["vehicles"][i]["speed"] == pytest.approx(t["speeds"][i], rel=1e-4)


def test_the_absorbed_reading_is_the_crash3_codes_own():
    """The energy loss the fit reads from absorbed crush energies is the energy
    that CRASH3 (impactsym.crash3, its own kernels) would need, read as
    dissipated, to give the delta-V it gives the same crush read as absorbed:
    delta-V grows as sqrt(E), so T_L = sum E x (dV_absorbed / dV_dissipated)^2."""
    e = 0.3
    t = truth(19)
    scene = absorbed_scene(t, e)
    (energy,) = [
        r for r in fit(scene, draws=0).to_json_dict()["residuals"] if r["label"].startswith("energy")
    ]
    vehicles = [
        {k: v for k, v in vehicle.items() if k != "heading"} | {"crush": scene["evidence"][3 + i]["crush"]}
        for i, vehicle in enumerate(scene["vehicles"])
    ]

    def crash(mode):
        options = {"energy": mode, "restitution": e}
        return crash3({"units": "SI", "impact": scene["impact"], "vehicles": vehicles, "crash3": options})

    absorbed, dissipated = crash("absorbed"), crash("dissipated")
    ratio = absorbed.vehicles[0].delta_v_magnitude / dissipated.vehicles[0].delta_v_magnitude
    assert energy["value"] == pytest.approx(dissipated.energy_total * ratio**2, rel=1e-9)
    assert energy["value"] < dissipated.energy_total


def test_absorbed_with_restitution_one_is_refused():
    t = truth(19)
    scene = absorbed_scene(t, 0.3)
    scene["crash3"]["restitution"] = 1.0
    with pytest.raises(SceneError) as err:
        fit(scene, draws=0)
    assert err.value.field == "crash3.restitution" and "\n" not in str(err.value)


def test_an_unused_vehicle_crush_block_is_named_in_the_warnings():
    t = truth(19)
    scene, _ = scene_with_crush(t, 0.4, own=True)
    del scene["evidence"][4]
    got = fit(scene, draws=0).to_json_dict()
    assert any(w.startswith("vehicles[1].crush is not used") for w in got["warnings"])
    assert not any(w.startswith("vehicles[0].crush is not used") for w in got["warnings"])


def test_a_crash3_restitution_the_fit_rules_out_is_named():
    """The absorbed reading uses crash3.restitution, not the fitted e: when the
    fitted e's 90 % interval excludes it the answer says the two readings
    disagree; at the truth's own e it does not."""
    t = truth(19)
    said = "outside the fitted restitution's 90 % interval"
    near = fit(absorbed_scene(t, t["row"]["e"]), draws=200, seed=1)
    assert near.estimates["restitution"].determined
    assert not any(said in w for w in near.warnings)
    far = fit(absorbed_scene(t, 0.9), draws=200, seed=1)
    low, high = far.estimates["restitution"].interval
    assert not low <= 0.9 <= high
    assert any(
        w.startswith("the crush energies were read as absorbed with crash3.restitution 0.9")
        for w in far.warnings
    )
