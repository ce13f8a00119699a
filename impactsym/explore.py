"""An interactive explorer for one scene in Jupyter (ipywidgets, optional).

Sliders for restitution e, impulse ratio μ (its description shows the current
critical ratio μ_c), moment restitution e_m and the crush-surface (normal)
angle; every change re-solves the scene on the single-scene path (the
generated code run as plain Python: no JIT compile) and redraws the diagram
and a readout of delta-V, energy loss and its parts, and the flags.
"""

from __future__ import annotations

import copy
import html
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Union

from .result import UNIT_LABELS
from .scene import Scene, SceneError, load_scene
from .single import solve

INSTALL_HINT = "impactsym.explore needs ipywidgets and matplotlib: pip install 'impactsym[explore]'"


def explore(scene: Union[Scene, Mapping, str, Path]):
    """Build the explorer for a forward scene and return its widget (display it
    in a notebook cell, or let the cell show it as its value)."""
    return Explorer(scene).widget


class Explorer:
    """The explorer's state: the base scene, the sliders, the last result.

    `update()` re-solves with the sliders' values and redraws; it is what every
    slider change calls, and tests call it directly (no display needed).
    `last_timing` holds the seconds spent solving and drawing in the last update.
    """

    def __init__(self, scene: Union[Scene, Mapping, str, Path]):
        try:
            import ipywidgets as widgets
        except ImportError:
            raise ImportError(INSTALL_HINT) from None
        self.scene = load_scene(scene)
        self.base = self.scene.to_dict()
        impact = self.scene.impact
        mu_c = abs(self._critical_ratio(self.base))
        start_mu = mu_c if impact.critical else float(impact.impulse_ratio)
        span = max(2.0 * mu_c, abs(start_mu), 0.5)
        self.sliders = {
            "restitution": widgets.FloatSlider(value=impact.restitution, min=0.0, max=1.0,
                                               step=0.01, description="e"),
            "impulse_ratio": widgets.FloatSlider(value=start_mu, min=-span, max=span,
                                                 step=span / 200, description="μ"),
            "moment_restitution": widgets.FloatSlider(
                value=impact.moment_restitution if impact.moment_restitution is not None else 1.0,
                min=-1.0, max=1.0, step=0.01, description="e_m"),
            "normal_angle": widgets.FloatSlider(value=impact.normal_angle,
                                                min=impact.normal_angle - 90.0,
                                                max=impact.normal_angle + 90.0, step=1.0,
                                                description="Γ [deg]"),
        }
        self.readout = widgets.HTML()
        self.figure = widgets.Output()
        self.result = None
        self.last_timing = (0.0, 0.0)
        for slider in self.sliders.values():
            slider.observe(lambda _change: self.update(), names="value")
        self.widget = widgets.VBox([widgets.HBox([widgets.VBox(list(self.sliders.values())),
                                                  self.readout]), self.figure])
        self.update()

    def current_scene(self) -> dict:
        """The base scene with the sliders' coefficients and normal angle."""
        data = copy.deepcopy(self.base)
        for key, slider in self.sliders.items():
            data["impact"][key] = slider.value
        return data

    def update(self) -> None:
        """Re-solve, update μ's description with μ_c, redraw and refresh the readout."""
        data = self.current_scene()
        start = time.perf_counter()
        try:
            self.result = solve(data)
            mu_c = self._critical_ratio(data)
        except SceneError as exc:
            self.result = None
            self.readout.value = f"<b>cannot solve:</b> {html.escape(str(exc))}"
            return
        solved = time.perf_counter()
        self.sliders["impulse_ratio"].description = f"μ (μ_c={mu_c:.3g})"
        self.readout.value = self._readout_html()
        self._draw(data)
        self.last_timing = (solved - start, time.perf_counter() - solved)

    def _critical_ratio(self, data: dict) -> float:
        critical = copy.deepcopy(data)
        critical["impact"]["impulse_ratio"] = "critical"
        return solve(critical).mu_c

    def _readout_html(self) -> str:
        r = self.result
        labels = UNIT_LABELS[r.units]
        rows = [(f"|ΔV| {v.name}", f"{v.delta_v_magnitude:.3g} {labels['velocity']}")
                for v in r.vehicles]
        rows += [("TL", f"{r.TL:.4g} {labels['energy']}"),
                 ("TLn / TLt / TLm", f"{r.TLn:.3g} / {r.TLt:.3g} / {r.TLm:.3g}"),
                 ("μ_c", f"{r.mu_c:.4g}"),
                 ("flags", ", ".join(html.escape(w) for w in r.warnings) or "none")]
        body = "".join(f"<tr><td>{k}</td><td>{v}</td></tr>" for k, v in rows)
        return f"<table>{body}</table>"

    def _draw(self, data: dict) -> None:
        import matplotlib.pyplot as plt

        from .plot import scene as draw_scene

        self.figure.clear_output(wait=True)
        with self.figure:
            fig, ax = plt.subplots(figsize=(8, 5.5))
            draw_scene(self.result, ax, scene=data)
            plt.show()
            plt.close(fig)

