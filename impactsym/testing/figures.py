"""Readability checks of drawn figures (matplotlib): which texts overlap.

Used by the scene-diagram tests (tests/test_plot_labels.py) and the
uncertainty-figure tests: a figure is drawn once, every visible text (titles,
axis and tick labels, legends, annotations) is measured with matplotlib's own
extent, and any two whose boxes overlap (edges excluded) are reported.
"""

from __future__ import annotations

from itertools import combinations

__all__ = ["overlapping", "text_boxes"]


def text_boxes(fig) -> list[tuple[str, object]]:
    """(text, window extent) of every text drawn in ``fig``, after drawing it.
    Tick labels outside their axes' span (kept by matplotlib but not drawn)
    are left out."""
    from matplotlib.text import Text

    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    off_span = set()
    for ax in fig.axes:
        for labels, along_x in ((ax.get_xticklabels(), True), (ax.get_yticklabels(), False)):
            for label in labels:
                box = label.get_window_extent(renderer)
                centre = (box.x0 + box.x1) / 2 if along_x else (box.y0 + box.y1) / 2
                low, high = (ax.bbox.x0, ax.bbox.x1) if along_x else (ax.bbox.y0, ax.bbox.y1)
                if not low - 1.0 <= centre <= high + 1.0:
                    off_span.add(id(label))
    boxes = []
    for text in fig.findobj(Text):
        if id(text) in off_span or not text.get_visible() or not text.get_text().strip():
            continue
        box = Text.get_window_extent(text, renderer)  # the text itself, not a leader line
        if box.width > 0 and box.height > 0:
            boxes.append((text.get_text(), box))
    return boxes


def overlapping(texts) -> list[tuple[str, str]]:
    """The pairs of ``(text, box)`` whose boxes overlap."""
    return [(a, b) for (a, box_a), (b, box_b) in combinations(texts, 2) if box_a.overlaps(box_b)]
