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


def pytest_configure(config):
    """Keep the random_realistic draws between runs in pytest's cache folder.

    A draw costs two 50-digit reference solves a row (about 46 s over the fast
    loop, ~12 ms a row); it is deterministic in its arguments, the generator's and
    the reference solver's source and the NumPy and mpmath versions, which name
    the file. A fresh checkout (CI) draws everything; a developer's second run
    loads them."""
    if config.cache is None:  # -p no:cacheprovider
        return
    import functools
    import hashlib
    from pathlib import Path

    import mpmath
    import numpy as np

    from impactsym.testing import reference, scenes

    folder = config.cache.mkdir("impactsym-scenes")
    sources = b"".join(Path(m.__file__).read_bytes() for m in (scenes, reference))
    versions = f"{np.__version__} {mpmath.__version__}".encode()
    digest = hashlib.sha256(sources + versions).hexdigest()[:16]
    draw = scenes._random_realistic.__wrapped__

    @functools.lru_cache(maxsize=64)
    def kept(n, seed, model, barrier):
        path = folder / f"{digest}-{n}-{seed}-{model}-{barrier}.npz"
        if path.exists():
            with np.load(path) as saved:
                return {key: saved[key] for key in saved.files}
        columns = draw(n, seed, model, barrier)
        partial = path.with_suffix(f".{os.getpid()}.npz")
        np.savez(partial, **columns)
        partial.replace(path)
        return columns

    scenes._random_realistic = kept
