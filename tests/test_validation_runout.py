"""The run-out against the RICSAC rest positions Day published (SAE 2004-01-1207,
Table 7: RICSAC 2, 3, 6, 10 as his VC-7, VC-3, VC-8, VC-11).

Tolerances were written and COMMITTED BEFORE the comparison ran for the first
time (the commit says so); a bound the model misses is a strict xfail carrying
the finding, never a loosened bound.

Inputs are read, not measured at separation: the separation pose is SIMON's pose
at the end of the collision pulse read from Day's Figures 9-12; the separation
velocity is Vossou & Koulocheris' measured post-impact velocity (contaminated:
momentum off by up to 17 % in tests 1-10, README); the wheels are ASSUMED all
rolling (Day: "moved freely ... no driver steering, braking or throttle"), μ =
skid number / 100 = 0.87, the contract's α_max = 10° and f_r = 0.01; wheelbase and
CG position ASSUMED from nominal manufacturer data. With that many assumptions:

- (a) forward run-out from the measured separation velocity: rest position within
  25 % of the measured run-out distance (separation to rest, straight line) and
  rest heading within 30° (wrapped), per vehicle with a free run-out (VC-11's
  Torino struck a transformer box: shown, not judged). EDSMAC4 and SIMON, with
  inputs their authors chose, miss the free run-outs by up to ~6 ft and ~21° (Table 7).
- (b) fit to the measured rest pose: the fit converges to within 0.1 ft and 0.5°;
  the fitted separation speed within 25 % of the measured speed and the direction
  of the fitted separation velocity within 20° of the measured direction.
"""

import math

import pytest

from impactsym.validation import runout as ro

FORWARD_POSITION_FRACTION = 0.25  # of the measured run-out distance
FORWARD_HEADING_DEG = 30.0
FIT_POSITION_FT = 0.1
FIT_HEADING_DEG = 0.5
FIT_SPEED_PCT = 25.0
FIT_DIRECTION_DEG = 20.0

FORWARD_CASES = ["VC-3.1", "VC-3.2", "VC-8.1", "VC-8.2", "VC-11.1"]
FIT_MEASURED = ["VC-3.1", "VC-3.2", "VC-8.1", "VC-8.2", "VC-11.1"]
FIT_ALL = ["VC-3.1", "VC-3.2", "VC-7.1", "VC-7.2", "VC-8.1", "VC-8.2", "VC-11.1"]
# Findings of the first run (bounds above unchanged). With every wheel rolling at the
# contract's f_r = 0.01 a car at the measured separation speed rolls 4-9 times the
# measured distance: the straight roll to the measured rest needs a drag of 0.05-0.10 g
# (column drag_needed); the cars rolled in gear with crushed fronts, which the
# assumed wheel states leave out. The fit then reaches the rest pose only by sliding
# sideways (directions 40-90 deg off the measured ones) or does not converge.
# Session 13: the grid search, run when no start of the fit converges, made the
# Pinto's, the Rabbit's and the Honda's fits converge, far from the measured
# speeds (bounds unchanged; their residual checks and the Honda's direction now hold).
ROLL = "all wheels rolling at f_r = 0.01 rolls 4.6-9.5x the measured run-out distance (a straight roll needs 0.05-0.10 g, the spinning cars 0.3 g)"
XFAIL: dict[tuple[str, str], str] = {
    **{("forward position", c): ROLL for c in FORWARD_CASES},
    (
        "forward heading",
        "VC-11.1",
    ): "Honda: |W| 5.24 rad/s with rolling wheels spins ~255 deg, measured 77 deg",
    ("fit speed", "VC-3.1"): "Torino: fitted 3.2 m/s against 5.3 measured (the fit slides to stop in 103 ft)",
    ("fit speed", "VC-3.2"): "Pinto: fitted 12.9 m/s against 6.8 measured (the grid search's rescue)",
    (
        "fit speed",
        "VC-8.2",
    ): "Rabbit: fitted 0.5 m/s spinning at -4.6 rad/s against 5.6 m/s measured (the grid search's rescue)",
    ("fit speed", "VC-11.1"): "Honda: fitted 2.0 m/s against 8.7 measured (the grid search's rescue)",
    ("fit direction", "VC-3.1"): "Torino: fitted velocity 40 deg off the measured (sideways slide)",
    ("fit direction", "VC-3.2"): "Pinto: fitted velocity 63 deg off the measured (sideways slide)",
    ("fit direction", "VC-8.1"): "Chevelle: fitted velocity 71 deg off the measured (sideways slide)",
    ("fit direction", "VC-8.2"): "Rabbit: fitted velocity 77 deg off the measured (spinning nearly in place)",
}


def _row(rows, label):
    (row,) = [r for r in rows if r["label"] == label]
    return row


def _case(kind: str, label: str):
    reason = XFAIL.get((kind, label))
    marks = [pytest.mark.xfail(strict=True, reason=reason)] if reason else []
    return pytest.param(label, marks=marks, id=label)


@pytest.fixture(scope="module")
def forward():
    return ro.ricsac_runout_forward()


@pytest.fixture(scope="module")
def fitted():
    return ro.ricsac_runout_fit()


@pytest.mark.parametrize("label", [_case("forward position", c) for c in FORWARD_CASES])
def test_forward_rest_position(forward, label):
    r = _row(forward, label)
    assert r["free"]
    assert r["position_error_ft"] <= FORWARD_POSITION_FRACTION * r["runout_distance_ft"], r


@pytest.mark.parametrize("label", [_case("forward heading", c) for c in FORWARD_CASES])
def test_forward_rest_heading(forward, label):
    r = _row(forward, label)
    assert abs(r["heading_error_deg"]) <= FORWARD_HEADING_DEG, r


@pytest.mark.parametrize("label", [_case("fit residual", c) for c in FIT_ALL])
def test_fit_reaches_measured_rest(fitted, label):
    r = _row(fitted, label)
    assert r["converged"], r
    assert r["residual_ft"] <= FIT_POSITION_FT and r["residual_deg"] <= FIT_HEADING_DEG, r


@pytest.mark.parametrize("label", [_case("fit speed", c) for c in FIT_MEASURED])
def test_fit_speed_against_measured(fitted, label):
    r = _row(fitted, label)
    assert r["converged"], r  # added after the first run: only a converged fit is a fitted speed
    assert abs(r["speed_pct"]) <= FIT_SPEED_PCT, r


@pytest.mark.parametrize("label", [_case("fit direction", c) for c in FIT_MEASURED])
def test_fit_direction_against_measured(fitted, label):
    r = _row(fitted, label)
    assert r["converged"], r  # added after the first run (a tightening): as for the speed
    assert abs(r["direction_error_deg"]) <= FIT_DIRECTION_DEG, r


def test_table_has_the_published_predictions_beside(forward):
    """Every Table-7 vehicle of RICSAC 2, 3, 6, 10 is in the table with SIMON and EDSMAC4."""
    labels = {r["label"] for r in ro.ricsac_runout_table()}
    assert labels == {f"VC-{t}.{v}" for t in (3, 7, 8, 11) for v in (1, 2)}
    for r in ro.ricsac_runout_table():
        for source in ("measured", "SIMON", "EDSMAC4"):
            assert all(math.isfinite(r[f"{source} {k}"]) for k in ("X", "Y", "psi"))


def test_report_states_the_assumptions():
    from impactsym import validation

    text = validation.markdown(validation.report())
    assert "RICSAC rest positions" in text
    for word in ("rolling", "Figures 9", "Vossou", "transformer"):
        assert word in text
