"""Transitional: the uncertainty engine lives in :mod:`impactsym.uncertainty.propagation`.

Only ``benchmarks/uncertainty.py`` (changed in a parallel branch) still imports
it from here; the merge points it at the uncertainty room and deletes this module."""

from .uncertainty.propagation import *  # noqa: F403
from .uncertainty.propagation import __all__ as __all__
