"""A first use's compile on two cores.

numba compiles a run-out driver in one thread, callee by callee, and caches
each one it compiles. At the first driver call of a process whose numba cache
holds none of the kernels of the generated PRIME list, `ahead()` starts a
second Python process that compiles those kernels (the callees the driver's
compile reaches last) into the same cache; by the time this process's
compile reaches them it finds them there and loads them. On an empty cache
this cut a first fit with `cg_height` from 7.1-8.0 s to 5.0-5.7 s (session 19,
docs/runout.md "First use").

It cannot change a result: numba loads a cached kernel only for the same
source file and argument types, and compiles it itself otherwise (the second
process late, on another copy of the package, or failed). It runs at most
once per process and not at all with IMPACTSYM_PRIME=0, when numba's cache
already holds those kernels, or when caching is off. A process that exits
before the second one has finished stops it.

The second process runs `main` (SECOND), which compiles the PRIME kernels of
generated/runout_jit.py if that module is the file this process uses.
"""

from __future__ import annotations

import atexit
import os
import subprocess
import sys
import threading

from . import _door

# the second process's program; run by -c, not -m, which would import this
# module twice (once by the package's imports, once as __main__)
SECOND = "import sys; from impactsym.runout.prime import main; sys.exit(main(sys.argv[1:]))"
_lock = threading.Lock()
_asked = False


def ahead() -> subprocess.Popen | None:
    """Start the second process if this is the process's first call and the
    cache is cold (see the module doc); returns it, else None."""
    global _asked
    if _asked:  # every run-out after the first: no lock taken
        return None
    with _lock:
        if _asked:
            return None
        _asked = True
    if os.environ.get("IMPACTSYM_PRIME", "1") == "0":
        return None
    jit = _door.jit()
    if not (sys.executable and _cold(jit)):  # no interpreter to start (an embedded Python)
        return None
    paths = [p or os.getcwd() for p in sys.path]  # the same imports as this process
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(paths), IMPACTSYM_PRIME="0")
    try:
        proc = subprocess.Popen(
            [sys.executable, "-c", SECOND, jit.__file__],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            env=env,
        )
    except OSError:  # no process to be had: this one compiles everything, as without
        return None
    atexit.register(_stop, proc)
    return proc


def _cold(jit) -> bool:
    """True when numba's cache has no index file for any PRIME kernel. False
    when caching is off (numba's NullCache has no index) or numba's cache
    internals are not where numba 0.68 keeps them."""
    try:
        return not any(
            os.path.exists(getattr(jit, name)._cache._cache_file._index_path) for name, _ in jit.PRIME
        )
    except AttributeError:
        return False


def _stop(proc: subprocess.Popen) -> None:
    """At exit: end the second process if it is still compiling (numba writes
    each cache file under a temporary name and then renames it, so a stopped
    compile leaves no half-written entry)."""
    if proc.poll() is None:
        proc.kill()
    proc.wait()


def main(argv: list[str]) -> int:
    """The second process: compile the PRIME kernels of generated/runout_jit.py
    if it is the file argv[0] (else its cache entries would serve no one)."""
    jit = _door.jit()
    if argv and os.path.realpath(jit.__file__) != os.path.realpath(argv[0]):
        return 1
    from numba.core.sigutils import normalize_signature  # numba only in the second process

    for name, signature in jit.PRIME:
        # as a tuple of types: numba files a kernel in its cache under the
        # signature it was compiled with, and a caller's compile asks by the tuple
        getattr(jit, name).compile(tuple(normalize_signature(signature)[0]))
    return 0
