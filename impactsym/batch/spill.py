"""The temporary folder a streamed summary spills to, and the clean-up of the
folders runs killed before their end left behind (SIGKILL, a power cut: no
``finally`` runs).

Each folder is named ``impactsym-summary-<pid>-<random>`` after the process
that made it; at every start the folders of processes no longer alive are
removed, so a killed run's spill (hundreds of MB) lasts only until the next.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

__all__ = ["SPILL_PREFIX", "remove_stale", "spill_folder"]

SPILL_PREFIX = "impactsym-summary-"
_OWNED = re.compile(re.escape(SPILL_PREFIX) + r"(\d+)-")


def _alive(pid: int) -> bool:
    """Whether a process ``pid`` exists (one of another user's counts as alive)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True
    return True


def remove_stale(folder: str | None = None) -> list[Path]:
    """Remove the spill folders in ``folder`` (the temporary folder) whose
    process is gone; return them."""
    removed = []
    for path in Path(folder or tempfile.gettempdir()).glob(f"{SPILL_PREFIX}*"):
        owner = _OWNED.match(path.name)
        if owner and path.is_dir() and not _alive(int(owner.group(1))):
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path)
    return removed


@contextlib.contextmanager
def spill_folder() -> Iterator[str]:
    """A fresh spill folder (removed on exit), after removing stale ones."""
    remove_stale()
    with tempfile.TemporaryDirectory(prefix=f"{SPILL_PREFIX}{os.getpid()}-") as folder:
        yield folder
