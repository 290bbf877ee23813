"""The report writers: one self-contained HTML file, a short Markdown summary, JSON for
machines; all from the same document model, written atomically."""
from __future__ import annotations

import io
import json
import math
import re
from dataclasses import dataclass
from html.parser import HTMLParser

import numpy as np
import pandas as pd
import pytest

from reports.html import html_text, write_html
from reports.jsonreport import write_json
from reports.markdown import markdown_text, write_markdown
from reports.render import Report, Section, Table, anchors, png_size
from reports.render_tables import HTML_MAX_ROWS, MARKDOWN_MAX_ROWS
from reports.render_values import format_number, jsonable

EVIL = "<script>document.body.dataset.pwned='yes'</script> & \"quotes\""


@dataclass(frozen=True)
class FakeFigure:
    """Stands in for reports.figures.FigureOut (same four attributes)."""

    name: str
    caption: str
    png: bytes
    alt: str


def tiny_png(slope: float) -> bytes:
    """A real, small PNG drawn with matplotlib's Agg canvas."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3, 2), dpi=40)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    t = np.linspace(0, 1, 20)
    ax.plot(t, slope * t)
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()


def make_report(status: str = "fail", long_rows: int = 0) -> Report:
    """Two sections, tables with NaN / negative / large numbers / highlights, two figures."""
    scores = pd.DataFrame({
        "method": ["equation-error", "output-error", "stepwise <b>"],
        "Cm_alpha": [-0.0812345, -0.08, np.nan],
        "error_pct": [1.23456, -45.6789, np.inf],
        "samples": np.array([1001, 250000, 3], dtype=np.int64),
        "big": [1.5e9, -2.25e-7, 123456.789],
    })
    truth = pd.DataFrame({"truth": [-0.0813, -4.57], "estimate": [-0.0809, np.nan]},
                         index=pd.Index(["Cm_alpha", "Cm_q"], name="parameter"))
    sections = [
        Section(
            title="Scores",
            paragraphs=("Scores of every method against the simulator's truth.", EVIL),
            tables=(Table("Method scores", scores, caption="Errors in percent of truth.",
                          highlight=((1, "error_pct", "bad"), (0, "error_pct", "good"),
                                     (2, "Cm_alpha", "warn"))),),
            figures=(FakeFigure("residuals", "Residuals of the fit.", tiny_png(1.0),
                                "Residuals against time"),),
        ),
        Section(
            title="Truth & estimates",
            paragraphs=("Derivatives per rad.",),
            tables=(Table("Truth vs estimate", truth),),
            figures=(FakeFigure("bode plot", "Frequency response <fit>.", tiny_png(-2.0),
                                "Bode plot of the pitch axis"),),
        ),
    ]
    if long_rows:
        frame = pd.DataFrame({"t": np.arange(long_rows) * 0.02,
                              "q": np.sin(np.arange(long_rows) * 0.01)})
        sections.append(Section("Time history", tables=(Table("Samples", frame),)))
    return Report(
        title="Nightly <campaign> report",
        kind="nightly",
        provenance={"campaign": "nightly-f16", "file": "harness/campaigns/nightly.toml",
                    "sha256": "ab" * 32, "commit": "0123456789abcdef0123", "dirty": True,
                    "versions": {"python": "3.11.7", "numpy": "2.4.6", "jsbsim": "1.3.3"},
                    "seed": 20240611, "executor": "process", "workers": 2,
                    "start": "2026-01-01T00:00:00+00:00", "end": "2026-01-01T00:03:05+00:00",
                    "generated_at": "2026-01-01T00:03:06+00:00"},
        summary=("2 of 3 methods within tolerance", "stepwise: Cm_alpha missing <NaN>"),
        sections=tuple(sections),
        numbers={"Cm_alpha": {"truth": np.float64(-0.0813), "estimate": np.nan},
                 "n_runs": np.int64(12), "worst": float("inf"),
                 "series": np.array([1.0, np.nan, -np.inf, 2.5]), "ok": np.bool_(False)},
        status=status,
    )


class _Collector(HTMLParser):
    """Collects tags with their attributes, table row counts and text per element id."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict[str, str | None]]] = []
        self.rows: dict[str, int] = {}
        self._table: str | None = None
        self._in_body = False

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        self.tags.append((tag, attributes))
        if tag == "table":
            self._table = attributes.get("id")
            self.rows[self._table] = 0
        elif tag == "tbody":
            self._in_body = True
        elif tag == "tr" and self._in_body and self._table:
            self.rows[self._table] += 1

    def handle_endtag(self, tag):
        if tag == "tbody":
            self._in_body = False
        elif tag == "table":
            self._table = None


def _parse(html: str) -> _Collector:
    parser = _Collector()
    parser.feed(html)
    return parser


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    report = make_report()
    paths = {"html": write_html(report, out / "report.html"),
             "md": write_markdown(report, out / "report.md", html_name="report.html"),
             "json": write_json(report, out / "report.json")}
    return report, out, paths


def test_html_is_one_self_contained_file(written):
    _, _, paths = written
    html = paths["html"].read_text(encoding="utf-8")
    assert html.startswith("<!DOCTYPE html>")
    assert "http://" not in html and "https://" not in html
    assert "url(" not in html and "@import" not in html and "<link" not in html
    parsed = _parse(html)
    sources = [a.get("src") for _, a in parsed.tags if "src" in a]
    assert len(sources) == 2
    assert all(s.startswith("data:image/png;base64,") for s in sources)
    assert not [t for t, _ in parsed.tags if t == "script"]
    hrefs = [a["href"] for _, a in parsed.tags if "href" in a]
    assert hrefs and all(h.startswith("#") for h in hrefs)
    ids = {a.get("id") for _, a in parsed.tags}
    assert all(h[1:] in ids for h in hrefs), "table-of-contents links point at sections"


def test_html_structure_ids_and_provenance(written):
    report, _, paths = written
    html = paths["html"].read_text(encoding="utf-8")
    parsed = _parse(html)
    assert ("html", {"lang": "en"}) in parsed.tags
    assert ("meta", {"charset": "utf-8"}) in parsed.tags
    assert "<title>Nightly &lt;campaign&gt; report</title>" in html
    ids = anchors(report)
    assert ids.tables == (("table-method-scores",), ("table-truth-vs-estimate",))
    assert ids.figures == (("figure-residuals",), ("figure-bode-plot",))
    for table_id in ("table-method-scores", "table-truth-vs-estimate"):
        assert f'id="{table_id}"' in html
    for figure_id in ("figure-residuals", "figure-bode-plot"):
        assert f'<figure id="{figure_id}">' in html
    assert html.count("<figcaption>") == 2
    assert "Frequency response &lt;fit&gt;." in html
    assert 'alt="Bode plot of the pitch axis"' in html
    # status badge, provenance block, summary
    assert 'class="badge badge-fail"' in html and ">FAIL<" in html
    for text in ("nightly-f16", "0123456789abcdef0123 (+dirty)", "20240611", "jsbsim 1.3.3",
                 "process, 2 workers", "2026-01-01T00:03:06+00:00", "3 min 5 s", "ab" * 32):
        assert text in html, text
    assert "<li><strong>stepwise</strong>: Cm_alpha missing &lt;NaN&gt;</li>" in html


def test_html_escapes_all_text(written):
    _, _, paths = written
    html = paths["html"].read_text(encoding="utf-8")
    assert "<script" not in html
    assert "&lt;script&gt;document.body.dataset.pwned=&#x27;yes&#x27;&lt;/script&gt; " \
           "&amp; &quot;quotes&quot;" in html
    assert "stepwise &lt;b&gt;" in html and "<b>" not in html


def test_html_numbers_are_formatted_and_highlighted(written):
    _, _, paths = written
    html = paths["html"].read_text(encoding="utf-8")
    for cell in ('<td class="num">-0.08123</td>', '<td class="num">1.5e+09</td>',
                 '<td class="num">250000</td>', '<td class="num">-2.25e-07</td>',
                 '<td class="num">1.235e+05</td>', '<td class="num missing">—</td>',
                 '<td class="num bad" title="bad">-45.68</td>',
                 '<td class="num good" title="good">1.235</td>',
                 '<td class="num missing warn" title="warn">—</td>',
                 '<td class="num">inf</td>', '<th scope="row">Cm_alpha</th>'):
        assert cell in html, cell
    assert "@media print" in html and "max-width: 1100px" in html
    assert "nth-child(even)" in html


def test_format_number():
    assert format_number(3.14159265) == "3.142"
    assert format_number(-0.000123456) == "-0.0001235"
    assert format_number(np.float32(2.5)) == "2.5"
    assert format_number(np.int64(-7)) == "-7"
    assert format_number(-0.0) == "0"
    assert format_number(float("nan")) == "—" and format_number(None) == "—"
    assert format_number(-math.inf) == "-inf"


def test_json_layout_nulls_and_numpy(written):
    report, _, paths = written
    text = paths["json"].read_text(encoding="utf-8")
    assert not re.search(r"[:,\[]\s*-?(NaN|Infinity)\b", text)
    data = json.loads(text)
    assert set(data) == {"title", "kind", "status", "status_note", "provenance", "summary", "numbers",
                         "sections"}
    assert data["status"] == "fail" and data["kind"] == "nightly"
    assert data["numbers"] == {"Cm_alpha": {"truth": -0.0813, "estimate": None},
                               "n_runs": 12, "worst": None,
                               "series": [1.0, None, None, 2.5], "ok": False}
    assert data["provenance"]["versions"]["numpy"] == "2.4.6"
    first = data["sections"][0]
    assert set(first) == {"title", "paragraphs", "tables", "figures"}
    assert first["paragraphs"][1] == EVIL
    table = first["tables"][0]
    assert table["columns"] == ["method", "Cm_alpha", "error_pct", "samples", "big"]
    assert table["rows"][2] == ["stepwise <b>", None, None, 3, 123456.789]
    assert table["rows"][1][3] == 250000 and table["total_rows"] == 3
    assert first["figures"] == [{"name": "residuals", "caption": "Residuals of the fit."}]
    second = data["sections"][1]["tables"][0]
    assert second["columns"] == ["parameter", "truth", "estimate"]
    assert second["rows"][1] == ["Cm_q", -4.57, None]


def test_markdown_summary(written):
    report, _, paths = written
    md = paths["md"].read_text(encoding="utf-8")
    assert md == markdown_text(report, html_name="report.html")
    assert md.startswith("# Nightly \\<campaign\\> report\n")
    assert "FAIL" in md
    assert "- 2 of 3 methods within tolerance" in md
    assert "commit 0123456789abcdef0123 (+dirty)" in md and "seed 20240611" in md
    assert "| method | Cm\\_alpha |" not in md  # underscores are left alone
    assert "| method | Cm_alpha | error_pct | samples | big |" in md
    assert "| --- | ---: | ---: | ---: | ---: |" in md
    assert "| parameter | truth | estimate |" in md
    assert "stepwise \\<b\\>" in md
    assert "base64" not in md and "![" not in md
    assert "report.html" in md
    assert len(md.splitlines()) < 60


def test_writes_are_atomic_and_deterministic(written, tmp_path):
    report, out, paths = written
    assert sorted(p.name for p in out.iterdir()) == ["report.html", "report.json", "report.md"]
    again = {"html": write_html(report, tmp_path / "a" / "r.html"),
             "md": write_markdown(report, tmp_path / "a" / "r.md", html_name="report.html"),
             "json": write_json(report, tmp_path / "a" / "r.json")}
    for key, path in again.items():
        assert path.read_bytes() == paths[key].read_bytes(), key
    write_html(make_report(status="ok"), again["html"])  # replaces the file in place
    assert 'class="badge badge-ok"' in again["html"].read_text(encoding="utf-8")
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["r.html", "r.json", "r.md"]


def test_figure_png_is_embedded_with_its_size():
    png = tiny_png(0.5)
    assert png_size(png) == (120, 80)
    html = html_text(make_report())
    assert 'width="120" height="80"' in html


def test_long_tables_are_truncated_with_a_note(tmp_path):
    report = make_report(long_rows=1000)
    html = write_html(report, tmp_path / "r.html").read_text(encoding="utf-8")
    assert _parse(html).rows["table-samples"] == HTML_MAX_ROWS
    assert "Showing the first 300 of 1,000 rows." in html
    data = json.loads(write_json(report, tmp_path / "r.json").read_text(encoding="utf-8"))
    samples = data["sections"][2]["tables"][0]
    assert samples["total_rows"] == 1000 and len(samples["rows"]) == HTML_MAX_ROWS
    md = markdown_text(report)
    table_lines = [line for line in md.split("## Time history")[1].splitlines()
                   if line.startswith("| ")]
    assert len(table_lines) == 2 + MARKDOWN_MAX_ROWS
    assert "Showing the first 15 of 1,000 rows." in md
    assert "see the HTML report" in md


def test_hundred_thousand_rows_are_truncated_in_html_and_kept_in_json(tmp_path):
    """Correctness only; the time it takes is measured by `sidbench bench`."""
    n = 100_000
    frame = pd.DataFrame({"t": np.arange(n) * 0.02, "alpha": np.random.default_rng(1)
                          .normal(size=n), "flag": np.arange(n) % 7})
    report = Report("Big", "benchmark", {"seed": 1}, ("big table",),
                    (Section("Data", tables=(Table("All samples", frame),)),),
                    {"alpha": frame["alpha"].to_numpy()})
    html = write_html(report, tmp_path / "big.html")
    write_markdown(report, tmp_path / "big.md")
    data_path = write_json(report, tmp_path / "big.json")
    assert html.stat().st_size < 200_000
    assert "Showing the first 300 of 100,000 rows." in html.read_text(encoding="utf-8")
    data = json.loads(data_path.read_text(encoding="utf-8"))
    assert len(data["numbers"]["alpha"]) == n  # every number given is kept


def test_duplicate_titles_get_distinct_ids():
    frame = pd.DataFrame({"x": [1.0]})
    report = Report("t", "campaign", {}, (), (
        Section("A", tables=(Table("Same", frame), Table("Same", frame))),
        Section("A", tables=(Table("Same", frame),))), {})
    ids = anchors(report)
    assert ids.sections == ("section-a", "section-a-2")
    assert ids.tables == (("table-same", "table-same-2"), ("table-same-3",))


def test_model_refuses_bad_input():
    frame = pd.DataFrame({"x": [1.0, 2.0]})
    with pytest.raises(ValueError, match="kind"):
        Report("t", "weekly", {}, (), (), {})
    with pytest.raises(ValueError, match="status"):
        Report("t", "nightly", {}, (), (), {}, status="maybe")
    with pytest.raises(ValueError, match="row 2"):
        Table("t", frame, highlight=((2, "x", "bad"),))
    with pytest.raises(ValueError, match="column 'y'"):
        Table("t", frame, highlight=((0, "y", "bad"),))
    with pytest.raises(ValueError, match="class 'red'"):
        Table("t", frame, highlight=((0, "x", "red"),))
    with pytest.raises(TypeError, match="single string"):
        Section("s", paragraphs="one paragraph")
    with pytest.raises(TypeError, match="lacks"):
        Section("s", figures=(object(),))
    with pytest.raises(ValueError, match="not PNG"):
        Section("s", figures=(FakeFigure("f", "c", b"GIF89a", "a"),))


def test_jsonable_converts_numpy_and_pandas():
    out = jsonable({1: np.array([[1, 2], [3, 4]], dtype=np.int32), "s": pd.Series([0.5, np.nan]),
                    "t": pd.Timestamp("2026-01-02T03:04:05"), "c": (np.float32(0.25),)})
    assert out == {"1": [[1, 2], [3, 4]], "s": [0.5, None], "t": "2026-01-02T03:04:05",
                   "c": [0.25]}
    assert json.dumps(out, allow_nan=False)
    assert not re.search(r"\bNaN\b", json.dumps(jsonable({"x": float("nan")})))
