"""Issue 22 item 11: the picture's title shows enough digits to see why a flag
was raised (e_m = 1.00067 is not "1")."""

import json
from pathlib import Path

import impactsym
from impactsym.pictures.diagram import _title, shown_beside
from impactsym.scene import load_scene

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "reconstruct_two_car_si.json"


def test_the_reconstruct_title_shows_e_m_beyond_one():
    result = impactsym.reconstruct(EXAMPLE)
    assert 1.0 < result.e_m < 1.001  # flagged: outside [-1, 1]
    title = _title(load_scene(EXAMPLE, kind="reconstruct"), result)
    assert "e_m = 1.001" in title and "e_m = 1," not in title


def test_mu_beyond_mu_c_is_shown_apart_from_it():
    data = json.loads((EXAMPLE.parent / "two_car_us.json").read_text())
    result = impactsym.solve(data)
    title = _title(load_scene(data), result)
    assert f"μ_c = {result.mu_c:.3g}" in title  # ordinary values keep 3 digits


def test_digits_grow_only_until_the_value_leaves_its_bound():
    assert shown_beside(1.00067, (-1.0, 1.0)) == "1.001"
    assert shown_beside(0.99996, (-1.0, 1.0)) == "0.99996"
    assert shown_beside(0.99, (-1.0, 1.0)) == "0.99"
    assert shown_beside(1.0, (1.0,)) == "1"
    assert shown_beside(-3e-9, (0.0,)) == "-3e-09"
    assert shown_beside(0.30000004, (0.3,)) == "0.30000004"
