"""Issue 22 item 7: an uncertainty run with too few draws for a 90 % interval
is refused on the command line (and noted by the API), and --draws, --seed or
--sobol without --uncertainty are not silently ignored."""

from pathlib import Path

import pytest

import impactsym
from impactsym.cli import main
from impactsym.uncertainty.result import MIN_INTERVAL_DRAWS

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
UNCERTAIN = EXAMPLES / "reconstruct_intersection_uncertain.json"


@pytest.mark.parametrize("draws", ["2", str(MIN_INTERVAL_DRAWS - 1)])
def test_too_few_draws_for_an_interval_are_refused(draws, capsys):
    assert main(["reconstruct", str(UNCERTAIN), "--uncertainty", "--draws", draws]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--draws" in err and f"at least {MIN_INTERVAL_DRAWS}" in err


def test_the_minimum_is_accepted_and_documented(capsys):
    assert (
        main(
            [
                "reconstruct",
                str(UNCERTAIN),
                "--uncertainty",
                "--draws",
                str(MIN_INTERVAL_DRAWS),
                "--seed",
                "1",
            ]
        )
        == 0
    )
    assert "90 % interval" in capsys.readouterr().out
    text = (Path(__file__).resolve().parents[1] / "docs" / "uncertainty.md").read_text()
    assert f"at least {MIN_INTERVAL_DRAWS} draws" in text


def test_the_api_notes_an_interval_from_too_few_accepted_draws():
    u = impactsym.uncertainty(UNCERTAIN, command="reconstruct", draws=20, seed=1)
    assert any("90 % interval" in note and str(MIN_INTERVAL_DRAWS) in note for note in u.notes)
    u = impactsym.uncertainty(UNCERTAIN, command="reconstruct", draws=2000, seed=1)  # 17 % accepted
    assert not any("90 % interval" in note for note in u.notes)


@pytest.mark.parametrize("option", [["--draws", "500"], ["--seed", "3"], ["--sobol"]])
def test_uncertainty_options_without_uncertainty_are_named(option, capsys):
    assert main(["reconstruct", str(UNCERTAIN), *option]) == 0
    err = capsys.readouterr().err
    assert option[0] in err and "--uncertainty" in err and "ignored" in err


def test_no_warning_without_those_options(capsys):
    assert main(["reconstruct", str(UNCERTAIN)]) == 0
    assert "ignored" not in capsys.readouterr().err


def test_the_linearity_note_needs_a_ratio_past_its_factor_and_enough_draws():
    from impactsym.uncertainty.propagation import LINEAR_FACTOR, linearity_notes

    def outputs(ratio):
        return {"a": {"sd": 1.0, "sd_linear": 1.0}, "b": {"sd": ratio, "sd_linear": 1.0}}

    assert linearity_notes(outputs(0.99 * LINEAR_FACTOR), 1000, 1000) == []
    assert linearity_notes(outputs(1.0 / (0.99 * LINEAR_FACTOR)), 1000, 1000) == []
    for ratio in (1.01 * LINEAR_FACTOR, 1.0 / (1.01 * LINEAR_FACTOR)):
        (note,) = linearity_notes(outputs(ratio), 1000, 2000)
        assert "1 of 2 outputs" in note and "(most: b," in note and "50% of the draws rejected" in note
    assert linearity_notes(outputs(3.0), MIN_INTERVAL_DRAWS - 1, 1000) == []
    assert linearity_notes({"c": {"sd": 1.0, "sd_linear": float("nan")}}, 1000, 1000) == []
