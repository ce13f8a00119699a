"""Reading a Kudlich–Slibar case in Brach's terms, and back.

Both are point-impulse models with the same normal restitution (K–S's Poisson
ε at a constant impulse ratio is Newton's e: the final normal relative
velocity is -ε times the initial, proved in derive/kudlich_slibar.py), so:

* K–S → PIM: e = ε and μ = the K–S impulse ratio Pt/Pn (for a full impact,
  Brach's critical ratio at e = 0, not at e = ε) give the same impulse.
* PIM → K–S: ε = e; the full contact when μ is K–S's full ratio, otherwise the
  sliding contact with friction |μ|, which gives the same impulse only when μ
  drags vehicle 1 along the slip (Pt of the slip's sign) and |μ| is below the
  full impact's ratio; other rows have no K–S equivalent (``exact`` false).
"""

from __future__ import annotations

import numpy as np

from .batches import run_batch

#: Relative agreement of the impulses taken as "the same impulse".
SAME = 1e-9


def ks_to_pim(columns, contact: str = "full") -> dict:
    """Brach's (e, μ) (e_m = 1) that give each row's K–S impulse: ``e``, ``mu``,
    with the K–S ``Pn``, ``Pt`` and ``status``."""
    out = run_batch("kudlich_slibar", contact, {k: v for k, v in columns.items() if k not in ("mu", "e_m")})
    return {
        "e": np.asarray(columns["e"], dtype=float) + 0 * out["Pn"],
        "mu": out["mu"],
        "Pn": out["Pn"],
        "Pt": out["Pt"],
        "status": out["status"],
    }


def pim_to_ks(columns) -> dict:
    """K–S's (ε, contact, friction) for Brach's (e, μ) of each row (columns of
    the rigid batch with e_m = 1): ``eps``, ``sliding`` (1: sliding contact),
    ``mu_f``, and ``exact`` (the K–S impulse equals Brach's to SAME)."""
    from ..batch.solve import solve_batch  # the rigid family's batch (Brach)

    rigid = {k: columns[k] for k in columns if k != "mu_f"}
    rigid.setdefault("e_m", 1.0)
    brach = solve_batch(rigid, model="rigid")
    law = {k: v for k, v in rigid.items() if k not in ("mu", "e_m")}
    full = run_batch("kudlich_slibar", "full", law)
    mu = np.asarray(brach["mu"], dtype=float)
    sliding = ~_same(full["Pt"], brach["Pt"], brach["Pn"]) | ~_same(full["Pn"], brach["Pn"], brach["Pt"])
    slide = run_batch("kudlich_slibar", "sliding", dict(law, mu_f=np.abs(mu)))
    pn = np.where(sliding, slide["Pn"], full["Pn"])
    pt = np.where(sliding, slide["Pt"], full["Pt"])
    exact = _same(pn, brach["Pn"], brach["Pt"]) & _same(pt, brach["Pt"], brach["Pn"])
    return {
        "eps": np.asarray(rigid["e"], dtype=float) + 0 * mu,
        "sliding": sliding.astype(np.int64),
        "mu_f": np.where(sliding, np.abs(mu), np.nan),
        "exact": exact,
        "status": brach["status"],
    }


def _same(a, b, other):
    """|a - b| within SAME of the impulse's size."""
    scale = np.hypot(b, other)
    return np.abs(np.asarray(a) - np.asarray(b)) <= SAME * scale
