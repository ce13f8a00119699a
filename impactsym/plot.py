"""Pictures of scenes, results and sweeps (matplotlib; ``pip install 'impactsym[plot]'``).

The public face of :mod:`impactsym.pictures`: :func:`scene` and
:func:`save_plot` draw a scene or a solved scene (a CRASH3 result as its CRASH3
diagram; :func:`crash3_figure` that diagram alone), :func:`sweep` and :func:`save_sweep` a parameter sweep,
:func:`add_plot_argument` gives a command its ``--plot PATH`` option and
:func:`default_velocity_scale` the arrow scale :func:`scene` would choose.
matplotlib is imported inside the functions, so ``import impactsym`` neither
needs nor loads it.
"""

from .pictures.argument import add_plot_argument
from .pictures.crash3 import crash3_figure
from .pictures.diagram import default_velocity_scale, save_plot, scene
from .pictures.inputs import PRE_IMPACT_KINDS
from .pictures.sweep import save_sweep, sweep

__all__ = [
    "scene",
    "save_plot",
    "sweep",
    "save_sweep",
    "add_plot_argument",
    "default_velocity_scale",
    "crash3_figure",
    "PRE_IMPACT_KINDS",
]
