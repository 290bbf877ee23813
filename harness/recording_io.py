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
import io
import json
import math
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from harness.atomic import write_atomic, write_text_atomic
from maneuvers.recording import Recording, RecordingError, to_canonical

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


def _csv_lines(data: pd.DataFrame) -> Iterator[str]:
    yield ",".join(data.columns) + "\n"
    columns = [[repr(v) for v in data[c].to_numpy(dtype=np.float64).tolist()] for c in data.columns]
    for row in zip(*columns):
        yield ",".join(row) + "\n"


def _write_csv_body(data: pd.DataFrame, fh: IO[bytes]) -> None:
    fh.write("".join(_csv_lines(data)).encode("utf-8"))


def _read_csv_frame(path: Path) -> pd.DataFrame:
    """Read a recording CSV exactly (Python's correctly rounded float parser)."""
    source = str(path)
    text = path.read_text(encoding="utf-8-sig")
    rows = list(csv.reader(io.StringIO(text)))
    while rows and not rows[-1]:  # trailing blank lines
        rows.pop()
    if not rows:
        raise RecordingError("file is empty; expected a header row", source=source, key="header",
                             rule="empty-file")
    header = [h.strip() for h in rows[0]]
    seen: set[str] = set()
    for h in header:
        if h in seen:
            raise RecordingError("column appears twice in the header", source=source,
                                 key=f"column {h!r}", rule="duplicate-quantity")
        seen.add(h)
    body = rows[1:]
    for i, row in enumerate(body):
        if len(row) != len(header):
            raise RecordingError(
                f"line {i + 2} has {len(row)} field(s), the header has {len(header)} "
                "(ragged row: column lengths do not match)",
                source=source, key=f"line {i + 2}", rule="length-mismatch",
            )
    columns: dict[str, np.ndarray] = {}
    for j, name in enumerate(header):
        cells = [row[j] for row in body]
        try:
            columns[name] = np.fromiter(map(float, cells), dtype=np.float64, count=len(cells))
        except ValueError:
            for i, cell in enumerate(cells):
                try:
                    float(cell)
                except ValueError:
                    raise RecordingError(
                        f"cannot read {cell!r} on line {i + 2} as a number",
                        source=source, key=f"column {name!r}", rule="non-numeric",
                    ) from None
            raise
    return pd.DataFrame(columns, index=pd.RangeIndex(len(body)))


# --------------------------------------------------------------------------------------
# Parquet
# --------------------------------------------------------------------------------------


def _write_parquet_body(data: pd.DataFrame, meta_json: str, fh: IO[bytes]) -> None:
    table = pa.Table.from_pandas(data, preserve_index=False)
    metadata = dict(table.schema.metadata or {})
    metadata[PARQUET_META_KEY] = meta_json.encode("utf-8")
    pq.write_table(table.replace_schema_metadata(metadata), fh)


def _read_parquet(path: Path) -> tuple[pd.DataFrame, dict[str, Any]]:
    source = str(path)
    table = pq.read_table(path)
    metadata = table.schema.metadata or {}
    if PARQUET_META_KEY not in metadata:
        raise RecordingError(
            f"Parquet schema metadata has no {PARQUET_META_KEY.decode()!r} entry",
            source=source, key="meta", rule="missing-meta",
        )
    meta = _parse_meta(metadata[PARQUET_META_KEY].decode("utf-8"), source)
    return table.to_pandas(), meta


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
    if not path.is_file():
        raise FileNotFoundError(f"{source}: no such recording file")
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
        meta = _parse_meta(meta_path.read_text(encoding="utf-8"), str(meta_path))
        frame = _read_csv_frame(path)
    else:
        frame, meta = _read_parquet(path)
    return Recording(to_canonical(frame, source), meta, name=path.stem).validate(source)
