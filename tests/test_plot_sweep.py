"""Sweep plots: heatmap masks, the μ = μ_c line, line plots, errors and the PNG file.

Frames are built the way ``impactsym.sweep`` builds them: a meshgrid (C order,
first parameter slowest) around the intersection example, solved with
``solve_batch``, varied parameters first, then the outputs, ``status``, ``flags``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
import pytest

import impactsym
from impactsym import plot
from impactsym.pictures import sweep as plot_sweep
from tests.helpers import new_axes

matplotlib.use("Agg")
SCENE = Path(__file__).resolve().parent.parent / "examples" / "intersection_si.toml"
E = np.array([0.0, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0])  # non-uniform on purpose
MU = np.linspace(-0.8, 0.6, 15)
MIN_PNG_BYTES = 20_000  # a blank 9x6.5 in figure at 120 dpi is about 8 kB
IMPOSSIBLE = 1 | 2 | 4


def _frame(**axes) -> pd.DataFrame:
    """A sweep frame over the given parameters (``normal_angle`` in degrees)."""
    family, _critical, values = impactsym.load_scene(SCENE).to_inputs()
    grids = [grid.ravel() for grid in np.meshgrid(*axes.values(), indexing="ij")]
    varied = dict(zip(axes, grids))
    columns = {name: np.full(grids[0].size, value) for name, value in values.items()}
    columns.update(varied)
    if "normal_angle" in varied:
        columns["gamma"] = np.radians(columns.pop("normal_angle"))
    result = impactsym.solve_batch(columns, model=family, outputs="all")
    return pd.DataFrame({**varied, **{name: result[name] for name in result if name not in varied}})


@pytest.fixture(scope="module")
def e_mu():
    return _frame(e=E, mu=MU)


def _by_gid(ax, gid):
    return [artist for artist in ax.get_children() if artist.get_gid() == gid]


def _covered(collection, xs, ys) -> np.ndarray:
    """Which grid cells (centres xs × ys, shape (len(ys), len(xs))) a collection of rectangles covers."""
    covered = np.zeros((len(ys), len(xs)), dtype=bool)
    for path in collection.get_paths():
        (x0, y0), (x1, y1) = path.vertices.min(axis=0), path.vertices.max(axis=0)
        covered |= ((xs > x0) & (xs < x1))[None, :] & ((ys > y0) & (ys < y1))[:, None]
    return covered


def _grid_of(df, column, x, y):
    """A column as a (len(ys), len(xs)) array, from the C-ordered frame."""
    return df.sort_values([y, x])[column].to_numpy().reshape(df[y].nunique(), df[x].nunique())


def _legend_texts(ax):
    (legend,) = ax.figure.legends  # below the axes, off the data
    return [text.get_text() for text in legend.get_texts()]


# --------------------------------------------------------------------------- heatmap


def test_impossible_mask_covers_exactly_the_flagged_cells(e_mu):
    flagged = _grid_of(e_mu, "flags", "e", "mu") & IMPOSSIBLE != 0
    assert flagged.any() and not flagged.all()
    assert (_grid_of(e_mu, "mu", "e", "mu") < _grid_of(e_mu, "mu_c", "e", "mu"))[flagged].any()  # beyond μ_c
    shuffled = e_mu.sample(frac=1.0, random_state=1)  # row order does not matter
    ax = plot_sweep.sweep(shuffled, "e", "mu", ax=new_axes(layout="constrained"), units="SI")
    (mask,) = _by_gid(ax, "impossible")
    np.testing.assert_array_equal(_covered(mask, E, MU), flagged)
    assert not _by_gid(ax, "not_solved")  # every row solved
    (mesh,) = _by_gid(ax, "values")
    values = mesh.get_array()  # impossible cells keep their colour under the translucent hatch
    assert not np.ma.getmaskarray(values).any()
    np.testing.assert_allclose(values.compressed(), _grid_of(e_mu, "TL", "e", "mu").ravel())
    assert plot_sweep.IMPOSSIBLE_LABEL in _legend_texts(ax)
    transposed = plot_sweep.sweep(
        shuffled, "mu", "e", ax=new_axes(layout="constrained")
    )  # two flagged runs along each row
    (mask,) = _by_gid(transposed, "impossible")
    np.testing.assert_array_equal(_covered(mask, MU, E), flagged.T)


def test_not_solved_cells_have_their_own_mask():
    df = _frame(normal_angle=np.linspace(-30.0, 80.0, 12), mu=np.linspace(-0.8, 0.6, 8))
    unsolved = _grid_of(df, "status", "normal_angle", "mu") != 0
    assert unsolved.any() and not unsolved.all()  # a steep normal: not approaching
    ax = plot_sweep.sweep(df, "normal_angle", "mu", ax=new_axes(layout="constrained"))
    xs, ys = np.unique(df["normal_angle"]), np.unique(df["mu"])
    (mask,) = _by_gid(ax, "not_solved")
    np.testing.assert_array_equal(_covered(mask, xs, ys), unsolved)
    (impossible,) = _by_gid(ax, "impossible")
    assert not (_covered(impossible, xs, ys) & unsolved).any()
    assert plot_sweep.NOT_SOLVED_LABEL in _legend_texts(ax)
    assert ax.get_xlabel() == "normal angle Γ [°]"


def test_cell_edges_are_halfway_between_non_uniform_values(e_mu):
    ax = plot_sweep.sweep(e_mu, "e", "mu", ax=new_axes(layout="constrained"))
    (mesh,) = _by_gid(ax, "values")
    xedges = mesh.get_coordinates()[0, :, 0]
    np.testing.assert_allclose(xedges, [-0.025, 0.025, 0.075, 0.15, 0.3, 0.55, 0.85, 1.15])
    assert ax.get_xlim() == pytest.approx((-0.025, 1.15))


def test_a_single_value_along_an_axis_gets_a_cell(e_mu):
    ax = plot_sweep.sweep(e_mu[e_mu.e == 0.4], "e", "mu", color="dV1", ax=new_axes(layout="constrained"))
    (mesh,) = _by_gid(ax, "values")
    np.testing.assert_allclose(mesh.get_coordinates()[0, :, 0], [0.36, 0.44])
    (line,) = _by_gid(ax, "mu_c")  # spans the single cell
    np.testing.assert_allclose(line.get_xdata(), [0.36, 0.44])


def test_mu_c_line_follows_mu_c_against_the_other_axis(e_mu):
    mu_c = e_mu.groupby("e")["mu_c"].first().to_numpy()
    assert np.ptp(mu_c) > 0.05  # μ_c varies with e
    ax = plot_sweep.sweep(e_mu, "e", "mu", ax=new_axes(layout="constrained"))
    (line,) = _by_gid(ax, "mu_c")
    np.testing.assert_allclose(line.get_xdata(), E)
    np.testing.assert_allclose(line.get_ydata(), mu_c)
    assert "μ = μ_c" in _legend_texts(ax)
    transposed = plot_sweep.sweep(e_mu, "mu", "e", ax=new_axes(layout="constrained"))
    (line,) = _by_gid(transposed, "mu_c")
    np.testing.assert_allclose(line.get_xdata(), mu_c)
    np.testing.assert_allclose(line.get_ydata(), E)


def test_no_mu_c_line_without_mu_on_an_axis():
    df = _frame(e=E, normal_angle=np.array([0.0, 10.0, 20.0]))
    ax = plot_sweep.sweep(df, "e", "normal_angle", ax=new_axes(layout="constrained"))
    assert not _by_gid(ax, "mu_c")
    assert "mu" in df and plot_sweep.MU_C_LABEL not in [line.get_label() for line in ax.lines]


def test_colourbar_label_carries_the_quantity_and_units(e_mu):
    labels = {}
    for units in ("SI", "US", None):
        ax = plot_sweep.sweep(e_mu, "e", "mu", color="dV1", ax=new_axes(layout="constrained"), units=units)
        labels[units] = [other.get_ylabel() for other in ax.figure.axes if other is not ax][0]
    assert labels == {"SI": "delta-V dV1 [m/s]", "US": "delta-V dV1 [ft/s]", None: "delta-V dV1"}
    ax = plot_sweep.sweep(e_mu, "e", "mu", ax=new_axes(layout="constrained"), units="US")
    assert [other.get_ylabel() for other in ax.figure.axes if other is not ax] == ["energy loss TL [ft·lb]"]


def test_colour_range_spans_every_solved_cell():
    """Solved cells, possible or not, lie inside the colour range, which is
    their min to max; rows not solved are left out (not approaching: NaN outputs)."""
    df = _frame(normal_angle=np.linspace(-30.0, 80.0, 12), mu=np.linspace(-0.8, 0.6, 8))
    solved = df["status"].to_numpy() == 0
    impossible = solved & (df["flags"].to_numpy() & IMPOSSIBLE != 0)
    assert impossible.any() and (~solved).any()
    ax = plot_sweep.sweep(df, "normal_angle", "mu", ax=new_axes(layout="constrained"))
    (mesh,) = _by_gid(ax, "values")
    tl = df["TL"].to_numpy()[solved]
    assert mesh.get_clim() == (pytest.approx(tl.min()), pytest.approx(tl.max()))
    assert tl[impossible[solved]].min() < tl[~impossible[solved]].min()  # the case the old range left out


@pytest.mark.parametrize("y", ["mu", None], ids=["heatmap", "lines"])
def test_the_legend_is_off_the_data(e_mu, y):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 6.5), layout="constrained")
    FigureCanvasAgg(fig)
    frame = e_mu if y else e_mu[e_mu.e == 0.2]
    ax = plot_sweep.sweep(frame, "e" if y else "mu", y, ax=fig.add_subplot(), units="SI")
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    (legend,) = fig.legends
    box = legend.get_window_extent(renderer)
    for other in fig.axes:  # the data and the colour bar
        assert not box.overlaps(other.get_window_extent(renderer))
    assert not box.overlaps(ax.xaxis.label.get_window_extent(renderer))
    assert box.y1 < ax.get_window_extent(renderer).y0  # below the axes


# --------------------------------------------------------------------------- line plot


def test_line_plot_marks_the_impossible_points(e_mu):
    one = e_mu[e_mu.e == 0.2].sample(frac=1.0, random_state=2)
    ax = plot_sweep.sweep(one, "mu", ax=new_axes(layout="constrained"), units="SI")
    (line,) = _by_gid(ax, "values")
    ordered = one.sort_values("mu")
    np.testing.assert_allclose(line.get_xdata(), ordered["mu"])
    np.testing.assert_allclose(line.get_ydata(), ordered["TL"])
    flagged = ordered["flags"].to_numpy() & IMPOSSIBLE != 0
    assert flagged.any() and not flagged.all()
    (crosses,) = _by_gid(ax, "impossible")
    np.testing.assert_allclose(crosses.get_xdata(), ordered["mu"][flagged])
    (mu_c,) = _by_gid(ax, "mu_c")
    assert mu_c.get_xdata()[0] == pytest.approx(one["mu_c"].iloc[0])
    assert plot_sweep.IMPOSSIBLE_LABEL in _legend_texts(ax) and ax.get_ylabel() == "energy loss TL [J]"


def test_line_plot_of_several_columns(e_mu):
    one = e_mu[e_mu.mu == MU[5]]
    ax = plot_sweep.sweep(one, "e", color=["dV1", "dV2"], ax=new_axes(layout="constrained"), units="SI")
    lines = _by_gid(ax, "values")
    assert [line.get_label() for line in lines] == ["delta-V dV1 [m/s]", "delta-V dV2 [m/s]"]
    np.testing.assert_allclose(lines[1].get_ydata(), one.sort_values("e")["dV2"])
    assert ax.get_ylabel() == "dV1, dV2 [m/s]"
    assert not _by_gid(ax, "mu_c")


# --------------------------------------------------------------------------- errors


@pytest.mark.parametrize(
    "args, name", [(("speed", "mu"), "speed"), (("e", "nope"), "nope"), (("e", "mu", "energy"), "energy")]
)
def test_unknown_column_is_named(e_mu, args, name):
    with pytest.raises(ValueError, match=f"^{name}: no such column"):
        plot_sweep.sweep(e_mu, *args, ax=new_axes(layout="constrained"))


def test_a_varied_column_the_axes_do_not_use_asks_to_filter(e_mu):
    with pytest.raises(ValueError, match="varies mu.*filter") as error:
        plot_sweep.sweep(e_mu, "e", ax=new_axes(layout="constrained"))
    assert "\n" not in str(error.value)
    three = _frame(e=E[:3], mu=MU[:3], m1=np.array([1200.0, 1500.0]))
    with pytest.raises(ValueError, match="varies m1"):
        plot_sweep.sweep(three, "e", "mu", ax=new_axes(layout="constrained"))
    plot_sweep.sweep(
        three[three.m1 == 1500.0], "e", "mu", ax=new_axes(layout="constrained")
    )  # filtered: fine


def test_rows_that_do_not_form_a_full_grid(e_mu):
    with pytest.raises(ValueError, match="not a full grid"):
        plot_sweep.sweep(e_mu.iloc[1:], "e", "mu", ax=new_axes(layout="constrained"))


def test_bad_units_and_a_list_colour_on_a_heatmap(e_mu):
    with pytest.raises(ValueError, match="units"):
        plot_sweep.sweep(e_mu, "e", "mu", ax=new_axes(layout="constrained"), units="metric")
    with pytest.raises(ValueError, match="heatmap shows one column"):
        plot_sweep.sweep(e_mu, "e", "mu", color=["dV1", "dV2"], ax=new_axes(layout="constrained"))


# --------------------------------------------------------------------------- file


def test_save_sweep_writes_a_png_without_pyplot_figures(e_mu, tmp_path):
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    for y in ("mu", None):
        frame = e_mu if y else e_mu[e_mu.e == 0.4]
        path = plot_sweep.save_sweep(frame, tmp_path / f"sweep_{y}.png", "e" if y else "mu", y, units="SI")
        data = Path(path).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n"
        assert len(data) > MIN_PNG_BYTES, len(data)
    assert plt.get_fignums() == before


def test_the_sweep_plots_are_also_impactsym_plot_names():
    assert plot.sweep is plot_sweep.sweep and plot.save_sweep is plot_sweep.save_sweep
