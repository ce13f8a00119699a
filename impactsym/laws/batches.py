"""Law batches by (model, law): `impactsym.solve_batch` with the model ``"<model>:<law>"``.

The batch room runs a law's registry kernel through the door's runner as it
runs a forward group (columns checked and normalised once, one driver call);
this module only names the law. Columns and outputs: :mod:`impactsym.laws.kernels`.
"""

from __future__ import annotations

from collections.abc import Mapping

from ._door import kernel


def run_batch(model: str, law: str, columns: Mapping) -> dict:
    """Every row of `columns` through the law's kernel. Returns a dict of
    arrays (or a DataFrame for a DataFrame): every forward output, the law's
    extra one (``sliding``, ``slip_class``), `status`, `flags`."""
    # function level: the batch room imports this room's dispatch at module level
    from ..batch.solve import solve_batch

    kernel(model, law)  # an unknown model or law: its one-line error
    return solve_batch(columns, model=f"{model}:{law}")
