"""A short Markdown summary of a report, for CI logs and pull requests.

Title, status (and why), the summary lines, provenance in a line or two, and each section's first table
(its first :data:`reports.render_tables.MARKDOWN_MAX_ROWS` rows) as a GitHub table. No images: the
figures and the other tables are in the HTML report, which the text points to.
"""
from __future__ import annotations

import re
from pathlib import Path

from harness.atomic import write_text_atomic
from reports.render import Report
from reports.render_tables import MARKDOWN_MAX_ROWS, table_view
from reports.render_values import provenance_items, split_label

__all__ = ["markdown_text", "write_markdown"]

_SPECIAL = re.compile(r"([\\`*\[\]<>|])")


def _md(text: object) -> str:
    """Escape Markdown/HTML punctuation and fold the text onto one line."""
    return _SPECIAL.sub(r"\\\1", " ".join(str(text).split()))


def _summary_item(line: str) -> str:
    """One lead line as a list item, its label (``'Largest bias'``) in bold."""
    label, rest = split_label(line)
    return f"- **{_md(label)}**: {_md(rest)}" if label else f"- {_md(line)}"


def _provenance_lines(report: Report) -> list[str]:
    """The provenance in two lines: the run itself, then versions and the rest."""
    items = dict(provenance_items(report.provenance))
    file = items.pop("File", "")
    sha = items.pop("SHA-256", "")
    first = []
    if "Campaign" in items or file or sha:
        text = items.pop("Campaign", "")
        detail = ", ".join(x for x in (Path(file).name if file else "",
                                       f"sha256 {sha[:12]}…" if sha else "") if x)
        text = f"{text} ({detail})" if text and detail else (text or detail)
        first.append(f"campaign {_md(text)}")
    for label in ("Commit", "Seed", "Executor", "Run"):
        if label in items:
            first.append(f"{label.lower()} {_md(items.pop(label))}")
    second = [f"{label.lower()} {_md(text)}" for label, text in items.items()]
    return [" · ".join(part) for part in (first, second) if part]


def markdown_text(report: Report, *, html_name: str | None = None,
                  max_rows: int = MARKDOWN_MAX_ROWS) -> str:
    """The report's Markdown summary.

    Parameters
    ----------
    report : Report
    html_name : str, optional
        The HTML report's file name (or link) to point readers to for figures and full
        tables; without it the text says "the HTML report".
    max_rows : int, optional
        Rows shown per table (default 15).

    Returns
    -------
    str
    """
    status = {"ok": "OK", "findings": "FINDINGS"}.get(report.status, "FAIL")
    icon = {"ok": "✅", "findings": "⚠️"}.get(report.status, "❌")
    note = f" ({_md(report.status_note)})" if report.status_note else ""
    lines = [f"# {_md(report.title)}", "",
             f"**Status: {icon} {status}**{note} · {_md(report.kind)} report", ""]
    if report.summary:
        lines += [_summary_item(line) for line in report.summary] + [""]
    provenance = _provenance_lines(report)
    if provenance:
        lines += [line + "  " for line in provenance[:-1]] + [provenance[-1], ""]
    for section in report.sections:
        if not section.tables:
            continue
        table = section.tables[0]
        view = table_view(table, max_rows)
        lines += [f"## {_md(section.title)}", "", f"**{_md(table.title)}**", ""]
        if view.columns:
            lines.append("| " + " | ".join(_md(c) or " " for c in view.columns) + " |")
            lines.append("| " + " | ".join("---:" if n else "---" for n in view.numeric)
                         + " |")
            for row in view.rows:
                cells = []
                for cell in row:
                    text = _md(cell.text)
                    if cell.css == "bad":
                        text = f"**{text}** ❌"
                    elif cell.css == "warn":
                        text = f"**{text}** ⚠️"
                    elif cell.css == "good":
                        text = f"{text} ✅"
                    cells.append(text)
                lines.append("| " + " | ".join(cells) + " |")
        else:
            lines.append("_(no columns)_")
        if view.truncated:
            lines.append("")
            lines.append(f"_{view.note()}_")
        lines.append("")
    where = _md(html_name) if html_name else "the HTML report"
    lines.append(f"Figures and full tables: see {where}.")
    return "\n".join(lines) + "\n"


def write_markdown(report: Report, path: str | Path, *, html_name: str | None = None,
                   max_rows: int = MARKDOWN_MAX_ROWS) -> Path:
    """Write the Markdown summary atomically (see :func:`markdown_text`).

    Returns
    -------
    Path
        ``path``.
    """
    return write_text_atomic(path, markdown_text(report, html_name=html_name,
                                                 max_rows=max_rows))
