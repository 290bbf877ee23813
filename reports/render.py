"""The report document model, independent of any output format.

A :class:`Report` is a title, a kind, provenance, a few summary lines (the at-a-glance
verdict), :class:`Section` s holding paragraphs, :class:`Table` s and figures, and a mapping
``numbers`` holding every number shown, for machines. The writers in :mod:`reports.html`,
:mod:`reports.markdown` and :mod:`reports.jsonreport` turn one report into a file each.

Figures are any object with the attributes ``name``, ``caption``, ``png`` (PNG bytes) and
``alt`` (for instance ``reports.figures.FigureOut``); this module does not import them.

The helpers shared by the writers, so that the three formats show the same rows, the same
ids and the same numbers, are the ids below the model (:func:`anchors`, :func:`slugify`), the
tables as shown in :mod:`reports.render_tables` (:func:`~reports.render_tables.table_view`) and
the numbers, values and provenance as text and JSON in :mod:`reports.render_values`
(:func:`~reports.render_values.format_number`, :func:`~reports.render_values.json_value`, ...).
"""
from __future__ import annotations

import re
import struct
import unicodedata
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

__all__ = [
    "KINDS", "STATUSES", "HIGHLIGHT_CLASSES",
    "Table", "Section", "Report", "Anchors",
    "anchors", "slugify", "png_size",
]

KINDS: tuple[str, ...] = ("campaign", "nightly", "benchmark", "maneuver-review", "diagnosis", "estimate")
"""The kinds of report the project writes."""
STATUSES: tuple[str, ...] = ("ok", "fail", "findings")
"""Report outcomes: ``fail`` when a gate failed, ``findings`` when biases, coverage failures or
effects were found, ``ok`` otherwise (see :func:`reports.findings.status_of`)."""
HIGHLIGHT_CLASSES: tuple[str, ...] = ("bad", "good", "warn")
"""CSS classes a highlighted table cell may carry."""

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
# Figures and columns
# --------------------------------------------------------------------------------------

def png_size(png: bytes) -> tuple[int, int] | None:
    """Width and height in pixels from a PNG's header, or None if it is not a PNG."""
    data = bytes(png[:24])
    if len(data) < 24 or data[:8] != PNG_SIGNATURE or data[12:16] != b"IHDR":
        return None
    width, height = struct.unpack(">II", data[16:24])
    return int(width), int(height)

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
