"""The interactive explorer builds and updates without a display."""

from __future__ import annotations

import sys

import matplotlib
import pytest

from impactsym.explore import Explorer, explore

matplotlib.use("Agg")
SCENE = "examples/intersection_si.toml"


def test_explorer_updates_readout_and_marks_the_critical_ratio():
    ex = Explorer(SCENE)
    first = ex.readout.value
    assert "μ_c" in ex.sliders["impulse_ratio"].description
    mu_c = ex.result.mu_c
    assert ex.sliders["impulse_ratio"].max >= abs(mu_c)
    ex.sliders["restitution"].value = 0.4  # observe() calls update()
    assert ex.readout.value != first
    assert ex.result.TLn < ex.result.TLn + 1 and "|ΔV|" in ex.readout.value
    ex.sliders["impulse_ratio"].value = ex.sliders["impulse_ratio"].max  # far beyond μ_c
    assert "not between 0 and the critical ratio" in ex.readout.value


def test_explorer_reports_an_unsolvable_setting_instead_of_failing():
    ex = Explorer(SCENE)
    ex.sliders["normal_angle"].value = ex.sliders["normal_angle"].value + 90.0
    assert "cannot solve" in ex.readout.value or "|ΔV|" in ex.readout.value


def test_without_ipywidgets_explore_says_how_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "ipywidgets", None)
    with pytest.raises(ImportError, match="pip install 'impactsym\\[explore\\]'"):
        explore(SCENE)
