"""Reconstruction from evidence: `fit(scene)` and EDR crash-pulse reading.

One answer from all the evidence (EDR speed and delta-V, departure
directions, final motion, energy), with intervals, and a plain statement of
what the evidence cannot determine (conventions.md, "Reconstruction from
evidence"). The observation equations are generated (derive/evidence.py);
this room reads the evidence, solves the weighted least-squares problem and
reports identifiability.
"""

from .edr import read_edr
from .fit import FitResult, fit

__all__ = ["FitResult", "fit", "read_edr"]
