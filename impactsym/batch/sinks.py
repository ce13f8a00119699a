"""Writing sweep and sample rows to files chunk by chunk: Parquet and CSV.

`sink(out, repeated)` opens the writer for a path (``.parquet``: one pyarrow
row group per chunk; ``.csv``: the header once), `writing(sink)` closes it
after a block or removes the partial file when the block fails, and
`write_frame` writes a whole frame the same way.
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

from .._util import require

__all__ = ["SINKS", "sink", "writing", "write_frame"]

SINKS = (".parquet", ".csv")


def _file_frame(frame):
    """A frame as files hold it: an object column (a ``mu`` axis mixing
    numbers and ``"critical"``) becomes text, as CSV writes it anyway."""
    text = {name: str for name in frame.columns if frame[name].dtype == object}
    return frame.astype(text) if text else frame


class _FileSink:
    """A file opened at once (an unwritable path fails before any work),
    removed again by `abort`."""

    def __init__(self, path: Path, mode: str, **options):
        # open now, so an unwritable path fails before any work; closed by close/abort
        self.path, self._file = path, open(path, mode, **options)  # noqa: SIM115

    def close(self) -> None:
        self._file.close()

    def abort(self) -> None:
        self.close()
        self.path.unlink(missing_ok=True)


class _ParquetSink(_FileSink):
    """Parquet through one pyarrow ParquetWriter, one row group per chunk.
    Dictionary encoding only for ``repeated`` columns (grid axes, status,
    flags): on the float outputs it costs time and saves nothing."""

    def __init__(self, path: Path, repeated: tuple[str, ...]):
        super().__init__(path, "wb")
        self._writer, self._repeated = None, repeated

    def write(self, frame) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pandas(_file_frame(frame), preserve_index=False)
        if self._writer is None:
            dictionary = [name for name in table.column_names if name in self._repeated]
            self._writer = pq.ParquetWriter(self._file, table.schema, use_dictionary=dictionary)
        self._writer.write_table(table, row_group_size=max(table.num_rows, 1))

    def close(self) -> None:
        if self._writer is not None:
            self._writer.close()
        super().close()


class _CsvSink(_FileSink):
    """CSV: the header once, then each chunk appended; floats as their
    shortest round-trip text, NaN as an empty field (pandas reads it back
    exactly; ``status`` and ``flags`` come back as int64)."""

    def __init__(self, path: Path):
        super().__init__(path, "w", newline="", encoding="utf-8")
        self._header = True

    def write(self, frame) -> None:
        _file_frame(frame).to_csv(self._file, header=self._header, index=False)
        self._header = False


class _NoSink:
    """No file: only the summary is kept."""

    def write(self, frame) -> None:
        pass

    def close(self) -> None:
        pass

    def abort(self) -> None:
        pass


def sink(out, repeated: tuple[str, ...] = ()):
    """The writer for ``out`` (None: no file); ValueError for another suffix.
    ``repeated``: columns besides status and flags with few distinct values."""
    if out is None:
        return _NoSink()
    path = Path(out)
    suffix = path.suffix.lower()
    if suffix == ".parquet":
        require("pyarrow", extra="sweep", what="out=*.parquet")
        return _ParquetSink(path, ("status", "flags", *repeated))
    if suffix == ".csv":
        return _CsvSink(path)
    raise ValueError(f"out: unknown file type {suffix or '(none)'!r} for {path} (use {' or '.join(SINKS)})")


def write_frame(frame, out, repeated: tuple[str, ...] = ()) -> None:
    """Write a whole frame to ``out`` as `sweep`/`sample` would (``.parquet``
    or ``.csv``); ``repeated`` as for the grid axes of a sweep."""
    writer = sink(out, repeated)
    with writing(writer):
        writer.write(frame)


@contextmanager
def writing(sink):
    """Close ``sink`` after the block, or remove its partial file if the block fails."""
    try:
        yield sink
    except BaseException:
        sink.abort()
        raise
    sink.close()
