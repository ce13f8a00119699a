"""Issue 22 item 13: the uncertainty figure is labelled for people (vehicle
names, quantities and units, readable ticks, no JSON paths) and no two of its
texts overlap, for every command that has it."""

import json
from pathlib import Path

import matplotlib
import pytest

import impactsym
from impactsym.testing.figures import overlapping, text_boxes
from impactsym.uncertainty.plot import uncertainty_figure

matplotlib.use("Agg")
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _solve(d):
    d["impact"]["impulse_ratio"] = {"normal": [-0.103, 0.01]}
    d["impact"]["restitution"] = {"uniform": [0.05, 0.15]}
    d["vehicles"][0]["mass"] = {"normal": [d["vehicles"][0]["mass"], 2.0]}


def _invert(d):
    d["impact"]["restitution"] = {"uniform": [0.15, 0.25]}


def _crash3(d):
    d["vehicles"][0]["crush"]["pdof"] = {"normal": [d["vehicles"][0]["crush"]["pdof"], 5.0]}
    d["vehicles"][1]["crush"]["A"] = {"normal": [d["vehicles"][1]["crush"]["A"], 10.0]}


CASES = [
    ("solve", "two_car_us.json", _solve, impactsym.solve),
    ("invert", "invert_two_car_si.json", _invert, impactsym.invert),
    ("reconstruct", "reconstruct_intersection_uncertain.json", None, impactsym.reconstruct),
    ("crash3", "crash3_two_car_us.json", _crash3, impactsym.crash3),
]


@pytest.mark.parametrize("command, name, edit, run", CASES, ids=[c[0] for c in CASES])
def test_the_uncertainty_figure_reads_cleanly(command, name, edit, run):
    data = json.loads((EXAMPLES / name).read_text())
    if edit:
        edit(data)
    result = run(data)
    u = impactsym.uncertainty(data, command=command, draws=3000, seed=1)
    fig = uncertainty_figure(u, names=[v.name for v in result.vehicles], units=result.units)
    texts = text_boxes(fig)
    assert not overlapping(texts)
    words = [t for t, _ in texts]
    assert not [t for t in words if "vehicles[" in t or "energy_loss" in t or "_" in t.split("[")[0]]
    histograms = fig.axes[:-1]
    for ax in histograms:
        assert "[" in ax.get_xlabel() and ax.get_ylabel()  # quantity [unit], and what is counted
    assert any(result.vehicles[0].name in ax.get_title() for ax in histograms)
    assert fig.axes[-1].get_xlabel()


def test_save_uncertainty_plot_still_writes_a_file(tmp_path):
    from impactsym.uncertainty.plot import save_uncertainty_plot

    u = impactsym.uncertainty(
        EXAMPLES / "reconstruct_intersection_uncertain.json", command="reconstruct", draws=2000, seed=1
    )
    save_uncertainty_plot(u, tmp_path / "u.png")
    assert (tmp_path / "u.png").stat().st_size > 10_000
