"""Scene diagrams read cleanly: in every bundled example (forward scenes, and the
``--plot`` of invert and reconstruct) no two texts overlap and no text lies on
an arrow or crosses a vehicle outline.

Checked on the figure ``save_plot`` writes (9 x 6.5 in, constrained layout,
120 dpi), after drawing it, with matplotlib's own extents of the text
(``Text.get_window_extent``) and of the arrows' drawn paths."""

from __future__ import annotations

from pathlib import Path as FilePath

import matplotlib
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import FancyArrowPatch, Polygon
from matplotlib.path import Path
from matplotlib.text import Text

import impactsym
from impactsym import plot
from impactsym.testing.figures import overlapping
from tests.helpers import forward_examples

matplotlib.use("Agg")
EXAMPLES = FilePath(__file__).resolve().parent.parent / "examples"
FORWARD = forward_examples()
CASES = (
    [(impactsym.solve, p) for p in FORWARD]
    + [(impactsym.invert, p) for p in sorted(EXAMPLES.glob("invert_*"))]
    + [(impactsym.reconstruct, p) for p in sorted(EXAMPLES.glob("reconstruct_*"))]
)


def _drawn(make, path):
    fig = Figure(figsize=(9.0, 6.5), dpi=120, layout="constrained")
    FigureCanvasAgg(fig)
    ax = plot.scene(make(path), fig.add_subplot(), scene=path)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    texts = [
        (t.get_text(), Text.get_window_extent(t, renderer))  # the text itself, not a leader line
        for t in ax.texts
        if t.get_visible() and t.get_text()
    ]
    return ax, texts


@pytest.mark.parametrize("make, path", CASES, ids=lambda c: getattr(c, "name", ""))
def test_no_two_texts_overlap_and_none_lies_on_an_arrow_or_an_outline(make, path):
    ax, texts = _drawn(make, path)
    assert len(texts) >= 4  # vehicle names, n, and the result's labels are there to check
    assert not overlapping(texts)
    arrows = [p for p in ax.patches if isinstance(p, FancyArrowPatch)]
    assert len(arrows) >= 3
    outlines = [
        p for p in ax.patches if isinstance(p, Polygon) and not p.get_hatch() and len(p.get_xy()) == 5
    ]
    crossed = []
    for patch in arrows + outlines:
        drawn = patch.get_transform().transform_path(patch.get_path())
        # as polylines: intersects_bbox would take a CLOSEPOLY's placeholder vertex for a point
        parts = [Path(polygon) for polygon in drawn.to_polygons(closed_only=False) if len(polygon) > 1]
        crossed += [
            (text, type(patch).__name__)
            for text, box in texts
            if any(part.intersects_bbox(box, filled=False) for part in parts)
        ]
    assert not crossed


def test_every_label_stays_inside_the_axes():
    ax, texts = _drawn(impactsym.solve, EXAMPLES / "intersection_si.toml")
    frame = ax.bbox
    outside = [
        text
        for text, box in texts
        if not (frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1)
    ]
    assert not outside


def test_one_pdof_style_with_or_without_a_heading():
    """Both vehicles' PDOF in the CRASH3 habit (degrees clockwise from straight
    ahead and the clock), also in a scene without headings (two_car_us.json)."""
    ax, texts = _drawn(impactsym.solve, EXAMPLES / "two_car_us.json")
    pdof = [text for text, _ in texts if "PDOF" in text]
    assert len(pdof) == 2 and all(text.endswith("o'clock)") for text in pdof), pdof
