"""Reading and writing recordings: CSV + ``.meta.json``, Parquet, SIDPAC ``.mat``.

Forms
-----
``NAME.csv`` + ``NAME.meta.json``
    The interchange form of the format. One header row, comma separated, ``.``
    decimal point; every float is written with ``repr`` (the shortest string that
    reads back to the same float64), so values round-trip bit for bit.
``NAME.parquet``
    Same columns; the metadata is stored as JSON under the schema-metadata key
    :data:`PARQUET_META_KEY`. Round-trips bit for bit.
``NAME.mat``
    SIDPAC flight data, read only (:func:`harness.sidpac.import_sidpac`).

Writes are atomic per file (:mod:`harness.atomic`): each file is written to a
temporary file in the same folder and moved into place with :func:`os.replace`, so a
reader never sees a half written file. The CSV and its ``.meta.json`` are two files,
written one after the other (data first).
"""

from __future__ import annotations

import csv
import json
import math
import re
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from harness.atomic import write_atomic, write_text_atomic
from maneuvers.recording import (
    ROW_CONVENTION,
    Recording,
    RecordingError,
    canonical_names,
    convert_in_place,
    frame_from_columns,
    row_label,
)

__all__ = ["PARQUET_META_KEY", "meta_path_for", "read_recording", "write_recording"]

PARQUET_META_KEY = b"flight-recording.meta"
"""Parquet schema-metadata key holding the recording's metadata as UTF-8 JSON."""

_META_SUFFIX = ".meta.json"


def meta_path_for(csv_path: str | Path) -> Path:
    """Path of the metadata file beside a CSV recording (``NAME.csv`` -> ``NAME.meta.json``)."""
    p = Path(csv_path)
    return p.with_name(p.stem + _META_SUFFIX)


# --------------------------------------------------------------------------------------
# Metadata as JSON
# --------------------------------------------------------------------------------------


def _jsonable(value: Any, path: str, source: str) -> Any:
    """Return ``value`` as plain JSON types, refusing what JSON cannot hold exactly.

    NumPy scalars become Python numbers, NumPy arrays and tuples become lists. Non
    finite floats, non-string keys and other types are refused naming the key path.
    """
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise RecordingError(
                    f"metadata keys must be strings, got {k!r}", source=source, key=path,
                    rule="bad-meta",
                )
            out[k] = _jsonable(v, f"{path}[{k!r}]", source)
        return out
    if isinstance(value, (list, tuple)):
        return [_jsonable(v, f"{path}[{i}]", source) for i, v in enumerate(value)]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist(), path, source)
    if isinstance(value, np.generic):
        return _jsonable(value.item(), path, source)
    if value is None or isinstance(value, (str, bool, int)):
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            raise RecordingError(
                f"non-finite number {value!r} cannot be written to JSON",
                source=source, key=path, rule="bad-meta",
            )
        return value
    raise RecordingError(
        f"value of type {type(value).__name__} cannot be written to JSON",
        source=source, key=path, rule="bad-meta",
    )


def _meta_json(meta: dict[str, Any], source: str) -> str:
    return json.dumps(_jsonable(meta, "meta", source), indent=2, ensure_ascii=False, allow_nan=False) + "\n"


def _parse_meta(text: str, source: str) -> dict[str, Any]:
    try:
        meta = json.loads(text)
    except json.JSONDecodeError as exc:
        raise RecordingError(
            f"metadata is not valid JSON: {exc}", source=source, key="meta", rule="bad-meta-json",
        ) from None
    if not isinstance(meta, dict):
        raise RecordingError(
            f"metadata must be a JSON object, got {type(meta).__name__}",
            source=source, key="meta", rule="bad-meta-json",
        )
    return meta


# --------------------------------------------------------------------------------------
# CSV
# --------------------------------------------------------------------------------------


_WRITE_CHUNK_ROWS = 65_536


def _csv_lines(data: pd.DataFrame) -> Iterator[str]:
    """The CSV text in pieces of at most :data:`_WRITE_CHUNK_ROWS` rows (memory stays bounded)."""
    yield ",".join(data.columns) + "\n"
    arrays = [data[c].to_numpy(dtype=np.float64) for c in data.columns]
    for start in range(0, len(data), _WRITE_CHUNK_ROWS):
        columns = [[repr(v) for v in a[start:start + _WRITE_CHUNK_ROWS].tolist()] for a in arrays]
        yield "".join(",".join(row) + "\n" for row in zip(*columns))


def _write_csv_body(data: pd.DataFrame, fh: IO[bytes]) -> None:
    for piece in _csv_lines(data):
        fh.write(piece.encode("utf-8"))


def _read_header(path: Path) -> list[str]:
    """The header row (file line 1), decoded as UTF-8 (a BOM is skipped), duplicates refused."""
    source = str(path)
    with path.open("rb") as fh:
        raw = fh.readline()
        if not raw.strip() and not fh.read(1):
            raise RecordingError("file is empty; expected a header row", source=source, key="header",
                                 rule="empty-file")
    text = _decode_utf8(raw.removeprefix(b"\xef\xbb\xbf"), source, "header (file line 1)")
    header = [h.strip() for h in next(csv.reader([text.rstrip("\r\n")]), [])]
    if not any(header):
        raise RecordingError("the first line is blank; expected a header row", source=source, key="header",
                             rule="empty-file")
    seen: set[str] = set()
    for h in header:
        if h in seen:
            raise RecordingError("column appears twice in the header", source=source,
                                 key=f"column {h!r}", rule="duplicate-quantity")
        seen.add(h)
    return header


def _decode_utf8(raw: bytes, source: str, where: str) -> str:
    """``raw`` as text, or an error naming the line and column of the first byte that is not UTF-8."""
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise RecordingError(
            f"not valid UTF-8: byte 0x{raw[exc.start]:02x} at line {line}, column {column} of the {where} "
            "(Latin-1 or another encoding?); save the file as UTF-8",
            source=source, key=where, rule="bad-encoding",
        ) from None


class _InvalidRows:
    """Invalid-row handler for pyarrow's CSV reader: remembers the first ragged row."""

    def __init__(self) -> None:
        self.first: tuple[int | None, int, int] | None = None

    def __call__(self, row: Any) -> str:
        if self.first is None:
            self.first = (row.number, row.actual_columns, row.expected_columns)
        return "error"


def _arrow_csv(path: Path, header: list[str], *, threads: bool = True, handler: Any = None,
               types: Any = None, include: list[str] | None = None) -> pa.Table:
    """The body of a recording CSV as an Arrow table (header given, blank lines kept as null rows)."""
    column_type = types or pa.float64()
    return pacsv.read_csv(
        path,
        read_options=pacsv.ReadOptions(column_names=header, skip_rows=1, use_threads=threads,
                                       block_size=1 << 24),
        parse_options=pacsv.ParseOptions(ignore_empty_lines=False, invalid_row_handler=handler),
        convert_options=pacsv.ConvertOptions(
            column_types={h: column_type for h in (include or header)}, include_columns=include,
            null_values=[""], strings_can_be_null=False, quoted_strings_can_be_null=False, check_utf8=False),
        memory_pool=pa.system_memory_pool(),
    )


def _line_text(row: int) -> str:
    """``'row 3 (data rows counted from 1; file line 4)'`` for the 1-based data row ``row``."""
    return f"row {row} ({ROW_CONVENTION}; file line {row + 1})"


def _ragged_row_error(path: Path, header: list[str], first: tuple[int | None, int, int]) -> RecordingError:
    number, actual, expected = first
    if number is None or number < 0:  # the threaded reader does not count lines: find it again
        handler = _InvalidRows()
        try:
            _arrow_csv(path, header, threads=False, handler=handler)
        except pa.ArrowInvalid:
            pass
        if handler.first is not None:
            number, actual, expected = handler.first
    where = _line_text(number - 1) if number and number > 0 else "a row"
    return RecordingError(
        f"{where} has {actual} field(s), the header has {expected} (ragged row: column lengths do not match)",
        source=str(path), key=f"line {number}" if number else "rows", rule="length-mismatch",
    )


_NUMBER_RE = r"^\s*[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|nan|inf|infinity)\s*$"


def _non_numeric_error(path: Path, header: list[str], message: str) -> RecordingError:
    """Name the column and row of the first cell the reader could not take as a number."""
    match = re.search(r"column #(\d+)", message)
    name = header[int(match.group(1))] if match and int(match.group(1)) < len(header) else None
    if name is None:
        return RecordingError(f"cannot read the file as numbers: {message}", source=str(path), key="data",
                              rule="non-numeric")
    cells = _arrow_csv(path, header, types=pa.binary(), include=[name]).column(0)
    ok = pc.match_substring_regex(cells, _NUMBER_RE, ignore_case=True)
    index = pc.index(ok, False).as_py()
    if index < 0:
        return RecordingError(f"cannot read a cell as a number: {message}", source=str(path),
                              key=f"column {name!r}", rule="non-numeric")
    cell = cells[index].as_py().decode("utf-8", errors="backslashreplace")
    return RecordingError(
        f"cannot read {cell!r} on {_line_text(index + 1)} as a number",
        source=str(path), key=f"column {name!r}", rule="non-numeric",
    )


class _Columns:
    """Float64 NumPy columns filled batch by batch (memory: the data once, plus one batch).

    The capacity is a row count estimated up front (exact for Parquet); it grows by a quarter
    when exceeded and is trimmed in place at the end.
    """

    def __init__(self, names: list[str], capacity: int, source: str) -> None:
        self.names, self.source = names, source
        self.capacity = max(1, capacity)
        self.arrays = [np.empty(self.capacity, dtype=np.float64) for _ in names]
        self.n = 0
        self.blank: list[np.ndarray] = []  # rows where every field is empty (blank lines)

    def add(self, batch: pa.RecordBatch) -> None:
        k = batch.num_rows
        if self.n + k > self.capacity:
            self.capacity = max(self.n + k, self.capacity + self.capacity // 4)
            for a in self.arrays:
                a.resize(self.capacity, refcheck=False)
        self._check_nulls(batch)
        for j in range(len(self.names)):
            self.put(j, self.n, batch.column(j), blank_rows_checked=True)
        self.n += k

    def put(self, j: int, offset: int, column: pa.Array, blank_rows_checked: bool = False) -> int:
        """Copy ``column`` into column ``j`` from row ``offset``; the next offset. Empty values are
        refused unless the caller has already told blank lines from empty fields."""
        if not (pa.types.is_floating(column.type) or pa.types.is_integer(column.type)):
            raise RecordingError(f"values must be numbers, the column holds {column.type}", source=self.source,
                                 key=f"column {self.names[j]!r}", rule="non-numeric")
        if column.null_count and not blank_rows_checked:
            row = offset + pc.index(pc.is_null(column), True).as_py()
            raise RecordingError(f"empty value at {row_label(row)}", source=self.source,
                                 key=f"column {self.names[j]!r}", rule="non-numeric")
        k = len(column)
        self.arrays[j][offset:offset + k] = column.to_numpy(zero_copy_only=False)
        return offset + k

    def _check_nulls(self, batch: pa.RecordBatch) -> None:
        if not any(c.null_count for c in batch.columns):
            return
        nulls = np.column_stack([np.asarray(pc.is_null(c)) for c in batch.columns])
        every, some = nulls.all(axis=1), nulls.any(axis=1)
        partial = np.flatnonzero(some & ~every)
        if partial.size:
            i = int(partial[0])
            j = int(np.flatnonzero(nulls[i])[0])
            raise RecordingError(f"empty value at {_line_text(self.n + i + 1)}", source=self.source,
                                 key=f"column {self.names[j]!r}", rule="non-numeric")
        self.blank.append(self.n + np.flatnonzero(every))

    def finish(self) -> dict[str, np.ndarray]:
        """The columns, blank lines at the end dropped; a blank line among the data is refused."""
        blank = np.concatenate(self.blank) if self.blank else np.empty(0, dtype=np.int64)
        n = self.n - blank.size
        if blank.size and blank[0] < n:
            row = int(blank[0]) + 1
            raise RecordingError(f"{_line_text(row)} is blank (a blank line among the data)", source=self.source,
                                 key=f"line {row + 1}", rule="length-mismatch")
        for a in self.arrays:
            a.resize(n, refcheck=False)
        return dict(zip(self.names, self.arrays))


_STREAM_BLOCK = 1 << 22


def _csv_columns(path: Path) -> dict[str, np.ndarray]:
    """Read a recording CSV with pyarrow's streaming reader (columnar, float64, correctly rounded)."""
    if path.stat().st_size == 0:
        raise RecordingError("file is empty; expected a header row", source=str(path), key="header",
                             rule="empty-file")
    header = _read_header(path)
    canonical_names(header, str(path))  # names are checked before any data are read
    handler = _InvalidRows()
    columns: _Columns | None = None
    try:
        reader = _arrow_csv_stream(path, header, handler)
        for batch in reader:
            if columns is None:  # rows per byte of the first block -> the whole file's row count
                columns = _Columns(header, int(path.stat().st_size * batch.num_rows / _STREAM_BLOCK * 1.02) + 16,
                                   str(path))
            columns.add(batch)
    except pa.ArrowInvalid as exc:
        if handler.first is not None:
            raise _ragged_row_error(path, header, handler.first) from None
        raise _non_numeric_error(path, header, str(exc)) from None
    return (columns or _Columns(header, 1, str(path))).finish()


def _arrow_csv_stream(path: Path, header: list[str], handler: Any) -> pacsv.CSVStreamingReader:
    return pacsv.open_csv(
        path,
        read_options=pacsv.ReadOptions(column_names=header, skip_rows=1, use_threads=False,
                                       block_size=_STREAM_BLOCK),
        parse_options=pacsv.ParseOptions(ignore_empty_lines=False, invalid_row_handler=handler),
        convert_options=pacsv.ConvertOptions(
            column_types={h: pa.float64() for h in header}, null_values=[""], strings_can_be_null=False,
            quoted_strings_can_be_null=False),
        memory_pool=pa.system_memory_pool(),
    )


def _frame(columns: dict[str, np.ndarray], source: str) -> pd.DataFrame:
    """Canonical names and units, in place (the columns are given up), as a table without copies."""
    n = len(next(iter(columns.values()))) if columns else 0
    targets = canonical_names(list(columns), source)
    return frame_from_columns(convert_in_place(columns, targets), n)


# --------------------------------------------------------------------------------------
# Parquet
# --------------------------------------------------------------------------------------


def _write_parquet_body(data: pd.DataFrame, meta_json: str, fh: IO[bytes]) -> None:
    table = pa.Table.from_pandas(data, preserve_index=False)
    metadata = dict(table.schema.metadata or {})
    metadata[PARQUET_META_KEY] = meta_json.encode("utf-8")
    pq.write_table(table.replace_schema_metadata(metadata), fh)


def _read_parquet(path: Path) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    source = str(path)
    try:
        pf = pq.ParquetFile(path)
        metadata = pf.schema_arrow.metadata or {}
        if PARQUET_META_KEY not in metadata:
            raise RecordingError(
                f"Parquet schema metadata has no {PARQUET_META_KEY.decode()!r} entry",
                source=source, key="meta", rule="missing-meta",
            )
        meta = _parse_meta(_decode_utf8(metadata[PARQUET_META_KEY], source, "embedded metadata"), source)
        names = list(pf.schema_arrow.names)
        canonical_names(names, source)
        columns = _Columns(names, pf.metadata.num_rows, source)
        for j in range(len(names)):  # column by column: a row group is never decoded whole
            offset = 0
            for batch in pf.iter_batches(batch_size=1 << 16, columns=[names[j]], use_threads=False):
                offset = columns.put(j, offset, batch.column(0))
        columns.n = pf.metadata.num_rows
    except (pa.ArrowException, OSError) as exc:
        raise RecordingError(f"not a readable Parquet file ({' '.join(str(exc).split())[:200]})", source=source,
                             key="file", rule="bad-parquet") from None
    return columns.finish(), meta


# --------------------------------------------------------------------------------------
# Public API
# --------------------------------------------------------------------------------------


def write_recording(rec: Recording, path: str | Path) -> Path:
    """Validate ``rec`` and write it atomically.

    Parameters
    ----------
    rec : Recording
        The recording (canonical units).
    path : str or Path
        ``NAME.csv`` (writes ``NAME.csv`` and ``NAME.meta.json``) or ``NAME.parquet``
        (metadata embedded). Existing files are replaced.

    Returns
    -------
    Path
        ``path`` as a :class:`~pathlib.Path`.

    Raises
    ------
    RecordingError
        If the recording breaks a rule, its metadata cannot be written to JSON
        exactly, or the suffix is neither ``.csv`` nor ``.parquet``.
    """
    path = Path(path)
    source = str(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".parquet"):
        raise RecordingError(
            f"cannot write {path.suffix!r} files; use '.csv' or '.parquet'",
            source=source, key="file suffix", rule="unknown-file-type",
        )
    rec.validate(source)
    meta_json = _meta_json(rec.meta, source)
    if suffix == ".csv":
        write_atomic(path, lambda fh: _write_csv_body(rec.data, fh))
        write_text_atomic(meta_path_for(path), meta_json)
    else:
        write_atomic(path, lambda fh: _write_parquet_body(rec.data, meta_json, fh))
    return path


def read_recording(path: str | Path) -> Recording:
    """Read a recording, convert it to canonical units and validate it.

    Parameters
    ----------
    path : str or Path
        ``NAME.csv`` (with ``NAME.meta.json`` beside it), ``NAME.parquet``, or a SIDPAC
        ``NAME.mat`` file.

    Returns
    -------
    Recording
        Named ``NAME``, validated with ``source=str(path)``.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    RecordingError
        If the metadata file is missing or unreadable, a row is ragged, a column
        cannot be understood, or any rule of the format is broken.
    """
    path = Path(path)
    source = str(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".parquet", ".mat"):
        raise RecordingError(
            f"cannot read {path.suffix!r} files; expected '.csv', '.parquet' or '.mat'",
            source=source, key="file suffix", rule="unknown-file-type",
        )
    _check_input_file(path)
    if suffix == ".mat":
        from harness.sidpac import import_sidpac  # local import: scipy.io only when needed

        return import_sidpac(path)
    if suffix == ".csv":
        meta_path = meta_path_for(path)
        if not meta_path.is_file():
            raise RecordingError(
                f"metadata file {str(meta_path)!r} is missing (expected beside the CSV)",
                source=source, key=str(meta_path), rule="missing-meta-file",
            )
        meta = _parse_meta(_decode_utf8(meta_path.read_bytes(), str(meta_path), "metadata"), str(meta_path))
        columns = _csv_columns(path)
    else:
        columns, meta = _read_parquet(path)
    return Recording(_frame(columns, source), meta, name=path.stem).validate(source)


def _check_input_file(path: Path) -> None:
    """A missing file or a folder is refused naming it."""
    if path.is_dir():
        raise RecordingError("is a folder, not a recording file", source=str(path), key="file", rule="not-a-file")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such recording file")
