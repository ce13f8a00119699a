"""Compiling every batch driver once per machine, so no later call waits.

numba compiles a batch driver the first time it runs on a machine and caches
it on disk; each driver has one signature (impactsym._kernels), so a new mix
of scalar and array columns never compiles again, but a driver never used
before still would (2–10 s each, about 100 drivers). After the first batch
call on a machine, impactsym therefore compiles all the others once, in a
background process (`impactsym compile`, at low priority), and leaves a
marker beside numba's cache; from then on every batch call only loads.

Set ``IMPACTSYM_BACKGROUND_COMPILE=0`` to turn the background compile off
(the test suite does); ``impactsym compile`` does the same in the foreground.
This module decides *when*; `impactsym._kernels.compile_all` does the compiling.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

ENV = "IMPACTSYM_BACKGROUND_COMPILE"
# A "compiling" claim older than this is from a process that died: try again.
STALE_CLAIM_SECONDS = 3600.0


def cache_dir(generated_file: str) -> Path:
    """Where numba caches the generated drivers: NUMBA_CACHE_DIR, else the
    ``__pycache__`` folder beside generated/ (numba's default for a writable
    package; the door sets NUMBA_CACHE_DIR for a read-only one)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"])
    return Path(generated_file).resolve().parent / "__pycache__"


def marker(generated_file: str, digest: str) -> Path:
    """The file saying that every driver of this generated code is compiled."""
    return cache_dir(generated_file) / f"impactsym-compiled-{digest[:16]}"


def _claim(done: Path) -> bool:
    """Take the right to compile (one background compile at a time): True if
    this process created the claim file, or replaced a stale one."""
    claim = done.with_suffix(".compiling")
    try:
        claim.parent.mkdir(parents=True, exist_ok=True)
        if claim.exists() and time.time() - claim.stat().st_mtime > STALE_CLAIM_SECONDS:
            claim.unlink()
        fd = os.open(claim, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except OSError:
        return False
    os.close(fd)
    return True


def start_background(generated_file: str, digest: str) -> bool:
    """After a first batch call: start `impactsym compile` in the background
    unless every driver is compiled already, one is running, or the user
    turned it off. Says so on stderr once. True if it started one."""
    if os.environ.get(ENV, "1") == "0":
        return False
    done = marker(generated_file, digest)
    if done.exists() or not _claim(done):
        return False
    print(
        "impactsym: compiling the other batch kernels in the background, once per machine "
        f"(a few minutes; {ENV}=0 turns this off)",
        file=sys.stderr,
    )
    subprocess.Popen(
        [sys.executable, "-m", "impactsym", "compile", "--quiet", "--claimed"],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
        env={**os.environ, ENV: "0"},
    )
    return True


def finish(generated_file: str, digest: str) -> None:
    """Leave the marker and drop the claim (after `compile_all` succeeded)."""
    done = marker(generated_file, digest)
    done.parent.mkdir(parents=True, exist_ok=True)
    done.touch()
    done.with_suffix(".compiling").unlink(missing_ok=True)


def release(generated_file: str, digest: str) -> None:
    """Drop the claim without the marker (the compile failed or was stopped)."""
    marker(generated_file, digest).with_suffix(".compiling").unlink(missing_ok=True)
