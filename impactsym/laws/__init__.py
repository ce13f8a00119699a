"""The impact laws other tools use, and one that never creates energy (conventions.md, "Other impact laws").

* Kudlich–Slibar (PC-Crash, Virtual CRASH): ``"model": "kudlich_slibar"``.
* The Coulomb process with Newton, Poisson or energetic restitution:
  ``"model": "coulomb"``.

Per scene: :func:`solve_law` (also reached through :func:`impactsym.solve`).
Batches: :func:`kudlich_slibar_batch`, :func:`coulomb_batch` (columns as in
:mod:`impactsym.laws.kernels`). Conversions between K–S's ε and Brach's
(e, μ): :func:`ks_to_pim`, :func:`pim_to_ks`.
"""

from __future__ import annotations

from .batches import run_batch
from .convert import ks_to_pim, pim_to_ks
from .kernels import LAWS, SLIP_CLASSES
from .scene import LAW_MODELS, LawScene, is_law_scene, load_law_scene
from .single import LawResult, solve_law

__all__ = [
    "LAWS",
    "LAW_MODELS",
    "SLIP_CLASSES",
    "LawResult",
    "LawScene",
    "coulomb_batch",
    "is_law_scene",
    "kudlich_slibar_batch",
    "ks_to_pim",
    "load_law_scene",
    "pim_to_ks",
    "solve_law",
]


def kudlich_slibar_batch(columns, contact: str = "full") -> dict:
    """Kudlich–Slibar, one scene per row: ``contact`` "full" or "sliding" (then
    a ``mu_f`` column). Columns and outputs: :mod:`impactsym.laws.kernels`."""
    return run_batch("kudlich_slibar", contact, columns)


def coulomb_batch(columns, restitution_law: str = "newton") -> dict:
    """The Coulomb process, one scene per row, ended by ``restitution_law``
    ("newton", "poisson", "energetic"); ``mu_f`` is the friction coefficient.
    Adds ``slip_class`` (0 continues, 1 stops, 2 reverses)."""
    return run_batch("coulomb", restitution_law, columns)
