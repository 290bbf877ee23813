"""An HTML report as a browser sees it: headless Chromium (Debian's ``chromium``) loads the
file, every embedded image decodes, the main tables are there, escaped text stays text.

Skipped when Chromium is not installed, except under CI=true, where it must run (``.ci/run``
installs it)."""
from __future__ import annotations

import os
import struct
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from reports.browser import chromium_args, dump_dom, find_chromium, screenshot
from reports.html import write_html
from reports.render import Report, Section, Table

ROOT = Path(__file__).resolve().parents[1]
TABLE_IDS = ("table-method-scores", "table-truth-vs-estimate")

CHECK_SCRIPT = """<script>
(function () {
  function check() {
    var images = Array.prototype.slice.call(document.images);
    var bad = images.filter(function (img) {
      return !(img.complete && img.naturalWidth > 0);
    }).length;
    document.body.dataset.images = bad === 0 ? "ok" : "bad:" + bad;
    document.body.dataset.imagecount = String(images.length);
    document.body.dataset.tables = String(document.querySelectorAll("table[id^=table-]").length);
  }
  if (document.readyState === "complete") { check(); }
  else { window.addEventListener("load", check); }
})();
</script>
"""


from test_report_render import FakeFigure  # noqa: E402  (shared test doubles)
from test_report_render import tiny_png as _png  # noqa: E402


def _report() -> Report:
    scores = pd.DataFrame({"method": ["equation-error", "output-error"],
                           "Cm_alpha": [-0.0812, np.nan], "error_pct": [1.2, -45.7],
                           "samples": [1001, 250000]})
    truth = pd.DataFrame({"truth": [-0.0813, -4.57], "estimate": [-0.0809, 1e12]},
                         index=pd.Index(["Cm_alpha", "Cm_q"], name="parameter"))
    return Report(
        title="Browser <check> report", kind="campaign",
        provenance={"campaign": "demo", "commit": "abc123", "dirty": False, "seed": 7},
        summary=("all good",),
        sections=(
            Section("Scores", ("<script>document.body.dataset.pwned='yes'</script>",),
                    (Table("Method scores", scores, highlight=((1, "error_pct", "bad"),)),),
                    (FakeFigure("residuals", "Residuals.", _png(1.0), "Residuals"),)),
            Section("Truth", (), (Table("Truth vs estimate", truth),),
                    (FakeFigure("bode", "Bode plot.", _png(-1.0), "Bode plot"),)),
        ),
        numbers={"Cm_alpha": -0.0812})


def _chromium() -> str:
    """Chromium's path; skips the test without it, or fails it when CI=true."""
    exe = find_chromium()
    if exe is None:
        why = ("looked for chromium, chromium-browser, google-chrome on PATH and "
               "/usr/bin/chromium; install Debian's package: apt-get install chromium")
        if os.environ.get("CI", "").strip().lower() in ("true", "1"):
            pytest.fail(f"headless Chromium not installed but CI=true requires the browser "
                        f"test: {why}")
        pytest.skip(f"headless Chromium not installed: {why}")
    return exe


@pytest.fixture(scope="module")
def report_html(tmp_path_factory) -> Path:
    return write_html(_report(), tmp_path_factory.mktemp("browser") / "report.html")


class _BodyAttributes(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.body: dict[str, str | None] | None = None
        self.ids: set[str] = set()

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        if tag == "body" and self.body is None:
            self.body = attributes
        if attributes.get("id"):
            self.ids.add(attributes["id"])


def _parse(dom: str) -> _BodyAttributes:
    parser = _BodyAttributes()
    parser.feed(dom)
    assert parser.body is not None, dom[:500]
    return parser


def test_flags_include_a_fresh_profile(tmp_path):
    args = chromium_args(tmp_path / "profile")
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update",
                 "--disable-sync"):
        assert flag in args
    assert f"--user-data-dir={tmp_path / 'profile'}" in args


def test_page_loads_with_its_tables(report_html):
    chromium = _chromium()
    dom = dump_dom(report_html, chromium=chromium)
    assert "<title>Browser &lt;check&gt; report</title>" in dom
    parsed = _parse(dom)
    for table_id in TABLE_IDS:
        assert table_id in parsed.ids
    assert {"figure-residuals", "figure-bode", "provenance", "summary"} <= parsed.ids
    assert "pwned" not in str(parsed.body), "escaped text must not run as a script"


def test_every_image_decodes(report_html, tmp_path):
    chromium = _chromium()
    html = report_html.read_text(encoding="utf-8")
    assert html.count("</body>") == 1
    probe = tmp_path / "probe.html"
    probe.write_text(html.replace("</body>", CHECK_SCRIPT + "</body>"), encoding="utf-8")
    body = _parse(dump_dom(probe, chromium=chromium)).body
    assert body.get("data-imagecount") == "2", body
    assert body.get("data-images") == "ok", body
    assert body.get("data-tables") == str(len(TABLE_IDS)), body
    assert "data-pwned" not in body


def test_screenshot_command_writes_a_png(report_html, tmp_path):
    _chromium()
    out = tmp_path / "shots" / "report.png"
    done = subprocess.run([sys.executable, "-m", "reports.screenshot", str(report_html),
                           str(out), "--width", "800", "--height", "600"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == str(out)
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", data[16:24]) == (800, 600)
    assert sorted(p.name for p in out.parent.iterdir()) == ["report.png"]


def test_screenshot_of_a_missing_file_says_so(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such HTML file"):
        screenshot(tmp_path / "nope.html", tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()


def test_screenshot_command_help_and_errors(tmp_path):
    done = subprocess.run([sys.executable, "-m", "reports.screenshot", "--help"], cwd=ROOT,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and "--width" in done.stdout and "--height" in done.stdout
    done = subprocess.run([sys.executable, "-m", "reports.screenshot",
                           str(tmp_path / "missing.html"), str(tmp_path / "out.png")],
                          cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert done.stderr.startswith("screenshot: ") and "missing.html" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def _fake_chromium(folder: Path, body: str) -> str:
    script = folder / "fake-chromium"
    script.write_text("#!/bin/sh\n" + body + "\n")
    script.chmod(0o755)
    return str(script)


def test_a_hanging_browser_is_killed_with_a_clear_error(tmp_path, report_html):
    fake = _fake_chromium(tmp_path, "sleep 30")
    with pytest.raises(RuntimeError, match="longer than 0.5 s"):
        dump_dom(report_html, chromium=fake, timeout=0.5)


def test_a_failing_browser_reports_its_stderr(tmp_path, report_html):
    fake = _fake_chromium(tmp_path, "echo 'cannot open display' >&2; exit 3")
    with pytest.raises(RuntimeError, match="exit status 3.*cannot open display"):
        screenshot(report_html, tmp_path / "x.png", chromium=fake)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fake-chromium"]
    fake = _fake_chromium(tmp_path, "exit 0")
    with pytest.raises(RuntimeError, match="wrote no PNG"):
        screenshot(report_html, tmp_path / "x.png", chromium=fake)
    with pytest.raises(RuntimeError, match="printed no DOM"):
        dump_dom(report_html, chromium=fake)
