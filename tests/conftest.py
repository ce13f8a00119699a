"""Test-suite settings shared by every test module."""

import os

# The suite compiles the drivers it uses as it goes; a background compile of all
# the others (impactsym.warmup) would only compete with it for the two cores.
os.environ.setdefault("IMPACTSYM_BACKGROUND_COMPILE", "0")
# Many tests compare stderr exactly; on a cold numba cache the "compiling ..."
# notice would land in it. The notice is tested on its own (test_batch.py).
os.environ.setdefault("IMPACTSYM_COMPILE_NOTICE_AFTER", "inf")

import pytest  # noqa: E402


@pytest.fixture(autouse=True)
def _batches_run_the_drivers(monkeypatch):
    """In this process every batch runs the numba drivers, however small: a small
    batch before numba loads would otherwise run the per-scene functions, and
    which tests exercised the drivers would depend on the order tests ran in.
    tests/test_python_rows.py proves the two paths give the same bits and sets
    the threshold back where it tests the per-scene path. (Subprocess tests run
    the runtime as users do.)"""
    from impactsym import _kernels

    monkeypatch.setattr(_kernels, "PYTHON_BELOW", 0)
