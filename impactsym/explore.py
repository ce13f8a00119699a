"""An interactive explorer for one scene in Jupyter (ipywidgets, optional).

Sliders for the coefficients the scene's model uses (restitution e, impulse
ratio μ, moment restitution e_m; IMPAC's sideswipe ``slip``) and the normal
angle Γ (the crush surface lies along ``t``, at Γ + 90°). Every change
re-solves the scene on the single-scene path (the generated code run as plain
Python: no JIT compile) and redraws the scene diagram (:mod:`impactsym.plot`)
and a readout of delta-V, energy loss and its parts, and the flags.

μ's slider follows the critical ratio μ_c of the current setting: its range
runs from 0 to ``MU_RANGE_FACTOR`` × μ_c (and includes the scene's μ), its
description shows μ_c, the note below it marks the physical range between 0
and μ_c, and the handle turns red outside it. The "μ = μ_c" box solves with
the critical ratio instead (no sliding at separation).

The diagram is drawn on a plain Agg figure and shown as a PNG image widget, so
no interactive matplotlib backend is needed. Updates take a few ms to solve
and a few tens of ms to draw (``Explorer.timings``; notebooks/07_explorer.ipynb
measures them).

Needs ``pip install 'impactsym[explore]'`` (ipywidgets and matplotlib).
"""

from __future__ import annotations

import copy
import html
import io
import math
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ._util import require
from .result import UNIT_LABELS
from .scene import CRITICAL, Scene, SceneError, load_scene
from .single import solve

__all__ = ["explore", "Explorer", "MU_RANGE_FACTOR"]

#: μ's slider reaches this multiple of μ_c (beyond μ_c the result is flagged).
MU_RANGE_FACTOR = 1.5

_COEFFICIENTS = ("restitution", "impulse_ratio", "moment_restitution", "slip")


def explore(scene: Scene | Mapping | str | Path) -> Explorer:
    """Build the explorer of a forward scene (a Scene, a mapping or a file path).

    The returned :class:`Explorer` shows itself as the widget when it is a
    notebook cell's value (``impactsym.explore("examples/intersection_si.toml")``);
    ``.widget`` is the widget, ``.result`` the current result.
    """
    return Explorer(scene)


class Explorer:
    """The explorer's state: the base scene, the widgets, the current result.

    ``sliders`` maps ``restitution``, ``impulse_ratio``, ``moment_restitution``,
    ``slip`` and ``normal_angle`` to their sliders (the ones the model does not
    use are hidden and disabled); ``critical`` is the "μ = μ_c" checkbox.
    :meth:`update` re-solves with the widgets' values and redraws; every
    widget change calls it, and tests call it directly (no display needed).
    ``last_timing`` is ``(solve, draw)`` in seconds for the last update,
    ``timings`` the total of every update.
    """

    def __init__(self, scene: Scene | Mapping | str | Path, *, figsize=(8.5, 5.2), dpi: int = 80):
        widgets = require("ipywidgets", extra="explore", what="impactsym.explore")
        require("matplotlib", extra="explore", what="impactsym.explore", load=False)
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        from .pictures import diagram, labels

        self._diagram, self._labels = diagram, labels
        self.scene = load_scene(scene)
        if self.scene.source is not None:
            self.name = self.scene.source.name
        else:
            self.name = "scene"
        self.base = self.scene.to_dict()
        from ._kernels import PRESETS

        preset = PRESETS[self.scene.model]
        self.used = tuple(key for key in _COEFFICIENTS if key in (*preset["required"], *preset["optional"]))
        self.fixed_critical = preset["fixed"].get("impulse_ratio") == CRITICAL
        impact = self.scene.impact
        self.result = None
        self.error: str | None = None
        self.last_timing = (0.0, 0.0)
        self.timings: list[float] = []
        self._busy = False
        self._limits = None

        def coefficient(key, default):
            value = getattr(impact, key, None)
            return default if value is None or (isinstance(value, float) and math.isnan(value)) else value

        critical = bool(impact.critical) or self.fixed_critical
        mu = coefficient("impulse_ratio", 0.0)
        mu = 0.0 if mu == CRITICAL else float(mu)
        style = {"description_width": "110px"}
        layout = widgets.Layout(width="340px")
        self.sliders = {
            "restitution": widgets.FloatSlider(
                value=float(coefficient("restitution", 0.0)),
                min=0.0,
                max=1.0,
                step=0.01,
                description="e",
                style=style,
                layout=layout,
                continuous_update=True,
            ),
            "impulse_ratio": widgets.FloatSlider(
                value=mu,
                min=min(mu, 0.0) - 0.1,
                max=max(mu, 0.0) + 0.1,
                step=0.001,
                description="μ",
                readout_format=".3f",
                style=dict(style),
                layout=layout,
            ),
            "moment_restitution": widgets.FloatSlider(
                value=float(coefficient("moment_restitution", 1.0)),
                min=-1.0,
                max=1.0,
                step=0.01,
                description="e_m",
                style=style,
                layout=layout,
            ),
            "slip": widgets.FloatSlider(
                value=float(coefficient("slip", 0.0)),
                min=0.0,
                max=1.0,
                step=0.01,
                description="slip",
                style=style,
                layout=layout,
            ),
            "normal_angle": widgets.FloatSlider(
                value=impact.normal_angle,
                min=impact.normal_angle - 90.0,
                max=impact.normal_angle + 90.0,
                step=1.0,
                description="crush Γ [°]",
                style=style,
                layout=layout,
                tooltip="normal angle Γ: the crush surface lies along t, at Γ + 90°",
            ),
        }
        self.critical = widgets.Checkbox(
            value=critical,
            description="μ = μ_c (critical)",
            disabled=self.fixed_critical or "impulse_ratio" not in self.used,
            indent=False,
            layout=widgets.Layout(margin="0 0 0 114px"),
        )
        self.mu_note = widgets.HTML(layout=widgets.Layout(margin="0 0 0 114px"))
        self.angle_note = widgets.HTML(layout=widgets.Layout(margin="0 0 0 114px"))
        for key, slider in self.sliders.items():
            if key != "normal_angle" and key not in self.used:
                slider.disabled = True
                slider.layout.display = "none"
        if "impulse_ratio" not in self.used:
            self.critical.layout.display = "none"
            self.mu_note.layout.display = "none"
        self.readout = widgets.HTML()
        self.image = widgets.Image(format="png")
        self._figure = Figure(figsize=figsize, dpi=dpi)
        self._canvas = FigureCanvasAgg(self._figure)
        self._ax = self._figure.add_axes((0.07, 0.1, 0.6, 0.8))
        self._background = self._background_key = None
        self._full_redraws = 0
        self._velocity_scale = None

        for slider in self.sliders.values():
            slider.observe(self._changed, names="value")
        self.critical.observe(self._changed, names="value")
        controls = widgets.VBox(
            [
                widgets.HTML(self._header_html(preset)),
                self.sliders["restitution"],
                self.sliders["impulse_ratio"],
                self.critical,
                self.mu_note,
                self.sliders["moment_restitution"],
                self.sliders["slip"],
                self.sliders["normal_angle"],
                self.angle_note,
                self.readout,
            ],
            layout=widgets.Layout(width="380px"),
        )
        self.widget = widgets.HBox([controls, self.image])
        self.update()

    def _header_html(self, preset: Mapping) -> str:
        names = {"restitution": "e", "impulse_ratio": "μ", "moment_restitution": "e_m"}
        fixed = ", ".join(
            f"{names.get(key, key)} = {'μ_c' if value == CRITICAL else value}"
            for key, value in preset["fixed"].items()
        )
        text = (
            f"<b>{html.escape(self.name)}</b>: {html.escape(self.scene.model)} model, "
            f"{self.scene.units} units"
        )
        if fixed:
            text += f"<br><small>fixed by the model: {html.escape(fixed)}</small>"
        return text

    # ------------------------------------------------------------------ state

    def current_scene(self) -> dict:
        """The base scene (scene-file form) with the widgets' coefficients and normal angle."""
        data = copy.deepcopy(self.base)
        impact = data["impact"]
        for key in self.used:
            impact[key] = self.sliders[key].value
        if "impulse_ratio" in self.used and self.critical.value:
            impact["impulse_ratio"] = CRITICAL
        impact["normal_angle"] = self.sliders["normal_angle"].value
        return data

    def _changed(self, _change) -> None:
        if not self._busy:
            self.update()

    def update(self) -> None:
        """Re-solve with the widgets' values; update μ's range and marks, the readout and the diagram."""
        if self._busy:
            return
        self._busy = True
        try:
            begin = time.perf_counter()
            data = self.current_scene()
            try:
                self.result, self.error = solve(data), None
            except SceneError as exc:
                self.result, self.error = None, str(exc)
            solved = time.perf_counter()
            self._update_mu()
            self.readout.value = self._readout_html()
            self._draw(data)
            done = time.perf_counter()
            self.last_timing = (solved - begin, done - solved)
            self.timings.append(done - begin)
        finally:
            self._busy = False

    # ------------------------------------------------------------------ μ

    def _update_mu(self) -> None:
        slider = self.sliders["impulse_ratio"]
        gamma = self.sliders["normal_angle"].value
        self.angle_note.value = (
            f"<small>normal Γ = {gamma:g}°, crush surface along "
            f"{(gamma + 90.0 + 180.0) % 360.0 - 180.0:g}°</small>"
        )
        if "impulse_ratio" not in self.used:
            return
        critical = self.critical.value
        slider.disabled = critical
        mu_c = self.result.mu_c if self.result is not None else math.nan
        if not math.isfinite(mu_c):
            slider.description = "μ (μ_c = ?)"
            self.mu_note.value = "<small>μ_c unknown for this setting</small>"
            return
        mu = mu_c if critical else slider.value
        lo, hi = mu_range(mu_c, mu)
        _set_range(slider, lo, hi)
        if critical:
            slider.value = mu_c
        slider.description = f"μ (μ_c={mu_c:.3g})"
        inside = min(0.0, mu_c) - 1e-12 <= mu <= max(0.0, mu_c) + 1e-12
        slider.style.handle_color = None if inside else "crimson"
        span = f"{min(0.0, mu_c):.3g} … {max(0.0, mu_c):.3g}"
        if inside:
            self.mu_note.value = f"<small>physical: μ between 0 and μ_c ({span})</small>"
        else:
            self.mu_note.value = (
                f"<small style='color:crimson'>μ = {mu:.3g} is beyond the physical "
                f"range {span}: flagged</small>"
            )

    # ------------------------------------------------------------------ readout and diagram

    def _setting_html(self) -> str:
        """The current setting in scene-file terms (what to copy into the file)."""
        names = {"restitution": "e", "impulse_ratio": "μ", "moment_restitution": "e_m", "slip": "slip"}
        parts = [f"Γ = {self.sliders['normal_angle'].value:g}°"]
        for key in self.used:
            if key == "impulse_ratio" and self.critical.value:
                parts.append("μ = critical")
            else:
                parts.append(f"{names[key]} = {self.sliders[key].value:.3g}")
        return f"<div><small>{', '.join(parts)}</small></div>"

    def _readout_html(self) -> str:
        setting = self._setting_html()
        if self.result is None:
            return (
                f"{setting}<p style='color:crimson'><b>cannot solve:</b> {html.escape(self.error or '')}</p>"
            )
        r = self.result
        labels = UNIT_LABELS[r.units]
        speed, energy = labels["velocity"], labels["energy"]
        rows = []
        for vehicle in r.vehicles:
            dx, dy = vehicle.delta_v
            direction = (
                f" at {math.degrees(math.atan2(dy, dx)) % 360.0:.0f}°"
                if vehicle.delta_v_magnitude > 0
                else ""
            )
            rows.append(
                (f"|ΔV| {html.escape(vehicle.name)}", f"{vehicle.delta_v_magnitude:.4g} {speed}{direction}")
            )
        rows += [
            ("energy loss TL", f"{r.TL:.5g} {energy}"),
            ("&nbsp;&nbsp;normal TLn", f"{r.TLn:.5g} {energy}"),
            ("&nbsp;&nbsp;tangential TLt", f"{r.TLt:.5g} {energy}"),
            ("&nbsp;&nbsp;moment TLm", f"{r.TLm:.5g} {energy}"),
            ("μ used / μ_c", f"{r.mu:.4g} / {r.mu_c:.4g}"),
        ]
        body = "".join(f"<tr><td style='padding-right:1em'>{k}</td><td>{v}</td></tr>" for k, v in rows)
        if r.flags:
            flags = "".join(f"<li>{html.escape(text)}</li>" for text in r.warnings)
            status = f"<div style='color:crimson'><b>flags {r.flags}:</b><ul>{flags}</ul></div>"
        else:
            extra = "".join(f"<li>{html.escape(text)}</li>" for text in r.warnings)
            status = "<div style='color:green'><b>flags: none</b></div>" + (
                f"<ul>{extra}</ul>" if extra else ""
            )
        return f"{setting}<table>{body}</table>{status}"

    def _draw(self, data: dict) -> None:
        """Redraw the diagram into the image widget.

        The axes, ticks, grid and legend change only when the limits or the
        legend's entries do; they are drawn then and kept as a background, and
        an ordinary update restores it and draws only the scene's own artists
        on top (blitting on the Agg canvas), which keeps an update fast.
        """
        from PIL import Image

        ax, canvas = self._ax, self._canvas
        for artist in [*ax.patches, *ax.lines, *ax.texts]:
            artist.remove()
        source: Any = data if self.result is None else self.result
        options = {"scene": data} if self.result is not None else {}
        if self._velocity_scale is None:
            self._velocity_scale = self._diagram.default_velocity_scale(source, **options)
        # no title on the picture: the header and readout carry it (a title costs ~7 ms to draw)
        handles, legend_title = self._diagram.render(
            ax, source, velocity_scale=self._velocity_scale, title="", **options
        )
        limits = (ax.get_xlim(), ax.get_ylim())
        limits = _grown(self._limits, limits)
        ax.set_xlim(*limits[0])
        ax.set_ylim(*limits[1])
        self._labels.place_labels(ax)  # now that the limits are final
        dynamic = sorted(
            [*ax.patches, *ax.lines, *ax.texts, ax.title], key=lambda artist: artist.get_zorder()
        )
        for artist in dynamic:
            artist.set_animated(True)
        key = (limits, legend_title, tuple(handle.get_label() for handle in handles))
        if self._background is None or key != self._background_key:
            self._diagram.add_legend(ax, handles, legend_title)
            canvas.draw()  # everything but the animated (scene) artists
            self._background, self._background_key = canvas.copy_from_bbox(self._figure.bbox), key
            self._full_redraws += 1
        else:
            canvas.restore_region(self._background)
        self._limits = limits
        renderer = canvas.get_renderer()
        for artist in dynamic:
            artist.draw(renderer)
        width, height = canvas.get_width_height()
        image = Image.frombuffer("RGBA", (width, height), canvas.buffer_rgba(), "raw", "RGBA", 0, 1)
        buffer = io.BytesIO()
        image.convert("RGB").save(buffer, format="png", compress_level=1)
        self.image.value = buffer.getvalue()

    def _repr_mimebundle_(self, **kwargs):
        """Show the widget when the explorer is a notebook cell's value."""
        return self.widget._repr_mimebundle_(**kwargs)


def _grown(old, new, headroom: float = 0.15):
    """Axis limits that only grow, so the picture does not jump as sliders move;
    when ``new`` does not fit in ``old`` the union gets some headroom, so the
    background (ticks, legend) is redrawn only now and then."""
    if old is None:
        return new
    grown = []
    for (a0, a1), (b0, b1) in zip(old, new):
        if b0 >= a0 and b1 <= a1:
            grown.append((a0, a1))
            continue
        low, high = min(a0, b0), max(a1, b1)
        pad = headroom * (high - low)
        grown.append((low - pad if b0 < a0 else low, high + pad if b1 > a1 else high))
    return tuple(grown)


def mu_range(mu_c: float, mu: float) -> tuple[float, float]:
    """μ's slider range: from 0 to ``MU_RANGE_FACTOR`` × μ_c (either sign), a
    little past 0 on the other side, and always including ``mu``."""
    span = max(abs(mu_c), 0.05)
    lo = min(-0.1 * span, MU_RANGE_FACTOR * mu_c, mu)
    hi = max(0.1 * span, MU_RANGE_FACTOR * mu_c, mu)
    return lo, hi


def _set_range(slider, lo: float, hi: float) -> None:
    """Set a slider's min and max without passing through min > max."""
    if lo > slider.max:
        slider.max, slider.min = hi, lo
    else:
        slider.min, slider.max = lo, hi
    slider.step = 10.0 ** math.floor(math.log10((hi - lo) / 200.0))
