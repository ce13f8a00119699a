"""The drawing surface of a diagram: arrows, arcs, outlines, lines, markers and
labels on a matplotlib axes, remembering every point for the limits."""

from __future__ import annotations

import math

from .inputs import _norm, _sub
from .labels import _PREFERRED


class _Canvas:
    """Draws on an axes and remembers every point, for the limits."""

    def __init__(self, ax):
        from matplotlib.patches import FancyArrowPatch, Polygon
        from matplotlib.path import Path as MplPath

        self.ax = ax
        self.points: list[tuple[float, float]] = []
        self._arrow, self._polygon, self._path = FancyArrowPatch, Polygon, MplPath

    def arrow(self, tail, head, color, lw=2.0, ls="-", alpha=1.0, zorder=4, scale=14):
        if _norm(_sub(head, tail)) <= 0:
            return
        self.ax.add_patch(
            self._arrow(
                tail,
                head,
                arrowstyle="-|>",
                mutation_scale=scale,
                color=color,
                lw=lw,
                linestyle=ls,
                alpha=alpha,
                shrinkA=0,
                shrinkB=0,
                zorder=zorder,
            )
        )
        self.points += [tail, head]

    def arc(self, centre, radius, start_deg, sweep_deg, color, ls, zorder=5):
        steps = max(8, int(abs(sweep_deg) / 6))
        points = []
        for step in range(steps + 1):
            angle = math.radians(start_deg + sweep_deg * step / steps)
            points.append((centre[0] + radius * math.cos(angle), centre[1] + radius * math.sin(angle)))
        self.ax.add_patch(
            self._arrow(
                path=self._path(points),
                arrowstyle="-|>",
                mutation_scale=11,
                color=color,
                lw=1.6,
                linestyle=ls,
                zorder=zorder,
            )
        )
        self.points += points
        return points[-1]

    def polygon(self, corners, **style):
        self.ax.add_patch(self._polygon(corners, closed=True, **style))
        self.points += list(corners)

    def line(self, a, b, **style):
        self.ax.plot([a[0], b[0]], [a[1], b[1]], **style)
        self.points += [a, b]

    def marker(self, point, **style):
        self.ax.plot([point[0]], [point[1]], **style)
        self.points.append(point)

    def label(self, anchor, text, prefer_deg: float, wrapped: str | None = None, **style):
        """A label near ``anchor`` (data coordinates); :func:`place_labels` later
        moves it around the anchor, trying the screen direction ``prefer_deg`` first
        and the text ``wrapped`` (on two lines) when the one line finds no free place."""
        label = self.ax.annotate(
            text,
            anchor,
            xytext=(0.0, 0.0),
            textcoords="offset points",
            ha="center",
            va="center",
            zorder=6,
            annotation_clip=False,
            bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.75),
            **style,
        )
        label.set_in_layout(False)  # kept inside the axes by place_labels; must not move the layout
        _PREFERRED[label] = (prefer_deg, wrapped)
        self.points.append(anchor)

    def limits(self, pad: float):
        xs = [p[0] for p in self.points]
        ys = [p[1] for p in self.points]
        return (min(xs) - pad, max(xs) + pad), (min(ys) - pad, max(ys) + pad)


def _angle(vector) -> float:
    """Direction of a vector, degrees counter-clockwise from +x (the screen
    direction too: the axes have equal aspect)."""
    return math.degrees(math.atan2(vector[1], vector[0]))
