"""Compiling every batch driver once per machine (impactsym.warmup, _kernels.compile_all)."""

import numpy as np
import pytest

from impactsym import _kernels, warmup
from impactsym.cli import main


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """Markers and claims go to a fresh folder; background compiles allowed."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv(warmup.ENV, "1")
    started = []
    monkeypatch.setattr(warmup.subprocess, "Popen", lambda *a, **k: started.append(a[0]))
    return tmp_path, started


def test_first_batch_starts_one_background_compile(cache, capsys):
    folder, started = cache
    assert warmup.start_background("x/generated/__init__.py", "abc123")
    assert started == [[warmup.sys.executable, "-m", "impactsym", "compile", "--quiet", "--claimed"]]
    assert "in the background" in capsys.readouterr().err
    # a second process finds the claim and starts nothing
    assert not warmup.start_background("x/generated/__init__.py", "abc123")
    assert len(started) == 1


def test_nothing_starts_when_compiled_or_turned_off(cache, monkeypatch):
    folder, started = cache
    warmup.finish("x/generated/__init__.py", "abc123")
    assert warmup.marker("x/generated/__init__.py", "abc123").exists()
    assert not warmup.start_background("x/generated/__init__.py", "abc123")
    monkeypatch.setenv(warmup.ENV, "0")
    assert not warmup.start_background("x/generated/__init__.py", "other")
    assert started == []


def test_a_stale_claim_is_taken_over(cache):
    folder, started = cache
    claim = warmup.marker("g/__init__.py", "d").with_suffix(".compiling")
    claim.parent.mkdir(parents=True, exist_ok=True)
    claim.touch()
    assert not warmup.start_background("g/__init__.py", "d")
    old = claim.stat().st_mtime - warmup.STALE_CLAIM_SECONDS - 10
    import os

    os.utime(claim, (old, old))
    assert warmup.start_background("g/__init__.py", "d")


def test_every_runtime_driver_is_listed_once():
    drivers = [(ks.name, p, n) for ks, p, n in _kernels.batch_drivers()]
    assert len(drivers) == len(set(drivers))
    names = {name for name, _, _ in drivers}
    assert {
        "rigid",
        "particle_critical",
        "rigid_inverse",
        "reconstruct",
        "crash3_delta_v",
        "delta_v_from_energy",
        "kinetic_energy",
    } <= names
    assert not any(name.endswith("_jacobian") for name in names)


def test_compile_command_compiles_with_the_runtime_signature(cache, monkeypatch):
    """`impactsym compile` gives each driver the one signature batches use, so a
    later batch (any scalar/array mix, read-only input) adds none; then the marker."""
    folder, _ = cache
    ks = _kernels.KINETIC_ENERGY
    monkeypatch.setattr(_kernels, "batch_drivers", lambda: iter([(ks, True, False), (ks, False, False)]))
    assert main(["compile", "--quiet"]) == 0
    assert warmup.marker(_kernels.generated.__file__, _kernels.generated_digest()).exists()
    parallel, serial = ks.driver(True), ks.driver(False)
    assert len(parallel.signatures) == len(serial.signatures) == 1
    n = 200
    columns = [np.full(n, 2.0) for _ in ks.inputs]
    columns[0] = 3.0  # a scalar column
    columns[-1] = np.broadcast_to(np.float64(1.5), (n,))  # read-only
    _kernels.run_batch(ks, columns, n)
    _kernels.run_batch(ks, [1.0] * len(ks.inputs), 10)
    assert len(parallel.signatures) == len(serial.signatures) == 1
