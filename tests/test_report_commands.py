"""The three report kinds from real campaign output, and the real report in headless Chromium."""
from __future__ import annotations

import json
import re

import pytest

from harness.cli import main
from reports.browser import dump_dom
from reports.figures import fig_excursions, fig_time_histories
from reports.load import read_output
from test_report_browser import CHECK_SCRIPT, _chromium, _parse

CAMPAIGN = """
name = "report-test"
seed = 3
realizations = 4
[grid]
variant = ["exact-truth"]
maneuver = ["2-1-1-2"]
noise = ["white"]
method = ["ee-time", "ee-freq", "oe"]
errors = ["conventional", "colored"]
equations = ["Cm = alpha + qhat + de", "CZ = alpha + qhat + de"]
"""


@pytest.fixture(scope="module")
def campaign_dir(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("reports")
    (tmp / "c.toml").write_text(CAMPAIGN)
    assert main(["campaign", str(tmp / "c.toml"), "--out", str(tmp / "out"), "--workers", "2",
                 "--cache", str(tmp / "cache"), "--quiet"]) == 0
    return tmp / "out"


def test_report_command_writes_three_formats(campaign_dir, capsys):
    assert main(["report", str(campaign_dir)]) == 0
    out = capsys.readouterr().out
    assert "# Campaign report: report-test" in out
    html = (campaign_dir / "report.html").read_text()
    for needle in ('id="table-scores-accuracy"', 'id="table-scores-honesty-of-the-bounds"', "data:image/png;base64,",
                   "<figcaption", "report-test", "Seed"):
        assert needle in html, needle
    d = json.loads((campaign_dir / "report.json").read_text())
    assert d["kind"] == "campaign" and d["numbers"]["scores"] and d["provenance"]["seed"] == 3
    names = {f["name"] for s in d["sections"] for f in s["figures"]}
    assert {"bias", "coverage", "se_ratio", "model_fit", "residuals", "time_histories"} <= names
    assert (campaign_dir / "report.md").read_text().startswith("# Campaign report")


def test_benchmark_report(campaign_dir, tmp_path):
    assert main(["report", str(campaign_dir), "--kind", "benchmark", "--out", str(tmp_path)]) == 0
    d = json.loads((tmp_path / "benchmark.json").read_text())
    methods = {r["method_label"] for r in d["numbers"]["overall"]}
    assert {"ee-time (conventional)", "ee-freq (conventional)", "oe (cramer-rao)"} <= methods
    assert any(line.startswith("Only 4 realizations per cell (fewer than 30)") for line in d["summary"])


def test_review_maneuvers_recommends_with_numbers(tmp_path, capsys):
    assert main(["review-maneuvers", "--out", str(tmp_path / "review"), "--maneuvers", "doublet,3-2-1-1",
                 "--axis", "lon", "--realizations", "3", "--workers", "2", "--cache", str(tmp_path / "cache"),
                 "--quiet"]) == 0
    d = json.loads((tmp_path / "review" / "review.json").read_text())
    rec = d["numbers"]["recommendations"]
    assert len(rec) == 1 and rec[0].startswith("Longitudinal") and "Cramér-Rao" in rec[0] and "alpha" in rec[0]
    assert d["summary"][-1].startswith("Only 3 realizations per cell (fewer than 30)")
    titles = [s["title"] for s in d["sections"]]
    assert "Regressor correlation (seed Eq. 50)" in titles and "Excursions from trim" in titles


def test_real_report_renders_in_headless_chromium(campaign_dir, tmp_path):
    """The generated campaign report loads, every image decodes and the main tables exist."""
    chromium = _chromium()
    if not (campaign_dir / "report.html").is_file():
        assert main(["report", str(campaign_dir)]) == 0
    html = (campaign_dir / "report.html").read_text(encoding="utf-8")
    probe = tmp_path / "probe.html"
    probe.write_text(html.replace("</body>", CHECK_SCRIPT + "</body>"), encoding="utf-8")
    parsed = _parse(dump_dom(probe, chromium=chromium))
    body = parsed.body
    assert body.get("data-images") == "ok", body
    assert int(body.get("data-imagecount")) >= 8
    assert {"table-methods", "table-scores-accuracy", "table-scores-honesty-of-the-bounds"} <= parsed.ids


WIDTH_SCRIPT = """<script>
(function () {
  function check() {
    var wide = [], hidden = [], page = document.documentElement.clientWidth;
    document.querySelectorAll(".table-scroll").forEach(function (box) {
      if (box.scrollWidth > box.clientWidth + 1) {
        var t = box.querySelector("table"); wide.push((t && t.id) || "?");
      }
    });
    document.querySelectorAll("thead th").forEach(function (th) {
      var text = th.textContent.trim();
      if ((text === "SE ratio" || text === "coverage") && th.getBoundingClientRect().right > page) {
        hidden.push(th.closest("table").id + ":" + text);
      }
    });
    document.body.dataset.wide = wide.join(" ") || "none";
    document.body.dataset.hidden = hidden.join(" ") || "none";
    document.body.dataset.pagewidth = String(document.documentElement.scrollWidth);
    document.body.dataset.viewport = String(page);
  }
  if (document.readyState === "complete") { check(); } else { window.addEventListener("load", check); }
})();
</script>
"""


def test_tables_fit_a_1280_px_window(campaign_dir, tmp_path):
    """Every table of the real report fits a 1280 px window: no horizontal scrolling, the
    standard-error ratio and coverage columns in view."""
    chromium = _chromium()
    if not (campaign_dir / "report.html").is_file():
        assert main(["report", str(campaign_dir)]) == 0
    html = (campaign_dir / "report.html").read_text(encoding="utf-8")
    probe = tmp_path / "probe.html"
    probe.write_text(html.replace("</body>", WIDTH_SCRIPT + "</body>"), encoding="utf-8")
    body = _parse(dump_dom(probe, chromium=chromium, window=(1280, 900))).body
    assert body.get("data-wide") == "none", body
    assert body.get("data-hidden") == "none", body
    assert int(body["data-pagewidth"]) <= int(body["data-viewport"]) <= 1280, body


def test_pitch_only_campaign_leaves_out_still_channels_and_says_few_realizations(campaign_dir):
    out = read_output(campaign_dir)
    history = fig_time_histories(out.flights)
    assert "β" not in history.alt and "δa" not in history.alt and {"δe", "α", "q"} <= set(
        history.alt.split("(")[1].split(")")[0].split(", "))
    left_out = re.search(r"([^.]*) stay at trim on this maneuver and are left out", history.caption)
    assert left_out and "β" in left_out.group(1)
    excursions = fig_excursions(out.results[out.results["method"] == "excursion"])
    assert "β" not in excursions.alt
    if not (campaign_dir / "report.json").is_file():
        assert main(["report", str(campaign_dir)]) == 0
    d = json.loads((campaign_dir / "report.json").read_text())
    assert d["status"] in ("ok", "findings") and d["status_note"]
    assert any("Only 4 realizations per cell (fewer than 30)" in line for line in d["summary"])
    assert d["summary"][1].startswith("Flown: the JSBSim F-16 with exactly linear body-axis aerodynamics")
