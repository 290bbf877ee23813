"""Reports lead with what matters (issue 16 §2): the lead names the largest bias first and the
comparison the campaign was built for, with the numbers the scores hold; the badge is computed;
gate rows carry their interval and ungated cells are not failures; few realizations, efficiency
above 1 and a one-night trend are said so; the campaign's noises and aircraft are stated."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from reports.campaign_report import campaign_report
from reports.campaign_setup import flown_text, noise_table, read_setup
from reports.figures import fig_trend
from reports.findings import find, status_of
from reports.html import html_text
from reports.load import CampaignOutput
from reports.markdown import markdown_text
from reports.nightly_report import nightly_report

ROOT = Path(__file__).resolve().parents[1]
TRUTH = {"Cm_alpha": -0.08, "Cm_de": -0.53}
# worst |bias z| per noise and method: the seed's §III.C pattern, with numbers of our own
BIAS_Z = {("noisy", "ee-time"): 31.7, ("noisy", "ee-smooth"): 2.4, ("noisy", "ee-freq"): 2.2, ("noisy", "oe"): 1.0,
          ("clean", "ee-time"): 1.3, ("clean", "ee-smooth"): 1.2, ("clean", "ee-freq"): 1.5, ("clean", "oe"): 0.4}
METHODS = (("ee-time", "conventional"), ("ee-time", "colored"), ("ee-smooth", "conventional"),
           ("ee-smooth", "colored"), ("ee-freq", "conventional"), ("oe", "cramer-rao"))


def _row(noise: str, method: str, errors: str, parameter: str, n: int, bias_z: float, coverage: float) -> dict:
    truth = TRUTH[parameter]
    std = 0.02 * abs(truth)
    mcse = std / np.sqrt(n)
    lo, hi = max(coverage - 0.06, 0.0), min(coverage + 0.04, 1.0)
    return dict(campaign="t", aircraft="f16", variant="linear", condition="seed-5deg", maneuver="2-1-1-2",
                loop="open", noise=noise, method=method, errors=errors, equation="Cm = alpha + de", dependent="Cm",
                parameter=parameter, truth_definition="local", n=n, failures=0, truth=truth,
                mean=truth + bias_z * mcse, bias=bias_z * mcse, bias_pct=100 * bias_z * mcse / truth,
                bias_mcse=mcse, bias_z=bias_z, std=std, rmse=std, mean_se=std, se_ratio=1.0, coverage=coverage,
                coverage_lo=lo, coverage_hi=hi, time_s=0.002, max_corr=0.6, crb=np.nan, efficiency=np.nan)


def scores(n: int = 100, bias_z: dict | None = None, bad_coverage: bool = True) -> pd.DataFrame:
    """Scores of a small regressor-noise-like campaign: Cm_de carries each method's worst bias."""
    bz = BIAS_Z if bias_z is None else bias_z
    rows = []
    for noise in ("clean", "noisy"):
        for method, errors in METHODS:
            for parameter in TRUTH:
                z = bz[(noise, method)] * (1.0 if parameter == "Cm_de" else 0.5)
                cov = 0.30 if bad_coverage and (method, errors, noise) == ("ee-smooth", "conventional", "noisy") \
                    else 0.95
                rows.append(_row(noise, method, errors, parameter, n, z, cov))
    return pd.DataFrame(rows)


def output(s: pd.DataFrame, file: str = "/nonexistent/campaign.toml") -> CampaignOutput:
    meta = {"campaign": {"name": "lead-test", "description": "A test of the lead: noisy regressors bias least squares",
                         "file": file, "sha256": "0" * 64, "realizations": int(s["n"].min()), "cells": 12},
            "estimates": 1200, "wall_s": 1.0, "executor": "test", "seed": 1}
    return CampaignOutput(path=Path("."), meta=meta, results=pd.DataFrame(), scores=s)


class _NoFigures:
    """Stands in for :mod:`reports.figures`: these tests read the text, the figures have their own."""

    def __getattr__(self, name):
        return lambda *args, **kwargs: None


@pytest.fixture(autouse=True)
def no_figures(monkeypatch):
    monkeypatch.setattr("reports.campaign_report.F", _NoFigures())
    monkeypatch.setattr("reports.nightly_report.F", _NoFigures())


@pytest.fixture
def report():
    return campaign_report(output(scores()))


def _table(report, title: str):
    return next(t for s in report.sections for t in s.tables if t.title == title)


def test_lead_names_the_largest_bias_first(report):
    lines = report.summary
    assert lines[0].startswith("lead-test: A test of the lead")
    assert "not the nonlinear JSBSim F-16" in lines[1]
    biased = [i for i, line in enumerate(lines) if "standard errors" in line]
    first = lines[biased[0]]
    assert first.startswith("Findings: 2 of 16 biases beyond")  # 2 noises x 4 methods x 2 parameters
    largest = lines[biased[1]]
    assert largest.startswith("Largest bias: least squares (ee-time), noise noisy: Cm_de")
    assert "31.7 Monte Carlo standard errors" in largest
    case = lines[biased[2]]  # the worst case's comparison comes next, then the clean one
    assert case.startswith("Noise noisy") and "least squares (ee-time) is biased by 31.7 standard errors" in case
    assert "smoothed regressors (ee-smooth) 2.4, frequency domain (ee-freq) 2.2 and output error (oe) 1.0 " \
           "stay within" in case
    assert lines[biased[3]].startswith("Noise clean: no method biased beyond")
    # the HTML's first list is the lead, before the provenance
    html = html_text(report)
    assert html.index('id="summary"') < html.index('id="provenance"')
    assert html.index("<strong>Largest bias</strong>: least squares (ee-time)") < \
        html.index("<strong>Noise clean</strong>")


def test_the_lead_reads_the_numbers_the_scores_hold():
    other = dict(BIAS_Z) | {("noisy", "ee-time"): 12.4, ("clean", "ee-freq"): 19.0}
    lines = campaign_report(output(scores(bias_z=other))).summary
    largest = next(line for line in lines if line.startswith("Largest bias"))
    assert "frequency domain (ee-freq), noise clean: Cm_de" in largest and "19.0 Monte Carlo" in largest
    assert any("least squares (ee-time) is biased by 12.4 standard errors" in line for line in lines)


def test_findings_tables_lead_the_report(report):
    assert [s.title for s in report.sections[:2]] == ["Findings", "Campaign set-up"]
    biases = _table(report, "Largest biases").frame
    assert list(biases["bias z"]) == sorted(biases["bias z"], key=abs, reverse=True)
    assert biases["bias z"].iloc[0] == pytest.approx(31.7)
    cmp = _table(report, "Method comparison")
    assert list(cmp.frame.columns) == ["case", "ee-time", "ee-smooth", "ee-freq", "oe"]
    assert {(c, k) for _, c, k in cmp.highlight} == {("ee-time", "bad")}
    cov = _table(report, "Coverage failures").frame
    assert set(cov["method"] + "/" + cov["errors"]) == {"ee-smooth/conventional"}


def test_badge_is_computed():
    assert campaign_report(output(scores())).status == "findings"
    clean = {k: 1.0 for k in BIAS_Z}
    ok = campaign_report(output(scores(bias_z=clean, bad_coverage=False)))
    assert ok.status == "ok" and ok.status_note == "no bias or coverage finding"
    only_coverage = campaign_report(output(scores(bias_z=clean)))
    assert only_coverage.status == "findings" and "2 coverage failures" in only_coverage.status_note
    html = html_text(only_coverage)
    assert 'class="badge badge-findings"' in html and ">FINDINGS<" in html and ">OK<" not in html
    assert "FINDINGS" in markdown_text(only_coverage).splitlines()[2]
    assert status_of(find(scores(bias_z=clean, bad_coverage=False)), failed_gates=1) == "fail"


def _gates(s: pd.DataFrame, fail: bool) -> pd.DataFrame:
    rows = []
    for _, r in s[(s["method"] == "ee-freq") & (s["noise"] == "noisy")].iterrows():
        passed = not (fail and r["parameter"] == "Cm_de")
        rows.append(dict(gate="honest error bounds", kind="coverage", noise=r["noise"], method=r["method"],
                         errors=r["errors"], maneuver=r["maneuver"], parameter=r["parameter"], value=r["coverage"],
                         limit="[0.9, 0.99]", passed=passed, message=f"ee-freq {r['parameter']}"))
    return pd.DataFrame(rows)


def test_nightly_badge_fails_on_a_failed_gate_and_ungated_cells_are_not_failures():
    clean = {k: 1.0 for k in BIAS_Z}
    s = scores(bias_z=clean)
    failed = nightly_report(output(s), _gates(s, fail=True), [], None)
    assert failed.status == "fail" and failed.status_note == "1 of 2 gated cells fail"
    assert 'class="badge badge-fail"' in html_text(failed)
    passed = nightly_report(output(s), _gates(s, fail=False), [], None)
    assert passed.status == "findings"  # gates pass, but the ungated conventional bounds fail coverage
    rows = _table(passed, "All gated cells").frame
    assert list(rows["interval"]) == ["[0.890, 0.990]"] * 2  # the coverage's exact binomial interval
    honesty = _table(passed, "Scores: honesty of the bounds")
    marks = {css for _, column, css in honesty.highlight if column == "coverage"}
    assert marks == {"warn"}, "a coverage failure outside the gates is amber, not red"
    assert {css for _, c, css in _table(campaign_report(output(s)), "Scores: honesty of the bounds").highlight
            if c == "coverage"} == {"bad"}, "without gates a coverage failure is red"


def test_few_realizations_are_said_so():
    lines = campaign_report(output(scores(n=12))).summary
    assert any("Only 12 realizations per cell (fewer than 30)" in line for line in lines)
    assert not any("fewer than 30" in line for line in campaign_report(output(scores(n=30))).summary)


def test_efficiency_above_one_is_explained_where_it_appears():
    s = scores()
    s.loc[(s["method"] == "ee-freq") & (s["parameter"] == "Cm_de"), ["crb", "efficiency"]] = [0.01, 1.8]
    table = _table(campaign_report(output(s)), "Scores: accuracy")
    assert "efficiency" in table.frame.columns
    assert "Efficiency above 1 (2 cells: ee-freq; up to 1.80) does not mean a method beat" in table.caption
    assert "Efficiency above 1" not in _table(campaign_report(output(scores())), "Scores: accuracy").caption


def test_one_night_trend_has_a_dated_single_position():
    night = scores().assign(run_id="r1", start="2026-12-01T19:47:34+00:00")
    fig = fig_trend(night)
    assert "(1 run, 2026-12-01 19:47 UTC)" in fig.caption and "Only one run so far" in fig.caption


def test_setup_states_what_was_flown_and_each_noise():
    file = ROOT / "harness" / "campaigns" / "regressor-noise.toml"
    from harness.campaign import load_campaign
    meta = {"campaign": {"file": str(file), "sha256": load_campaign(file).text_hash}}
    setup = read_setup(meta)
    assert setup.problem == ""
    table = noise_table(setup.noises).set_index("noise")
    assert list(table.index) == ["output-only", "regressors", "regressors-output-x3", "regressors-x3"]
    assert table.loc["regressors-x3", "definition"].startswith("preset white × 3 on the regressors only")
    assert "α, β 0.3°" in table.loc["regressors-x3", "sensor noise (σ)"]
    assert "σ CZ 0.015, Cm 0.0015" in table.loc["regressors-output-x3", "definition"]
    changed = read_setup({"campaign": {"file": str(file), "sha256": "f" * 64}})
    assert changed.noises == () and "has changed since the run" in changed.problem
    text = flown_text(scores())
    assert text.startswith("Flown: the seed's linear models") and "not the nonlinear JSBSim F-16" in text
    assert "maneuver 2-1-1-2" in text
