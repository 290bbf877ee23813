"""The report as JSON, for machines.

Layout::

    {"title", "kind", "status", "status_note", "provenance", "summary", "numbers",
     "sections": [{"title", "paragraphs",
                   "tables": [{"title", "caption", "columns", "rows", "total_rows"}],
                   "figures": [{"name", "caption"}]}]}

``numbers`` is written whole. Table ``rows`` are the rows the HTML report shows (the first
:data:`reports.render_tables.HTML_MAX_ROWS` by default) and ``total_rows`` says how many the table
had; ``columns`` include the index level(s) when the HTML shows them. NaN and infinities
become ``null``; numpy and pandas scalars become plain JSON values. Figures carry no image
data (the PNGs are in the HTML report).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

from harness.atomic import write_json_atomic
from reports.render import Report
from reports.render_tables import HTML_MAX_ROWS, table_view
from reports.render_values import jsonable

__all__ = ["report_dict", "write_json"]


def report_dict(report: Report, *, max_rows: int | None = HTML_MAX_ROWS) -> dict[str, Any]:
    """The report as a JSON-ready dict (see the module docstring for the layout).

    Parameters
    ----------
    report : Report
    max_rows : int or None, optional
        Rows kept per table; None keeps every row.

    Returns
    -------
    dict
    """
    sections = []
    for section in report.sections:
        tables = []
        for table in section.tables:
            view = table_view(table, max_rows)
            tables.append({
                "title": table.title,
                "caption": table.caption,
                "columns": list(view.columns),
                "rows": [[cell.value for cell in row] for row in view.rows],
                "total_rows": view.total_rows,
            })
        sections.append({
            "title": section.title,
            "paragraphs": list(section.paragraphs),
            "tables": tables,
            "figures": [{"name": str(f.name), "caption": str(f.caption)}
                        for f in section.figures],
        })
    return {
        "title": report.title,
        "kind": report.kind,
        "status": report.status,
        "status_note": report.status_note,
        "provenance": jsonable(report.provenance),
        "summary": list(report.summary),
        "numbers": jsonable(report.numbers),
        "sections": jsonable(sections),
    }


def write_json(report: Report, path: str | Path, *,
               max_rows: int | None = HTML_MAX_ROWS) -> Path:
    """Write the report as indented JSON, atomically (NaN/inf as null).

    Parameters
    ----------
    report : Report
    path : str or Path
    max_rows : int or None, optional
        Rows kept per table (see :func:`report_dict`).

    Returns
    -------
    Path
        ``path``.
    """
    return write_json_atomic(path, report_dict(report, max_rows=max_rows))
