"""A fit read as an alternative impact law (issue 25, "in fit as an alternative law").

The fit itself is law-free: it finds the pre-impact motion and the impulse, and
reads them in Brach's terms (e, mu, mu_c). A fit scene with ``"model":
"kudlich_slibar"`` also reads that answer as the Kudlich–Slibar law of PC-Crash:
the Poisson ε, the contact ("full" or "sliding") and the friction that give the
fitted impulse on the fitted pre-impact motion (impactsym.laws.convert.pim_to_ks;
``exact`` false when no K–S contact gives it). A point estimate at the fit: no
interval.
"""

from __future__ import annotations

import numpy as np

from ..laws.convert import pim_to_ks
from .case import STATE, FitCase

_PARAMS = ("m1", "m2", "I1", "I2", "r1x", "r1y", "r2x", "r2y", "gamma")
_NO_KS = (
    "no Kudlich-Slibar contact gives the fitted impulse (its impulse ratio is beyond the full "
    "impact's, or drags against the slip)"
)


def law_reading(case: FitCase, z, derived, estimates) -> dict | None:
    """The ``law`` object of the fit's JSON, or None for a rigid fit scene.
    `z` is the fitted state (STATE), `derived` evidence_derived at the fit."""
    if case.law is None:
        return None
    reading = {"model": case.law, "restitution": None, "contact": None, "friction": None, "exact": None}
    why = _unread(case, derived, estimates)
    if why:
        return reading | {"determined": False, "why": why}
    columns = {k: np.array([float(case.params[k])]) for k in _PARAMS}
    columns |= {name: np.array([float(v)]) for name, v in zip(STATE[:6], z[:6])}
    columns |= {"e": np.array([derived["e"]]), "mu": np.array([derived["mu"]]), "e_m": np.array([1.0])}
    ks = pim_to_ks(columns)
    if ks["status"][0] != 0:
        return reading | {
            "determined": False,
            "why": f"the rigid solve at the fit failed (status {ks['status'][0]})",
        }
    sliding, exact = bool(ks["sliding"][0]), bool(ks["exact"][0])
    reading.update(
        restitution=float(ks["eps"][0]),
        contact="sliding" if sliding else "full",
        friction=float(ks["mu_f"][0]) if sliding else None,
        exact=exact,
    )
    return reading | ({"determined": True} if exact else {"determined": False, "why": _NO_KS})


def _unread(case: FitCase, derived, estimates) -> str:
    """Why the fit cannot be read as the law ('' when it can)."""
    if case.moment:
        return "a moment impulse is fitted (impact.moment_restitution): Kudlich-Slibar is a point impulse"
    if derived is None:
        return "needs impact.normal_angle: the law splits the impulse into normal and tangential parts"
    for path in ("restitution", "impulse_ratio"):
        if path in estimates and not estimates[path].determined:
            return f"{path} is not determined: {estimates[path].why}"
    if derived["status"] != 0:
        return "e and mu are not defined at the estimate"
    return ""


def law_line(reading: dict) -> str:
    """One line of the fit table for the law reading."""
    if not reading["determined"] and reading["restitution"] is None:
        return f"read as {reading['model']}: not determined ({reading['why']})"
    friction = "" if reading["friction"] is None else f", friction {reading['friction']:.4g}"
    head = f"read as {reading['model']}: epsilon {reading['restitution']:.4g}, {reading['contact']} contact{friction}"
    return head + ("" if reading["exact"] else f" (not exact: {reading['why']})")
