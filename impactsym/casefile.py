"""Transitional: the case-file language lives in :mod:`impactsym.scene.casefile`.

Only ``batch.py`` (moved into the batch room in a parallel change) still imports
``unknown_key`` from here; the merge points that import at the scene room and
deletes this module."""

from .scene.casefile import unknown_key

__all__ = ["unknown_key"]
