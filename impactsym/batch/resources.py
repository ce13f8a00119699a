"""Will a sweep or sample fit the machine? Estimates checked before any work.

A run is refused (a one-line ValueError that says how to proceed) when

- its rows, held in memory as one DataFrame, would take more than
  `MEMORY_FRACTION` of the memory available now (the chunks and their
  concatenation are both alive at the end: twice the frame);
- the values it spills to the temporary folder for exact percentiles (8 bytes
  per summarised output and row) would take more than `DISK_FRACTION` of
  the free space there.

Estimates are upper bounds (every row counted as solved) from the plan alone;
nothing is allocated or written to make them.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

__all__ = [
    "AXIS_COPIES",
    "DISK_FRACTION",
    "MEMORY_FRACTION",
    "available_memory",
    "check_axis",
    "check_disk",
    "check_memory",
    "size",
]

#: The largest share of the available memory an in-memory result may take.
MEMORY_FRACTION = 0.5
#: The largest share of the free temporary space the spill files may take.
DISK_FRACTION = 0.9
#: Bytes of one float64 value.
VALUE_BYTES = 8
#: Copies of a sweep axis alive while a plan is built (the values as given, as
#: float64, in kernel units): a one-axis grid of N points holds 3·8·N bytes
#: before its first row, whatever the chunk size.
AXIS_COPIES = 3


def available_memory() -> int | None:
    """Bytes of memory available to a new allocation without swapping: psutil's
    ``available`` when installed, else ``MemAvailable`` of /proc/meminfo
    (Linux), else free pages by ``os.sysconf``; None when none can tell."""
    try:
        import psutil
    except ImportError:
        psutil = None
    if psutil is not None:
        return int(psutil.virtual_memory().available)
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None


def size(n_bytes: float) -> str:
    """``n_bytes`` for people: ``"7.3 TiB"``."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n_bytes < 1024 or unit == "PiB":
            return f"{n_bytes:.3g} {unit}"
        n_bytes /= 1024
    raise AssertionError("unreachable")


def check_memory(rows: int, values_per_row: int, what: str) -> None:
    """ValueError when ``rows`` rows of ``values_per_row`` 8-byte values
    (held twice while the chunks are joined) exceed `MEMORY_FRACTION` of the
    available memory."""
    need = 2 * rows * values_per_row * VALUE_BYTES
    available = available_memory()
    if available is not None and need > MEMORY_FRACTION * available:
        raise ValueError(
            f"{what}: {rows:,} rows need about {size(need)} in memory, more than half of the "
            f"{size(available)} available; write the rows to a file chunk by chunk (-o "
            "rows.parquet; out= in the API), or use fewer points"
        )


def check_axis(name: str, count: int) -> None:
    """ValueError, before an axis of ``count`` values is built, when its
    :data:`AXIS_COPIES` copies exceed `MEMORY_FRACTION` of the available memory
    (a sweep ``--vary e=0:1:1000000000`` is 24 GB of axis before any row)."""
    need = AXIS_COPIES * count * VALUE_BYTES
    available = available_memory()
    if available is not None and need > MEMORY_FRACTION * available:
        raise ValueError(
            f"{name}: {count:,} values need about {size(need)} in memory to build the axis, more "
            f"than half of the {size(available)} available; use fewer points (or several shorter "
            "sweeps)"
        )


def check_disk(rows: int, values_per_row: int, what: str) -> None:
    """ValueError when the spill of ``rows`` rows of ``values_per_row``
    8-byte values exceeds `DISK_FRACTION` of the free space of the
    temporary folder (``TMPDIR``)."""
    need = rows * values_per_row * VALUE_BYTES
    folder = tempfile.gettempdir()
    free = shutil.disk_usage(folder).free
    if need > DISK_FRACTION * free:
        raise ValueError(
            f"{what}: {rows:,} rows need about {size(need)} of temporary space for exact "
            f"percentiles in {folder}, which has {size(free)} free; use fewer points (or "
            "point TMPDIR at a larger disk)"
        )
