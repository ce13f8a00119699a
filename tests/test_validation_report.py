"""The validation report (impactsym.validation) against published crash data.

Tolerances were chosen BEFORE running the models on the data (written into this
file before the first run), with the reasoning beside each; where the data are
known inconsistent the test asserts that the report says so, never a tuned bound.
A bound here that the models miss is a finding to report, not to loosen.

- NHTSA 4364/4438/4474 (Rose et al. 2006): the same rigid model on the published
  inputs must reproduce the published PIM results. Energies are printed to the
  ft·lb and the inputs to 0.1 ft / 0.1° (README: a careful reproduction agrees to
  about 1 %): total energy loss within 2 %, its normal/tangential split within 5 %
  (the split moves with the impact-centre angle), delta-V within 3 %, final yaw
  rates (printed as unsigned integers, sensitive to d at 0.1 ft) within 15 %; the
  measured delta-V (within 0.5 % of the published PIM) within 5 %.
- IIHS barrier tests with Brach's fitted e, μ, d, φ, Γ: the fits reproduce their
  own tests, but every car is given the Fusion's k (inertia unknown): |ΔV| median
  5 %, worst 15 %; yaw-rate change (∝ 1/k² for a given impulse) median 15 %,
  worst 50 %; the source's own outlier CF11006 is excluded.
- RICSAC CRASH3: CRASH3's delta-V is known to scatter by tens of percent (the
  seed's Tables 6 and 8; Neades): with Neades' adjustments median |error| against
  the Brach & Smith measured delta-V within 25 %, with the published profiles within
  35 %; no worst-case bound (crush data of 1978 with known defects). Our
  published-profile run against Neades' raw CRASH delta-V (the same inputs, a
  different implementation): median within 15 %. Our crush energies against
  Woolley's 1985 CRASH3 energies (same profiles): median within 20 %.
- RICSAC rigid model with Brach's e and μ = μ_c and an approximated impact centre:
  delta-V median within 20 % of the measured (Brach & Smith), energy loss median
  within 25 % of Brach's PIM loss.
- IIHS vehicle-to-vehicle tests (9 tests, 18 vehicles) with Brach's fitted e, μ, φ,
  Γ but an APPROXIMATED CG-to-impact distance d (Brach's barrier d1 of the same
  model) and ASSUMED equal masses (the Fusion's) and k (the Fusion's). Written
  before the V2V code existed: with the right d the same fits give the barrier
  |ΔV| to a median 1 %, worst 7.5 %; two cars of unknown masses (midsize sedans,
  plausibly within ±10 % of each other) move ΔV_a ∝ m_b/(m_a + m_b) by up to ~5 %,
  and d off by ±0.5 ft moves the effective mass by a few percent more, so |ΔV|
  median 10 %, worst 25 % over all 18 vehicles; per kind, sideswipe (12) median
  10 %, non-sideswipe (6) median 15 % (two of them are 15° oblique tests whose
  relative heading is a further assumption). The yaw-rate change goes as
  d·P/(k²m): with the exact d the barrier median is 2 %, worst 26 %; d off by
  ±10 % moves it 10–20 % and the mass and k assumptions add to that, so median
  30 %, worst 75 % over all 18; per kind median 30 % (sideswipe) and 40 %
  (non-sideswipe).
"""

import math

import pytest

from impactsym import validation
from impactsym.validation import iihs

V2V = "rigid PIM (Brach's fits, approx. d, equal masses)"
BOUNDS = {
    # (dataset, model, quantity, reference): (median bound %, worst bound % or None)
    ("nhtsa", "rigid PIM", "energy loss", "published PIM"): (2.0, 2.0),
    ("nhtsa", "rigid PIM", "normal energy loss", "published PIM"): (5.0, 5.0),
    ("nhtsa", "rigid PIM", "tangential energy loss", "published PIM"): (5.0, 5.0),
    ("nhtsa", "rigid PIM", "delta-V", "published PIM"): (3.0, 3.0),
    ("nhtsa", "rigid PIM", "final yaw rate", "published PIM"): (15.0, 15.0),
    ("nhtsa", "rigid PIM", "delta-V", "measured"): (5.0, 5.0),
    ("iihs", "rigid PIM (Brach's fits)", "delta-V", "measured"): (5.0, 15.0),
    ("iihs", "rigid PIM (Brach's fits)", "yaw-rate change", "measured"): (15.0, 50.0),
    ("ricsac", "CRASH3 (Neades' adjustments)", "delta-V", "measured, Brach & Smith 2002"): (25.0, None),
    ("ricsac", "CRASH3 (published profiles)", "delta-V", "measured, Brach & Smith 2002"): (35.0, None),
    ("ricsac", "CRASH3 (published profiles)", "delta-V", "Neades' raw CRASH"): (15.0, None),
    ("ricsac", "CRASH3 (published profiles)", "energy loss", "Woolley's CRASH3 (1985)"): (20.0, None),
    ("ricsac", "rigid PIM (approx. impact centre)", "delta-V", "measured, Brach & Smith 2002"): (20.0, None),
    ("ricsac", "rigid PIM (approx. impact centre)", "energy loss", "Brach's PIM (SAE 871993)"): (25.0, None),
    ("iihs_v2v", V2V, "delta-V", "measured"): (10.0, 25.0),
    ("iihs_v2v", V2V, "delta-V", "measured, sideswipe"): (10.0, None),
    ("iihs_v2v", V2V, "delta-V", "measured, non-sideswipe"): (15.0, None),
    ("iihs_v2v", V2V, "yaw-rate change", "measured"): (30.0, 75.0),
    ("iihs_v2v", V2V, "yaw-rate change", "measured, sideswipe"): (30.0, None),
    ("iihs_v2v", V2V, "yaw-rate change", "measured, non-sideswipe"): (40.0, None),
}


@pytest.fixture(scope="module")
def datasets():
    return {ds.name: ds for ds in validation.report()}


def comparison(datasets, key):
    dataset, model, quantity, reference = key
    found = [
        c
        for c in datasets[dataset].comparisons
        if (c.model, c.quantity, c.reference) == (model, quantity, reference)
    ]
    assert len(found) == 1, key
    return found[0]


# Bounds chosen before looking that the first run MISSED: kept as chosen, run as
# strict xfails (the test fails if the miss ever disappears), and reported in
# docs/validation.md. Keyed by (comparison, "median" | "worst").
# 1. Our crush energies reproduce Woolley's 1985 CRASH3 energies within 1-4 % in
# the five tests with small PDOFs (3, 4, 5, 11, 12) but exceed them by 33-207 % in
# the oblique and side tests: Woolley's side inputs differ from the category
# defaults Neades published (even uncorrected, test 1 gives 67 000 ft·lb against
# his 48 392), and the capped correction doubles the side energies.
# 2. IIHS V2V yaw-rate change (first run; the median bounds of all 18 vehicles and
# of the 12 sideswipe vehicles held: 20.6 % and 19.2 %): the two 15° oblique tests
# CF10012 and CF10013 come out with the yaw of the two cars swapped (e.g. CF10013:
# 5.9 and 235 deg/s against the measured 205 and 73) under the geometry decided
# before the run (b's heading 195°, converging, Γ in a's frame). The opposite sense
# (165°) gives a median 25 % on those four vehicles (report table "oblique
# readings"), so the oblique geometry was most likely the other one; it is NOT
# switched after looking: the decided reading stays the one reported and tested.
MISSED = {
    (
        ("ricsac", "CRASH3 (published profiles)", "energy loss", "Woolley's CRASH3 (1985)"),
        "median",
    ): "first run: median 32.5 %, worst 207 % (bound 20 %): Woolley's 1985 side-impact "
    "inputs differ from the published defaults",
    (
        ("iihs_v2v", V2V, "yaw-rate change", "measured"),
        "worst",
    ): "first run: worst 220 % (bound 75 %), CF10013b: the oblique tests' yaws come out swapped "
    "between the cars under the a-priori oblique geometry (195 deg, converging)",
    (
        ("iihs_v2v", V2V, "yaw-rate change", "measured, non-sideswipe"),
        "median",
    ): "first run: median 71.8 % (bound 40 %): the two oblique tests (4 of the 6 vehicles), as above",
}


def _cases():
    cases = []
    for key in sorted(BOUNDS):
        for which, bound in zip(("median", "worst"), BOUNDS[key]):
            if bound is None:
                continue
            case = (key, which)
            reason = MISSED.get(case)
            cases.append(
                pytest.param(case, marks=pytest.mark.xfail(strict=True, reason=reason)) if reason else case
            )
    return cases


@pytest.mark.parametrize("case", _cases(), ids=lambda c: " | ".join(c[0]) + " | " + c[1])
def test_errors_within_the_bounds_chosen_before_looking(datasets, case):
    key, which = case
    stats = comparison(datasets, key).stats()
    bound = BOUNDS[key][which == "worst"]
    assert stats["n"] > 0
    assert stats[which] <= bound, stats


def test_every_row_is_run(datasets):
    ricsac = datasets["ricsac"]
    assert len(ricsac.tables["crash3 published"]) == 24
    assert len(ricsac.tables["energy"]) == 11  # test 2 has no energies
    assert len(ricsac.tables["pim"]) == 11  # Vossou has no test 2
    assert len(datasets["iihs"].tables["barrier"]) == 41
    assert len(datasets["nhtsa"].tables["nhtsa"]) == 6
    assert len(datasets["iihs_v2v"].tables["v2v"]) == 18
    measured = comparison(
        datasets, ("ricsac", "CRASH3 (Neades' adjustments)", "delta-V", "measured, Brach & Smith 2002")
    )
    assert len(measured.rows) == 22  # 11 tests with accelerometers


def test_side_impacts_beyond_45_degrees_are_capped(datasets):
    """The struck cars of the 60° tests have PDOF 30° on a side face: α = -60°,
    beyond EDCRASH's cap in the published data; Neades' adjusted PDOFs are not."""
    published = {r["vehicle"]: r for r in datasets["ricsac"].tables["crash3 published"]}
    adjusted = {r["vehicle"]: r for r in datasets["ricsac"].tables["crash3 neades"]}
    for key in ("1.2", "2.2", "6.2", "7.2"):
        assert published[key]["alpha"] == -60.0 and published[key]["capped"]
        assert not adjusted[key]["capped"]


def test_crush_energy_above_the_initial_kinetic_energy_is_flagged(datasets):
    """Physically impossible results are flagged, never silently returned."""
    energy = datasets["ricsac"].tables["energy"]
    flagged = {r["test"] for r in energy if r["impossible"]}
    assert flagged == {
        r["test"] for r in energy if max(r["published"], r["published, woolley"], r["neades"]) > r["initial"]
    }
    notes = [n for n in datasets["ricsac"].notes if n.startswith("PHYSICALLY IMPOSSIBLE")]
    assert len(notes) == len(flagged)


def test_cg_and_effective_mass_delta_v(datasets):
    for row in datasets["ricsac"].tables["crash3 neades"]:
        assert row["dv"] == pytest.approx(row["gamma"] * row["dv_eff"], rel=1e-12)
    for row in datasets["ricsac"].tables["crash3 neades, gamma = 1"]:
        assert row["gamma"] == 1.0 and row["dv"] == row["dv_eff"]


def test_the_report_says_the_separation_velocities_are_inconsistent(datasets):
    momentum = datasets["ricsac"].tables["momentum"]
    worst = max(abs(r["x_pct"]) for r in momentum)
    assert worst > 10.0  # README: up to ~22 % in x
    assert any("do not conserve momentum" in note for note in datasets["ricsac"].notes)


def test_statistics_are_of_the_rows():
    c = validation.Comparison("d", "m", "q", "r", (("a", 11.0, 10.0), ("b", 8.0, 10.0), ("c", 10.5, 10.0)))
    assert c.errors == pytest.approx([10.0, -20.0, 5.0])
    assert c.stats() == {
        "n": 3,
        "median": pytest.approx(10.0),
        "worst": pytest.approx(20.0),
        "bias": pytest.approx(5.0),
    }
    assert math.isnan(validation.stats([])["median"])


def test_cli_validate(capsys, tmp_path):
    from impactsym.cli import main

    assert main(["validate"]) == 0
    out = capsys.readouterr().out
    assert all(name in out for name in ("ricsac", "iihs", "nhtsa"))
    assert main(["validate", "--markdown", "--plots", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "| model | quantity | reference |" in out and "PHYSICALLY IMPOSSIBLE" in out
    assert {p.name for p in tmp_path.glob("*.png")} == {
        "ricsac.png",
        "ricsac_runout.png",
        "ricsac_runout_plan.png",
        "iihs.png",
        "iihs_v2v.png",
        "nhtsa.png",
    }
    # each dataset's section links its own figure (the run-out's plan view has none)
    for title, name in (("IIHS small-overlap barrier", "iihs"), ("NHTSA car-to-SUV", "nhtsa")):
        (line,) = [ln for ln in out.splitlines() if ln.startswith(f"![{title}")]
        assert line.endswith(f"{name}.png)"), line


def test_v2v_conserves_momentum_and_is_physical(datasets):
    """Each V2V test: the two delta-V vectors are opposite and in the inverse ratio
    of the masses (linear momentum, exact), and no solution is flagged (μ ≤ μ_c and
    e ≥ 0 cannot create energy)."""
    rows = datasets["iihs_v2v"].tables["v2v"]
    for a, b in zip(rows[::2], rows[1::2]):
        assert a["test"] == b["test"]
        for axis in (0, 1):
            assert a["mass"] * a["delta_v"][axis] + b["mass"] * b["delta_v"][axis] == pytest.approx(
                0.0, abs=1e-9 * a["mass"] * a["dv"]
            )
    assert not [r["test"] for r in rows if r["flags"]]


def test_v2v_states_its_assumptions_and_sensitivity(datasets):
    """The approximated d, the masses and the inertia are stated per vehicle, and the
    sensitivity to d (barrier range), the mass ratio (±15 %) and k (±10 %) is reported."""
    ds = datasets["iihs_v2v"]
    for row in ds.tables["v2v"]:
        assert row["d_source"] and row["d"] > 0 and row["mass"] > 0 and row["yaw_inertia"] > 0
    assert "APPROXIMATED" in validation.ASSUMPTIONS["iihs_v2v"]
    cases = {r["case"] for r in ds.tables["sensitivity"]}
    assert {"d = barrier min", "d = barrier max", "m_b x 0.85", "m_b x 1.15", "k x 0.9", "k x 1.1"} <= cases
    # Momentum, from outside the solver: with m_b scaled by s and m_a fixed,
    # |dV_a| scales by exactly s (1 + 1)/(1 + s) relative to |dV_b|'s 2/(1 + s)
    # ratio: |dV_a|/|dV_b| = m_b/m_a.
    for row in ds.tables["sensitivity"]:
        if row["case"].startswith("m_b x"):
            assert row["ratio_a_to_b"] == pytest.approx(float(row["case"].split()[-1]), rel=1e-9)
    assert any("Sensitivity" in note for note in ds.notes)


def test_v2v_head_on_geometry_is_point_symmetric():
    """Truth from symmetry, not from the solver: two identical cars (the same row
    as a and b) head-on, each struck on its left front, are the same crash seen
    from either car, so their |delta-V| and yaw-rate changes must be equal and the
    yaw counter-clockwise (toward the struck side) for both."""
    a, _ = iihs.v2v_tests()["CF11009"]
    result = iihs.v2v_solve((a, a))
    one, two = result.vehicles
    assert one.delta_v_magnitude == pytest.approx(two.delta_v_magnitude, rel=1e-9)
    assert one.yaw_rate == pytest.approx(two.yaw_rate, rel=1e-9)
    assert one.yaw_rate > 0.0 and result.flags == 0
