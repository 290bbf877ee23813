"""One self-contained HTML file per report.

No external CSS, JavaScript, fonts or images: the style sheet is inline and figures are
``data:image/png;base64`` images, so the file can be mailed, archived or attached to a CI run
and still reads the same. All text is escaped. The page is sized for a laptop screen
(content at most ~1100 px wide; column headings wrap so that tables fit a 1280 px window) and
prints cleanly (``@media print``). The header leads with the status badge (and why) and the
summary lines, then the provenance.

Ids are stable for the same report: ``section-<slug>``, ``table-<slug>`` (from the table
title) and ``figure-<slug>`` (from the figure name); see :func:`reports.render.anchors`.
"""
from __future__ import annotations

import base64
from html import escape
from pathlib import Path
from typing import Any

from harness.atomic import write_text_atomic
from reports.render import Report, Section, Table, anchors, png_size
from reports.render_tables import HTML_MAX_ROWS, table_view
from reports.render_values import provenance_items, split_label

__all__ = ["write_html", "html_text"]

_KIND_LABELS = {
    "campaign": "Campaign report",
    "nightly": "Nightly report",
    "benchmark": "Benchmark report",
    "maneuver-review": "Maneuver review",
    "diagnosis": "Discrepancy diagnosis",
    "estimate": "Estimate",
}

_CSS = """
:root {
  --fg: #1f2328; --muted: #59636e; --line: #d1d9e0; --zebra: #f6f8fa; --bg: #ffffff;
  --page: #f3f4f6; --link: #0550ae;
  --ok-bg: #1a7f37; --fail-bg: #cf222e;
  --bad-bg: #ffebe9; --bad-fg: #82071e; --good-bg: #dafbe1; --good-fg: #116329;
  --warn-bg: #fff8c5; --warn-fg: #6f4400;
}
* { box-sizing: border-box; }
html { -webkit-text-size-adjust: 100%; }
body {
  margin: 0; background: var(--page); color: var(--fg);
  font: 16px/1.5 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial,
        "Noto Sans", "Liberation Sans", sans-serif;
}
main {
  max-width: 1100px; margin: 24px auto; padding: 28px 36px 36px; background: var(--bg);
  border: 1px solid var(--line); border-radius: 8px; box-shadow: 0 1px 3px rgba(0,0,0,.08);
}
a { color: var(--link); }
h1 { font-size: 1.75rem; line-height: 1.25; margin: 0; }
h2 { font-size: 1.35rem; margin: 2.2rem 0 .6rem; padding-bottom: .3rem;
     border-bottom: 1px solid var(--line); }
p { margin: .5rem 0 .8rem; max-width: 80ch; }
code, .mono { font-family: ui-monospace, SFMono-Regular, Menlo, Consolas, "Liberation Mono",
              monospace; font-size: .9em; }
.titlebar { display: flex; flex-wrap: wrap; align-items: center; gap: .6rem 1rem; }
.kind { color: var(--muted); font-size: .95rem; margin: .15rem 0 1rem; }
.badge {
  display: inline-block; padding: .15rem .7rem; border-radius: 999px; color: #fff;
  font-weight: 700; font-size: .9rem; letter-spacing: .04em;
  -webkit-print-color-adjust: exact; print-color-adjust: exact;
}
.badge-ok { background: var(--ok-bg); }
.badge-fail { background: var(--fail-bg); }
.badge-findings { background: var(--warn-bg); color: var(--warn-fg); border: 1px solid #d4a72c; }
.status-note { color: var(--muted); font-size: .95rem; }
.provenance {
  display: grid; grid-template-columns: max-content 1fr; gap: .15rem 1rem; margin: 0 0 1rem;
  padding: .7rem 1rem; background: var(--zebra); border-radius: 6px; font-size: .9rem;
}
.provenance dt { color: var(--muted); }
.provenance dd { margin: 0; overflow-wrap: anywhere; }
.summary { margin: .4rem 0 1rem; padding-left: 1.3rem; font-size: 1.05rem; }
.summary li { margin: .15rem 0; }
.toc { font-size: .95rem; margin: 1rem 0; }
.toc h2 { font-size: 1rem; margin: 0 0 .3rem; border: 0; padding: 0; color: var(--muted); }
.toc ol { margin: 0; padding-left: 1.4rem; }
.table-block { margin: 1rem 0 1.5rem; }
.table-scroll { display: inline-block; max-width: 100%; min-width: min(100%, 28rem);
                overflow-x: auto; border: 1px solid var(--line); border-radius: 6px;
                vertical-align: top; }
.table-scroll.long { max-height: 70vh; overflow-y: auto; }
table { border-collapse: collapse; width: 100%; font-size: .9rem;
        font-variant-numeric: tabular-nums; }
caption { caption-side: top; text-align: left; font-weight: 600; padding: .5rem .6rem; }
th, td { padding: .3rem .6rem; border-bottom: 1px solid var(--line); text-align: left;
         vertical-align: top; }
thead th { position: sticky; top: 0; background: #eef1f4; border-bottom: 2px solid var(--line);
           overflow-wrap: normal; hyphens: manual; }
tbody tr:nth-child(even) { background: var(--zebra); }
tbody tr:last-child td, tbody tr:last-child th { border-bottom: 0; }
tbody th { font-weight: 600; }
.num { text-align: right; white-space: nowrap; }
thead th.num { white-space: normal; }
td.missing { color: var(--muted); }
td.bad, th.bad { background: var(--bad-bg); color: var(--bad-fg); font-weight: 600; }
td.good, th.good { background: var(--good-bg); color: var(--good-fg); font-weight: 600; }
td.warn, th.warn { background: var(--warn-bg); color: var(--warn-fg); font-weight: 600; }
.table-caption, .note { color: var(--muted); font-size: .88rem; margin: .35rem 0 0; }
.label { color: var(--muted); font-weight: 600; }
figure { margin: 1.2rem 0 1.6rem; text-align: center; }
figure img { max-width: 100%; height: auto; border: 1px solid var(--line); border-radius: 4px; }
figcaption { color: var(--muted); font-size: .9rem; margin: .4rem auto 0; max-width: 80ch; }
footer { margin-top: 2.5rem; color: var(--muted); font-size: .85rem; border-top: 1px solid
         var(--line); padding-top: .6rem; }
@media (max-width: 700px) {
  main { margin: 0; padding: 16px; border: 0; border-radius: 0; }
  .provenance { grid-template-columns: 1fr; }
}
@media print {
  @page { margin: 15mm; }
  body { background: #fff; font-size: 11pt; }
  main { max-width: none; margin: 0; padding: 0; border: 0; box-shadow: none; }
  * { box-shadow: none !important; text-shadow: none !important; }
  .table-scroll, .table-scroll.long { display: block; max-height: none; overflow: visible; }
  thead { display: table-header-group; }
  thead th { position: static; }
  tr, figure, img, .provenance { break-inside: avoid; page-break-inside: avoid; }
  .table-block { break-inside: auto; }
  table, figure { break-inside: avoid; page-break-inside: avoid; }
  h2 { break-after: avoid; page-break-after: avoid; }
  a { color: #000; text-decoration: underline; }
  a[href^="http"]::after { content: " (" attr(href) ")"; font-size: .85em; }
  td.bad, td.good, td.warn { -webkit-print-color-adjust: exact; print-color-adjust: exact; }
}
"""


def _e(text: Any) -> str:
    """Escape text for HTML content and attribute values."""
    return escape(str(text), quote=True)


def _summary_item(line: str) -> str:
    """One lead line, its label (``'Largest bias'``) in bold."""
    label, rest = split_label(line)
    return f"<li><strong>{_e(label)}</strong>: {_e(rest)}</li>" if label else f"<li>{_e(line)}</li>"


def _table_html(table: Table, table_id: str, number: int, max_rows: int | None) -> str:
    view = table_view(table, max_rows)
    long = " long" if len(view.rows) > 25 else ""
    out = ['<div class="table-block">', f'<div class="table-scroll{long}">',
           f'<table id="{_e(table_id)}">',
           f'<caption><span class="label">Table {number}.</span> {_e(table.title)}</caption>',
           "<thead><tr>"]
    for label, numeric in zip(view.columns, view.numeric):
        css = ' class="num"' if numeric else ""
        out.append(f'<th scope="col"{css}>{_e(label)}</th>')
    out.append("</tr></thead>")
    out.append("<tbody>")
    for row in view.rows:
        cells = []
        for c, cell in enumerate(row):
            classes = " ".join(x for x in ("num" if cell.numeric else "",
                                           "missing" if cell.missing else "", cell.css) if x)
            attrs = f' class="{classes}"' if classes else ""
            if cell.css:
                attrs += f' title="{_e(cell.css)}"'
            tag = "th" if c < view.index_columns else "td"
            scope = ' scope="row"' if tag == "th" else ""
            cells.append(f"<{tag}{scope}{attrs}>{_e(cell.text)}</{tag}>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</tbody></table></div>")
    if table.caption:
        out.append(f'<p class="table-caption">{_e(table.caption)}</p>')
    if view.truncated:
        out.append(f'<p class="note">{_e(view.note())}</p>')
    out.append("</div>")
    return "\n".join(out)


def _figure_html(figure: Any, figure_id: str, number: int) -> str:
    png = bytes(figure.png)
    data = base64.b64encode(png).decode("ascii")
    size = png_size(png)
    dims = f' width="{size[0]}" height="{size[1]}"' if size else ""
    return (f'<figure id="{_e(figure_id)}">'
            f'<img src="data:image/png;base64,{data}" alt="{_e(figure.alt)}"{dims}>'
            f'<figcaption><span class="label">Figure {number}.</span> '
            f'{_e(figure.caption)}</figcaption></figure>')


def _section_html(section: Section, section_id: str, table_ids: tuple[str, ...],
                  figure_ids: tuple[str, ...], counters: dict[str, int],
                  max_rows: int | None) -> str:
    out = [f'<section id="{_e(section_id)}">', f"<h2>{_e(section.title)}</h2>"]
    out += [f"<p>{_e(p)}</p>" for p in section.paragraphs]
    for table, table_id in zip(section.tables, table_ids):
        counters["table"] += 1
        out.append(_table_html(table, table_id, counters["table"], max_rows))
    for figure, figure_id in zip(section.figures, figure_ids):
        counters["figure"] += 1
        out.append(_figure_html(figure, figure_id, counters["figure"]))
    out.append("</section>")
    return "\n".join(out)


def html_text(report: Report, *, max_rows: int | None = HTML_MAX_ROWS) -> str:
    """The report as one self-contained HTML document.

    Parameters
    ----------
    report : Report
    max_rows : int or None, optional
        The most rows shown per table (default :data:`reports.render_tables.HTML_MAX_ROWS`);
        longer tables show their first rows and a note. None shows every row.

    Returns
    -------
    str
    """
    ids = anchors(report)
    status = report.status
    note_title = f' title="{_e(report.status_note)}"' if report.status_note else ""
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        '<meta name="generator" content="sidbench reports">',
        f"<title>{_e(report.title)}</title>",
        f"<style>{_CSS}</style>",
        "</head>",
        f'<body data-kind="{_e(report.kind)}" data-status="{_e(status)}">',
        "<main>",
        '<header id="report-header">',
        '<div class="titlebar">',
        f"<h1>{_e(report.title)}</h1>",
        f'<span class="badge badge-{_e(status)}" id="status" '
        f'aria-label="status: {_e(status)}"{note_title}>{_e(status.upper())}</span>',
    ]
    if report.status_note:
        parts.append(f'<span class="status-note" id="status-note">{_e(report.status_note)}</span>')
    parts += ["</div>", f'<p class="kind">{_e(_KIND_LABELS.get(report.kind, report.kind))}</p>']
    if report.summary:  # the lead: what matters first, before where it came from
        parts.append('<ul class="summary" id="summary">')
        parts += [_summary_item(line) for line in report.summary]
        parts.append("</ul>")
    items = provenance_items(report.provenance)
    if items:
        parts.append('<dl class="provenance" id="provenance">')
        for label, text in items:
            mono = ' class="mono"' if label in ("SHA-256", "Commit", "File") else ""
            parts.append(f"<dt>{_e(label)}</dt><dd{mono}>{_e(text)}</dd>")
        parts.append("</dl>")
    parts.append("</header>")
    if report.sections:
        parts.append('<nav class="toc" aria-label="Contents"><h2>Contents</h2><ol>')
        parts += [f'<li><a href="#{_e(sid)}">{_e(section.title)}</a></li>'
                  for section, sid in zip(report.sections, ids.sections)]
        parts.append("</ol></nav>")
    counters = {"table": 0, "figure": 0}
    for section, sid, tids, fids in zip(report.sections, ids.sections, ids.tables,
                                        ids.figures):
        parts.append(_section_html(section, sid, tids, fids, counters, max_rows))
    generated = report.provenance.get("generated_at")
    footer = "Generated by sidbench"
    if generated not in (None, ""):
        footer += f" at {generated}"
    parts += [f"<footer>{_e(footer)}.</footer>", "</main>", "</body>", "</html>", ""]
    return "\n".join(parts)


def write_html(report: Report, path: str | Path, *,
               max_rows: int | None = HTML_MAX_ROWS) -> Path:
    """Write the report as one self-contained HTML file, atomically.

    Parameters
    ----------
    report : Report
    path : str or Path
        The file to write; its folder is created if needed.
    max_rows : int or None, optional
        The most rows shown per table (see :func:`html_text`).

    Returns
    -------
    Path
        ``path``.
    """
    return write_text_atomic(path, html_text(report, max_rows=max_rows))
