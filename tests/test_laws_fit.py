"""impactsym fit read as the Kudlich–Slibar law (issue 25, item 1: "in fit as an
alternative law"). Truth: scenes solved by the independent 50-digit K–S reference
(impactsym.testing.laws), their final motion given to the fit as evidence."""

from __future__ import annotations

import copy

import pytest

from impactsym.evidence import fit
from impactsym.scene import SceneError
from impactsym.testing import laws as L

from .evidence_truth import base_scene, observed, truth

#: Both final velocities and yaw rates: every unknown of the fit determined.
SIX_ITEMS = [("final_velocity", 0), ("final_velocity", 1), ("final_yaw_rate", 0), ("final_yaw_rate", 1)]


def ks_truth(seed: int, contact: str, mu_f: float = 0.0) -> dict:
    """evidence_truth's scene geometry, solved by the 50-digit K–S reference."""
    t = truth(seed)
    row = dict(t["row"], mu_f=mu_f)
    t["ref"] = {k: float(v) for k, v in L.kudlich_slibar_reference(row, contact).items()}
    t["row"] = row
    return t


def ks_fit_scene(t: dict) -> dict:
    scene = base_scene(t)
    scene["model"] = "kudlich_slibar"
    for quantity, vehicle in SIX_ITEMS:
        scene["evidence"].append(
            {"vehicle": vehicle, "quantity": quantity, "value": observed(t, quantity, vehicle), "sd": 0.01}
        )
    return scene


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_full_impact_is_read_back_as_its_epsilon(seed):
    t = ks_truth(seed, "full")
    assert t["ref"]["sliding"] == 0
    law = fit(ks_fit_scene(t), draws=0).to_json_dict()["law"]
    assert law["model"] == "kudlich_slibar" and law["determined"] and law["exact"]
    assert law["contact"] == "full" and law["friction"] is None
    assert law["restitution"] == pytest.approx(t["row"]["e"], rel=1e-6)


def test_a_sliding_contact_is_read_back_with_its_friction():
    for seed in range(1, 40):
        t = ks_truth(seed, "sliding", mu_f=0.2)
        if t["ref"]["sliding"] == 1 and t["ref"]["Pt"] * t["ref"]["Pn"] != 0:
            break
    else:
        pytest.fail("no sliding K-S scene drawn")
    law = fit(ks_fit_scene(t), draws=0).to_json_dict()["law"]
    assert law["contact"] == "sliding" and law["exact"]
    assert law["friction"] == pytest.approx(0.2, rel=1e-6)
    assert law["restitution"] == pytest.approx(t["row"]["e"], rel=1e-6)


def test_a_rigid_fit_has_no_law_and_the_moment_impulse_is_no_point_impulse():
    t = ks_truth(1, "full")
    scene = ks_fit_scene(t)
    rigid = copy.deepcopy(scene)
    del rigid["model"]
    assert "law" not in fit(rigid, draws=0).to_json_dict()
    scene["impact"]["moment_restitution"] = 0.5
    law = fit(scene, draws=0).to_json_dict()["law"]
    assert not law["determined"] and "point impulse" in law["why"]
    with pytest.raises(SceneError, match="model.*alternative law kudlich_slibar"):
        fit(dict(scene, model="coulomb"), draws=0)
