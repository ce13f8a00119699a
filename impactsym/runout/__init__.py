"""Post-impact run-out: from separation to rest, and fitted back from rest
(conventions.md, "Post-impact run-out"; model and proofs in derive/runout.py)."""

from .api import runout
from .batch import runout_batch
from .fit import fit_rest, starting_estimate
from .scene import load_runout

__all__ = ["fit_rest", "load_runout", "runout", "runout_batch", "starting_estimate"]
