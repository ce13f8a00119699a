"""Scene diagrams render for every example, result kind and the CLI's --plot."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import pytest

import impactsym
from impactsym import plot
from impactsym.cli import main

matplotlib.use("Agg")
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
FORWARD = [p for p in sorted(EXAMPLES.glob("*.json")) + sorted(EXAMPLES.glob("*.toml"))
           if not p.name.startswith(("invert_", "reconstruct_", "crash3_"))]
MIN_PNG_BYTES = 20_000  # a blank 9x6.5 in figure at 120 dpi is about 8 kB


def _check_png(path: Path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(data) > MIN_PNG_BYTES, len(data)


@pytest.mark.parametrize("path", FORWARD, ids=lambda p: p.name)
def test_every_forward_example_renders_scene_and_result(path, tmp_path):
    _check_png(plot.save_plot(path, tmp_path / "scene.png"))
    _check_png(plot.save_plot(impactsym.solve(path), tmp_path / "result.png", scene=path))


@pytest.mark.parametrize("make, name", [(impactsym.invert, "invert_two_car_si.json"),
                                        (impactsym.reconstruct, "reconstruct_two_car_si.json")])
def test_inverse_and_reconstruction_results_render(make, name, tmp_path):
    path = EXAMPLES / name
    _check_png(plot.save_plot(make(path), tmp_path / "out.png", scene=path))


@pytest.mark.parametrize("command, name", [("solve", "barrier_si.json"),
                                           ("invert", "invert_two_car_si.json"),
                                           ("reconstruct", "reconstruct_two_car_si.json")])
def test_cli_plot_option_writes_the_diagram(command, name, tmp_path, capsys):
    out = tmp_path / "d.png"
    assert main([command, str(EXAMPLES / name), "--plot", str(out)]) == 0
    _check_png(out)


def test_cli_plot_rejects_an_unknown_image_type(tmp_path, capsys):
    assert main(["solve", str(EXAMPLES / "barrier_si.json"), "--plot", str(tmp_path / "d.txt")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--plot" in err[0]
