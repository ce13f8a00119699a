"""impactsym: the impact phase of planar vehicle collisions.

Closed forms derived with SymPy (``derive/``) and emitted as numba kernels
(``generated/``) for the two-particle model and Brach's planar rigid-body model,
as reviewed in "A Review of Impact Models for Vehicle Collision", with the
seed's Limpert, Macmillan and IMPAC models as named presets (``MODELS``), CRASH3
(``crash3``) and a side-by-side comparison of them all (``compare``). Frame, signs
and units: conventions.md (n from vehicle 1 toward vehicle 2; P is the impulse
on vehicle 1; lower case initial, upper case final).

    import impactsym
    result = impactsym.solve("examples/two_car_us.json")
    table = impactsym.solve_batch(columns, model="rigid")
    grid = impactsym.sweep("examples/two_car_us.json", e=[0.1, 0.2], mu=[0.0, 0.3])
    draws = impactsym.sample("examples/two_car_us.json", {"e": ("uniform", 0, 0.3)}, 1000, seed=1)
    u = impactsym.uncertainty("case.json", command="reconstruct", draws=100_000, seed=1)
"""

from . import plot
from ._version import __version__ as __version__
from .batch import percentiles, sample, solve_batch, sweep
from .codes import FLAG_MESSAGES, STATUS_MESSAGES, describe_flags, describe_status
from .compare import compare
from .crash3 import crash3
from .energy import delta_v_from_energy
from .evidence import fit, read_edr
from .explore import explore
from .inverse import invert, invert_batch
from .reconstruct import reconstruct, reconstruct_batch
from .result import Result
from .runout import runout, runout_batch
from .scene import MODELS, Impact, Scene, SceneError, Vehicle, load_scene
from .single import solve
from .uncertain_scene import uncertainty

__all__ = [
    "FLAG_MESSAGES",
    "MODELS",
    "STATUS_MESSAGES",
    "Impact",
    "Result",
    "Scene",
    "SceneError",
    "Vehicle",
    "compare",
    "crash3",
    "delta_v_from_energy",
    "describe_flags",
    "describe_status",
    "explore",
    "fit",
    "invert",
    "invert_batch",
    "load_scene",
    "percentiles",
    "read_edr",
    "plot",
    "reconstruct",
    "reconstruct_batch",
    "runout",
    "runout_batch",
    "sample",
    "solve",
    "solve_batch",
    "sweep",
    "uncertainty",
]
