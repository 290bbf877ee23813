"""The report document model, independent of any output format.

A :class:`Report` is a title, a kind, provenance, a few summary lines (the at-a-glance
verdict), :class:`Section` s holding paragraphs, :class:`Table` s and figures, and a mapping
``numbers`` holding every number shown, for machines. The writers in :mod:`reports.html`,
:mod:`reports.markdown` and :mod:`reports.jsonreport` turn one report into a file each.

Figures are any object with the attributes ``name``, ``caption``, ``png`` (PNG bytes) and
``alt`` (for instance ``reports.figures.FigureOut``); this module does not import them.

The helpers below the model (:func:`table_view`, :func:`format_number`, :func:`anchors`,
:func:`json_value`, ...) are shared by the writers so that the three formats show the same
rows, the same ids and the same numbers.
"""
from __future__ import annotations

import datetime as _dt
import math
import re
import struct
import unicodedata
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import PurePath
from typing import Any

import numpy as np
import pandas as pd

__all__ = [
    "KINDS", "STATUSES", "HIGHLIGHT_CLASSES", "HTML_MAX_ROWS", "MARKDOWN_MAX_ROWS",
    "Table", "Section", "Report", "Cell", "TableView", "Anchors",
    "table_view", "anchors", "slugify", "format_number", "format_value", "json_value",
    "jsonable", "png_size", "provenance_items", "LABEL_MAX", "split_label",
]

KINDS: tuple[str, ...] = ("campaign", "nightly", "benchmark", "maneuver-review", "diagnosis", "estimate")
"""The kinds of report the project writes."""
STATUSES: tuple[str, ...] = ("ok", "fail", "findings")
"""Report outcomes: ``fail`` when a gate failed, ``findings`` when biases, coverage failures or
effects were found, ``ok`` otherwise (see :func:`reports.findings.status_of`)."""
HIGHLIGHT_CLASSES: tuple[str, ...] = ("bad", "good", "warn")
"""CSS classes a highlighted table cell may carry."""
HTML_MAX_ROWS: int = 300
"""Rows of one table shown in the HTML (and JSON) report; longer tables carry a note."""
MARKDOWN_MAX_ROWS: int = 15
"""Rows of one table shown in the Markdown summary."""
LABEL_MAX: int = 40
"""A summary line starting with a label this short followed by ': ' shows the label in bold."""

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_FIGURE_ATTRIBUTES = ("name", "caption", "png", "alt")


def _tuple_of_str(value: Any, what: str) -> tuple[str, ...]:
    """Coerce a sequence of strings to a tuple, refusing a bare string (``tuple('abc')``)."""
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{what} must be a sequence of strings, not a single string")
    out = tuple(value)
    for item in out:
        if not isinstance(item, str):
            raise TypeError(f"{what} must hold strings; got {type(item).__name__}: {item!r}")
    return out


@dataclass(frozen=True, eq=False)
class Table:
    """A titled table.

    Parameters
    ----------
    title : str
        Shown above the table; also gives its id (``table-<slug>``).
    frame : pandas.DataFrame
        The data. Its index is shown as leading column(s) unless it is a plain unnamed
        integer index. The frame is not copied: do not change it after building the table.
    caption : str, optional
        A sentence shown under the table.
    highlight : tuple of (int, str, str), optional
        Cells to colour: ``(row position, column name, css class)`` with the row counted from
        0 in the frame's order (``iloc``) and the class one of ``'bad'``, ``'good'``,
        ``'warn'``.

    Notes
    -----
    Tables compare by identity (a DataFrame has no single truth value).
    """

    title: str
    frame: pd.DataFrame
    caption: str = ""
    highlight: tuple[tuple[int, str, str], ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.title, str):
            raise TypeError(f"Table title must be a string, not {type(self.title).__name__}")
        if not isinstance(self.frame, pd.DataFrame):
            raise TypeError(f"Table {self.title!r}: frame must be a pandas DataFrame, "
                            f"not {type(self.frame).__name__}")
        if not isinstance(self.caption, str):
            raise TypeError(f"Table {self.title!r}: caption must be a string")
        cells = []
        for item in self.highlight:
            try:
                row, column, css = item
            except (TypeError, ValueError):
                raise ValueError(f"Table {self.title!r}: highlight entries are "
                                 f"(row, column, class) triples; got {item!r}") from None
            if isinstance(row, bool) or not isinstance(row, (int, np.integer)):
                raise TypeError(f"Table {self.title!r}: highlight row must be an integer "
                                f"position; got {row!r}")
            if not 0 <= int(row) < len(self.frame):
                raise ValueError(f"Table {self.title!r}: highlight row {row} is outside the "
                                 f"table's {len(self.frame)} rows")
            if not _column_positions(self.frame, column):
                raise ValueError(f"Table {self.title!r}: highlight column {column!r} is not "
                                 f"one of {[str(c) for c in self.frame.columns]}")
            if css not in HIGHLIGHT_CLASSES:
                raise ValueError(f"Table {self.title!r}: highlight class {css!r} is not one "
                                 f"of {HIGHLIGHT_CLASSES}")
            cells.append((int(row), column, css))
        object.__setattr__(self, "highlight", tuple(cells))


@dataclass(frozen=True, eq=False)
class Section:
    """A titled part of a report: paragraphs, then tables, then figures.

    Parameters
    ----------
    title : str
        The heading; also gives the section's id (``section-<slug>``).
    paragraphs : tuple of str, optional
        Plain text (escaped by the writers; no markup).
    tables : tuple of Table, optional
    figures : tuple, optional
        Objects with ``name``, ``caption``, ``png`` (PNG bytes) and ``alt`` attributes,
        such as ``reports.figures.FigureOut``.
    """

    title: str
    paragraphs: tuple[str, ...] = ()
    tables: tuple[Table, ...] = ()
    figures: tuple[Any, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.title, str):
            raise TypeError(f"Section title must be a string, not {type(self.title).__name__}")
        object.__setattr__(self, "paragraphs",
                           _tuple_of_str(self.paragraphs, f"Section {self.title!r} paragraphs"))
        tables = tuple(self.tables)
        for table in tables:
            if not isinstance(table, Table):
                raise TypeError(f"Section {self.title!r}: tables must be Table objects; "
                                f"got {type(table).__name__}")
        object.__setattr__(self, "tables", tables)
        figures = tuple(self.figures)
        for figure in figures:
            missing = [a for a in _FIGURE_ATTRIBUTES if not hasattr(figure, a)]
            if missing:
                raise TypeError(f"Section {self.title!r}: a figure lacks {missing} "
                                f"(needs name, caption, png, alt): {type(figure).__name__}")
            png = figure.png
            if not isinstance(png, (bytes, bytearray, memoryview)) or \
                    not bytes(png[:8]) == PNG_SIGNATURE:
                raise ValueError(f"Section {self.title!r}: figure {figure.name!r} png is not "
                                 f"PNG bytes")
        object.__setattr__(self, "figures", figures)


@dataclass(frozen=True, eq=False)
class Report:
    """One report, in no particular format.

    Parameters
    ----------
    title : str
    kind : str
        ``'campaign'``, ``'nightly'``, ``'benchmark'`` or ``'maneuver-review'``.
    provenance : Mapping
        Where the numbers come from. Known keys (all optional): ``campaign``, ``file``,
        ``sha256``, ``commit``, ``dirty``, ``versions`` (a mapping package -> version),
        ``seed``, ``executor``, ``workers``, ``start``, ``end``, ``generated_at``. Other keys
        are shown after those. The writers add no clock of their own: the same report gives
        the same bytes.
    summary : tuple of str
        Short lines, the at-a-glance verdict.
    sections : tuple of Section
    numbers : Mapping
        Every number shown, for machines (written whole to the JSON report).
    status : str, optional
        ``'ok'`` (default), ``'fail'`` (a gate failed) or ``'findings'`` (a diagnosis that
        found effects, a campaign with biases or coverage failures: not a failure, not "OK"
        either).
    status_note : str, optional
        Why the status is what it is, in a few words (shown beside the badge).

    Notes
    -----
    ``provenance`` and ``numbers`` are copied (shallowly) into plain dicts; treat them as
    read-only. Reports compare by identity.
    """

    title: str
    kind: str
    provenance: Mapping[str, Any]
    summary: tuple[str, ...]
    sections: tuple[Section, ...]
    numbers: Mapping[str, Any]
    status: str = "ok"
    status_note: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.title, str):
            raise TypeError(f"Report title must be a string, not {type(self.title).__name__}")
        if self.kind not in KINDS:
            raise ValueError(f"Report kind {self.kind!r} is not one of {KINDS}")
        if self.status not in STATUSES:
            raise ValueError(f"Report status {self.status!r} is not one of {STATUSES}")
        if not isinstance(self.status_note, str):
            raise TypeError("Report status_note must be a string")
        for name in ("provenance", "numbers"):
            value = getattr(self, name)
            if not isinstance(value, Mapping):
                raise TypeError(f"Report {name} must be a mapping, not {type(value).__name__}")
            object.__setattr__(self, name, dict(value))
        object.__setattr__(self, "summary", _tuple_of_str(self.summary, "Report summary"))
        sections = tuple(self.sections)
        for section in sections:
            if not isinstance(section, Section):
                raise TypeError(f"Report sections must be Section objects; "
                                f"got {type(section).__name__}")
        object.__setattr__(self, "sections", sections)


# --------------------------------------------------------------------------------------
# Values and numbers
# --------------------------------------------------------------------------------------

def _is_missing(value: Any) -> bool:
    """True for None, NaN, pandas NA and NaT (scalars only)."""
    if value is None or value is pd.NA or value is pd.NaT:
        return True
    if isinstance(value, (float, np.floating)):
        return math.isnan(value)
    if isinstance(value, (np.datetime64, np.timedelta64)):
        return bool(np.isnat(value))
    return False


def _is_number(value: Any) -> bool:
    """True for real or complex numbers other than booleans."""
    return isinstance(value, (int, float, complex, np.number)) and \
        not isinstance(value, (bool, np.bool_))


def format_number(value: Any, digits: int = 4) -> str:
    """Format a number for people: integers exactly, others to ``digits`` significant digits.

    Parameters
    ----------
    value : number
    digits : int, optional
        Significant digits for non-integers (default 4).

    Returns
    -------
    str
        ``'—'`` for NaN/NA, ``'inf'``/``'-inf'`` for infinities, ``'-0'`` shown as ``'0'``.

    Examples
    --------
    >>> format_number(3.14159265), format_number(-123456.7), format_number(120000)
    ('3.142', '-1.235e+05', '120000')
    """
    if _is_missing(value):
        return "—"
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (complex, np.complexfloating)):
        return f"{complex(value):.{digits}g}"
    number = float(value)
    if math.isinf(number):
        return "inf" if number > 0 else "-inf"
    if number == 0:
        return "0"
    return f"{number:.{digits}g}"


def format_value(value: Any, digits: int = 4) -> str:
    """Format any table or provenance value as text (numbers via :func:`format_number`)."""
    if _is_missing(value) or _is_number(value) or isinstance(value, (bool, np.bool_)):
        return format_number(value, digits)
    if isinstance(value, (pd.Timestamp, _dt.datetime, _dt.date)):
        return value.isoformat()
    if isinstance(value, Mapping):
        return ", ".join(f"{k} {format_value(v, digits)}" for k, v in value.items())
    if isinstance(value, (list, tuple)):
        return ", ".join(format_value(v, digits) for v in value)
    return str(value)


def json_value(value: Any) -> Any:
    """Convert one scalar to a JSON-ready value: NaN/inf/NA -> None, numpy -> Python."""
    if _is_missing(value):
        return None
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        number = float(value)
        return number if math.isfinite(number) else None
    if isinstance(value, (complex, np.complexfloating)):
        return {"real": json_value(value.real), "imag": json_value(value.imag)}
    if isinstance(value, (pd.Timestamp, _dt.datetime, _dt.date, _dt.time)):
        return value.isoformat()
    if isinstance(value, (pd.Timedelta, _dt.timedelta)):
        return value.total_seconds()
    if isinstance(value, np.datetime64):
        return str(value)
    if isinstance(value, str):
        return value
    if isinstance(value, PurePath):
        return str(value)
    return str(value)


def jsonable(obj: Any) -> Any:
    """Convert a nested structure to JSON-ready values.

    Mappings become dicts with string keys, sequences, sets, arrays, Series and DataFrames
    become lists (a DataFrame: a list of row records), numpy scalars become Python ones,
    NaN/inf become ``None``; anything else unknown becomes its ``str``.
    """
    kind = type(obj)
    if kind is float:
        return obj if math.isfinite(obj) else None
    if obj is None or kind is str or kind is int or kind is bool:
        return obj
    if isinstance(obj, Mapping):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, pd.DataFrame):
        return [jsonable(dict(zip(map(str, obj.columns), row)))
                for row in obj.itertuples(index=False, name=None)]
    if isinstance(obj, (pd.Series, pd.Index)):
        return jsonable(obj.to_numpy())
    if isinstance(obj, (list, tuple, set, frozenset)):
        items = sorted(obj, key=str) if isinstance(obj, (set, frozenset)) else obj
        return [jsonable(v) for v in items]
    return json_value(obj)


def png_size(png: bytes) -> tuple[int, int] | None:
    """Width and height in pixels from a PNG's header, or None if it is not a PNG."""
    data = bytes(png[:24])
    if len(data) < 24 or data[:8] != PNG_SIGNATURE or data[12:16] != b"IHDR":
        return None
    width, height = struct.unpack(">II", data[16:24])
    return int(width), int(height)


# --------------------------------------------------------------------------------------
# Tables as shown
# --------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Cell:
    """One shown table cell.

    Attributes
    ----------
    text : str
        As shown to people (numbers to 4 significant digits).
    value : Any
        As written to JSON (NaN and infinities are None).
    numeric : bool
        Whether the cell is a number (right-aligned), a missing one included.
    css : str
        Highlight class (``'bad'``, ``'good'``, ``'warn'``) or ``''``.
    missing : bool
        Whether the value is missing (None, NaN, NA, NaT).
    """

    text: str
    value: Any
    numeric: bool
    css: str = ""
    missing: bool = False


@dataclass(frozen=True)
class TableView:
    """The part of a :class:`Table` a writer shows, formatted.

    Attributes
    ----------
    columns : tuple of str
        Header labels, index level(s) first when the index is shown.
    numeric : tuple of bool
        Whether each column holds numbers (right-aligned).
    index_columns : int
        How many leading columns come from the index.
    rows : tuple of tuple of Cell
    total_rows : int
        Rows in the whole frame.
    """

    columns: tuple[str, ...]
    numeric: tuple[bool, ...]
    index_columns: int
    rows: tuple[tuple[Cell, ...], ...]
    total_rows: int

    @property
    def truncated(self) -> bool:
        """True when fewer rows are shown than the frame has."""
        return len(self.rows) < self.total_rows

    def note(self) -> str:
        """A sentence saying how many rows are shown, or ``''`` when all are."""
        if not self.truncated:
            return ""
        return f"Showing the first {len(self.rows):,} of {self.total_rows:,} rows."


def _column_positions(frame: pd.DataFrame, column: Any) -> list[int]:
    """Positions of the columns named ``column`` (exactly or by their text)."""
    found = [i for i, c in enumerate(frame.columns) if c == column]
    if not found:
        found = [i for i, c in enumerate(frame.columns) if _label(c) == str(column)]
    return found


def _label(label: Any) -> str:
    """A header label as text (tuples from MultiIndex columns joined by ' / ')."""
    if isinstance(label, tuple):
        return " / ".join(str(part) for part in label if str(part) != "")
    return "" if label is None else str(label)


def _shows_index(index: pd.Index) -> bool:
    """Whether a frame's index carries information worth a column."""
    if any(name is not None for name in index.names):
        return True
    return not pd.api.types.is_integer_dtype(index.dtype)


def _numeric_dtype(series: pd.Series | pd.Index) -> bool:
    dtype = series.dtype
    return pd.api.types.is_numeric_dtype(dtype) and not pd.api.types.is_bool_dtype(dtype)


def table_view(table: Table, max_rows: int | None = HTML_MAX_ROWS) -> TableView:
    """Format the first ``max_rows`` rows of a table (all rows if None).

    Parameters
    ----------
    table : Table
    max_rows : int or None, optional
        The most rows to show (default :data:`HTML_MAX_ROWS`).

    Returns
    -------
    TableView
    """
    frame = table.frame
    total = len(frame)
    shown = frame if max_rows is None or total <= max_rows else frame.iloc[:max(0, max_rows)]
    columns: list[list[Any]] = []
    labels: list[str] = []
    numeric: list[bool] = []
    index_columns = 0
    if _shows_index(frame.index):
        index = shown.index
        for level in range(index.nlevels):
            values = index.get_level_values(level)
            columns.append(values.tolist())
            name = frame.index.names[level]
            labels.append(_label(name))
            numeric.append(_numeric_dtype(values))
            index_columns += 1
    for position, label in enumerate(frame.columns):
        series = shown.iloc[:, position]
        columns.append(series.tolist())
        labels.append(_label(label))
        numeric.append(_numeric_dtype(series))
    marks: dict[tuple[int, int], str] = {}
    for row, column, css in table.highlight:
        for position in _column_positions(frame, column):
            marks[(row, index_columns + position)] = css
    rows = []
    for r, values in enumerate(zip(*columns)) if columns else ():
        rows.append(tuple(
            Cell(text=format_value(v), value=json_value(v),
                 numeric=_is_number(v) or (numeric[c] and _is_missing(v)),
                 css=marks.get((r, c), ""), missing=_is_missing(v))
            for c, v in enumerate(values)))
    if not columns:
        rows = [() for _ in range(len(shown))]
    return TableView(columns=tuple(labels), numeric=tuple(numeric),
                     index_columns=index_columns, rows=tuple(rows), total_rows=total)


# --------------------------------------------------------------------------------------
# Ids
# --------------------------------------------------------------------------------------

def slugify(text: str, fallback: str = "item") -> str:
    """Lower-case ASCII words joined by '-' (``'Cm_α fit (F-16)'`` -> ``'cm-fit-f-16'``)."""
    ascii_text = unicodedata.normalize("NFKD", str(text)).encode("ascii", "ignore").decode()
    slug = re.sub(r"[^a-z0-9]+", "-", ascii_text.lower()).strip("-")
    return slug or fallback


@dataclass(frozen=True)
class Anchors:
    """Stable, unique ids for a report's sections, tables and figures.

    Attributes
    ----------
    sections : tuple of str
        ``section-<slug>`` per section.
    tables : tuple of tuple of str
        ``table-<slug>`` per table, per section.
    figures : tuple of tuple of str
        ``figure-<slug of name>`` per figure, per section.
    """

    sections: tuple[str, ...]
    tables: tuple[tuple[str, ...], ...]
    figures: tuple[tuple[str, ...], ...]


def anchors(report: Report) -> Anchors:
    """Give every section, table and figure an id, in document order.

    Ids come from titles (tables, sections) and names (figures); a repeated id gets
    ``-2``, ``-3``, ... in document order, so ids are stable for the same report.
    """
    used: set[str] = set()

    def unique(base: str) -> str:
        candidate, n = base, 1
        while candidate in used:
            n += 1
            candidate = f"{base}-{n}"
        used.add(candidate)
        return candidate

    sections, tables, figures = [], [], []
    for s, section in enumerate(report.sections, start=1):
        sections.append(unique("section-" + slugify(section.title, f"{s}")))
    for s, section in enumerate(report.sections, start=1):
        tables.append(tuple(unique("table-" + slugify(t.title, f"{s}-{k}"))
                            for k, t in enumerate(section.tables, start=1)))
        figures.append(tuple(unique("figure-" + slugify(str(f.name), f"{s}-{k}"))
                             for k, f in enumerate(section.figures, start=1)))
    return Anchors(tuple(sections), tuple(tables), tuple(figures))


# --------------------------------------------------------------------------------------
# Provenance
# --------------------------------------------------------------------------------------

_PROVENANCE_ORDER = ("campaign", "file", "sha256", "commit", "dirty", "versions", "seed",
                     "executor", "workers", "start", "end", "generated_at")


def _parse_time(value: Any) -> _dt.datetime | None:
    if isinstance(value, _dt.datetime):
        return value
    if isinstance(value, str):
        try:
            return _dt.datetime.fromisoformat(value.replace("Z", "+00:00"))
        except ValueError:
            return None
    return None


def _duration(start: Any, end: Any) -> str:
    """``'12.3 s'``/``'4 min 5 s'``/``'2 h 3 min'`` between two times, or '' if unknown."""
    t0, t1 = _parse_time(start), _parse_time(end)
    if t0 is None or t1 is None or (t0.tzinfo is None) != (t1.tzinfo is None):
        return ""
    seconds = (t1 - t0).total_seconds()
    if seconds < 0:
        return ""
    if seconds < 60:
        return f"{seconds:.3g} s"
    if seconds < 3600:
        return f"{int(seconds // 60)} min {int(seconds % 60)} s"
    return f"{int(seconds // 3600)} h {int(seconds % 3600 // 60)} min"


def provenance_items(provenance: Mapping[str, Any]) -> list[tuple[str, str]]:
    """The provenance as ``(label, text)`` pairs in a fixed, readable order.

    Known keys are merged where that reads better (commit with ``+dirty``, executor with
    its workers, start and end with the duration); unknown keys follow in their own order.
    Missing or empty keys are left out.
    """
    p = dict(provenance)
    items: list[tuple[str, str]] = []

    def present(key: str) -> bool:
        return key in p and p[key] is not None and p[key] != ""

    if present("campaign"):
        items.append(("Campaign", format_value(p["campaign"])))
    if present("file"):
        items.append(("File", format_value(p["file"])))
    if present("sha256"):
        items.append(("SHA-256", format_value(p["sha256"])))
    if present("commit"):
        commit = format_value(p["commit"])
        if p.get("dirty"):
            commit += " (+dirty)"
        items.append(("Commit", commit))
    elif p.get("dirty"):
        items.append(("Commit", "(+dirty)"))
    if present("versions"):
        versions = p["versions"]
        text = (" · ".join(f"{k} {format_value(v)}" for k, v in versions.items())
                if isinstance(versions, Mapping) else format_value(versions))
        items.append(("Versions", text))
    if present("seed"):
        items.append(("Seed", format_value(p["seed"])))
    if present("executor") or present("workers"):
        text = format_value(p["executor"]) if present("executor") else ""
        if present("workers"):
            workers = format_value(p["workers"])
            text = f"{text}, {workers} workers" if text else f"{workers} workers"
        items.append(("Executor", text))
    if present("start") or present("end"):
        start = format_value(p["start"]) if present("start") else "?"
        end = format_value(p["end"]) if present("end") else "?"
        duration = _duration(p.get("start"), p.get("end"))
        items.append(("Run", f"{start} → {end}" + (f" ({duration})" if duration else "")))
    if present("generated_at"):
        items.append(("Generated", format_value(p["generated_at"])))
    for key, value in p.items():
        if key in _PROVENANCE_ORDER or value is None or value == "":
            continue
        items.append((str(key).replace("_", " ").capitalize(), format_value(value)))
    return items


def split_label(line: str, max_chars: int = LABEL_MAX) -> tuple[str, str]:
    """``('Largest bias', 'least squares ...')`` for ``'Largest bias: least squares ...'``: the
    text before the first ``': '`` when it is at most ``max_chars`` long, else ``('', line)``."""
    head, sep, rest = line.partition(": ")
    if sep and head.strip() and len(head) <= max_chars:
        return head, rest
    return "", line
