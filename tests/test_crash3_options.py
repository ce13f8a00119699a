"""CRASH3 as practitioners run it: stiffness categories, Woolley's correction, the
EDCRASH cap, absorbed vs dissipated crush energy, the effective-mass delta-V,
scenes without an impact block, crush-only compare, and one-line errors (API and CLI).

Expected values come from outside the kernels: the published table (read here
with the csv module from impactsym/data/, the one copy the runtime reads),
trigonometry at known angles, and the 1-D impact algebra written out by hand.
"""

import copy
import csv
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

import impactsym
from impactsym.cli import main
from impactsym.crash3.tables import class_dimensions, stiffness
from impactsym.scene import SceneError

ROOT = Path(__file__).resolve().parents[1]
BARRIER = json.loads((ROOT / "examples" / "crash3_barrier_si.json").read_text())
TWO_CAR = json.loads((ROOT / "examples" / "crash3_two_car_us.json").read_text())
CATEGORIES = ROOT / "examples" / "crash3_categories_us.json"
LBF, INCH = 4.4482216152605, 0.0254


def barrier(pdof=0.0, **crush):
    data = copy.deepcopy(BARRIER)
    data["vehicles"][0]["crush"].update(pdof=pdof, **crush)
    return data


def published_rows():
    with open(ROOT / "impactsym" / "data" / "crash3_stiffness_categories.csv", newline="") as handle:
        return list(csv.DictReader(handle))


@pytest.mark.parametrize("row", published_rows(), ids=lambda r: f"{r['category']}-{r['face']}")
def test_category_lookup_equals_the_published_table(row):
    got = stiffness(int(row["category"]), row["face"])
    assert (float(row["A_lb_per_in"]), float(row["B_lb_per_in2"])) == (got.A, got.B)
    si = stiffness(int(row["category"]), row["face"], "SI")
    assert pytest.approx(got.A * LBF / INCH, rel=1e-15) == si.A
    assert pytest.approx(got.B * LBF / INCH**2, rel=1e-15) == si.B


def test_category_misprints_and_gaps():
    assert stiffness(1, "front").A == 302.0  # printed "J02"
    assert stiffness(6, "side") == stiffness(5, "side").__class__(6, "side", 177.0, 47.0)
    for category, face in ((7, "side"), (8, "side"), (9, "rear"), (9, "side")):
        with pytest.raises(ValueError, match=f"category {category} has no {face} stiffness"):
            stiffness(category, face)
    assert class_dimensions(3)["k_squared_in2"] == 3324.0
    with pytest.raises(ValueError, match="class must be one of"):
        class_dimensions(8)


def test_category_in_a_scene_equals_explicit_a_b():
    """A crush table naming category 3 front gives the same result as the same
    A, B typed in (SI scene: the table converted to N/m, N/m²)."""
    by_category = barrier(category=3, face="front")
    for key in ("A", "B"):
        del by_category["vehicles"][0]["crush"][key]
    explicit = barrier(A=317 * LBF / INCH, B=56 * LBF / INCH**2)
    a, b = impactsym.crash3(by_category), impactsym.crash3(explicit)
    assert a.energy_total == pytest.approx(b.energy_total, rel=1e-14)


def test_mixed_category_and_explicit_scene_and_class_k2():
    result = impactsym.crash3(CATEGORIES)
    data = json.loads(CATEGORIES.read_text())
    k = math.sqrt(3324.0) / 12.0  # class 3 k² [in²] in feet
    h = data["vehicles"][1]["crush"]["moment_arm"]
    assert result.vehicles[1].mass_factor == pytest.approx(k * k / (k * k + h * h), rel=1e-14)
    assert result.options.to_json_dict() == {
        "restitution": 0.1,
        "energy": "absorbed",
        "correction": "woolley",
    }


@pytest.mark.parametrize("alpha", [0.0, 15.0, 30.0, 44.9])
def test_woolley_and_crash3_corrections_at_known_angles(alpha):
    plain = impactsym.crash3(barrier()).energy_total
    crash = impactsym.crash3(barrier(alpha)).energy_total
    woolley = impactsym.crash3(barrier(alpha), correction="woolley").energy_total
    c = math.cos(math.radians(alpha))
    assert crash == pytest.approx(plain / c**2, rel=1e-13)
    assert woolley == pytest.approx(plain / c, rel=1e-13)
    # 30°: 1 + tan² = 4/3, 1/cos = 2/√3.
    if alpha == 30.0:
        assert crash / plain == pytest.approx(4 / 3, rel=1e-13)
        assert woolley / plain == pytest.approx(2 / math.sqrt(3), rel=1e-13)


@pytest.mark.parametrize("alpha", [50.0, -60.0, 89.0])
def test_edcrash_cap_at_45_degrees_with_a_warning(alpha):
    plain = impactsym.crash3(barrier()).energy_total
    crash = impactsym.crash3(barrier(alpha))
    woolley = impactsym.crash3(barrier(alpha), correction="woolley")
    assert crash.energy_total == pytest.approx(2 * plain, rel=1e-13)
    assert woolley.energy_total == pytest.approx(math.sqrt(2) * plain, rel=1e-13)
    assert any("capped at 45 degrees" in w and "vehicles[0].crush.pdof" in w for w in crash.warnings)
    assert not any("capped" in w for w in impactsym.crash3(barrier(45.0)).warnings)


@pytest.mark.parametrize("e", [0.0, 0.1, 0.3, 0.6])
def test_absorbed_and_dissipated_restitution(e):
    """Into a rigid barrier (γ = 1), E the crush energy: dissipated, E = m v²(1 - e²)/2
    and ΔV = v(1 + e); absorbed, E = m v²/2 and ΔV = (1 + e)·v."""
    m = BARRIER["vehicles"][0]["mass"]
    dissipated = impactsym.crash3(barrier(), restitution=e)
    absorbed = impactsym.crash3(barrier(), restitution=e, energy="absorbed")
    energy = dissipated.energy_total
    approach = math.sqrt(2 * energy / m)
    assert absorbed.vehicles[0].delta_v_magnitude == pytest.approx((1 + e) * approach, rel=1e-13)
    closing = math.sqrt(2 * energy / (m * (1 - e * e)))
    assert dissipated.vehicles[0].delta_v_magnitude == pytest.approx((1 + e) * closing, rel=1e-13)
    ratio = absorbed.vehicles[0].delta_v_magnitude / dissipated.vehicles[0].delta_v_magnitude
    assert ratio == pytest.approx(math.sqrt(1 - e * e), rel=1e-13)


def test_absorbed_allows_e_one_dissipated_does_not():
    assert impactsym.crash3(barrier(), restitution=1.0, energy="absorbed").vehicles[0].delta_v_magnitude > 0
    with pytest.raises(SceneError, match=r"^restitution: must be in \[0, 1\) when the crush energy"):
        impactsym.crash3(barrier(), restitution=1.0)


def test_effective_mass_delta_v_relation():
    """ΔV_cg = γ ΔV_eff, and ΔV_eff is Day's √(2E/(M1 (1 + M1/M2))) with M = γ m."""
    data = copy.deepcopy(TWO_CAR)
    for vehicle, h, k in zip(data["vehicles"], (1.5, 2.5), (4.0, 4.4)):
        vehicle["crush"].update(moment_arm=h, radius_of_gyration=k)
    result = impactsym.crash3(data)
    big_m = [v.mass_factor * d["mass"] for v, d in zip(result.vehicles, data["vehicles"])]
    day = math.sqrt(2 * result.energy_total / (big_m[0] * (1 + big_m[0] / big_m[1])))
    assert result.vehicles[0].delta_v_effective_mass == pytest.approx(day, rel=1e-13)
    for v in result.vehicles:
        assert v.delta_v_magnitude == pytest.approx(v.mass_factor * v.delta_v_effective_mass, rel=1e-14)
        assert v.mass_factor < 1.0


def test_scene_options_and_arguments_override_them():
    data = copy.deepcopy(BARRIER)
    data["crash3"] = {"restitution": 0.2, "energy": "absorbed", "correction": "woolley"}
    from_scene = impactsym.crash3(data)
    assert from_scene.options.to_json_dict() == data["crash3"]
    overridden = impactsym.crash3(data, restitution=0.0, energy="dissipated", correction="crash3")
    assert overridden.options.to_json_dict() == {
        "restitution": 0.0,
        "energy": "dissipated",
        "correction": "crash3",
    }
    assert overridden.energy_total == impactsym.crash3(BARRIER).energy_total


def test_no_impact_block_needed():
    data = copy.deepcopy(BARRIER)
    del data["impact"]
    result = impactsym.crash3(data)
    with_impact = impactsym.crash3(BARRIER)
    assert result.vehicles[0].delta_v is None
    assert result.vehicles[0].delta_v_magnitude == with_impact.vehicles[0].delta_v_magnitude
    data["vehicles"][0]["impact_point"] = [1.0, 0.2]
    with pytest.raises(SceneError, match=r"^impact.normal_angle: missing: the moment arm"):
        impactsym.crash3(data)


def test_compare_runs_a_crush_only_scene():
    comparison = impactsym.compare(CATEGORIES)
    assert [row.model for row in comparison.rows] == ["crash3"]
    assert set(comparison.skipped) == {
        "brach",
        "macmillan",
        "limpert",
        "impac",
        "impac_sideswipe",
        "particle",
    }
    assert all("(the pre-impact motion)" in reason for reason in comparison.skipped.values())
    crash = impactsym.crash3(CATEGORIES)
    assert [v.delta_v_magnitude for v in comparison.rows[0].vehicles] == [
        v.delta_v_magnitude for v in crash.vehicles
    ]
    assert comparison.initial_kinetic_energy is None
    assert "crash3" in comparison.table() and json.dumps(comparison.to_json_dict())


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"B": 0.0}, "vehicles[0].crush.B: must be > 0"),
        ({"category": 3, "face": "front"}, "vehicles[0].crush.category: give either A and B or category"),
        ({"pdof": 90.0}, "vehicles[0].crush.pdof: |pdof| = 90 must be < 90"),
        ({"widht": 1.5}, 'vehicles[0].crush.widht: unknown key; did you mean "width"?'),
    ],
)
def test_bad_crush_is_one_line_exit_2(change, field, tmp_path, capsys):
    data = barrier(**change)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    assert main(["crash3", str(path)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and field in err


def test_bad_category_face_and_option_names(tmp_path, capsys):
    data = copy.deepcopy(BARRIER)
    crush = data["vehicles"][0]["crush"]
    del crush["A"], crush["B"]
    crush.update(category=8, face="side")
    path = tmp_path / "pickup.json"
    path.write_text(json.dumps(data))
    assert main(["crash3", str(path)]) == 2
    assert "vehicles[0].crush.face: category 8 has no side stiffness" in capsys.readouterr().err
    data["crash3"] = {"energy": "lost"}
    crush["face"] = "front"
    path.write_text(json.dumps(data))
    assert main(["crash3", str(path)]) == 2
    assert "crash3.energy: must be one of dissipated, absorbed, got 'lost'" in capsys.readouterr().err
    assert main(["crash3", str(path), "--energy", "absorbed", "--correction", "cosine"]) == 2
    assert (
        capsys.readouterr().err.strip().endswith("correction: must be one of crash3, woolley, got 'cosine'")
    )


def test_cli_flags_in_a_subprocess():
    """The installed entry point with the three flags: JSON reflects them."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "impactsym",
            "crash3",
            str(CATEGORIES),
            "--json",
            "--restitution",
            "0.0",
            "--energy",
            "dissipated",
            "--correction",
            "crash3",
        ],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    result = json.loads(out.stdout)
    assert result["options"] == {"restitution": 0.0, "energy": "dissipated", "correction": "crash3"}
    assert "delta_v_effective_mass" in result["vehicles"][0]
    assert result["delta_v_reported"].startswith("centre of gravity")
