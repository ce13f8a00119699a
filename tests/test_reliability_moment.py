"""Issue 22 item 5: a reconstruction whose two angular-impulse equations
disagree by more than the moment impulse itself says so."""

import json
from pathlib import Path

import pytest

import impactsym

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "reconstruct_two_car_si.json"


def _scene(changes=None):
    data = json.loads(EXAMPLE.read_text())
    for (index, key), value in (changes or {}).items():
        data["vehicles"][index][key] = value
    return data


def _residual_warnings(result):
    return [w for w in result.warnings if "angular-impulse" in w]


def test_consistent_example_has_no_residual_warning():
    # M is small here (e_m ≈ 1) and the residual (6 N·m·s) is the rounding of
    # yaw rates read to 3 digits (I·ΔW ≈ 7000 N·m·s): not an inconsistency
    result = impactsym.reconstruct(_scene())
    assert abs(result.M_residual) < 0.01 * 3900 * 1.791
    assert not _residual_warnings(result)


@pytest.mark.parametrize(
    "changes",
    [
        {(1, "final_yaw_rate"): 5.0},  # a placeholder yaw rate
        {(0, "impact_point"): [1.0, -0.3]},  # the impact centre 1.1 m behind where it was
    ],
    ids=["placeholder-yaw-rate", "misplaced-impact-centre"],
)
def test_inconsistent_moment_equations_are_named(changes):
    result = impactsym.reconstruct(_scene(changes))
    assert abs(result.M_residual) > abs(result.M)
    (warning,) = _residual_warnings(result)
    assert "moment_residual" in warning and "final_yaw_rate" in warning and "impact_point" in warning
