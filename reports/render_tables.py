"""Tables as the report writers show them: the rows shown, formatted, with their highlights.

This module owns the view of a :class:`reports.render.Table` that the HTML, Markdown and JSON
writers share so that they show the same rows: how many rows each format shows
(:data:`HTML_MAX_ROWS`, :data:`MARKDOWN_MAX_ROWS`), the shown cell (:class:`Cell`), the shown
table (:class:`TableView`) and :func:`table_view`, which formats the first rows of a table.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pandas as pd

from reports.render import Table, _column_positions, _label
from reports.render_values import _is_missing, _is_number, format_value, json_value

__all__ = ["HTML_MAX_ROWS", "MARKDOWN_MAX_ROWS", "Cell", "TableView", "table_view"]

HTML_MAX_ROWS: int = 300
"""Rows of one table shown in the HTML (and JSON) report; longer tables carry a note."""
MARKDOWN_MAX_ROWS: int = 15
"""Rows of one table shown in the Markdown summary."""


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
