"""The CRASH3 diagram (``impactsym crash3 SCENE --plot OUT.png``): each crushed
vehicle's profile at the scene's depths, its PDOF arrow at the scene's angle,
texts that do not overlap."""

from __future__ import annotations

import json
import math
from itertools import combinations
from pathlib import Path

import numpy as np
import pytest

import impactsym
from impactsym import plot
from impactsym.cli import main
from impactsym.plot import crash3_figure

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CRASH3 = sorted(EXAMPLES.glob("crash3_*.json"))


@pytest.mark.parametrize("path", CRASH3, ids=lambda p: p.name)
def test_cli_crash3_plot_writes_the_diagram(path, tmp_path, capsys):
    out = tmp_path / "crash3.png"
    assert main(["crash3", str(path), "--plot", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "delta" in capsys.readouterr().out.lower()  # the table is still printed


@pytest.mark.parametrize("path", CRASH3, ids=lambda p: p.name)
def test_profiles_and_pdof_are_the_scenes(path):
    data = json.loads(path.read_text())
    crushed = [v for v in data["vehicles"] if not v.get("fixed")]
    fig = crash3_figure(impactsym.crash3(path), path)
    fig.canvas.draw()
    assert len(fig.axes) == len(crushed)
    for ax, vehicle in zip(fig.axes, crushed):
        crush = vehicle["crush"]
        width, depths = crush["width"], crush["depths"]
        (profile,) = [line for line in ax.lines if line.get_gid() == "profile"]
        expected = [(-width / 2 + width * i / (len(depths) - 1), -c) for i, c in enumerate(depths)]
        np.testing.assert_allclose(profile.get_xydata(), expected, rtol=1e-12)
        (arrow,) = [text for text in ax.texts if text.get_gid() == "pdof"]
        tail = arrow.xyann
        length = math.hypot(*tail)
        alpha = math.radians(crush["pdof"])  # counter-clockwise from the inward normal (down)
        assert (-tail[0] / length, -tail[1] / length) == pytest.approx((math.sin(alpha), -math.cos(alpha)))
        assert arrow.xy == pytest.approx((0.0, 0.0))  # pushing the face in at its middle
        assert vehicle["name"] in ax.get_title()
        renderer = fig.canvas.get_renderer()
        boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in ax.texts if t.get_text()]
        assert not [(a, b) for (a, x), (b, y) in combinations(boxes, 2) if x.overlaps(y)]
    assert fig.get_suptitle().startswith(f"{path.name}: CRASH3")


def test_save_plot_draws_a_crash3_result_only_with_its_scene(tmp_path):
    path = EXAMPLES / "crash3_two_car_us.json"
    result = impactsym.crash3(path)
    assert plot.save_plot(result, tmp_path / "c.png", scene=path).stat().st_size > 20_000
    with pytest.raises(TypeError, match="scene="):
        plot.save_plot(result, tmp_path / "c.png")
