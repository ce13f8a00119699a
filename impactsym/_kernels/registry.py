"""The one importer of generated/: the kernel registry and each kernel's code.

generated/registry.py (emitted by `python -m derive`) lists every kernel with
its family, variant, columns and outputs, and the tables the runtime needs
(output tiers, status codes, flags, presets). This module reads it and hands
out `KernelSet`s: a kernel's registry row plus, imported on first use, its
per-scene function (generated/<module>.py, plain Python) and its numba driver
(generated/<module>_jit.py). Nothing here writes a kernel's name or outputs:
they are all the registry's.
"""

from __future__ import annotations

import importlib
import os
import sys
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from types import SimpleNamespace

try:  # an installed wheel maps generated/ into the package
    from .. import _generated as generated
except ImportError:  # a checkout (or editable install): generated/ at the top
    import generated

if getattr(generated, "IMPACTSYM_GENERATED", None) != "impactsym":
    raise ImportError(
        f"the module 'generated' at {getattr(generated, '__file__', '?')} is not "
        "impactsym's generated kernels (another package named 'generated' shadows it)"
    )

TABLE = importlib.import_module(f"{generated.__name__}.registry")
PRESETS = TABLE.PRESETS
COEFFICIENT_INPUTS = TABLE.COEFFICIENT_INPUTS
TIERS_GIVEN = TABLE.TIERS
FAMILY_OUTPUTS = TABLE.FAMILY_OUTPUTS
SINCOS_LIMIT = TABLE.SINCOS_LIMIT
#: Status codes and flag bits as attributes: CODES.STATUS_OVERFLOW, CODES.FLAG_PDOF_CAPPED.
CODES = SimpleNamespace(
    **{f"STATUS_{k}": v for k, v in TABLE.STATUS.items()}, **{f"FLAG_{k}": v for k, v in TABLE.FLAGS.items()}
)


@cache
def module(name: str):
    """generated/<name>.py (plain Python), or with `_jit` its numba drivers.

    Families that emit a loop rather than straight-line kernels (the run-out's
    integrator) are reached by module through here: their rooms take their
    columns, outputs and codes from that module's plain half."""
    if name.endswith("_jit"):
        _set_numba_cache_dir()
    return importlib.import_module(f"{generated.__name__}.{name}")


def _set_numba_cache_dir() -> None:
    """A read-only install (generated/ not writable) caches compiled drivers
    in the user's cache directory; NUMBA_CACHE_DIR, when set, wins. Numba
    reads the variable when it is first imported, so this runs before that."""
    if "NUMBA_CACHE_DIR" in os.environ or "numba" in sys.modules:
        return
    here = Path(generated.__file__).resolve().parent
    if not os.access(here, os.W_OK):
        base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
        os.environ["NUMBA_CACHE_DIR"] = str(Path(base) / "impactsym" / "numba")


@dataclass(frozen=True)
class KernelSet:
    """One generated kernel, as its registry row gives it.

    `inputs` are the batch columns, `arguments` the per-scene function's
    (nx, ny in place of the angle for a kernel in normal form), `driver_columns`
    the driver's (the angle, then nx, ny), `outputs` the computed outputs and
    `constants` the outputs the kernel fixes to a number (e_m = 1: M = 0;
    a model without that output: particles' W1), which its driver writes after
    `outputs` (`driver_outputs`); `integers` the outputs coding a class, int64
    columns of the driver (-1 on a failed row).
    `scene`, `unit_normal` (plain Python) and `driver` (numba) are imported on
    first access."""

    name: str
    family: str
    variant: tuple
    module: str
    inputs: tuple[str, ...]
    arguments: tuple[str, ...]
    driver_columns: tuple[str, ...] | None
    outputs: tuple[str, ...]
    constants: dict
    integers: tuple[str, ...]
    angle: str | None
    operations: int

    @property
    def driver_outputs(self) -> tuple[str, ...]:
        """The columns a driver writes, in order (then status and flags)."""
        return self.outputs + tuple(self.constants)

    @property
    def scene(self):
        """The per-scene function (plain Python)."""
        return getattr(module(self.module), self.name)

    @property
    def unit_normal(self):
        """(nx, ny) of an angle [rad], as the kernels take it; None without an angle."""
        return module(self.module).unit_normal if self.angle else None

    @property
    def driver(self):
        """The numba batch driver (imports numba and the module's drivers)."""
        return getattr(module(f"{self.module}_jit"), f"{self.name}_batch")


@cache
def kernel(name: str) -> KernelSet:
    """The kernel of that registry name; KeyError if there is none."""
    row = TABLE.KERNELS[name]
    return KernelSet(
        name=name,
        family=row["family"],
        variant=tuple(row["variant"].items()),
        module=row["module"],
        inputs=row["columns"],
        arguments=row["arguments"],
        driver_columns=row["driver"],
        outputs=row["outputs"],
        constants=row["constants"],
        integers=row["integers"],
        angle=row["angle"],
        operations=row["operations"],
    )


@cache
def family(name: str) -> tuple[KernelSet, ...]:
    """Every kernel of a family, in registry order (the general one first)."""
    return tuple(kernel(k) for k, row in TABLE.KERNELS.items() if row["family"] == name)


@cache
def select(family_name: str, **variant) -> KernelSet:
    """The most specialised kernel of a family that serves `variant`: of the
    kernels whose variant is part of it (so every specialisation they make
    is asked for), the one with the most; ValueError if the family has none."""
    wanted = set(variant.items())
    fitting = [k for k in family(family_name) if set(k.variant) <= wanted]
    if not fitting:
        raise ValueError(f"no kernel of family {family_name!r} serves {variant}")
    return max(fitting, key=lambda k: len(k.variant))


def members(family_name: str, key: str) -> dict:
    """A family's kernels by the value of one variant key (crash3_energy by points)."""
    return {dict(k.variant)[key]: k for k in family(family_name)}


def batch_kernels() -> tuple[KernelSet, ...]:
    """Every kernel with a numba driver."""
    return tuple(kernel(k) for k, row in TABLE.KERNELS.items() if row["driver"] is not None)


def generated_digest() -> str:
    """The derive-source hash in generated/'s header: names this generated code."""
    with open(generated.__file__, encoding="utf-8") as handle:
        for line in handle:
            if "sha256" in line:
                return line.rsplit(" ", 1)[-1].strip()
    return "unknown"
