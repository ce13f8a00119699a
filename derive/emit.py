"""The emitter: Kernel descriptions → two source files per model in generated/.

* ``generated/<model>.py``, plain Python importing only `math`: the `MANIFEST`
  table (per kernel: batch columns, arguments, outputs, constants, tier, seed
  equations, operation count), the model's data tables, and per kernel the
  per-scene function (guards with early returns before the divisions they
  protect: it never raises). A single scene runs it as it is; nothing compiles.
* ``generated/<model>_jit.py``, numba: per kernel one straight-line body
  (`inline="always"`), shared by its drivers: a `prange` driver and a serial
  twin, and for a kernel in normal form the same two taking (nx, ny) in place
  of the angle. Every driver argument is a C-contiguous float64 1-D array
  (outputs caller-owned), so each driver has exactly one compiled signature.
  Bodies and drivers sit in one file: numba's cache does not notice a change
  of a jitted callee in another file.

Both files are printed from one program per kernel, so a batch row and a
single scene agree bitwise. Common subexpressions are eliminated over the
whole kernel; each one is computed at the start of the first block that uses
it, after the guards of the blocks before (a division never moves above the
guard that protects it), and named symbols stay single rounded quantities.
Every angle path takes (sin, cos) from derive/trig.py's `_sincos`. Output is
deterministic (SymPy's canonical ordering, fixed temporary names, no
timestamps); arithmetic is strict IEEE (no fastmath).
"""

from __future__ import annotations

import functools
import hashlib
import pprint
import re
from dataclasses import dataclass, replace
from pathlib import Path

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from .codes import FLAGS, STATUS
from .kernel import IsFinite, Kernel
from .legend import LEGEND
from .trig import SINCOS_LIMIT, SINCOS_SOURCE

DERIVE_DIR = Path(__file__).resolve().parent
WIDTH = 100  # emitted lines are wrapped at this width where they list names


class KernelPrinter(PythonCodePrinter):
    """Python/numba code for kernel formulas: float literals, x*x for squares."""

    def _print_IsFinite(self, expr):
        return f"math.isfinite({self._print(expr.args[0])})"

    def _print_NotNaN(self, expr):
        return f"not math.isnan({self._print(expr.args[0])})"

    def _print_Integer(self, expr):
        return f"{float(expr.p)!r}"

    def _print_Rational(self, expr):
        value = float(expr.p) / float(expr.q)
        if sp.Rational(value) == expr:  # exactly representable: one literal
            return repr(value)
        return f"({float(expr.p)!r}/{float(expr.q)!r})"

    def _print_Half(self, expr):
        return "0.5"

    def _print_Mul(self, expr):
        """As CodePrinter, except that a lone squared denominator keeps its
        parentheses: x/y**2 is printed x/(y*y), never x/y*y."""
        text = super()._print_Mul(expr)
        dens = [a for a in sp.Mul.make_args(expr) if a.is_Pow and a.exp.is_Rational and a.exp.is_negative]
        if len(dens) == 1 and dens[0].exp == -2:
            square = self._print(sp.Pow(dens[0].base, 2, evaluate=False))
            if text.endswith("/" + square):
                text = text[: -len(square)] + f"({square})"
        return text

    def _print_Pow(self, expr, rational=False):
        base, exp = expr.args
        if exp == 2:
            b = self.parenthesize(base, sp.printing.precedence.PRECEDENCE["Mul"])
            return f"{b}*{b}"
        if exp == -1:
            return f"1.0/{self.parenthesize(base, sp.printing.precedence.PRECEDENCE['Pow'])}"
        return super()._print_Pow(expr, rational=rational)


class Float32Printer(KernelPrinter):
    """Single precision: every literal a float32, so arithmetic stays in float32."""

    def _print_Integer(self, expr):
        return f"np.float32({float(expr.p)!r})"

    def _print_Rational(self, expr):
        return f"np.float32({float(expr.p) / float(expr.q)!r})"

    def _print_Half(self, expr):
        return "np.float32(0.5)"

    def _print_Pow(self, expr, rational=False):
        if expr.args[1] == -1:
            base = self.parenthesize(expr.args[0], sp.printing.precedence.PRECEDENCE["Pow"])
            return f"np.float32(1.0)/{base}"
        return super()._print_Pow(expr, rational=rational)


_SETTINGS = {"fully_qualified_modules": True, "standard": "python3"}


@dataclass(frozen=True)
class Style:
    """How kernels are printed: the default (strict IEEE float64) is what
    generated/ holds; the others exist only to be measured against it."""

    jit_options: str
    printer: KernelPrinter
    imports: tuple[str, ...] = ("import math",)

    def jit(self, parallel: bool = False, inline: bool = False) -> str:
        extra = (", parallel=True" if parallel else "") + (', inline="always"' if inline else "")
        return f'njit(cache=True, error_model="numpy"{self.jit_options}{extra})'

    def code(self, expr) -> str:
        """One expression as Python source."""
        return self.printer.doprint(expr)


DEFAULT = Style("", KernelPrinter(_SETTINGS))
VARIANTS = {
    "default": DEFAULT,
    # nnan/ninf let LLVM delete the NaN/inf input checks; reassoc can undo the
    # ordering derive chose. Measured in benchmarks/, never offered at run time.
    "fastmath": Style(", fastmath=True", KernelPrinter(_SETTINGS)),
    "float32": Style("", Float32Printer(_SETTINGS), ("import math", "import numpy as np")),
}


def code(expr) -> str:
    """One expression as Python source, default style."""
    return DEFAULT.code(expr)


def source_hash() -> str:
    """sha256 of every derive/*.py file, in name order (the derive source)."""
    h = hashlib.sha256()
    for path in sorted(DERIVE_DIR.glob("*.py")):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def package_version() -> str:
    """impactsym's version, read (not imported) from impactsym/_version.py, the
    one place it is written."""
    text = (DERIVE_DIR.parent / "impactsym" / "_version.py").read_text()
    return re.search(r'^__version__ = "([^"]+)"', text, re.MULTILINE).group(1)


def header(model_file: str, digest: str) -> str:
    """The fixed first lines of every generated file."""
    return (
        f"# GENERATED by `python -m derive` from derive/{model_file}: DO NOT EDIT.\n"
        "# Regenerate: python -m derive    Check staleness: python -m derive --check\n"
        f"# SymPy {sp.__version__}; derive source sha256 {digest}\n"
        f"# impactsym {package_version()}\n"
    )


def _wrap(prefix: str, items, suffix: str, indent: str) -> list[str]:
    """`prefix` + comma-separated `items` + `suffix`, broken into lines of at
    most WIDTH characters, continuation lines indented by `indent`."""
    lines, line = [], prefix
    for k, item in enumerate(items):
        piece = item + (", " if k < len(items) - 1 else suffix)
        if len(line) + len(piece.rstrip()) > WIDTH and line.strip() != prefix.strip():
            lines.append(line.rstrip())
            line = indent
        line += piece
    if not items:
        line += suffix
    lines.append(line)
    return lines


# --- one program per kernel -------------------------------------------------


@dataclass(frozen=True)
class Program:
    """A kernel as printed statements. `steps` are, in order, ("assign",
    name, code) and ("guard", Guard) and ("comment", text); `flags` pairs of
    (flag name, printed conditions); `operations` the arithmetic operation
    count after common-subexpression elimination."""

    kernel: Kernel
    steps: tuple
    operations: int


@functools.cache
def program(kernel: Kernel, style: Style = DEFAULT) -> Program:
    """Common subexpressions eliminated over the whole kernel; each temporary
    is placed at the start of the first block that needs it (directly or
    through another temporary), so it follows every guard of the blocks
    before and every symbol it uses. Assignments nothing reads are left out
    (`_live`)."""
    kernel = _live(kernel)
    exprs = [x for block in kernel.blocks for _, x in block.assigns]
    for block in kernel.blocks:
        own = {s for s, _ in block.assigns}
        for _, expr in block.assigns:
            if expr.free_symbols & own:
                raise ValueError(f"a formula uses a symbol of its own block: {expr}")
    temps, reduced = _tidy(*sp.cse(exprs, symbols=sp.numbered_symbols("_t")), kernel)
    uses = {t: x.free_symbols for t, x in temps}
    placed: set = set()
    steps: list = [("guard", g) for g in kernel.checks]
    operations = 0
    at = 0
    for block in kernel.blocks:
        mine = reduced[at : at + len(block.assigns)]
        at += len(block.assigns)
        needed = set().union(*(x.free_symbols for x in mine if x is not None))
        needed |= {sym for sym, x in zip((s for s, _ in block.assigns), mine) if x is None}
        for t, _ in reversed(temps):  # a temporary's own temporaries come earlier
            if t in needed:
                needed |= uses[t]
        if block.equation:
            steps.append(("comment", block.equation))
        for t, x in temps:
            if t in needed and t not in placed:
                placed.add(t)
                steps.append(("assign", str(t), style.code(x)))
                operations += sp.count_ops(x)
        for (sym, _), x in zip(block.assigns, mine):
            if x is not None:  # None: computed as the temporary named after it
                steps.append(("assign", str(sym), style.code(x)))
                operations += sp.count_ops(x)
        if block.guard is not None:
            steps.append(("guard", block.guard))
    flags = tuple((flag, tuple(style.code(c) for c in conds)) for flag, conds in kernel.flags)
    return Program(kernel, tuple(steps) + (("flags", flags),), int(operations))


def _live(kernel: Kernel) -> Kernel:
    """`kernel` without dead stores: an assignment stays when an output, the
    finite check, a guard, a flag or a later kept assignment reads it (a
    derivation may name a quantity that only some of its kernels use: r12 in
    the sliding rigid kernel)."""
    needed = {*kernel.outputs, *kernel.finite_checked()}
    for guard in kernel.checks:
        needed |= set().union(*(c.free_symbols for c in guard.conditions))
    for _, conds in kernel.flags:
        needed |= set().union(*(sp.sympify(c).free_symbols for c in conds))
    blocks = []
    for block in reversed(kernel.blocks):
        if block.guard is not None:
            needed |= set().union(*(c.free_symbols for c in block.guard.conditions))
        assigns = tuple((sym, x) for sym, x in block.assigns if sym in needed)
        for _, x in assigns:
            needed |= x.free_symbols
        blocks.append(replace(block, assigns=assigns))
    return replace(kernel, blocks=tuple(reversed(blocks)))


def _tidy(temps, reduced, kernel: Kernel):
    """Two clean-ups of SymPy's CSE. A temporary that is only a negated
    symbol (-v2x) is put back (negation is exact: nothing to share). A
    temporary that a named symbol is assigned from (Pn = _t8) takes that name
    (Pn = bn/D, then Pt = Pn*mu): it is computed where the temporary would
    be, the first block that needs the value, and the named assignment goes
    (its entry in `reduced` becomes None)."""
    inline = {
        t: x for t, x in temps if x.is_Mul and len(x.args) == 2 and x.args[0] == -1 and x.args[1].is_Symbol
    }
    temps = [(t, x.xreplace(inline)) for t, x in temps if t not in inline]
    reduced = [x.xreplace(inline) for x in reduced]
    names = [sym for block in kernel.blocks for sym, _ in block.assigns]
    rename = {}
    for sym, x in zip(names, reduced):
        if x in dict(temps) and x not in rename:
            rename[x] = sym
    temps = [(rename.get(t, t), x.xreplace(rename)) for t, x in temps]
    reduced = [
        None if x in rename and rename[x] == sym else x.xreplace(rename) for sym, x in zip(names, reduced)
    ]
    return temps, reduced


def _lines(prog: Program, ind: str, style: Style, straight: bool) -> list[str]:
    """The program's statements. Per scene (`straight` false) a failed guard
    returns the failed row; straight-line, it sets `status` (the first failed
    guard wins) and evaluation goes on. Flags' conditions are joined by `or`
    per scene (an `if` per flag) and by `|` straight-line (the bit times the
    condition: no branch)."""
    name = prog.kernel.name
    lines = [f"{ind}status = 0"] if straight else []
    for step in prog.steps:
        if step[0] == "comment":
            lines.append(f"{ind}# {step[1]}")
        elif step[0] == "assign":
            lines.append(f"{ind}{step[1]} = {step[2]}")
        elif step[0] == "guard":
            guard = step[1]
            conds = _guard_conditions(guard, style)
            if straight:
                cond = " & ".join(f"({c})" for c in conds)
                lines += [
                    f"{ind}if (status == 0) & (not ({cond})):",
                    f"{ind}    status = {STATUS[guard.status]}  # {guard.status}",
                ]
            else:
                cond = " and ".join(f"({c})" for c in conds)
                lines += [
                    f"{ind}if not ({cond}):",
                    f"{ind}    return _{name}_failed({STATUS[guard.status]})  # {guard.status}",
                ]
        else:
            lines.append(f"{ind}flags = 0")
            for flag, conds in step[1]:
                if straight:
                    # The bit times the condition, not `if`: LLVM kept an `if`
                    # on e (E_OUT_OF_RANGE) as a costlier select (docs/kernels.md).
                    cond = " | ".join(f"({c})" for c in conds)
                    lines.append(f"{ind}flags |= {FLAGS[flag]} * ({cond})  # {flag}")
                else:
                    cond = " or ".join(f"({c})" for c in conds)
                    lines += [f"{ind}if {cond}:", f"{ind}    flags |= {FLAGS[flag]}  # {flag}"]
    every = all_finite([str(s) for s in prog.kernel.finite_checked()], style.code(sp.S.Zero))
    if straight:
        lines += [
            f"{ind}if (status == 0) & (not ({every})):",
            f"{ind}    status = {STATUS['OVERFLOW']}  # OVERFLOW",
        ]
    else:
        lines += [
            f"{ind}if not ({every}):",
            f"{ind}    return _{name}_failed({STATUS['OVERFLOW']})  # OVERFLOW",
        ]
    return lines


def all_finite(names: list[str], zero: str = "0.0") -> str:
    """A condition true exactly when every one of `names` is finite.

    ``x*0.0`` is ±0 for a finite x and NaN for ±inf and NaN (strict IEEE: no
    fastmath, so the product is not folded to 0), and a sum of zeros is 0
    unless a term is NaN: one comparison of a sum of products instead of a
    test, a comparison and an `and` per name. The sum is a balanced tree so
    that its additions do not wait on one another (a chain of 17 dependent
    additions cost more than the tests it replaces). `zero` is the style's
    literal 0. One name keeps ``math.isfinite``."""
    if len(names) == 1:
        return f"math.isfinite({names[0]})"
    terms = [f"{n}*{zero}" for n in names]
    while len(terms) > 1:
        pairs = [f"({a} + {b})" for a, b in zip(terms[::2], terms[1::2])]
        terms = pairs + terms[len(pairs) * 2 :]
    return f"{terms[0][1:-1]} == {zero}"


def _guard_conditions(guard, style: Style) -> list[str]:
    """A guard's conditions as printed: its `IsFinite` conditions joined into
    one `all_finite` test (in their place), the others one by one."""
    finite = [style.code(c.args[0]) for c in guard.conditions if isinstance(c, IsFinite)]
    printed, joined = [], False
    for c in guard.conditions:
        if not isinstance(c, IsFinite):
            printed.append(style.code(c))
        elif not joined:
            printed.append(all_finite(finite, style.code(sp.S.Zero)))
            joined = True
    return printed


# --- the plain module ---------------------------------------------------------


def column_names(kernel: Kernel) -> tuple[str, ...]:
    """The kernel's batch columns: its inputs, with the angle in place of the
    normal components for a kernel in normal form."""
    names = [str(s) for s in kernel.inputs]
    if kernel.angle is not None:
        at = names.index("nx")
        names[at : at + 2] = [str(kernel.angle)]
    return tuple(names)


def tier(kernel: Kernel) -> str:
    """The output tier a kernel serves: "velocities", or "all"."""
    return dict(kernel.variant).get("tier", "all")


def manifest_entry(kernel: Kernel, operations: int) -> dict:
    """One kernel's MANIFEST row (plain Python literals)."""
    return {
        "doc": kernel.doc,
        "columns": column_names(kernel),
        "arguments": tuple(str(s) for s in kernel.inputs),
        "outputs": kernel.output_names(),
        "constants": dict(kernel.constants),
        "integers": tuple(str(s) for s in kernel.integers),
        "tier": tier(kernel),
        "angle": None if kernel.angle is None else str(kernel.angle),
        "equations": tuple(b.equation for b in kernel.blocks if b.equation),
        "operations": operations,
    }


def scene_function(prog: Program, style: Style = DEFAULT) -> str:
    """The per-scene function: checks, blocks with guards, flags, finite check."""
    knl = prog.kernel
    outs = ", ".join(str(s) for s in knl.outputs)
    ind = "    "
    lines = _wrap(f"def {knl.name}(", [str(s) for s in knl.inputs], "):", " " * 8)
    lines += [
        f'{ind}"""{knl.doc}',
        "",
        f"{ind}Returns ({outs}, status, flags); a failed row has NaN outputs.",
        f'{ind}"""',
    ]
    lines += _lines(prog, ind, style, straight=False)
    lines.append(f"{ind}return ({outs}, 0, flags)")
    return "\n".join(lines) + "\n"


def failed_function(kernel: Kernel) -> str:
    """NaN outputs with a status: the return value of a row that is not solved."""
    nans = ", ".join(["math.nan"] * len(kernel.outputs))
    return f"def _{kernel.name}_failed(status):\n    return ({nans}, status, 0)\n"


def unit_normal_function() -> str:
    """`unit_normal(gamma)` → (nx, ny): `_sincos` within SINCOS_LIMIT, math's
    cos/sin beyond (as the batch runtime does), NaN for a non-finite angle
    (which the kernels then reject as a non-finite input)."""
    return (
        "def unit_normal(gamma):\n"
        '    """The contact normal (nx, ny) of the angle gamma [rad]."""\n'
        "    if not math.isfinite(gamma):\n        return (math.nan, math.nan)\n"
        "    if abs(gamma) <= SINCOS_LIMIT:\n"
        "        ny, nx = _sincos(gamma)\n        return (nx, ny)\n"
        "    return (math.cos(gamma), math.sin(gamma))\n"
    )


def _legend(kernels) -> list[str]:
    """Header lines naming every intermediate the module's kernels assign."""
    names = []
    for knl in kernels:
        for sym in knl.definitions():
            if str(sym) not in names and sym not in knl.outputs:
                names.append(str(sym))
    lines = [
        "#",
        "# Equations: 'seed appendix eq N' numbers the six equations of the seed's appendix in",
        "# its own order (1, 2 momentum along x, y; 3 angular momentum; 4 restitution; 5 friction",
        "# (impulse ratio); 6 moment restitution); 'seed eq N' the seed's numbered equations.",
        "#",
        "# Intermediate names (inputs and outputs: conventions.md):",
    ]
    for name in names:
        lines.append(f"#   {name:<10} {LEGEND.get(name, 'see derive/')}")
    lines.append(f"#   {'_t<k>':<10} common subexpressions (eliminated across a kernel's blocks)")
    return lines


def render_module(model_file: str, doc: str, kernels, digest: str, data=(), drivers: bool = True) -> str:
    """generated/<model>.py as text: header, MANIFEST, data tables, per-scene
    functions. `data` holds (NAME, value) pairs of plain Python literals
    (numbers, strings, tuples, dicts): tables a model module derives.
    `drivers`: whether generated/<model>_jit.py holds its batch drivers."""
    progs = [program(k) for k in kernels]
    model = model_file.removesuffix(".py")
    total = sum(p.operations for p in progs)
    parts = [
        header(model_file, digest).rstrip("\n"),
        f"# {len(progs)} kernels, {total} arithmetic operations after common-subexpression elimination;",
        f"# batch drivers: generated/{model}_jit.py."
        if drivers
        else "# no batch drivers: evaluated per scene.",
        *_legend(kernels),
        "",
        f'"""{doc}"""',
        "",
        "import math",
        "",
    ]
    parts += ["MANIFEST = {"]
    for prog in progs:
        parts.append(f"    {prog.kernel.name!r}: {{")
        for key, value in manifest_entry(prog.kernel, prog.operations).items():
            if isinstance(value, tuple) and len(value) > 1:
                parts += _wrap(f"        {key!r}: (", [repr(v) for v in value], "),", " " * 12)
            else:
                parts.append(f"        {key!r}: {value!r},")
        parts.append("    },")
    parts += ["}", ""]
    for name, value in data:
        parts += [f"{name} = {pprint.pformat(value, width=WIDTH, sort_dicts=False)}", ""]
    if any(k.angle is not None for k in kernels):
        parts += [f"SINCOS_LIMIT = {SINCOS_LIMIT!r}", "", "", SINCOS_SOURCE, "", unit_normal_function()]
    for prog in progs:
        parts += ["", failed_function(prog.kernel), "", scene_function(prog)]
    return "\n".join(parts).rstrip("\n") + "\n"


# --- the numba module ---------------------------------------------------------


def body_function(prog: Program, style: Style = DEFAULT) -> str:
    """The straight-line body every driver of the kernel inlines: every
    formula on every row (with numpy's error model a formula on a failed row
    gives NaN or inf, never an exception), a failed guard only sets the
    status, outputs selected at the end (NaN on a failed row). Straight-line
    code is what lets LLVM vectorise the drivers' loops."""
    knl = prog.kernel
    ind = "    "
    lines = [f"@{style.jit(inline=True)}"]
    lines += _wrap(f"def _{knl.name}_body(", [str(s) for s in knl.inputs], "):", " " * 8)
    lines.append(f'{ind}"""`{knl.name}` (generated/ per-scene function) without branches."""')
    lines += _lines(prog, ind, style, straight=True)
    lines.append(f"{ind}ok = status == 0")
    # A failed row: NaN, or -1 for a class code (its driver column is int64);
    # the constants are written too, so the runtime fills no column afterwards.
    values = [f"{s} if ok else {-1.0 if s in knl.integers else 'math.nan'}" for s in knl.outputs]
    values += [f"{value!r} if ok else math.nan" for _, value in knl.constants]
    values += ["status", "flags if ok else 0"]
    lines += _wrap(f"{ind}return (", values, ")", ind * 2)
    return "\n".join(lines) + "\n"


def driver_name(kernel: Kernel) -> str:
    """The kernel's one batch driver: rigid_batch."""
    return f"{kernel.name}_batch"


def driver_columns(kernel: Kernel) -> tuple[str, ...]:
    """The driver's input columns: the kernel's arguments, and for a kernel in
    normal form the angle just before (nx, ny) and the one normal of the
    batch, `normal`, just after."""
    args = [str(s) for s in kernel.inputs]
    if kernel.angle is not None:
        at = args.index("nx")
        args[at : at + 2] = [str(kernel.angle), "nx", "ny", "normal"]
    return tuple(args)


def driver_function(kernel: Kernel, style: Style = DEFAULT) -> str:
    """The batch driver into caller-owned outputs, one row per index, a
    `prange` loop (a batch of a few rows pays a few microseconds for the
    launch: benchmarks/results/performance.md). A kernel in normal form takes
    the angle column (`_sincos` per row), or `normal`, one (nx, ny) for every
    row as a length-2 array read once before the loop (no filled columns to
    write and read again), or (nx, ny) columns (angles beyond SINCOS_LIMIT,
    which the angle loop counts and returns, whose normal the runtime then
    forms with NumPy); the other two are None.

    Why three separate `if ... is not None` and not if/elif: numba prunes a
    branch on an argument typed None before it types the function, so each
    compiled signature holds only its own loop and a first use compiles one
    copy of the body, not three (an `elif` after a test on an array cannot be
    pruned: numba knows only that a None is None)."""
    args = [str(s) for s in kernel.inputs]
    outs = [f"out_{s}" for s in kernel.driver_output_names()] + ["out_status", "out_flags"]
    ind = "        "
    lines = [f"@{style.jit(parallel=True)}"]
    lines += _wrap(
        f"def {driver_name(kernel)}(", [f"c_{c}" for c in driver_columns(kernel)] + outs, "):", " " * 8
    )
    lines.append(f'    """Batch of `{kernel.name}` (see `_{kernel.name}_body`)."""')
    if kernel.angle is None:
        lines += ["    for i in prange(out_status.shape[0]):", *_row(kernel, args, outs, ind, False)]
        return "\n".join(lines) + "\n"
    angle = f"c_{kernel.angle}"
    lines += [
        "    n = out_status.shape[0]",
        "    beyond = 0",
        f"    if {angle} is not None:",
        "        for i in prange(n):",
        f"            g = {angle}[i]",
        "            # finite angles beyond SINCOS_LIMIT, counted in the same pass (no pass",
        "            # over the column before the call): the runtime solves such a batch",
        "            # again with NumPy's normals",
        f"            beyond += 1 if (abs(g) > {SINCOS_LIMIT!r}) & (g - g == 0.0) else 0",
        "            ny, nx = _sincos(g)",
        *_row(kernel, args, outs, ind + "    ", True),
        "    if c_normal is not None:",
        "        nx, ny = c_normal[0], c_normal[1]",
        "        for i in prange(n):",
        *_row(kernel, args, outs, ind + "    ", True),
        "    if c_nx is not None:",
        "        for i in prange(n):",
        "            nx, ny = c_nx[i], c_ny[i]",
        *_row(kernel, args, outs, ind + "    ", True),
        "    return beyond",
    ]
    return "\n".join(lines) + "\n"


def _row(kernel: Kernel, args: list, outs: list, ind: str, local_normal: bool) -> list:
    """One row of a driver: the outputs at i from the body of the inputs at i
    (nx, ny as locals when `local_normal`)."""
    values = [a if local_normal and a in ("nx", "ny") else f"c_{a}[i]" for a in args]
    return _wrap(f"{ind}(", [f"{o}[i]" for o in outs], ") = (", ind + "    ") + _wrap(
        f"{ind}    _{kernel.name}_body(", values, "))", ind + "    "
    )


def render_jit_module(model_file: str, kernels, digest: str, style: Style = DEFAULT) -> str:
    """generated/<model>_jit.py as text: `_sincos`, and per kernel its body and
    drivers."""
    model = model_file.removesuffix(".py")
    total = sum(program(k, style).operations for k in kernels)
    parts = [
        header(model_file, digest).rstrip("\n"),
        f"# {len(kernels)} kernels, {total} arithmetic operations after common-subexpression elimination;",
        "# one batch driver per kernel, <kernel>_batch.",
        "",
        f'"""Numba batch drivers of generated/{model}.py (see its MANIFEST and legend)."""',
        "",
        *style.imports,
        "",
        "from numba import njit, prange",
        "",
    ]
    if any(k.angle is not None for k in kernels):
        parts += ["", f"@{style.jit(inline=True)}", SINCOS_SOURCE]
    for knl in kernels:
        parts += ["", body_function(program(knl, style), style), "", driver_function(knl, style)]
    return "\n".join(parts).rstrip("\n") + "\n"


def registry_entry(kernel: Kernel, module: str, drivers: bool) -> dict:
    """One kernel's row of generated/registry.py (plain Python literals)."""
    return {
        "family": kernel.family_name(),
        "variant": dict(kernel.variant),
        "module": module,
        "driver": driver_columns(kernel) if drivers else None,
        **manifest_entry(kernel, program(kernel).operations),
    }


def _family_outputs(entries: dict) -> dict:
    """Family → every output name its kernels return (computed or constant),
    in the order of its first kernel, then of the others."""
    families: dict = {}
    for row in entries.values():
        names = families.setdefault(row["family"], [])
        for name in (*row["outputs"], *row["constants"]):
            if name not in names:
                names.append(name)
    return {family: tuple(names) for family, names in families.items()}


def render_registry(modules, digest: str, tiers: dict) -> str:
    """generated/registry.py: every emitted kernel and what the runtime needs
    to choose one, plain data (no numba, no math). `modules` holds, per
    derive module, (name, kernels, data, drivers) as __main__.render_all
    collects them; `tiers` the output tiers solve_batch accepts."""
    entries = {}
    data: list = []
    for name, kernels, module_data, drivers in modules:
        for knl in kernels:
            entries[knl.name] = registry_entry(knl, name, drivers)
        data += list(module_data)
    tables = [
        ("KERNELS", entries),
        ("FAMILY_OUTPUTS", _family_outputs(entries)),
        ("TIERS", tiers),
        ("STATUS", dict(STATUS)),
        ("FLAGS", dict(FLAGS)),
        ("SINCOS_LIMIT", SINCOS_LIMIT),
        *data,
    ]
    parts = [
        header("emit.py", digest).rstrip("\n"),
        f"# {len(entries)} kernels; see derive/__main__.py for how a kernel gets here.",
        "",
        '"""The kernel registry: every generated kernel, its family and variant, columns and',
        "outputs, and the tables the runtime reads (tiers, status codes, flags, presets).",
        "",
        "KERNELS[name]: family, variant (what sets it apart in its family: critical, a fixed",
        "input such as e_m, an output tier), module (generated/<module>.py holds the",
        "per-scene function <name>, generated/<module>_jit.py the driver <name>_batch),",
        "driver (its input columns in order, None if the kernel has no driver), doc,",
        "columns (batch inputs), arguments (per-scene function arguments), outputs",
        "(computed), constants (outputs fixed to a number; a driver writes the outputs, then",
        "the constants), integers (outputs coding a class: int64 in a driver, -1 on a failed",
        "row), tier, angle, equations, operations. FAMILY_OUTPUTS[family]: every output a",
        'family returns."""',
        "",
    ]
    for name, value in tables:
        parts += [f"{name} = {pprint.pformat(value, width=WIDTH, sort_dicts=False, compact=True)}", ""]
    return "\n".join(parts).rstrip("\n") + "\n"


def render_init(modules, digest: str) -> str:
    """generated/__init__.py with the marker the runtime checks."""
    return (
        header("emit.py", digest)
        + '"""Kernels emitted by impactsym\'s derive step: <model>.py (plain Python) '
        + 'and <model>_jit.py (numba)."""\n\n'
        + 'IMPACTSYM_GENERATED = "impactsym"\n'
        + f"MODULES = {tuple(modules)!r}\n"
    )
