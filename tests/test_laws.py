"""The impact laws (impactsym.laws): identities between the laws and Brach's model.

Kudlich–Slibar (K–S) and the Coulomb process are checked against results that come
from outside their closed forms: the seed's Table 2, Brach's rigid kernels
(impactsym.solve_batch), relative velocities and energies measured on the finals,
and each other where theory says they coincide.
"""

from __future__ import annotations

import numpy as np
import pytest

import impactsym
from impactsym import laws
from impactsym.testing import laws as L
from impactsym.testing import scenes

LAWS = ("newton", "poisson", "energetic")
CONTINUES, STOPS, REVERSES = 0, 1, 2
FINALS = ("V1x", "V1y", "W1", "V2x", "V2y", "W2")


@pytest.fixture(scope="module")
def realistic():
    return L.realistic(4000, 11)


@pytest.fixture(scope="module")
def stress():
    return L.stress(4000, 12)


def _relative_motion(c, out):
    """(gn, gt) initial and (Gn, Gt) final at the impact centre, from the velocities."""
    n = np.cos(c["gamma"]), np.sin(c["gamma"])
    t = -n[1], n[0]

    def rel(v1x, v1y, w1, v2x, v2y, w2):
        gx = (v2x - w2 * c["r2y"]) - (v1x - w1 * c["r1y"])
        gy = (v2y + w2 * c["r2x"]) - (v1y + w1 * c["r1x"])
        return gx * n[0] + gy * n[1], gx * t[0] + gy * t[1]

    g = rel(c["v1x"], c["v1y"], c["w1"], c["v2x"], c["v2y"], c["w2"])
    G = rel(out["V1x"], out["V1y"], out["W1"], out["V2x"], out["V2y"], out["W2"])
    return g, G


def _speed(c):
    return np.maximum(np.hypot(c["v1x"], c["v1y"]), np.hypot(c["v2x"], c["v2y"]))


def _brach(c, e, mu):
    """Brach's rigid model (point impulse, e_m = 1) on the law columns."""
    cols = {k: v for k, v in c.items() if k != "mu_f"}
    return impactsym.solve_batch(dict(cols, e=e, mu=mu, e_m=1.0), model="rigid")


def _same_finals(a, b, c, rows, tol=1e-11):
    """Velocities within tol of the largest speed, yaw rates of speed/arm, on `rows`."""
    speed = _speed(c)
    arm = np.maximum(np.hypot(c["r1x"], c["r1y"]), np.hypot(c["r2x"], c["r2y"]))
    for key in FINALS:
        scale = speed / arm if key.startswith("W") else speed
        scale = np.maximum(scale, np.abs(a[key]))
        err = np.abs(a[key] - b[key])[rows] / scale[rows]
        assert np.all(err <= tol), (key, float(err.max()))


# ------------------------------------------------------------------ seed Table 2


def test_table2_is_the_particle_limit_of_the_coulomb_process():
    """Seed Table 2 with mu as the friction coefficient: the Coulomb process gives
    the table's T_L up to mu_max and stays at the mu_max row beyond it (the slip
    stops: no energy is created), under every restitution law."""
    cols, table_tl = scenes.table2_scenes()
    mu_max = scenes.TABLE2_MU_MAX
    law_cols = {k: v for k, v in cols.items() if k != "mu"}
    law_cols.update(I1=1.0, I2=1.0, w1=0.0, w2=0.0, r1x=0.0, r1y=0.0, r2x=0.0, r2y=0.0, mu_f=cols["mu"])
    at_max = np.where(cols["e"] == 0.0, 192000.0, 96000.0)
    want = np.where(cols["mu"] <= mu_max, table_tl, at_max)
    assert np.any(want != table_tl)  # rows beyond mu_max differ from Brach's printed values
    for law in LAWS:
        out = laws.coulomb_batch(law_cols, law)
        assert np.all(out["status"] == 0)
        np.testing.assert_allclose(out["TL"], want, rtol=1e-12, atol=1e-9 * 192000.0)
        assert np.all(out["flags"] & 1 == 0)
        slip = np.where(cols["mu"] < mu_max, CONTINUES, STOPS)
        assert np.array_equal(out["slip_class"][cols["mu"] != mu_max], slip[cols["mu"] != mu_max])


# ------------------------------------------------------------------ Coulomb and Brach


@pytest.mark.parametrize("which", ["realistic", "stress"])
def test_coulomb_newton_is_brach_at_min_of_friction_and_critical(which, request):
    """Where the slip does not reverse, Coulomb + Newton is Brach's model at
    mu = min(mu_f, mu_c) with friction opposing the initial slip: where the slip
    stops, Brach's critical solution (and |mu_c| <= mu_f); where it continues,
    Brach at mu = -sgn(gt) mu_f (and mu_f <= |mu_c| when mu_c opposes the slip; with
    eccentric arms mu_c can have the other sign, and the slip then never stops)."""
    c = request.getfixturevalue(which)
    out = laws.coulomb_batch(c, "newton")
    crit = _brach(c, c["e"], "critical")
    mu_c = crit["mu_c"]
    s0 = np.sign(_relative_motion(c, out)[0][1])
    ok = (out["status"] == 0) & (crit["status"] == 0)
    stops, cont = ok & (out["slip_class"] == STOPS), ok & (out["slip_class"] == CONTINUES)
    assert np.all(np.abs(mu_c[stops]) <= c["mu_f"][stops] * (1 + 1e-12))
    opposing = cont & (np.sign(mu_c) == -s0)
    assert np.all(c["mu_f"][opposing] <= np.abs(mu_c[opposing]) * (1 + 1e-12))
    assert np.sum(cont & ~opposing) > 0  # mu_c along the slip: such rows exist
    mu = np.where(out["slip_class"] == STOPS, mu_c, -s0 * c["mu_f"])
    brach = _brach(c, c["e"], mu)
    rows = (out["status"] == 0) & (brach["status"] == 0) & (out["slip_class"] != REVERSES)
    assert rows.sum() > 0.9 * len(rows)
    _same_finals(out, brach, c, rows)
    # and where it reverses, Brach at min(mu_f, mu_c) is not the Coulomb answer
    rev = (out["status"] == 0) & (out["slip_class"] == REVERSES)
    if which == "stress":
        assert rev.sum() > 20
        assert np.any(np.abs(out["Pt"] - brach["Pt"])[rev] > 1e-6 * np.hypot(out["Pn"], out["Pt"])[rev])


@pytest.mark.parametrize("which", ["realistic", "stress"])
def test_the_three_laws_coincide_when_slip_continues(which, request):
    c = request.getfixturevalue(which)
    outs = {law: laws.coulomb_batch(c, law) for law in LAWS}
    gt0 = _relative_motion(c, outs["newton"])[0][1]
    rows = (outs["newton"]["status"] == 0) & (outs["newton"]["slip_class"] == CONTINUES) & (gt0 != 0)
    assert rows.sum() > 100
    for law in ("poisson", "energetic"):
        assert np.array_equal(outs[law]["slip_class"][rows], outs["newton"]["slip_class"][rows])
        _same_finals(outs[law], outs["newton"], c, rows)


def test_the_three_laws_coincide_when_w_tn_is_zero(realistic):
    """Lever arms along the normal (or none): W_tn = 0, one slope of gn, one answer."""
    c = dict(realistic)
    n = np.cos(c["gamma"]), np.sin(c["gamma"])
    for i in (1, 2):
        length = c[f"r{i}x"] * n[0] + c[f"r{i}y"] * n[1]
        c[f"r{i}x"], c[f"r{i}y"] = length * n[0], length * n[1]
    outs = {law: laws.coulomb_batch(c, law) for law in LAWS}
    rows = outs["newton"]["status"] == 0
    assert np.all(outs["newton"]["slip_class"][rows] != REVERSES)
    for law in ("poisson", "energetic"):
        _same_finals(outs[law], outs["newton"], c, rows)


def test_energetic_restitution_never_creates_energy():
    """T_L >= 0 (and every part) under the energetic law over 120,000 stress scenes,
    among them thousands whose slip reverses; Newton creates energy on some of them."""
    c = L.stress(130_000, 2025)
    n = len(c["e"])
    assert n >= 100_000
    counts = {}
    for law in LAWS:
        out = laws.coulomb_batch(c, law)
        ok = out["status"] == 0
        scale = np.abs(out["Pn"] * _relative_motion(c, out)[0][0]) + np.abs(
            out["Pt"] * _relative_motion(c, out)[0][1]
        )
        counts[law] = (int((out["TL"][ok] < -1e-13 * scale[ok]).sum()), int((out["flags"][ok] & 1 > 0).sum()))
        if law == "energetic":
            reversals = int((out["slip_class"][ok] == REVERSES).sum())
            assert ok.sum() > 0.99 * n
            assert reversals > 1000
            assert counts[law] == (0, 0)
    assert counts["newton"][0] > 0  # Kane–Levinson: Newton + reversal creates energy
    print(f"\nscenes {n}, reversals {reversals}; (TL < 0, flag 1) per law: {counts}")


def test_slip_classes_agree_with_the_final_slip(stress):
    out = laws.coulomb_batch(stress, "energetic")
    (gn, gt), (Gn, Gt) = _relative_motion(stress, out)
    ok = out["status"] == 0
    scale = 1e-9 * np.maximum(_speed(stress), 1.0)
    cls = out["slip_class"]
    assert np.all((np.abs(Gt) <= scale * 1e3)[ok & (cls == STOPS)])
    cont = ok & (cls == CONTINUES) & (gt != 0) & (np.abs(Gt) > scale)
    assert np.all(np.sign(Gt[cont]) == np.sign(gt[cont]))
    rev = ok & (cls == REVERSES) & (np.abs(Gt) > scale)
    assert rev.sum() > 20 and np.all(np.sign(Gt[rev]) == -np.sign(gt[rev]))


# ------------------------------------------------------------------ Kudlich–Slibar


def _compliance(c):
    """W in (n, t) from the arms (c1, c2, c3 of the paper), per row."""
    n = np.cos(c["gamma"]), np.sin(c["gamma"])
    k = 1 / c["m1"] + 1 / c["m2"]
    j = 1 / c["I1"], 1 / c["I2"]
    rn = [c[f"r{i}x"] * n[0] + c[f"r{i}y"] * n[1] for i in (1, 2)]
    rt = [c[f"r{i}y"] * n[0] - c[f"r{i}x"] * n[1] for i in (1, 2)]
    c1 = k + j[0] * rn[0] ** 2 + j[1] * rn[1] ** 2
    c2 = k + j[0] * rt[0] ** 2 + j[1] * rt[1] ** 2
    c3 = j[0] * rn[0] * rt[0] + j[1] * rn[1] * rt[1]
    return c2, -c3, c1


def test_ks_full_impact_identities(realistic):
    """Final relative velocity -eps times the initial in both components; energy
    loss (1 - eps^2)/2 g^T W^-1 g; the same impulse as Brach at e = eps and mu =
    Brach's critical ratio at e = 0 (not at e = eps)."""
    c = realistic
    out = laws.kudlich_slibar_batch(c, "full")
    ok = out["status"] == 0
    (gn, gt), (Gn, Gt) = _relative_motion(c, out)
    speed = _speed(c)
    assert np.all(np.abs(Gn + c["e"] * gn)[ok] <= 1e-11 * speed[ok])
    assert np.all(np.abs(Gt + c["e"] * gt)[ok] <= 1e-11 * speed[ok])
    wnn, wnt, wtt = _compliance(c)
    det = wnn * wtt - wnt**2
    quad = (wtt * gn * gn - 2 * wnt * gn * gt + wnn * gt * gt) / det
    tl = 0.5 * (1 - c["e"] ** 2) * quad
    np.testing.assert_allclose(out["TL"][ok], tl[ok], rtol=1e-10)
    crit0 = _brach(c, 0.0, "critical")
    brach = _brach(c, c["e"], crit0["mu_c"])
    _same_finals(out, brach, c, ok & (brach["status"] == 0))
    crit_e = _brach(c, c["e"], "critical")
    differs = ok & (c["e"] > 0.05)
    assert np.all(np.abs(out["mu"] - crit_e["mu_c"])[differs] > 1e-6 * np.abs(crit_e["mu_c"][differs]))


def test_ks_sliding_contact(realistic):
    """Where the full impact needs |Pt| > mu |Pn|: |Pt| = mu |Pn|, Pt of the sign of the
    initial slip, final normal velocity -eps gn, and Brach's answer at mu = -mu_f sgn(gt);
    elsewhere the full impact."""
    c = realistic
    full = laws.kudlich_slibar_batch(c, "full")
    out = laws.kudlich_slibar_batch(c, "sliding")
    ok = out["status"] == 0
    slide = ok & (out["sliding"] == 1)
    assert 100 < slide.sum() < ok.sum()
    assert np.array_equal(slide, ok & (np.abs(full["Pt"]) > -c["mu_f"] * full["Pn"]))
    (gn, gt), (Gn, _) = _relative_motion(c, out)
    P = np.hypot(out["Pn"], out["Pt"])
    assert np.all(np.abs(np.abs(out["Pt"]) - c["mu_f"] * np.abs(out["Pn"]))[slide] <= 1e-12 * P[slide])
    moving = slide & (gt != 0) & (c["mu_f"] > 0)
    assert np.all(np.sign(out["Pt"][moving]) == np.sign(gt[moving]))
    assert np.all(np.abs(Gn + c["e"] * gn)[slide] <= 1e-11 * _speed(c)[slide])
    brach = _brach(c, c["e"], -c["mu_f"] * np.sign(gt))
    _same_finals(out, brach, c, slide & (brach["status"] == 0))
    _same_finals(out, full, c, ok & ~slide, tol=0.0)


def test_ks_sliding_compression_always_ends(stress):
    """The guard of status 13 (NO_END_OF_COMPRESSION) never fires on an approaching
    scene: where the full impact needs |Pt| > mu|Pn|, Knn + mu_s Knt > 0 (with
    s = sgn gt > 0, gn = -1: sliding needs Knn gt + Knt > mu (Ktt + Knt gt), and
    mu >= Knn/Knt would make the right side exceed Knn gt + Knn Ktt/Knt > Knn gt + Knt).
    Checked on the stress set with friction up to 50."""
    for mu in (0.5, 5.0, 50.0):
        out = laws.kudlich_slibar_batch(dict(stress, mu_f=np.full(len(stress["e"]), mu)), "sliding")
        assert np.all(out["status"] == 0)
        assert np.any(out["sliding"] == 1)


def test_conversions_give_the_same_impulse(realistic):
    c = realistic
    for contact in ("full", "sliding"):
        pim = laws.ks_to_pim(c, contact)
        ok = pim["status"] == 0
        brach = _brach(c, pim["e"], pim["mu"])
        ks = laws.kudlich_slibar_batch(c, contact)
        _same_finals(brach, ks, c, ok & (brach["status"] == 0))
    # PIM -> K-S: Brach at a mu below the full ratio, dragging along the slip
    (gn, gt), _ = _relative_motion(c, ks)
    full = laws.kudlich_slibar_batch(c, "full")
    cols = {k: v for k, v in c.items() if k != "mu_f"}
    mu = 0.5 * full["mu"]
    back = laws.pim_to_ks(dict(cols, mu=mu, e_m=1.0))
    ok = back["status"] == 0
    agree = ok & (np.sign(-mu) == np.sign(gt))
    assert agree.sum() > 100 and np.all(back["exact"][agree])
    assert np.all(back["sliding"][agree] == 1)
    np.testing.assert_array_equal(back["eps"], c["e"])
    # and Brach at the full ratio is the full contact
    again = laws.pim_to_ks(dict(cols, mu=full["mu"], e_m=1.0))
    good = again["status"] == 0
    assert np.all(again["exact"][good]) and np.all(again["sliding"][good] == 0)


# ------------------------------------------------------------------ scenes and the CLI

SCENE = {
    "model": "coulomb",
    "units": "SI",
    "impact": {"normal_angle": 10.0, "restitution": 0.3, "friction": 0.8, "restitution_law": "energetic"},
    "vehicles": [
        {
            "name": "sedan",
            "mass": 1500.0,
            "yaw_inertia": 2500.0,
            "velocity": [20.0, 2.0],
            "yaw_rate": 0.0,
            "impact_point": [2.2, 0.6],
        },
        {
            "name": "suv",
            "mass": 2200.0,
            "yaw_inertia": 4200.0,
            "velocity": [-5.0, 8.0],
            "yaw_rate": 0.1,
            "impact_point": [-0.4, -1.0],
        },
    ],
}


def test_solve_a_coulomb_scene_matches_the_batch():
    result = impactsym.solve(SCENE)
    data = result.to_json_dict()
    assert data["model"] == "coulomb" and data["restitution_law"] == "energetic"
    assert data["slip"] in ("continues", "stops", "reverses")
    assert data["impulse"]["moment"] == 0.0 and data["energy_loss"]["moment"] == 0.0
    t = data["energy_loss"]
    assert abs(t["normal"] + t["tangential"] - t["total"]) <= 1e-12 * abs(t["total"])
    from impactsym.laws.scene import load_law_scene

    law_scene = load_law_scene(SCENE)
    cols = {k: np.array([v]) for k, v in law_scene.inputs().items()}
    out = laws.coulomb_batch(cols, "energetic")
    assert out["Pn"][0] == result.Pn and out["TL"][0] == result.TL
    assert "coulomb model (energetic, friction 0.8)" in result.table()


def test_solve_a_ks_scene_and_not_used_keys():
    scene = dict(SCENE, model="kudlich_slibar")
    scene["impact"] = {
        "normal_angle": 10.0,
        "restitution": 0.3,
        "contact": "sliding",
        "friction": 0.2,
        "moment_restitution": 0.5,
    }
    data = impactsym.solve(scene).to_json_dict()
    assert data["contact"] == "sliding" and data["contact_used"] in ("full", "sliding")
    assert any("moment_restitution" in w and "not used" in w for w in data["warnings"])


@pytest.mark.parametrize(
    "impact, field",
    [
        ({"normal_angle": 0.0, "restitution": 0.3, "friction": -0.1}, "impact.friction"),
        ({"normal_angle": 0.0, "restitution": 0.3}, "impact.friction"),
        (
            {"normal_angle": 0.0, "restitution": 0.3, "friction": 0.5, "restitution_law": "kane"},
            "impact.restitution_law",
        ),
        ({"normal_angle": 0.0, "restitution": 0.3, "friction": 0.5, "contact": "full"}, "impact.contact"),
    ],
)
def test_bad_law_scenes_name_the_field(impact, field):
    with pytest.raises(impactsym.SceneError) as err:
        impactsym.solve(dict(SCENE, impact=impact))
    assert str(err.value).startswith(field) and "\n" not in str(err.value)


def test_cli_solve_json_and_bad_scene(tmp_path):
    import json
    import os
    import subprocess
    import sys

    good, bad = tmp_path / "good.json", tmp_path / "bad.json"
    good.write_text(json.dumps(SCENE))
    bad.write_text(json.dumps(dict(SCENE, impact=dict(SCENE["impact"], friction="lots"))))
    env = dict(os.environ)
    run = [sys.executable, "-m", "impactsym", "solve"]
    proc = subprocess.run(run + [str(good), "--json"], capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert data["slip"] in ("continues", "stops", "reverses")
    proc = subprocess.run(run + [str(bad), "--json"], capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 2 and "impact.friction" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_compare_a_law_scene_reads_it_in_brachs_terms():
    """A K–S scene in compare: a row per law its data allow, and the seed's models at
    e = eps and mu = the K–S ratio, so the brach row is the K–S impulse."""
    scene = dict(SCENE, model="kudlich_slibar")
    scene["impact"] = {"normal_angle": 10.0, "restitution": 0.3, "contact": "full", "friction": 0.5}
    with pytest.raises(impactsym.SceneError, match="impact.friction"):
        impactsym.solve(scene)  # a full contact takes no friction
    scene["impact"]["contact"] = "sliding"
    rows = {row["model"]: row for row in impactsym.compare(scene).to_json_dict()["models"]}
    assert {
        "brach",
        "kudlich_slibar (full)",
        "kudlich_slibar (sliding)",
        "coulomb (newton)",
        "coulomb (poisson)",
        "coulomb (energetic)",
    } <= set(rows)
    own = rows["kudlich_slibar (sliding)"]
    assert rows["brach"]["impulse_ratio"] == own["impulse_ratio"]
    for a, b in zip(rows["brach"]["vehicles"], own["vehicles"]):
        assert a["velocity"] == pytest.approx(b["velocity"], rel=1e-12, abs=1e-12)
    assert rows["brach"]["energy_loss"]["total"] == pytest.approx(own["energy_loss"]["total"], rel=1e-12)
    assert own["energy_loss"]["moment"] is None


def test_solve_batch_sweep_and_sample_take_the_laws(realistic):
    """impactsym.solve_batch(model="coulomb:energetic") is the laws' batch; sweep and
    sample of a law scene vary its inputs (mu_f, restitution) through it."""
    c = {k: v[:200] for k, v in realistic.items()}
    out = impactsym.solve_batch(c, model="coulomb:energetic")
    own = laws.coulomb_batch(c, "energetic")
    assert out["status"].dtype == np.int32 and np.array_equal(out["slip_class"], own["slip_class"])
    assert np.array_equal(out["TL"], own["TL"])
    assert "V1x" in impactsym.solve_batch(c, model="kudlich_slibar:sliding", outputs="velocities")
    with pytest.raises(ValueError, match="unknown law"):
        impactsym.solve_batch(c, model="coulomb:kane")
    frame = impactsym.sweep(SCENE, mu_f=[0.0, 0.5], restitution=[0.1, 0.4])
    assert len(frame) == 4 and (frame["status"] == 0).all() and "slip_class" in frame
    assert (frame["TLt"][frame["mu_f"] == 0.0] == 0.0).all()
    single = impactsym.solve(dict(SCENE, impact=dict(SCENE["impact"], friction=0.5, restitution=0.4)))
    row = frame[(frame["mu_f"] == 0.5) & (frame["restitution"] == 0.4)].iloc[0]
    assert row["TL"] == single.TL
    by_name = impactsym.sweep(SCENE, friction=[0.0, 0.5], restitution=0.4)  # scene-file name
    assert list(by_name["TL"]) == list(frame["TL"][frame["restitution"] == 0.4])
    drawn = impactsym.sample(SCENE, {"mu_f": ("uniform", 0.0, 1.5)}, 300, seed=3)
    assert (drawn["status"] == 0).all() and set(drawn["slip_class"]) <= {0, 1, 2}


def test_uncertainty_of_a_law_scene():
    """--uncertainty propagates a law scene's distributions through the law's batch
    (Monte Carlo) and its Jacobian kernel (sd_linear and budget: tests/test_laws_jacobian.py)."""
    from impactsym.uncertainty import uncertainty

    scene = {
        "model": "coulomb",
        "units": "SI",
        "impact": {
            "normal_angle": {"normal": [10.0, 2.0]},
            "restitution": {"uniform": [0.2, 0.4]},
            "friction": 0.8,
            "restitution_law": "energetic",
        },
        "vehicles": SCENE["vehicles"],
    }
    u = uncertainty(scene, draws=500, seed=4).to_json_dict()
    assert u["accepted"] == 500 and set(u["inputs"]) == {"impact.normal_angle", "impact.restitution"}
    total = u["outputs"]["energy_loss.total"]
    nominal = impactsym.solve(scene).TL
    assert total["nominal"] == nominal and total["p5"] < nominal < total["p95"]
    assert total["sd_linear"] > 0 and abs(sum(total["budget"].values()) - 1) < 1e-12


def test_cli_compare_and_sweep_take_a_law_scene():
    import json
    import subprocess
    import sys
    from pathlib import Path

    scene = str(Path(__file__).resolve().parents[1] / "examples" / "corner_barrier_coulomb.json")
    run = [sys.executable, "-m", "impactsym"]
    proc = subprocess.run(run + ["compare", scene, "--json"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    models = [row["model"] for row in json.loads(proc.stdout)["models"]]
    assert "coulomb (energetic)" in models and "brach" in models
    proc = subprocess.run(
        run + ["sweep", scene, "--vary", "mu_f=0,0.4,0.8", "--no-progress"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0 and "rows 3: solved 3" in proc.stdout, proc.stdout + proc.stderr


def test_pim_to_ks_says_when_there_is_no_ks_equivalent(realistic):
    """Brach's mu along the slip (the wrong sign for K-S's friction) has no K-S
    equivalent unless it is the full impact's ratio: exact is false there."""
    c = {k: v for k, v in realistic.items() if k != "mu_f"}
    full = laws.kudlich_slibar_batch(c, "full")
    (gn, gt), _ = _relative_motion(realistic, full)
    mu = 0.5 * np.sign(gt) * np.abs(full["mu"])  # drags vehicle 1 against the slip
    back = laws.pim_to_ks(dict(c, mu=mu, e_m=1.0))
    rows = (back["status"] == 0) & (np.abs(full["mu"]) > 1e-3)
    assert rows.sum() > 100 and not back["exact"][rows].any()


def test_plot_of_a_law_scene_names_the_law(tmp_path):
    pytest.importorskip("matplotlib")
    from impactsym.pictures.diagram import _title
    from impactsym.plot import save_plot

    result = impactsym.solve(SCENE)
    out = save_plot(result, tmp_path / "law.png", scene=SCENE)
    assert out.exists() and out.stat().st_size > 10_000
    from impactsym.laws.scene import load_law_scene

    title = _title(load_law_scene(SCENE).scene, result)
    assert "coulomb (energetic, friction 0.8)" in title and "rigid" not in title


def test_friction_may_be_uncertain():
    """impact.friction is a leaf like any other: a distribution is drawn, and a
    draw below 0 is rejected with its reason."""
    from impactsym.uncertainty import uncertainty

    scene = dict(SCENE, impact=dict(SCENE["impact"], friction={"normal": [0.5, 0.3]}))
    nominal = impactsym.solve(scene)
    assert nominal.friction == 0.5
    u = uncertainty(scene, draws=2000, seed=5).to_json_dict()
    assert u["inputs"] == ["impact.friction"]
    assert 0 < sum(u["rejected"].values()) < 200 and u["accepted"] + sum(u["rejected"].values()) == 2000
    assert any("impact.friction" in reason for reason in u["rejected"])
    both = dict(scene, impact=dict(scene["impact"], restitution={"uniform": [0.2, 0.4]}))
    u = uncertainty(both, draws=500, seed=6).to_json_dict()
    assert set(u["inputs"]) == {"impact.friction", "impact.restitution"}
    with pytest.raises(impactsym.SceneError, match="impact.friction"):
        impactsym.solve(dict(SCENE, impact=dict(SCENE["impact"], friction="0.5 m")))
