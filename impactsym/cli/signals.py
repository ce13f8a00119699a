"""Ctrl-C and SIGTERM while a command runs: both become exceptions that unwind
cleanly (every ``finally`` and ``with`` runs: a sweep's spill folder removed, a
partial output deleted), and a signal that lands where Python would print and
drop the exception (a finaliser, llvmlite's object-cache ctypes callback while
numba loads a driver) is sent again once that code has returned.

Measured need, after drivers load only on demand (no background compile):
tests/test_first_use.py::test_an_interrupted_sweep_leaves_no_spill_file_and_no_traceback
run 8 times with the re-sending disabled failed once (the SIGINT landed in
llvmlite's object-cache callback while the sweep loaded its driver, and was
lost); 12 runs with it passed. So it stays.
"""

from __future__ import annotations

import os
import signal
import threading
from contextlib import contextmanager

from .common import EXIT_TERMINATED

__all__ = ["Terminated", "terminate_as_exit"]


class Terminated(SystemExit):
    """SIGTERM, raised as an exit so that every ``finally`` and ``with`` on
    the way out runs (a sweep's spill folder is removed, a partial output
    file deleted) instead of the process dying where it stands."""


def _raise_terminated(signum, frame):
    if not _deferred(signum, frame):
        raise Terminated(EXIT_TERMINATED)


def _raise_interrupted(signum, frame):
    if not _deferred(signum, frame):
        raise KeyboardInterrupt


# Python functions that C code calls through ctypes while numba loads or
# compiles a driver: llvmlite's object-cache hooks (ExecutionEngine). Python
# prints and drops an exception raised in a ctypes callback, as in a finaliser.
_CTYPES_CALLBACKS = ("_raw_object_cache_notify", "_raw_object_cache_getbuffer")


def _deferred(signum, frame) -> bool:
    """True when the signal landed where Python prints and drops an exception,
    so Ctrl-C would be lost: inside a finaliser (``__del__``; numba and llvmlite
    free compiler objects there) or a ctypes callback (`_CTYPES_CALLBACKS`,
    reached while numba loads a driver from its cache). The signal is sent
    again 50 ms later, when that code has returned."""
    while frame is not None:
        code = frame.f_code
        if code.co_name == "__del__" or (
            code.co_name in _CTYPES_CALLBACKS and "llvmlite" in code.co_filename
        ):
            threading.Timer(0.05, os.kill, (os.getpid(), signum)).start()
            return True
        frame = frame.f_back
    return False


@contextmanager
def terminate_as_exit():
    """SIGTERM raises :class:`Terminated` while the command runs (the main
    thread only: a signal handler cannot be set elsewhere); the previous
    handler is restored after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    # SIGINT as KeyboardInterrupt whatever the disposition inherited from the
    # parent (a script's background job inherits it ignored): Ctrl-C or
    # `kill -INT` always stops a command cleanly, spill files removed.
    previous_int = signal.signal(signal.SIGINT, _raise_interrupted)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
        signal.signal(signal.SIGINT, previous_int)
