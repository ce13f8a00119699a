"""impactsym.fit: the fit of mixed evidence, its identifiability and its intervals.

Truth comes from the 50-digit reference (tests/evidence_truth.py): forward
scenes solved by impactsym.testing.reference, evidence computed from them.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from impactsym.evidence import fit
from impactsym.reconstruct import reconstruct
from impactsym.scene import SceneError

from .evidence_truth import base_scene, observed, truth

SIX = [("final_velocity", 0), ("final_velocity", 1), ("final_yaw_rate", 0), ("final_yaw_rate", 1)]
# The published kind of evidence (issue 24): one car's EDR speed and longitudinal
# delta-V, both departure directions.
MIXED = [("speed", 0), ("delta_v_longitudinal", 0), ("final_direction", 0), ("final_direction", 1)]
LINEAR = [("speed", 0), ("delta_v_longitudinal", 0), ("delta_v_lateral", 0), ("final_velocity", 1)]
SD = {"final_direction": 2.0, "final_yaw_rate": 0.05}


def with_evidence(t, items, noise=None, sd_scale=1.0):
    """The fit scene of truth `t` with evidence items (quantity, vehicle); `noise`
    (a Generator) adds normal errors of the stated sd."""
    scene = base_scene(t)
    for quantity, vehicle in items:
        value = observed(t, quantity, vehicle)
        sd = SD.get(quantity, 0.5) * sd_scale
        if noise is not None:
            value = (np.asarray(value) + sd * noise.standard_normal(np.shape(value))).tolist()
        scene["evidence"].append({"vehicle": vehicle, "quantity": quantity, "value": value, "sd": sd})
    return scene


def _why(result, path):
    return next(w["reason"] for w in result["identifiability"]["why"] if w["quantity"] == path)


def reconstruct_scene(t):
    scene = base_scene(t)
    del scene["evidence"]
    for i, vehicle in enumerate(scene["vehicles"]):
        vehicle["final_velocity"] = observed(t, "final_velocity", i)
        vehicle["final_yaw_rate"] = observed(t, "final_yaw_rate", i)
    return scene


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_six_final_velocities_reproduce_reconstruct(seed):
    """Evidence = exactly the six final velocities: the fit is reconstruct's answer."""
    t = truth(seed)
    got = fit(with_evidence(t, SIX), draws=0).to_json_dict()
    want = reconstruct(reconstruct_scene(t))
    for i in range(2):
        assert got["vehicles"][i]["speed"] == pytest.approx(want.vehicles[i].speed, rel=1e-9)
        assert got["vehicles"][i]["velocity"] == pytest.approx(
            list(want.vehicles[i].velocity), rel=1e-9, abs=1e-9
        )
    assert got["restitution"] == pytest.approx(want.e, rel=1e-8)
    assert got["impulse_ratio"] == pytest.approx(want.mu, rel=1e-8)
    assert got["critical_impulse_ratio"] == pytest.approx(want.mu_c, rel=1e-8)
    assert got["energy_loss"]["total"] == pytest.approx(want.TL, rel=1e-8)
    assert got["impulse"]["normal"] == pytest.approx(want.Pn, rel=1e-9)
    assert max(abs(r["z"]) for r in got["residuals"]) < 1e-6
    # ... and the truth of the 50-digit reference
    assert got["vehicles"][1]["speed"] == pytest.approx(t["speeds"][1], rel=1e-9)
    assert got["restitution"] == pytest.approx(t["row"]["e"], rel=1e-8)


@pytest.mark.parametrize("seed", [4, 5])
def test_mixed_evidence_recovers_truth_and_everything_is_determined(seed):
    """EDR speed and longitudinal delta-V of car 1, both departure directions, the
    normal known: four observations, four unknowns, all determined (given Γ)."""
    t = truth(seed)
    got = fit(with_evidence(t, MIXED), draws=50).to_json_dict()
    assert got["identifiability"]["rank"] == 4
    assert got["vehicles"][1]["speed"] == pytest.approx(t["speeds"][1], rel=1e-7)
    assert got["restitution"] == pytest.approx(t["row"]["e"], rel=1e-6, abs=1e-8)
    assert got["impulse_ratio"] == pytest.approx(t["row"]["mu"], rel=1e-6, abs=1e-8)
    low, high = got["vehicles"][1]["speed_interval"]
    assert low < got["vehicles"][1]["speed"] < high


def test_without_the_normal_e_and_mu_are_not_determined_but_the_speeds_are():
    """The issue's point: (Px, Py) fixes the speeds; how it splits into Pn and Pt
    (so e, μ, μ_c) needs the crush-surface normal."""
    t = truth(6)
    scene = with_evidence(t, MIXED)
    del scene["impact"]
    got = fit(scene, draws=50).to_json_dict()
    assert got["vehicles"][1]["speed"] == pytest.approx(t["speeds"][1], rel=1e-7)
    for path in ("restitution", "impulse_ratio", "critical_impulse_ratio", "impulse.normal"):
        assert path in got["identifiability"]["not_determined"]
        assert "normal_angle" in _why(got, path)
    assert got["restitution"] is None and got["impulse_ratio"] is None


def test_a_speed_no_evidence_reaches_is_reported_not_determined():
    """Car 1's EDR (speed, delta-V both ways) says nothing of car 2's speed."""
    t = truth(7)
    got = fit(
        with_evidence(t, [("speed", 0), ("delta_v_longitudinal", 0), ("delta_v_lateral", 0)])
    ).to_json_dict()
    ident = got["identifiability"]
    assert ident["rank"] == 3 and len(ident["unknowns"]) == 4
    assert got["vehicles"][1]["speed"] is None and got["vehicles"][1]["speed_interval"] is None
    assert "vehicles[1].speed" in ident["not_determined"]
    assert "vehicles[1].speed" in _why(got, "vehicles[1].speed")
    assert ident["null_space"] == [[0.0, 1.0, 0.0, 0.0]]
    # what it does determine: car 1's speed and the impulse, with intervals
    assert "vehicles[0].speed" in ident["determined"] and "impulse.x" in ident["determined"]
    assert got["vehicles"][0]["speed"] == pytest.approx(t["speeds"][0], rel=1e-9)
    assert any("does not determine vehicles[1].speed" in w for w in got["warnings"])


@pytest.mark.parametrize("seed", [8, 9])
def test_linear_answer_equals_gauss_newton(seed):
    """On linear evidence the closed form and the Gauss–Newton solver agree."""
    t = truth(seed)
    scene = with_evidence(t, LINEAR, noise=np.random.default_rng(seed))
    closed = fit(scene, draws=0)
    iterated = fit(scene, draws=0, method="gauss-newton")
    assert closed.info["method"] == "closed form" and iterated.info["iterations"] >= 1
    for path, est in closed.estimates.items():
        other = iterated.estimates[path]
        assert est.determined == other.determined
        if est.determined:
            assert other.value == pytest.approx(est.value, rel=1e-9, abs=1e-9 * (1 + abs(est.value)))


def test_residuals_name_the_item_that_disagrees():
    t = truth(10)
    scene = with_evidence(t, LINEAR + [("speed", 1)])
    scene["evidence"][-1]["value"] += 5.0  # 10 sd off
    got = fit(scene, draws=0).to_json_dict()
    worst = max(got["residuals"], key=lambda r: abs(r["z"]))
    assert worst["evidence"] == 4
    assert any(w.startswith("evidence[4] (vehicles[1].speed) disagrees most") for w in got["warnings"])


def test_admissibility_is_flagged_not_imposed():
    """A speed that makes the impulse tensile is fitted and flagged."""
    t = truth(11)
    scene = with_evidence(t, SIX)
    for item in scene["evidence"][:2]:
        item["value"] = [-v for v in item["value"]]
    got = fit(scene, draws=0).to_json_dict()
    assert got["admissibility"]["checked_as"] == "flags"
    assert got["admissibility"]["flags"] != 0 and got["admissibility"]["violations"]


def test_units_in_evidence():
    t = truth(12)
    si = with_evidence(t, [("speed", 0)] + LINEAR[1:])
    us = copy.deepcopy(si)
    us["evidence"][0]["value"] = f"{si['evidence'][0]['value'] / 0.44704} mph"
    us["evidence"][0]["sd"] = f"{0.5 / 0.44704} mph"
    a, b = fit(si, draws=0).to_json_dict(), fit(us, draws=0).to_json_dict()
    assert b["vehicles"][0]["speed"] == pytest.approx(a["vehicles"][0]["speed"], rel=1e-12)
    assert b["vehicles"][0]["speed_sd"] == pytest.approx(a["vehicles"][0]["speed_sd"], rel=1e-12)


def test_module_delta_v_uses_the_yaw_change():
    """delta-V at a module away from the centre of gravity: the body point's change."""
    t = truth(13)
    ref, row = t["ref"], t["row"]
    dW = ref["W1"] - row["w1"]
    a, b = 0.8, -0.3  # forward, left
    scene = with_evidence(t, [("speed", 0), ("final_velocity", 1)])
    for quantity, shift in (("delta_v_longitudinal", -dW * b), ("delta_v_lateral", dW * a)):
        scene["evidence"].append(
            {
                "vehicle": 0,
                "quantity": quantity,
                "value": observed(t, quantity, 0) + shift,
                "sd": 0.1,
                "at": {"forward": a, "left": b},
            }
        )
    got = fit(scene, draws=0).to_json_dict()
    assert max(abs(r["z"]) for r in got["residuals"]) < 1e-6
    assert got["vehicles"][0]["final_yaw_rate"] == pytest.approx(ref["W1"], rel=1e-8)


def test_energy_loss_and_final_speed_evidence():
    t = truth(14)
    items = [
        ("speed", 0),
        ("final_speed", 0),
        ("final_direction", 0),
        ("final_speed", 1),
        ("energy_loss", None),
    ]
    scene = with_evidence(t, items)
    scene["evidence"][-1]["sd"] = 2000.0
    del scene["evidence"][-1]["vehicle"]
    got = fit(scene, draws=30).to_json_dict()
    assert got["vehicles"][1]["speed"] == pytest.approx(t["speeds"][1], rel=1e-6)
    assert got["energy_loss"]["total"] == pytest.approx(t["ref"]["TL"], rel=1e-6)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda s: s["evidence"][0].update(quantity="sped"), "evidence[0].quantity: unknown quantity"),
        (lambda s: s["evidence"][0].pop("sd"), "evidence[0].sd: missing"),
        (lambda s: s["evidence"][0].update(sd=0), "evidence[0].sd: must be a positive"),
        (lambda s: s["evidence"][0].update(sd=-1), "evidence[0].sd: must be a positive"),
        (lambda s: s["evidence"][0].update(vehicle=2), "evidence[0].vehicle: unknown vehicle"),
        (lambda s: s["evidence"][0].update(vehicle="truck"), "evidence[0].vehicle: unknown vehicle"),
        (lambda s: s["evidence"][0].update(value="12 kg"), "evidence[0].value: needs a speed"),
        (lambda s: s["evidence"][0].update(valeu=1), 'evidence[0].valeu: unknown key; did you mean "value"'),
        (
            lambda s: s["evidence"][0].update(
                quantity="rest", value={"position": [1, 2], "heading": 3}, sd={"position": 1, "heading": 1}
            ),
            "runout: missing (a rest item needs the run-out",
        ),
        (lambda s: s["vehicles"][1].pop("heading"), "vehicles[1].heading: missing"),
        (lambda s: s.update(evidence=[]), "evidence: must be a non-empty list"),
    ],
)
def test_bad_evidence_is_one_line(change, message):
    scene = with_evidence(truth(1), LINEAR)
    change(scene)
    with pytest.raises(SceneError) as err:
        fit(scene, draws=0)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_moment_impulse_with_moment_restitution():
    """e_m given: M is unknown and moment restitution holds exactly at the answer."""
    t = truth(15)
    scene = with_evidence(t, SIX)
    scene["impact"]["moment_restitution"] = 1.0  # e_m = 1: M = 0 exactly
    got = fit(scene, draws=0).to_json_dict()
    assert "impulse.moment" in got["identifiability"]["unknowns"]
    assert abs(got["impulse"]["moment"]) < 1e-6 * abs(got["impulse"]["x"])
    assert got["vehicles"][1]["speed"] == pytest.approx(t["speeds"][1], rel=1e-9)


def _coverage(items, trials, draws, sd_scale=1.0):
    hits = np.zeros(2)
    for k in range(trials):
        t = truth(1000 + k)
        got = fit(
            with_evidence(t, items, np.random.default_rng(k), sd_scale), draws=draws, seed=k
        ).to_json_dict()
        for i in range(2):
            low, high = got["vehicles"][i]["speed_interval"]
            hits[i] += low <= t["speeds"][i] <= high
    return hits


def _binomial_bounds(n, p=0.9):
    """The central 99.9 % range of Binomial(n, p) hits (normal approximation, 3.3 sd)."""
    sd = math.sqrt(n * p * (1 - p))
    return n * p - 3.3 * sd, n * p + 3.3 * sd


def test_coverage_of_linear_intervals():
    """200 seeded trials of linear evidence: the 90 % speed intervals hold the truth
    at the nominal rate (within binomial bounds chosen before running)."""
    trials = 200
    hits = _coverage(LINEAR + [("speed", 1)], trials, draws=0)
    low, high = _binomial_bounds(trials)
    assert all(low <= h <= high for h in hits), hits


@pytest.mark.slow
def test_coverage_of_monte_carlo_intervals():
    """200 seeded trials of the mixed (nonlinear) evidence with Monte Carlo intervals."""
    trials = 200
    hits = _coverage(MIXED + [("final_speed", 1)], trials, draws=200)
    low, high = _binomial_bounds(trials)
    assert all(low <= h <= high for h in hits), hits


def test_observed_yaw_rate_becomes_an_unknown():
    """A vehicle that gives no yaw_rate but whose pre-impact yaw rate is observed
    gets it as an unknown; the truth's 0 comes back."""
    t = truth(16)
    scene = with_evidence(t, SIX)
    scene["evidence"].append({"vehicle": 1, "quantity": "yaw_rate", "value": 0.0, "sd": 0.05})
    got = fit(scene, draws=0).to_json_dict()
    assert "vehicles[1].yaw_rate" in got["identifiability"]["unknowns"]
    assert abs(got["vehicles"][1]["yaw_rate"]) < 1e-8
    assert got["vehicles"][1]["speed"] == pytest.approx(t["speeds"][1], rel=1e-9)


def test_barrier_crush_energy_is_the_energy_loss():
    """Against a fixed barrier, one car's crush energy is the energy loss: with its
    speed and a departure direction the fit recovers the reference solution."""
    row = {"m1": 1500.0, "m2": math.inf, "I1": 2500.0, "I2": math.inf, "v1x": 15.0, "v1y": 0.0, "w1": 0.0,
           "v2x": 0.0, "v2y": 0.0, "w2": 0.0, "r1x": 2.2, "r1y": 0.5, "r2x": -0.1, "r2y": 0.0,
           "gamma": math.radians(10.0), "e": 0.1, "mu": 0.1, "e_m": 1.0}  # fmt: skip
    from impactsym.testing.reference import solve_reference

    ref = {k: float(v) for k, v in solve_reference(row).items()}
    scene = {
        "units": "SI",
        "impact": {"normal_angle": 10.0},
        "vehicles": [
            {
                "name": "car",
                "mass": 1500.0,
                "yaw_inertia": 2500.0,
                "heading": 0.0,
                "impact_point": [2.2, 0.5],
            },
            {"name": "barrier", "fixed": True, "impact_point": [-0.1, 0.0]},
        ],
        "evidence": [
            {"vehicle": "car", "quantity": "crush_energy", "value": ref["TL"], "sd": 2000.0},
            {"vehicle": "car", "quantity": "final_velocity", "value": [ref["V1x"], ref["V1y"]], "sd": 0.2},
        ],
    }
    got = fit(scene, draws=50).to_json_dict()
    assert got["identifiability"]["unknowns"] == ["vehicles[0].speed", "impulse.x", "impulse.y"]
    assert got["vehicles"][0]["speed"] == pytest.approx(15.0, rel=1e-6)
    assert got["restitution"] == pytest.approx(0.1, rel=1e-6)
    assert got["impulse_ratio"] == pytest.approx(0.1, rel=1e-6)
    twice = copy.deepcopy(scene)
    twice["evidence"].append(dict(scene["evidence"][0]))
    with pytest.raises(SceneError, match="given twice"):
        fit(twice, draws=0)


def test_crush_energies_of_both_vehicles_are_the_energy_loss():
    """CRASH3's energy dissipated: E1 + E2 = T_L (sds in quadrature)."""
    t = truth(19)
    scene = with_evidence(t, [("speed", 0), ("final_direction", 0), ("final_direction", 1)])
    share = 0.4 * t["ref"]["TL"]
    scene["evidence"] += [
        {"vehicle": 0, "quantity": "crush_energy", "value": share, "sd": 3000.0},
        {"vehicle": 1, "quantity": "crush_energy", "value": t["ref"]["TL"] - share, "sd": 4000.0},
    ]
    got = fit(scene, draws=0).to_json_dict()
    energy = [r for r in got["residuals"] if r["label"].startswith("energy_loss.total")]
    assert len(energy) == 1 and energy[0]["value"] == pytest.approx(t["ref"]["TL"], rel=1e-12)
    assert got["vehicles"][1]["speed"] == pytest.approx(t["speeds"][1], rel=1e-6)


def test_an_uncertain_normal_angle_widens_e_and_mu_not_the_speeds():
    """impact.normal_angle as a distribution: the Monte Carlo draws it, so the
    Γ-dependent quantities carry its spread while the speeds do not move."""
    t = truth(17)
    fixed = with_evidence(t, LINEAR)
    spread = copy.deepcopy(fixed)
    gamma = spread["impact"]["normal_angle"]
    spread["impact"]["normal_angle"] = {"uniform": [gamma - 6.0, gamma + 6.0]}
    a, b = fit(fixed, draws=300).to_json_dict(), fit(spread, draws=300).to_json_dict()
    assert b["vehicles"][1]["speed_interval"] == pytest.approx(a["vehicles"][1]["speed_interval"], rel=1e-12)
    assert b["restitution"] == pytest.approx(a["restitution"], rel=1e-12)  # the nominal angle

    def widths(result):
        return {
            r["quantity"]: r["interval"][1] - r["interval"][0]
            for r in result["estimates"]
            if r["quantity"] in ("impulse_ratio", "critical_impulse_ratio")
        }

    width, wider = widths(a), widths(b)
    assert all(wider[k] > 1.5 * width[k] for k in width), (width, wider)
    angle = next(r for r in b["estimates"] if r["quantity"] == "impact.normal_angle")
    assert angle["interval"] == pytest.approx([gamma - 5.4, gamma + 5.4], abs=0.2)  # 5 % and 95 % of ±6


def test_without_a_normal_angle_it_is_reported_not_determined():
    t = truth(18)
    scene = with_evidence(t, LINEAR)
    del scene["impact"]
    got = fit(scene, draws=0).to_json_dict()
    assert "impact.normal_angle" in got["identifiability"]["not_determined"]
    assert "crush-surface angle" in _why(got, "impact.normal_angle")
