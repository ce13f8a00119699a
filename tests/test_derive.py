"""The derive → generated pipeline: proofs, determinism, staleness, one-way doors."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import sympy as sp

from derive import __main__ as derive_main
from derive import crash3, delta_v, emit, frame, inverse, particle, planar, presets, reconstruct, report

ROOT = Path(__file__).resolve().parent.parent


def _run_derive(*args, cwd=ROOT):
    return subprocess.run(
        [sys.executable, "-m", "derive", *args], cwd=cwd, capture_output=True, text=True, timeout=300
    )


@pytest.mark.slow  # SymPy proves every claim: minutes
@pytest.mark.parametrize(
    "module",
    [particle, planar, delta_v, inverse, reconstruct, presets, crash3, report],
    ids=lambda m: m.__name__,
)
def test_every_proof_passes(module):
    failed = [claim for claim, ok in module.proofs() if not ok]
    assert not failed, f"failed proofs: {failed}"


@pytest.mark.slow  # SymPy re-proves the planar model
def test_a_wrong_formula_fails_its_proof(monkeypatch):
    """The proofs are not vacuous: perturb the restitution formula and they fail."""
    good = planar._impulse_blocks

    def wrong(sticking):
        blocks = good(sticking)
        first = blocks[0]
        bad = tuple((s, x * (1 + frame.e / 1000) if s == frame.dgn else x) for s, x in first.assigns)
        return (type(first)(bad, first.guard),) + blocks[1:]

    monkeypatch.setattr(planar, "_impulse_blocks", wrong)
    monkeypatch.setattr(planar, "KERNELS", (planar.kernel(False), planar.kernel(True)))
    results = dict(planar.proofs())
    assert not results["rigid: the closed forms satisfy the six equations"]


@pytest.mark.slow  # python -m derive proves and renders everything: minutes
def test_regenerating_into_a_temporary_folder_gives_identical_bytes(tmp_path):
    proc = _run_derive("--out", str(tmp_path))
    assert proc.returncode == 0, proc.stdout + proc.stderr
    for name in derive_main.render_all():
        assert (tmp_path / name).read_bytes() == (ROOT / "generated" / name).read_bytes(), name


@pytest.mark.slow  # python -m derive proves and renders everything: minutes
def test_check_passes_on_the_committed_files():
    proc = _run_derive("--check")
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.mark.slow  # python -m derive proves and renders everything: minutes
def test_check_fails_when_a_generated_file_was_edited(tmp_path):
    for name, text in derive_main.render_all().items():
        (tmp_path / name).write_text(text)
    (tmp_path / "planar.py").write_text((tmp_path / "planar.py").read_text() + "# edit\n")
    proc = _run_derive("--check", "--out", str(tmp_path))
    assert proc.returncode == 1 and "planar.py" in proc.stdout
    assert "\n-# edit\n" in proc.stdout  # the unified diff of what is stale


def test_plain_modules_import_only_math():
    """generated/<model>.py is plain Python (a single scene never imports
    numba); the numba drivers are in generated/<model>_jit.py, and a module
    evaluated per scene only (the Jacobians) has none."""
    for name in derive_main.MODEL_MODULES:
        src = (ROOT / "generated" / f"{name}.py").read_text()
        imports = [line for line in src.splitlines() if line.startswith(("import ", "from "))]
        assert imports == ["import math"], (name, imports)
        jit = ROOT / "generated" / f"{name}_jit.py"
        if name in derive_main.PER_SCENE_ONLY_MODULES:
            assert not jit.exists() and "# no batch drivers" in src, name
        else:
            assert "from numba import njit, prange" in jit.read_text()


def test_manifest_describes_every_kernel():
    import generated.planar as p
    import generated.planar_jit as pj

    for name, row in p.MANIFEST.items():
        assert callable(getattr(p, name)) and row["operations"] > 0
        assert row["angle"] == "gamma" and "gamma" in row["columns"]
        assert row["arguments"][14:16] == ("nx", "ny")
        assert callable(getattr(pj, f"{name}_batch"))
        assert not hasattr(pj, f"{name}_batch_serial") and not hasattr(pj, f"{name}_batch_normal")
    assert p.MANIFEST["rigid_em1"]["constants"] == {"M": 0.0, "TLm": 0.0}
    assert p.MANIFEST["rigid_velocities"]["tier"] == "velocities"


def test_the_registry_lists_every_emitted_kernel():
    """generated/registry.py has a row for every kernel of every listed derive
    module, with the module that holds it, and a driver exactly when the
    module has drivers; and nothing else."""
    import generated.registry as registry

    emitted = {knl.name: name for name, knl in _emitted_kernels()}
    assert set(registry.KERNELS) == set(emitted)
    for kernel, row in registry.KERNELS.items():
        assert row["module"] == emitted[kernel]
        assert (row["driver"] is None) == (row["module"] in derive_main.PER_SCENE_ONLY_MODULES)
    assert registry.KERNELS["rigid_critical_em1_velocities"]["variant"] == {
        "critical": True,
        "e_m": 1.0,
        "tier": "velocities",
    }
    assert registry.FAMILY_OUTPUTS["rigid"][:6] == ("V1x", "V1y", "W1", "V2x", "V2y", "W2")


def _emitted_kernels():
    """(module name, kernel) for every kernel python -m derive emits."""
    import importlib

    for name in derive_main.MODEL_MODULES:
        mod = importlib.import_module(f"derive.{name}")
        for knl in getattr(mod, "EMITTED", mod.KERNELS):
            yield name, knl


def test_every_block_names_the_equation_it_implements():
    """Each block of each emitted kernel carries an `equation` label (the
    comment above it in generated/), and the committed MANIFEST lists one
    label per block, so generated/ was rendered from labelled blocks."""
    import importlib

    unlabelled = [
        f"{name}.{knl.name} block {i} ({', '.join(str(s) for s, _ in block.assigns[:3])})"
        for name, knl in _emitted_kernels()
        for i, block in enumerate(knl.blocks)
        if not block.equation.strip()
    ]
    assert not unlabelled, f"blocks without an equation label: {unlabelled}"
    for name, knl in _emitted_kernels():
        manifest = importlib.import_module(f"generated.{name}").MANIFEST[knl.name]
        assert manifest["equations"] == tuple(b.equation for b in knl.blocks), (name, knl.name)


def test_generated_files_carry_the_header():
    """Every committed file of generated/ (that they are exactly what derive renders
    is the slow test_check_passes_on_the_committed_files)."""
    digest = emit.source_hash()
    files = sorted((ROOT / "generated").glob("*.py"))
    assert len(files) >= 10
    for path in files:
        head = path.read_text().splitlines()[:3]
        assert "DO NOT EDIT" in head[0]
        assert "python -m derive" in head[1]
        assert f"SymPy {sp.__version__}" in head[2] and digest in head[2]


def test_emitted_code_keeps_the_careful_forms():
    """1 - e and the approach velocity stay single quantities in the kernels."""
    src = (ROOT / "generated" / "planar.py").read_text()
    # Pn*gn may be a common subexpression (_t<k>); 1 - e stays the factor (e - 1.0).
    assert re.search(r"TLn = -0\.5\*(Pn\*gn|_t\d+)\*\(e - 1\.0\)", src)
    assert "dvx = -v1x + v2x" in src and "gx = dvx" in src
    assert "fastmath" not in src
    assert "fastmath" not in (ROOT / "generated" / "planar_jit.py").read_text()


def test_runtime_never_imports_sympy_or_derive():
    code = (
        "import sys, impactsym; impactsym.solve('examples/two_car_us.json'); "
        "bad = [m for m in sys.modules if m.split('.')[0] in ('sympy', 'derive')]; "
        "print(bad); sys.exit(1 if bad else 0)"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PYTHONPATH": ""},
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.mark.parametrize("expr", ["x/y**2", "x*z/y**2", "1/(1 + (x/y)**2)", "x/(y + z)**2", "-x/y**2"])
def test_a_squared_denominator_keeps_its_parentheses(expr):
    """x/y**2 must print as x/(y*y), never x/y*y (which is x)."""
    e = sp.sympify(expr)
    values = {"x": 2.0, "y": 3.0, "z": 5.0}
    assert eval(emit.code(e), {"math": __import__("math"), **values}) == pytest.approx(
        float(e.subs(values)), rel=1e-15
    )


@pytest.mark.parametrize(
    "module", ["planar", "particle", "inverse", "reconstruct", "delta_v", "presets", "report"]
)
def test_per_scene_functions_never_raise(module):
    """Guards precede the divisions and square roots they protect: on any mix of
    zeros, signs, infinities, NaN and extreme magnitudes a per-scene function
    returns a row (outputs, status, flags), it never raises."""
    import importlib
    import math
    import random

    mod = importlib.import_module(f"generated.{module}")
    values = (0.0, -0.0, -1.0, 1.0, 2.5, -3.0, math.inf, -math.inf, math.nan, 1e-300, 1e300, 5e-324)
    rng = random.Random(1)
    for name, row in mod.MANIFEST.items():
        function = getattr(mod, name)
        for _ in range(3000):
            args = [rng.choice(values) for _ in row["arguments"]]
            assert len(function(*args)) == len(row["outputs"]) + 2, (name, args)


@pytest.mark.parametrize("count", [2, 3, 7, 17, 19])
def test_the_emitted_finiteness_test_is_every_isfinite(count):
    """`all_finite` (one comparison of a tree of x*0.0) is true exactly when
    every value is finite, in Python and compiled by numba, on values that a
    sum would overflow (±max double), subnormals, signed zeros, ±inf, NaN."""
    import math
    import random

    import numba

    names = [f"x{k}" for k in range(count)]
    test = eval(f"lambda {', '.join(names)}: {emit.all_finite(names)}")
    compiled = numba.njit(error_model="numpy")(test)
    specials = [0.0, -0.0, 1.0, -2.5, 5e-324, 1.7976931348623157e308, -1.7976931348623157e308]
    specials += [math.inf, -math.inf, math.nan]
    rng = random.Random(count)
    rows = [[1.7976931348623157e308] * count]
    for _ in range(400):
        row = [rng.choice(specials[:7]) for _ in range(count)]
        if rng.random() < 0.6:
            row[rng.randrange(count)] = rng.choice(specials[7:])
        rows.append(row)
    assert {all(map(math.isfinite, row)) for row in rows} == {True, False}
    for row in rows:
        want = all(math.isfinite(x) for x in row)
        assert test(*row) is want and compiled(*row) == want, row


def test_no_dead_stores_in_generated_code():
    """Every name a per-scene function assigns is read later in it (the
    emitter leaves out assignments nothing reads)."""
    import re

    dead = []
    for path in sorted((ROOT / "generated").glob("*.py")):
        for function in re.split(r"\ndef ", path.read_text())[1:]:
            lines = function.split("\n")
            for k, line in enumerate(lines):
                assigned = re.match(r"    (\w+) = ", line)
                later = "\n".join(lines[k + 1 :])
                if assigned and not re.search(rf"\b{assigned.group(1)}\b", later):
                    dead.append(f"{path.name}: {function.split('(')[0]} {assigned.group(1)}")
    assert dead == []


def test_every_generated_module_header_counts_operations():
    """The plain and the numba modules both say how many operations their kernels take."""
    for path in sorted((ROOT / "generated").glob("*.py")):
        if path.name in ("__init__.py", "registry.py"):
            continue
        assert "arithmetic operations after common-subexpression elimination" in path.read_text()[:2000], path
