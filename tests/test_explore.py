"""The interactive explorer builds and updates without a display.

ipywidgets works headless: the widgets exist without a front end, and
:meth:`Explorer.update` (what every slider change calls) is called directly.
Update time is measured and printed, not asserted (timed assertions are flaky);
``pytest -s tests/test_explore.py`` shows it.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("ipywidgets")
pytest.importorskip("matplotlib")

from impactsym.explore import MU_RANGE_FACTOR, Explorer, explore, mu_range  # noqa: E402

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
INTERSECTION = EXAMPLES / "intersection_si.toml"  # critical impulse ratio, μ_c < 0
BARRIER = EXAMPLES / "barrier_si.json"  # μ = 0.025 inside [0, μ_c], μ_c > 0
PNG = b"\x89PNG\r\n\x1a\n"


def _png_ok(ex: Explorer) -> None:
    assert ex.image.value[:8] == PNG and len(ex.image.value) > 10_000


def test_explorer_builds_and_the_readout_follows_the_sliders():
    ex = Explorer(INTERSECTION)
    _png_ok(ex)
    first, first_image = ex.readout.value, ex.image.value
    assert "|ΔV| sedan" in first and "energy loss TL" in first and "tangential TLt" in first
    assert "flags: none" in first
    ex.sliders["restitution"].value = 0.4  # observe() calls update()
    assert ex.readout.value != first and ex.image.value != first_image
    assert ex.current_scene()["impact"]["restitution"] == 0.4
    before = ex.readout.value
    ex.sliders["moment_restitution"].value = 0.3
    ex.update()  # the same, called directly
    assert ex.readout.value != before and "e_m = 0.3" in ex.readout.value


def test_critical_scene_starts_at_mu_c_and_the_mu_range_is_marked_by_mu_c():
    ex = Explorer(INTERSECTION)
    slider, result = ex.sliders["impulse_ratio"], ex.result
    assert ex.critical.value and slider.disabled
    assert result.critical and result.mu == pytest.approx(result.mu_c) and result.flags == 0
    assert result.mu_c < 0
    assert slider.value == pytest.approx(result.mu_c, abs=1e-12)
    assert slider.min == pytest.approx(MU_RANGE_FACTOR * result.mu_c)  # the range reaches past μ_c
    assert slider.max > 0.0 and "μ_c" in slider.description and f"{result.mu_c:.3g}" in slider.description
    assert "physical" in ex.mu_note.value

    ex.critical.value = False  # a number again, starting at μ_c
    assert not slider.disabled and not ex.result.critical
    ex.sliders["impulse_ratio"].value = slider.max  # opposite sign to μ_c: flagged
    assert ex.result.flags != 0 and "not between 0 and the critical ratio" in ex.readout.value
    assert "beyond" in ex.mu_note.value and slider.style.handle_color == "crimson"


def test_mu_range_follows_mu_c_when_e_changes():
    ex = Explorer(BARRIER)
    slider = ex.sliders["impulse_ratio"]
    assert not ex.critical.value and ex.result.mu_c > 0 and ex.result.flags == 0
    assert slider.max == pytest.approx(MU_RANGE_FACTOR * ex.result.mu_c)
    old_mu_c = ex.result.mu_c
    ex.sliders["restitution"].value = 0.6
    mu_c = ex.result.mu_c
    assert mu_c != pytest.approx(old_mu_c)
    lo, hi = mu_range(mu_c, slider.value)
    assert (slider.min, slider.max) == (pytest.approx(lo), pytest.approx(hi))
    assert slider.max == pytest.approx(max(MU_RANGE_FACTOR * mu_c, slider.value))
    assert slider.min <= 0.0 <= mu_c <= slider.max


def test_an_unsolvable_setting_is_reported_and_the_scene_still_drawn():
    ex = Explorer(INTERSECTION)
    # separating (at +90 the geometry turns the normal round, which approaches again)
    ex.sliders["normal_angle"].value = ex.sliders["normal_angle"].value + 60.0
    assert ex.result is None and "cannot solve" in ex.readout.value and "approaching" in ex.readout.value
    _png_ok(ex)
    ex.sliders["normal_angle"].value = 10.0  # back to the scene's Γ
    assert ex.result is not None and "|ΔV|" in ex.readout.value


def test_preset_models_show_only_their_free_coefficients():
    limpert = Explorer(EXAMPLES / "limpert_two_car_us.json")
    assert limpert.used == () and limpert.critical.value and limpert.critical.disabled
    assert all(
        limpert.sliders[key].disabled for key in ("restitution", "impulse_ratio", "moment_restitution")
    )
    assert "fixed by the model" in limpert.widget.children[0].children[0].value
    sideswipe = Explorer(EXAMPLES / "impac_sideswipe_si.json")
    assert sideswipe.used == ("slip",)
    before = sideswipe.readout.value
    sideswipe.sliders["slip"].value = 0.2
    assert sideswipe.readout.value != before and "slip = 0.2" in sideswipe.readout.value
    particle = Explorer(EXAMPLES / "table2_e0_mu1.json")
    assert "moment_restitution" not in particle.used and particle.sliders["moment_restitution"].disabled
    assert particle.result.mu_c == pytest.approx(1.0)  # seed Table 2: μ_max = 1 at e = 0
    assert particle.sliders["impulse_ratio"].max == pytest.approx(MU_RANGE_FACTOR)
    _png_ok(particle)


def test_explore_returns_an_explorer_that_displays_as_its_widget():
    ex = explore(str(BARRIER))
    assert isinstance(ex, Explorer)
    bundle = ex._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in bundle
    assert bundle["application/vnd.jupyter.widget-view+json"]["model_id"] == ex.widget.model_id


def test_update_time_is_measured(capsys):
    """Each of ~20 slider changes records its update time: in seconds, inside the
    wall time of that change, split into solve and draw (which add up to it). The figures are printed, not bounded."""
    ex = Explorer(INTERSECTION)
    ex.timings.clear()
    values = [0.05 * k for k in range(20)]
    walls = []
    for value in values:
        start = time.perf_counter()
        ex.sliders["restitution"].value = value
        walls.append(time.perf_counter() - start)
    assert len(ex.timings) == len(values)
    assert all(0.0 < took <= wall for took, wall in zip(ex.timings, walls)), (ex.timings, walls)
    solve_time, draw_time = ex.last_timing
    assert solve_time > 0.0 and draw_time > 0.0
    assert solve_time + draw_time == pytest.approx(ex.timings[-1], rel=1e-9)
    with capsys.disabled():
        print(
            f"\nexplorer update: median {1e3 * statistics.median(ex.timings):.1f} ms, "
            f"mean {1e3 * sum(walls) / len(walls):.1f} ms, max {1e3 * max(ex.timings):.1f} ms over "
            f"{len(values)} updates (last solve {1e3 * solve_time:.2f} ms)"
        )


def test_without_ipywidgets_explore_says_how_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "ipywidgets", None)
    with pytest.raises(ImportError, match=r"pip install 'impactsym\[explore\]'"):
        explore(INTERSECTION)
