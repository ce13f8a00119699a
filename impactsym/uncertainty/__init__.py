"""Uncertainty of a scene's answers (docs/uncertainty.md): the engine
(``propagation``: Monte Carlo, first-order propagation, budget, Sobol), its
inputs (``inputs``: distributions and the Gaussian copula), the command maps
(``commands``: kernel columns -> the command's JSON numbers), the statistics
(``result``), the CLI options (``cli``) and the figure (``plot``).

``impactsym.uncertainty`` (the package's attribute) is the function
:func:`~impactsym.uncertainty.propagation.uncertainty`; the modules are reached
as ``impactsym.uncertainty.propagation`` and so on.
"""

from .propagation import Source, propagate, uncertainty
from .result import Stats, Uncertainty

__all__ = ["Source", "Stats", "Uncertainty", "propagate", "uncertainty"]
