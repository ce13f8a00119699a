"""Issue 22 items 9-11: the words a user reads name the right thing."""

import json
from pathlib import Path

import pytest

import impactsym
from impactsym import load_scene

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


# --------------------------------------------------------------------------- 9. compare, crash3 notes


def test_compare_on_a_crush_only_scene_names_what_each_model_needs():
    skipped = impactsym.compare(EXAMPLES / "crash3_two_car_us.json").skipped
    for name in ("limpert", "impac", "impac_sideswipe"):  # no coefficients: only the motion
        assert "restitution" not in skipped[name] and "vehicles[0].velocity" in skipped[name], skipped[name]
    for name in ("brach", "macmillan", "particle"):
        assert "impact.restitution" in skipped[name] and "impact.impulse_ratio" in skipped[name]
        assert "vehicles[0].velocity" in skipped[name]


def test_crash3_names_each_unused_coefficient_for_what_it_is():
    data = json.loads((EXAMPLES / "crash3_two_car_us.json").read_text())
    data["impact"].update(restitution=0.1, impulse_ratio=0.3, moment_restitution=1.0, slip=0.2)
    warnings = load_scene(data, kind="crash3").warnings
    for key in ("impulse_ratio", "moment_restitution", "slip"):
        (warning,) = [w for w in warnings if w.startswith(f"impact.{key} ")]
        assert "restitution from" not in warning
    (warning,) = [w for w in warnings if w.startswith("impact.restitution ")]
    assert "crash3 options" in warning


# --------------------------------------------------------------------------- 10. plots and validate


def test_save_plot_of_an_axes_says_what_to_do():
    import matplotlib

    matplotlib.use("Agg")
    from impactsym.plot import save_plot
    from impactsym.plot import sweep as sweep_plot

    frame = impactsym.sweep(EXAMPLES / "two_car_us.json", e=[0.1, 0.2, 0.3])
    ax = sweep_plot(frame, x="e")
    try:
        save_plot(ax, "x.png")
    except TypeError as exc:
        text = str(exc)
    assert "Axes" in text and "savefig" in text and "scene=" not in text


@pytest.mark.slow
def test_validate_prints_every_model_name_whole(capsys):
    from impactsym import validation
    from impactsym.cli import main

    assert main(["validate"]) == 0
    out = capsys.readouterr().out
    for row in validation.statistics_rows(validation.report()):
        assert f" {row['model']} " in out, row["model"]


def test_the_validation_legends_cover_no_point():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from impactsym import validation
    from impactsym.validation.figures import figure

    for ds in validation.report():
        fig = figure(ds, plt)
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        for ax in fig.axes:
            legend = ax.get_legend().get_window_extent(renderer)
            for points in ax.collections:
                xy = ax.transData.transform(points.get_offsets())
                inside = [p for p in xy if legend.contains(*p)]
                assert not inside, (ds.name, ax.get_title(), len(inside))
        plt.close(fig)


def test_an_emoji_or_cjk_vehicle_name_gives_one_line(tmp_path, capsys):
    from impactsym.cli import main

    data = json.loads((EXAMPLES / "two_car_us.json").read_text())
    data["vehicles"][0]["name"] = "车 🚗"
    scene = tmp_path / "names.json"
    scene.write_text(json.dumps(data, ensure_ascii=False), encoding="utf-8")
    assert main(["solve", str(scene), "--plot", str(tmp_path / "s.png")]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "车" in err and "🚗" in err and ".py" not in err
