"""Label placement: once the figure is laid out, each scene label takes the
nearest free position around its anchor (inside the axes, off every other label,
arrow, outline, line and marker), with a leader line when placed far away."""

from __future__ import annotations

import math
import weakref

#: Scene labels (annotations made by ``_Canvas.label``): the screen direction tried
#: first and the label on two lines (or None).
_PREFERRED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_RADII = (
    2.0,
    6.0,
    11.0,
    17.0,
    24.0,
    32.0,
    42.0,
    54.0,
    68.0,
    84.0,
    102.0,
    122.0,
    145.0,
)  # label distance from its anchor [points]
_DIRECTIONS = 24
_LEADER_FROM = 14.0  # labels further than this from their anchor [points] get a leader line


def _candidates(prefer_deg: float):
    """``(offset in points, ha, va)`` around an anchor: nearest first, and at each
    distance the directions closest to ``prefer_deg`` first. The alignment puts
    the side of the text facing the anchor at the offset."""
    angles = sorted(
        (360.0 * i / _DIRECTIONS for i in range(_DIRECTIONS)),
        key=lambda a: abs((a - prefer_deg + 180.0) % 360.0 - 180.0),
    )
    for radius in _RADII:
        for angle in angles:
            c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
            ha = "left" if c > 0.38 else "right" if c < -0.38 else "center"
            va = "bottom" if s > 0.38 else "top" if s < -0.38 else "center"
            yield (radius * c, radius * s), ha, va


def _renderer(fig):
    canvas = fig.canvas
    return canvas.get_renderer() if hasattr(canvas, "get_renderer") else fig._get_renderer()


def _obstacles(ax, renderer, labels) -> tuple[list, list]:
    """What a label must not cover, in display coordinates: ``(paths, boxes)``;
    paths as ``(path, filled, pad)`` (arrows, outlines and lines by their stroke,
    a hatched barrier or a small filled mark as an area; ``pad`` half the line
    width), boxes ``(x0, y0, x1, y1)`` for markers and fixed texts."""
    from matplotlib.patches import FancyArrowPatch

    points = renderer.points_to_pixels(1.0)
    paths, boxes = [], []
    for patch in ax.patches:
        path = patch.get_transform().transform_path(patch.get_path())
        filled = bool(patch.get_hatch()) or (
            patch.get_facecolor()[3] > 0
            and not isinstance(patch, FancyArrowPatch)
            and len(path.vertices) <= 5
        )  # a small filled mark (the front ▶)
        paths += [(part, filled, 0.5 * patch.get_linewidth() * points) for part in _polylines(path)]
    for line in ax.lines:
        xy = line.get_xydata()
        if len(xy) == 1:  # a marker
            x, y = ax.transData.transform(xy[0])
            half = (0.5 * line.get_markersize() + line.get_markeredgewidth()) * points
            boxes.append((x - half, y - half, x + half, y + half))
        else:
            path = line.get_transform().transform_path(line.get_path())
            paths += [(part, False, 0.5 * line.get_linewidth() * points) for part in _polylines(path)]
    for text in ax.texts:
        if text not in labels and text.get_visible() and text.get_text():  # e.g. the flags box
            patch = text.get_bbox_patch()
            boxes.append(tuple((patch or text).get_window_extent(renderer).extents))
    return paths, boxes


def _polylines(path) -> list:
    """A display path as plain polylines (curves flattened, closed parts closed):
    ``Path.intersects_bbox`` would take the placeholder vertex of a CLOSEPOLY
    code (often (0, 0)) for a real point."""
    from matplotlib.path import Path as MplPath

    return [MplPath(polygon) for polygon in path.to_polygons(closed_only=False) if len(polygon) > 1]


def place_labels(ax) -> None:
    """Move each scene label to the nearest position around its anchor where its
    box (text and background) lies inside the axes and touches no arrow, outline,
    line, marker or other text (greedy, in drawing order). A label that finds
    no free place on one line tries two (when it has a two-line form); when
    still none is free, the position running into the fewest things is kept."""
    fig = ax.figure
    if fig.get_layout_engine() is not None:
        # the final axes position: constrained layout around an equal-aspect axes
        # settles on its second pass (the first starts from the unshrunk axes)
        fig.draw_without_rendering()
        fig.draw_without_rendering()
    else:
        ax.apply_aspect()
    renderer = _renderer(fig)
    labels = [text for text in ax.texts if text in _PREFERRED]
    paths, boxes = _obstacles(ax, renderer, labels)
    obstacles = _Obstacles(ax.bbox.extents, paths, boxes)
    for label in labels:
        prefer, wrapped = _PREFERRED[label]
        best = _best_position(label, prefer, renderer, obstacles)
        if best[0] and wrapped:  # no free place: try the label on two lines
            line = label.get_text()
            label.set_text(wrapped)
            best = min(
                best + (line,),
                _best_position(label, prefer, renderer, obstacles) + (wrapped,),
                key=lambda choice: choice[0],
            )
            label.set_text(best[-1])
        _, offset, ha, va, box = best[:5]
        label.xyann = offset
        label.set_horizontalalignment(ha)
        label.set_verticalalignment(va)
        if math.hypot(*offset) > _LEADER_FROM:  # far from its anchor: a thin line says whose label it is
            start, end = _leader_segment(ax.transData.transform(label.xy), box)
            ax.plot(
                *zip(*ax.transData.inverted().transform([start, end])),
                color=label.get_color(),
                lw=0.7,
                alpha=0.7,
                zorder=label.get_zorder() - 0.5,
                gid="leader",
            )
            obstacles.add_leader(start, end)
        obstacles.boxes.append(box)


def _leader_segment(anchor, box):
    """The leader line of a label (display coordinates): from its anchor to the
    nearest point of its box."""
    x, y = anchor
    return (x, y), (min(max(x, box[0]), box[2]), min(max(y, box[1]), box[3]))


class _Obstacles:
    """The axes frame, paths and boxes a label's box is checked against
    (display coordinates). The cheap tests (frame, boxes, path extents) run on
    all candidate boxes at once; the exact path test only where a box reaches
    a path's extent."""

    def __init__(self, frame, paths, boxes):
        import numpy as np

        self.frame, self.paths, self.boxes = np.asarray(frame), paths, boxes
        self.extents = np.array([[*path.get_extents().extents] for path, _, _ in paths]).reshape(-1, 4)
        self.pads = np.array([pad for _, _, pad in paths])
        self.leaders: list = []

    def add_leader(self, start, end) -> None:
        """A leader line drawn: later labels neither cover nor cross it."""
        import numpy as np
        from matplotlib.path import Path as MplPath

        path = MplPath([start, end])
        self.paths.append((path, False, 1.0))
        self.extents = np.vstack([self.extents, path.get_extents().extents])
        self.pads = np.append(self.pads, 1.0)
        self.leaders.append(path)

    def _leader_crosses(self, anchor, box) -> bool:
        """Whether the leader line of a label at ``box`` would cross a placed
        label's box or another leader line."""
        from matplotlib.path import Path as MplPath
        from matplotlib.transforms import Bbox

        start, end = _leader_segment(anchor, box)
        leader = MplPath([start, end])
        return any(
            leader.intersects_bbox(Bbox([other[:2], other[2:]]), filled=False) for other in self.boxes
        ) or any(leader.intersects_path(other) for other in self.leaders)

    def best(self, candidates, anchor, far):
        """``(conflicts, index)`` of the first free box of ``candidates`` (an
        (N, 4) array of x0, y0, x1, y1), else of the one running into the
        fewest things (leaving the axes counts as many; a path whose extent a
        box reaches counts without the exact test). A box ``far`` from its
        ``anchor`` (display coordinates) gets a leader line, which should cross
        no placed label and no other leader: the first free box whose leader
        crosses is taken only when no box is free with its leader."""
        import numpy as np
        from matplotlib.transforms import Bbox

        x0, y0, x1, y1 = (candidates[:, i : i + 1] for i in range(4))
        fx0, fy0, fx1, fy1 = self.frame
        outside = ~((fx0 <= x0) & (x1 <= fx1) & (fy0 <= y0) & (y1 <= fy1))[:, 0]
        b = np.array(self.boxes, dtype=float).reshape(-1, 4)
        hits = ((x0 < b[:, 2]) & (b[:, 0] < x1) & (y0 < b[:, 3]) & (b[:, 1] < y1)).sum(axis=1)
        e, pad = self.extents, self.pads
        near = (x0 - pad <= e[:, 2]) & (e[:, 0] <= x1 + pad) & (y0 - pad <= e[:, 3]) & (e[:, 1] <= y1 + pad)
        cost = 100 * outside + hits + near.sum(axis=1)
        crossing = None
        for index in np.flatnonzero((~outside) & (hits == 0)):
            box = Bbox(candidates[index].reshape(2, 2))
            if any(
                self.paths[k][0].intersects_bbox(box.padded(self.pads[k]), filled=self.paths[k][1])
                for k in np.flatnonzero(near[index])
            ):
                continue
            if far[index] and self._leader_crosses(anchor, candidates[index]):
                crossing = int(index) if crossing is None else crossing
                continue
            return 0, int(index)
        if crossing is not None:  # a free box whose leader crosses: better than a box on something
            return 0, crossing
        index = int(np.argmin(cost))  # the first of the least crowded
        return int(cost[index]) or 1, index


def _best_position(label, prefer: float, renderer, obstacles: _Obstacles):
    """``(conflicts, offset, ha, va, box)``: the first free candidate position
    of ``label``, or the one running into the fewest things. The text's size
    is measured once; a candidate's box follows from its offset and alignment."""
    import numpy as np

    points = renderer.points_to_pixels(1.0)
    pad = 0.25 * label.get_fontsize() * points  # the background box around the text
    label.xyann = (0.0, 0.0)
    label.set_horizontalalignment("center")
    label.set_verticalalignment("center")
    centre = label.get_window_extent(renderer)
    half_w, half_h = 0.5 * centre.width, 0.5 * centre.height
    shift = {"left": 1.0, "right": -1.0, "center": 0.0, "bottom": 1.0, "top": -1.0}
    candidates = list(_candidates(prefer))
    middles = np.array(
        [
            (
                0.5 * (centre.x0 + centre.x1) + dx * points + shift[ha] * half_w,
                0.5 * (centre.y0 + centre.y1) + dy * points + shift[va] * half_h,
            )
            for (dx, dy), ha, va in candidates
        ]
    )
    size = np.array([half_w + pad, half_h + pad])
    boxes = np.hstack([middles - size, middles + size])
    far = np.array([math.hypot(*offset) > _LEADER_FROM for offset, _, _ in candidates])
    cost, index = obstacles.best(boxes, (0.5 * (centre.x0 + centre.x1), 0.5 * (centre.y0 + centre.y1)), far)
    offset, ha, va = candidates[index]
    return cost, offset, ha, va, tuple(boxes[index])
