"""`impactsym.uncertainty`: a scene's uncertainty, whichever room answers it.

A ``reconstruct`` scene with run-out data (a top-level ``runout`` object and
rest poses) goes through its fitted run-outs (`impactsym.runout.uncertain`,
as ``impactsym reconstruct SCENE --uncertainty`` does); every other scene to
the engine (`impactsym.uncertainty.propagation.uncertainty`).
"""

from __future__ import annotations

from .runout.scene import has_runout
from .uncertainty import propagation
from .uncertainty.result import Uncertainty


def uncertainty(
    scene,
    command: str = "solve",
    draws: int = 10_000,
    seed: int | None = None,
    sobol: bool = False,
    **crash3_options,
) -> Uncertainty:
    """Uncertainty of ``command``'s answers for a scene whose leaves carry
    distributions (conventions.md, Uncertainty); ``crash3_options``
    (``restitution``, ``energy``, ``correction``) as in
    `impactsym.uncertainty.propagation.uncertainty`."""
    if command == "reconstruct" and has_runout(scene):
        from .runout.uncertain import chained_uncertainty  # not at `import impactsym`

        return chained_uncertainty(scene, draws, seed, sobol)[1]
    return propagation.uncertainty(scene, command, draws, seed, sobol, **crash3_options)
