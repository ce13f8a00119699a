"""Scene diagrams render for every example, result kind and the CLI's --plot."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import pytest

import impactsym
from impactsym import plot
from impactsym.cli import main
from tests.helpers import forward_examples, new_axes

matplotlib.use("Agg")
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
FORWARD = forward_examples()
MIN_PNG_BYTES = 20_000  # a blank 9x6.5 in figure at 120 dpi is about 8 kB


def _check_png(path: Path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(data) > MIN_PNG_BYTES, len(data)


@pytest.mark.parametrize("path", FORWARD, ids=lambda p: p.name)
def test_every_forward_example_renders_scene_and_result(path, tmp_path):
    _check_png(plot.save_plot(path, tmp_path / "scene.png"))
    _check_png(plot.save_plot(impactsym.solve(path), tmp_path / "result.png", scene=path))


@pytest.mark.parametrize(
    "make, name",
    [(impactsym.invert, "invert_two_car_si.json"), (impactsym.reconstruct, "reconstruct_two_car_si.json")],
)
def test_inverse_and_reconstruction_results_render(make, name, tmp_path):
    path = EXAMPLES / name
    _check_png(plot.save_plot(make(path), tmp_path / "out.png", scene=path))


@pytest.mark.parametrize(
    "command, name",
    [
        ("solve", "barrier_si.json"),
        ("invert", "invert_two_car_si.json"),
        ("reconstruct", "reconstruct_two_car_si.json"),
    ],
)
def test_cli_plot_option_writes_the_diagram(command, name, tmp_path, capsys):
    out = tmp_path / "d.png"
    assert main([command, str(EXAMPLES / name), "--plot", str(out)]) == 0
    _check_png(out)


def test_cli_plot_rejects_an_unknown_image_type(tmp_path, capsys):
    assert main(["solve", str(EXAMPLES / "barrier_si.json"), "--plot", str(tmp_path / "d.txt")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--plot" in err[0]


# --------------------------------------------------------------------------- geometry and API


def _markers(ax, marker):
    return [tuple(line.get_xydata()[0]) for line in ax.lines if line.get_marker() == marker]


def test_import_impactsym_loads_neither_matplotlib_nor_ipywidgets():
    import subprocess
    import sys

    code = (
        "import sys, impactsym; "
        "assert not {'matplotlib', 'ipywidgets', 'sympy', 'derive'} & set(sys.modules), sys.modules.keys()"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_centres_of_gravity_sit_at_minus_r_from_the_impact_centre():
    ax = plot.scene(
        impactsym.solve(EXAMPLES / "two_car_us.json"), new_axes(), scene=EXAMPLES / "two_car_us.json"
    )
    assert _markers(ax, "X") == [(0.0, 0.0)]  # the impact centre at the origin
    cgs = _markers(ax, "+")
    assert cgs == [pytest.approx((-6.0, -1.0)), pytest.approx((1.5, 4.0))]


def test_impact_position_moves_the_whole_scene():
    import json

    data = json.loads((EXAMPLES / "two_car_us.json").read_text())
    data["impact"]["position"] = [10.0, -2.0]
    ax = plot.scene(data, new_axes())
    assert _markers(ax, "X") == [pytest.approx((10.0, -2.0))]
    assert _markers(ax, "+") == [pytest.approx((4.0, -3.0)), pytest.approx((11.5, 2.0))]


def test_particles_are_placed_either_side_of_the_impact_centre_along_n():
    import math

    data = {
        "model": "particle",
        "units": "SI",
        "impact": {"normal_angle": 30.0, "restitution": 0.2, "impulse_ratio": 0.1},
        "vehicles": [
            {"name": "a", "mass": 1.0, "velocity": [2.0, 1.0]},
            {"name": "b", "mass": 2.0, "velocity": [-1.0, 0.0]},
        ],
    }
    ax = plot.scene(impactsym.solve(data), new_axes(), scene=data)
    (x1, y1), (x2, y2) = _markers(ax, "+")
    n = (math.cos(math.radians(30.0)), math.sin(math.radians(30.0)))
    assert (x1, y1) == pytest.approx((-x2, -y2))  # symmetric about the impact centre
    assert x2 * n[1] - y2 * n[0] == pytest.approx(0.0, abs=1e-12) and x2 * n[0] + y2 * n[1] > 0


def test_outlines_barrier_and_legend_with_units():
    from matplotlib.patches import Polygon

    ax = plot.scene(
        impactsym.solve(EXAMPLES / "intersection_si.toml"),
        new_axes(),
        scene=EXAMPLES / "intersection_si.toml",
    )
    outlines = [p for p in ax.patches if isinstance(p, Polygon) and len(p.get_xy()) == 5]
    assert len(outlines) == 2  # two rectangles (closed: 5 vertices)
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert "velocity before [m/s]" in labels and "velocity after [m/s]" in labels
    assert "delta-V [m/s]" in labels and any("yaw rate after [rad/s]" in label for label in labels)
    assert any(label.startswith("PDOF") for label in labels)
    assert ax.get_legend().get_title().get_text().startswith("arrows: 1 m = ")
    barrier = plot.scene(
        impactsym.solve(EXAMPLES / "barrier_si.json"), new_axes(), scene=EXAMPLES / "barrier_si.json"
    )
    assert any(p.get_hatch() for p in barrier.patches)
    assert "fixed barrier" in [text.get_text() for text in barrier.get_legend().get_texts()]


def test_pdof_is_the_direction_of_the_impulse_and_matches_reconstruction():
    path = EXAMPLES / "reconstruct_two_car_si.json"
    result = impactsym.reconstruct(path)
    ax = plot.scene(result, new_axes(), scene=path)
    texts = [text.get_text().replace(":\n", ": ") for text in ax.texts]  # a crowded label is on two lines
    for vehicle in result.vehicles:
        assert f"{vehicle.name}: PDOF {vehicle.pdof_deg:.0f}° ({vehicle.pdof_clock} o'clock)" in texts


def test_a_duck_typed_result_is_drawn_with_its_scene():
    from types import SimpleNamespace

    path = EXAMPLES / "two_car_us.json"
    solved = impactsym.solve(path)
    fake = SimpleNamespace(
        vehicles=[
            SimpleNamespace(velocity=v.velocity, delta_v=v.delta_v, yaw_rate=v.yaw_rate)
            for v in solved.vehicles
        ],
        units="US",
    )
    ax = plot.scene(fake, new_axes(), scene=path)  # no Pn/Pt: PDOF from the delta-V direction
    assert "velocity after [ft/s]" in [text.get_text() for text in ax.get_legend().get_texts()]
    with pytest.raises(TypeError, match="scene="):
        plot.scene(fake, new_axes())


def test_scene_without_result_and_pyplot_defaultnew_axes():
    import matplotlib.pyplot as plt

    ax = plot.scene(EXAMPLES / "two_car_us.json")
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert "velocity before [ft/s]" in labels and "velocity after [ft/s]" not in labels
    assert ax.get_aspect() == 1.0
    plt.close(ax.figure)


def test_default_velocity_scale_is_what_scene_uses():
    path = EXAMPLES / "intersection_si.toml"
    result = impactsym.solve(path)
    k = plot.default_velocity_scale(result, scene=path)
    ax = plot.scene(result, new_axes(), scene=path)
    assert ax.get_legend().get_title().get_text() == f"arrows: 1 m = {1.0 / k:.3g} m/s"
