"""`python -m derive`: prove, then regenerate generated/; `--check`: fail if stale.

How a kernel family gets into the runtime (the whole contract): write a derive
module ``derive/<name>.py`` with ``KERNELS`` (a tuple of derive.kernel.Kernel;
``EMITTED`` instead when what is emitted differs from what is proved, e.g.
specialised variants), ``proofs()`` returning (claim, passed) pairs, and
optionally ``DATA`` ((NAME, plain literal) pairs); add ``name`` to
MODEL_MODULES below (and to PER_SCENE_ONLY_MODULES if it needs no batch
driver). `python -m derive` then writes generated/<name>.py (per-scene
functions), generated/<name>_jit.py (one numba driver per kernel) and the
kernel's row in generated/registry.py: family (Kernel.family, default its
name), variant (Kernel.variant), module, driver columns, inputs, outputs,
constants, tier, operations; a module's DATA is published there too. The
runtime finds kernels only through that registry (impactsym/_kernels/), so
nothing else has to be written for a batch or a single scene to run them. A
family whose kernel is a loop rather than straight-line code (the run-out's
integrator) is listed in RENDERED_MODULES instead: its module's render(digest)
writes its files, and its room reaches them by module through the registry.

Emission always runs every proof first and stops at the first failure.
`--check` re-renders in memory, compares bytes with generated/ and prints a
unified diff of every stale file (it does not re-run the proofs: the files it
compares were only written after they passed, and the source hash in their
header ties them to this derive source).
"""

from __future__ import annotations

import argparse
import difflib
import os
import sys
from pathlib import Path

MODEL_MODULES = (
    "particle",
    "planar",
    "delta_v",
    "inverse",
    "reconstruct",
    "presets",
    "crash3",
    "report",
    "jacobian",
    "evidence",
    "kudlich_slibar",
    "coulomb",
)
# Proved before emission but emitting no module of their own (emit inlines their source).
PROOF_ONLY_MODULES = ("trig", "load_transfer")
# Emitted without numba batch drivers: the linear method evaluates a Jacobian
# once per scene with the plain-Python function, and a driver returning the
# 100-300 outputs of a Jacobian does not compile (numba has no LIST_TO_TUPLE,
# which CPython uses for tuples of more than 30 values).
PER_SCENE_ONLY_MODULES = ("jacobian", "evidence")
# Seconds of the longest proofs on the 2-core development machine (2026-11-24),
# so that run_proofs starts them first; the rest take 3 s or less each.
PROOF_SECONDS = {"jacobian": 72.0, "runout": 28.0}
# Families that write their own files (a loop, not straight-line kernels): render(digest) -> {name: text}.
RENDERED_MODULES = ("runout",)
ROOT = Path(__file__).resolve().parent.parent


def _reexec_with_fixed_hash_seed() -> None:
    """SymPy's internal set orders can depend on hash randomisation; fix it so
    emission is byte-for-byte deterministic."""
    if os.environ.get("PYTHONHASHSEED") != "0":
        env = dict(os.environ, PYTHONHASHSEED="0")
        os.execve(sys.executable, [sys.executable, "-m", "derive", *sys.argv[1:]], env)


def render_all() -> dict[str, str]:
    """File name → text for every file of generated/."""
    import importlib

    from . import emit
    from .specialise import REQUEST_TIERS

    digest = emit.source_hash()
    files = {}
    listed = []
    for name in MODEL_MODULES:
        mod = importlib.import_module(f"derive.{name}")
        doc = (mod.__doc__ or "").strip().splitlines()[0]
        kernels = getattr(mod, "EMITTED", mod.KERNELS)
        data = getattr(mod, "DATA", ())
        drivers = name not in PER_SCENE_ONLY_MODULES
        files[f"{name}.py"] = emit.render_module(
            f"{name}.py", doc, kernels, digest, data=data, drivers=drivers
        )
        if drivers:
            files[f"{name}_jit.py"] = emit.render_jit_module(f"{name}.py", kernels, digest)
        listed.append((name, kernels, data, drivers))
    for name in RENDERED_MODULES:
        files.update(importlib.import_module(f"derive.{name}").render(digest))
    files["registry.py"] = emit.render_registry(listed, digest, REQUEST_TIERS)
    files["__init__.py"] = emit.render_init(MODEL_MODULES + RENDERED_MODULES, digest)
    return files


def run_proofs() -> bool:
    """Run every derive module's proofs; print each claim (in module order);
    False if any failed. The modules' proofs are independent: each runs in a
    process of its own (fork, as many as CPUs), so the longest, the Jacobians'
    (about 70 s here), overlaps the others (all in one process: about 120 s)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    names = MODEL_MODULES + PROOF_ONLY_MODULES + RENDERED_MODULES
    if "fork" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("fork")
        with ProcessPoolExecutor(max_workers=os.cpu_count() or 1, mp_context=context) as pool:
            futures = {
                name: pool.submit(_module_proofs, name) for name in sorted(names, key=_cost, reverse=True)
            }
            results = [futures[name].result() for name in names]
    else:  # no fork (Windows): one process
        results = [_module_proofs(name) for name in names]
    ok = True
    for claims in results:
        for claim, passed in claims:
            print(f"  [{'ok' if passed else 'FAILED'}] {claim}")
            ok = ok and passed
    return ok


def _cost(name: str) -> float:
    """Seconds a module's proofs took here (the longest are started first)."""
    return PROOF_SECONDS.get(name, 0.0)


def _module_proofs(name: str) -> list[tuple[str, bool]]:
    """(claim, passed) of derive/<name>.py's proofs."""
    import importlib

    return [(claim, bool(passed)) for claim, passed in importlib.import_module(f"derive.{name}").proofs()]


def stale_files(out: Path) -> dict[str, str]:
    """Name → unified diff (committed → fresh render) of every generated file
    that is missing or differs from a fresh render."""
    stale = {}
    for name, text in render_all().items():
        path = out / name
        old = path.read_text() if path.exists() else ""
        if old != text:
            stale[name] = "".join(
                difflib.unified_diff(
                    old.splitlines(keepends=True),
                    text.splitlines(keepends=True),
                    fromfile=f"{path} (committed)",
                    tofile=f"{path} (fresh render)",
                )
            )
    return stale


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m derive", description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="print a diff and exit 1 if generated/ is stale")
    parser.add_argument(
        "--out", type=Path, default=ROOT / "generated", help="output folder (default: generated/)"
    )
    args = parser.parse_args(argv)
    if args.check:
        stale = stale_files(args.out)
        if stale:
            for diff in stale.values():
                sys.stdout.write(diff)
            print(f"generated/ is stale: {', '.join(stale)}; run `python -m derive`")
            return 1
        print("generated/ is up to date")
        return 0
    print("proving:")
    if not run_proofs():
        print("a proof failed: nothing emitted")
        return 1
    args.out.mkdir(parents=True, exist_ok=True)
    for name, text in render_all().items():
        (args.out / name).write_text(text)
        print(f"wrote {args.out / name}")
    return 0


if __name__ == "__main__":
    _reexec_with_fixed_hash_seed()
    sys.exit(main())
