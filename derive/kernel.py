"""What a model module hands to the emitter: a kernel as ordered blocks of formulas.

A kernel is a straight-line program. Its blocks are evaluated in order; every
formula in a block may use the kernel inputs and the symbols assigned by earlier
blocks, never a symbol of its own block (the emitter places each common
subexpression at the start of the first block that uses it, so that rule keeps
temporaries in order). A block
may end with a guard: a condition that must hold for the row to go on, and the
status the row gets when it does not. Guards sit before the divisions and
transcendental calls they protect, so the plain-Python twin of a kernel never
raises.

Named intermediate symbols are how a derivation keeps a physical difference
(the approach velocity at the impact centre, ``1 - e``) as one rounded quantity:
once assigned, later blocks use the symbol, and no later simplification can
re-form the difference from large products.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp


@dataclass(frozen=True)
class Guard:
    """Every one of `conditions` must be true for the row to continue; otherwise
    the row gets `status`. Conditions are kept in the order given (no SymPy
    `And`, which would reorder them)."""

    conditions: tuple
    status: str


@dataclass(frozen=True)
class Block:
    """Assignments evaluated together, then a guard. `equation` names what the
    block implements (a seed equation, conventions.md), for the emitted comment."""

    assigns: tuple[tuple[sp.Symbol, sp.Expr], ...]
    guard: Guard | None = None
    equation: str = ""


@dataclass(frozen=True)
class Kernel:
    """A per-scene function plus its batch drivers, as the emitter writes them.

    `inputs` are the argument names (the batch column names of conventions.md),
    `checks` the input guards evaluated before any arithmetic, `blocks` the
    formulas, `outputs` the returned symbols in order (then `status`, `flags`),
    and `flags` pairs of (flag name, conditions any of which raises it) on a
    solved row. Specialised kernels (derive/specialise.py) also carry
    `constants` (outputs that are a fixed number, published by name rather
    than computed), `finite` (see `finite_checked`) and `angle` (the angle
    input that the normal components (nx, ny) among `inputs` stand for).
    A kernel whose model lacks an output (particles: no yaw; a point impulse:
    no moment) names it among `constants` too, so that its drivers write
    every output of the model's tier. `integers` are outputs that code a
    class (0, 1, 2, ...): the drivers write them as int64, -1 on a failed row.
    `family` and `variant` place the kernel in the registry
    (generated/registry.py): the family it belongs to (default: its name) and
    what distinguishes it there, as (key, value) pairs: ("critical", True),
    ("e_m", 1.0) for a fixed input, ("tier", "velocities") for pruned outputs.
    """

    name: str
    doc: str
    inputs: tuple[sp.Symbol, ...]
    checks: tuple[Guard, ...]
    blocks: tuple[Block, ...]
    outputs: tuple[sp.Symbol, ...]
    flags: tuple[tuple[str, tuple], ...] = field(default_factory=tuple)
    constants: tuple[tuple[str, float], ...] = ()
    finite: tuple[sp.Symbol, ...] | None = None
    angle: sp.Symbol | None = None
    integers: tuple[sp.Symbol, ...] = ()
    family: str = ""
    variant: tuple[tuple[str, object], ...] = ()

    def family_name(self) -> str:
        """The kernel family (the registry's key for a model): `family`, or
        the kernel's own name when it is the only member of its family."""
        return self.family or self.name

    @staticmethod
    def public_name(sym: sp.Symbol) -> str:
        """The batch column name of an output symbol: `mu_used` is `mu`."""
        return "mu" if sym.name == "mu_used" else sym.name

    def output_names(self) -> tuple[str, ...]:
        """Public output names (batch columns) of the computed outputs."""
        return tuple(self.public_name(s) for s in self.outputs)

    def driver_output_names(self) -> tuple[str, ...]:
        """What a batch driver writes, in order: the computed outputs, then the
        constants (then status and flags)."""
        return self.output_names() + tuple(name for name, _ in self.constants)

    def finite_checked(self) -> tuple[sp.Symbol, ...]:
        """The quantities whose overflow makes a row fail (status OVERFLOW):
        the outputs, or for a specialised kernel its base kernel's outputs that
        it still computes, so that the row status does not depend on the tier."""
        return self.outputs if self.finite is None else self.finite

    def definitions(self) -> dict[sp.Symbol, sp.Expr]:
        """Every assigned symbol with its formula, in evaluation order."""
        return {sym: expr for block in self.blocks for sym, expr in block.assigns}

    def expanded(self, expr: sp.Expr, keep: frozenset = frozenset()) -> sp.Expr:
        """`expr` with assigned symbols replaced by their formulas, down to the
        inputs, except the symbols in `keep` (used by proofs to stop at inverse
        masses and the normal's components)."""
        defs = self.definitions()
        for sym in reversed(list(defs)):
            if sym not in keep:
                expr = expr.xreplace({sym: defs[sym]})
        return expr


def real(names: str):
    """Real SymPy symbols, as a tuple (or one symbol for one name)."""
    return sp.symbols(names, real=True)


class IsFinite(sp.Function):
    """`math.isfinite(x)` as a SymPy function, for input guards."""


class NotNaN(sp.Function):
    """`not math.isnan(x)` as a SymPy function, for input guards."""


def finite_inputs(symbols, masses=()) -> Guard:
    """Guard: every one of `symbols` is a finite number and no mass or inertia is
    NaN (a mass may be +inf: a fixed body)."""
    return Guard(tuple(IsFinite(s) for s in symbols) + tuple(NotNaN(m) for m in masses), "NONFINITE_INPUT")


def positive_or_fixed(symbols) -> Guard:
    """Guard: masses/inertias are > 0 (NaN fails the comparison); +inf is a fixed body.

    The comparison is built on assumption-free copies of the symbols: the model
    symbols are declared positive, which would make SymPy fold `m > 0` to True."""
    return Guard(tuple(sp.StrictGreaterThan(sp.Symbol(s.name), 0) for s in symbols), "BAD_MASS")
