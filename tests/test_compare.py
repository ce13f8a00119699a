"""The comparison report: every model the data allow, in agreement with solving each
model alone; the reasons for the ones skipped; table, markdown, JSON and plot output."""

import json
import math
from pathlib import Path

import pytest

import impactsym
from impactsym._kernels import PRESETS
from impactsym.cli import main

ROOT = Path(__file__).resolve().parents[1]
MODELS_SCENE = ROOT / "examples" / "models_two_car_us.json"
DATA = json.loads(MODELS_SCENE.read_text())


def kinetic_energy(vehicles):
    """Initial kinetic energy, translational plus yaw (independent of the kernels)."""
    return sum(
        v["mass"] * (v["velocity"][0] ** 2 + v["velocity"][1] ** 2) / 2
        + v["yaw_inertia"] * v.get("yaw_rate", 0.0) ** 2 / 2
        for v in vehicles
    )


@pytest.fixture(scope="module")
def comparison():
    return impactsym.compare(MODELS_SCENE)


def test_every_model_runs_on_the_full_scene(comparison):
    assert [row.model for row in comparison.rows] == [
        "brach",
        "macmillan",
        "limpert",
        "impac",
        "impac_sideswipe",
        "particle",
        "crash3",
    ]
    assert comparison.skipped == {}
    assert comparison.initial_kinetic_energy == pytest.approx(kinetic_energy(DATA["vehicles"]), rel=1e-14)


def test_rows_equal_each_model_solved_alone(comparison):
    rows = {row.model: row for row in comparison.rows}
    for model in ("brach", "limpert", "impac_sideswipe", "particle"):
        keep = {
            "normal_angle",
            *PRESETS[model]["required"],
            *PRESETS[model]["optional"],
        }
        alone = impactsym.solve(
            {**DATA, "model": model, "impact": {k: v for k, v in DATA["impact"].items() if k in keep}}
        )
        row = rows[model]
        assert row.energy["total"] == alone.TL
        assert row.energy_percent["total"] == pytest.approx(
            100 * alone.TL / comparison.initial_kinetic_energy
        )
        for got, want in zip(row.vehicles, alone.vehicles):
            assert got.velocity == want.velocity and got.delta_v_magnitude == want.delta_v_magnitude
            assert got.speed == pytest.approx(math.hypot(*want.velocity))
            assert math.radians(got.direction) == pytest.approx(
                math.atan2(want.velocity[1], want.velocity[0])
            )
    assert rows["particle"].vehicles[0].yaw_rate is None and rows["particle"].energy["moment"] is None


def test_identical_models_give_identical_rows(comparison):
    rows = {row.model: row for row in comparison.rows}
    assert rows["limpert"].vehicles == rows["impac"].vehicles  # seed Table 7
    assert rows["macmillan"].vehicles == rows["brach"].vehicles  # the scene has e_m = 1


def test_crash3_row(comparison):
    row = next(row for row in comparison.rows if row.model == "crash3")
    alone = impactsym.crash3(DATA)
    assert row.energy["total"] == alone.energy_total and row.energy["normal"] is None
    for got, want, given in zip(row.vehicles, alone.vehicles, DATA["vehicles"]):
        assert got.delta_v_magnitude == want.delta_v_magnitude and got.yaw_rate is None
        assert got.velocity == (
            given["velocity"][0] + want.delta_v[0],
            given["velocity"][1] + want.delta_v[1],
        )
    assert any("implies" in w for w in row.warnings)


def test_models_the_data_do_not_allow_are_skipped_with_a_reason():
    result = impactsym.compare(ROOT / "examples" / "limpert_two_car_us.json")
    assert [row.model for row in result.rows] == ["limpert", "impac"]
    assert "impact.restitution: missing" in result.skipped["brach"]
    assert "slip" in result.skipped["impac_sideswipe"]
    assert "no crush table" in result.skipped["crash3"]


def test_cli_table_markdown_json_and_plot(capsys, tmp_path):
    assert main(["compare", str(MODELS_SCENE)]) == 0
    table = capsys.readouterr().out
    assert "TL %" in table and "crash3" in table and "n/a" in table
    assert main(["compare", str(MODELS_SCENE), "--markdown"]) == 0
    markdown = capsys.readouterr().out
    rows = [line for line in markdown.splitlines() if line.startswith("| ")]
    assert rows[0].startswith("| model |") and "\\|dV\\|" in rows[0] and len(rows) == 8
    assert main(["compare", str(MODELS_SCENE), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {"models", "skipped", "initial_kinetic_energy", "units"} <= set(data)
    assert data["models"][0]["energy_loss"]["tangential"] is not None
    png = tmp_path / "models.png"
    assert main(["compare", str(MODELS_SCENE), "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_compare_formats_are_exclusive(capsys):
    assert main(["compare", str(MODELS_SCENE), "--json", "--markdown"]) == 2
    assert "not allowed with" in capsys.readouterr().err


@pytest.mark.parametrize(
    "scene", [MODELS_SCENE, ROOT / "examples" / "crash3_two_car_us.json"], ids=lambda p: p.name
)
def test_plot_has_a_title_headroom_and_legends_off_the_bars(scene):
    from matplotlib.patches import Rectangle

    fig = impactsym.compare(scene).figure()
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    assert fig.get_suptitle().startswith(f"{scene.name}: model comparison")
    bars = {
        ax: [p for p in ax.patches if isinstance(p, Rectangle) and p.get_height() != 0] for ax in fig.axes
    }
    assert bars[fig.axes[0]]  # |delta-V| (a crush-only scene has no energy percentages)
    for ax, drawn in bars.items():
        low, high = ax.get_ylim()
        # at least 5 % of the axis height free above the highest bar
        assert max((bar.get_y() + bar.get_height() for bar in drawn), default=low) <= high - 0.05 * (
            high - low
        )
    legends = [ax.get_legend().get_window_extent(renderer) for ax in fig.axes if ax.get_legend()]
    covered = [
        (legend, bar)
        for legend in legends
        for drawn in bars.values()
        for bar in drawn
        if legend.overlaps(bar.get_window_extent(renderer))
    ]
    assert not covered
