"""Test-suite settings shared by every test module."""

import os


def pytest_configure(config):
    """Keep the random_realistic draws between runs in pytest's cache folder.

    A draw costs two 50-digit reference solves a row (about 46 s over the fast
    loop, ~12 ms a row); it is deterministic in its arguments, the generator's and
    the reference solver's source and the NumPy and mpmath versions, which name
    the file. A fresh checkout (CI) draws everything; a developer's second run
    loads them."""
    if getattr(config, "cache", None) is None:  # -p no:cacheprovider
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
