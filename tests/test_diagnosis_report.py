"""The diagnosis report from a synthetic ``sidbench diagnose`` folder (no flight, no estimation)."""
from __future__ import annotations

import base64
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from models.constants import BODY_COEFFICIENTS as COEFFICIENTS
from reports.diagnosis_channels import affected_channels, affected_coefficients
from reports.diagnosis_report import diagnosis_report, write_diagnosis_report
from reports.html import html_text
from reports.render import PNG_SIGNATURE, Report
from reports.render_values import format_number

CHANNELS = ("alpha", "beta", "p", "q", "r", "phi", "theta", "V", "ax", "ay", "az")
IMG = re.compile(r'<img\s[^>]*src="([^"]*)"')


def _series(seed: int, n: int = 400, dt: float = 0.02) -> pd.DataFrame:
    """Measured, smoothed, before and after signals with a pitch mismatch in 3-5 s."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    bump = np.exp(-((t - 4.0) / 0.6) ** 2)
    cols: dict[str, np.ndarray] = {"t_s": t}
    for k, c in enumerate(CHANNELS):
        truth = 0.05 * np.sin(2 * np.pi * (0.3 + 0.1 * k) * t)
        gap = 0.02 * bump if c in ("q", "alpha") else 0.0
        cols[f"meas_{c}"] = truth + 0.002 * rng.standard_normal(n)
        cols[f"smooth_{c}"] = truth
        cols[f"before_{c}"] = truth - gap
        cols[f"after_{c}"] = truth - 0.1 * gap
    for j in COEFFICIENTS:
        coef = 0.1 * np.cos(2 * np.pi * 0.5 * t)
        gap = 0.01 * bump * np.sin(2 * np.pi * 1.2 * t) if j == "Cm" else 0.0
        cols[f"coef_meas_{j}"] = coef + 0.001 * rng.standard_normal(n)
        cols[f"coef_model_{j}"] = coef - gap
        cols[f"coef_after_{j}"] = coef - 0.1 * gap
    for s in ("de", "da", "dr"):
        cols[s] = 0.01 * np.sign(np.sin(2 * np.pi * 0.4 * t))
    return pd.DataFrame(cols).astype("float64")


def _fit(scale: float, validation: bool) -> dict:
    fit = {"outputs": {c: {"rms": scale * 0.01, "theil_u": scale * 0.1} for c in ("alpha", "q", "theta")},
           "coefficients": {j: {"rms": scale * 0.002, "pse": scale * 1e-5} for j in ("CZ", "Cm")},
           "whiteness": {"Cm": {"lag_fraction_inside": 1.0 - 0.5 * scale, "ljung_box_z": 20 * scale}}}
    return {"identification": fit, "validation": fit} if validation else {"identification": fit}


def _located(validation: bool) -> dict:
    outputs = {c: {"rms": 0.01, "rms_raw": 0.012, "theil_u": 0.1, "noise_std": 0.002, "ratio": 5.0 if c == "q" else 1.1}
               for c in CHANNELS}
    located = {"outputs": {"identification": outputs},
               "coefficients": {"identification": {j: {"rms": 0.003, "noise_std": 0.001,
                                                       "ratio": 3.0 if j == "Cm" else 1.0, "pse": 1e-5}
                                                   for j in COEFFICIENTS}},
               "worst_output": "q", "worst_axis": "Cm", "time_window_s": [3.0, 5.0], "band_hz": [0.8, 2.0],
               "summary": "The pitch axis carries the mismatch, mostly between 3 and 5 s."}
    if validation:
        located["outputs"]["validation"] = outputs
    return located


FINDING = {"effect": "unsteady_alphadot", "axis": "pitch", "channel": None, "parameter": "Cm_alphadot",
           "estimate": -2.9, "std_error": 0.2, "units": "per rad (alphadot normalised by cbar/2V)",
           "evidence": {"t": 14.2, "explained_fraction": 0.83, "test": "stepwise on the Cm mismatch",
                        "lags": [1, 2]},
           "explanation": "Cm depends on the rate of change of alpha, which the model lacks."}
NONE = {"effect": "none", "axis": None, "channel": None, "parameter": None, "estimate": None, "std_error": None,
        "units": None, "evidence": {"max_ratio": 1.08, "test": "every channel within noise"},
        "explanation": "Every output and coefficient mismatch is within 1.1 noise standard deviations."}
CANDIDATES = [
    {"effect": "nonlinear_alpha", "axis": "pitch", "channel": None, "parameter": "Cm_alpha2", "estimate": 0.4,
     "std_error": 0.3, "t": 1.3, "explained_fraction": 0.05, "selected": False, "reason": "|t| below 4"},
    {"effect": "unsteady_alphadot", "axis": "pitch", "channel": None, "parameter": "Cm_alphadot",
     "estimate": -2.9, "std_error": 0.2, "t": -14.2, "explained_fraction": 0.83, "selected": True,
     "reason": "largest |t|"},
    {"effect": "sensor_offset", "axis": None, "channel": "alpha", "parameter": "alpha_bias", "estimate": 1e-4,
     "std_error": None, "t": None, "explained_fraction": None, "selected": False, "reason": "not estimable"}]


def _write_dir(root: Path, effect: str, validation: bool) -> Path:
    """A diagnosis folder following the data contract."""
    finding = dict(FINDING if effect != "none" else NONE)
    finding["fit_before"] = _fit(1.0, validation)
    finding["fit_after"] = _fit(0.2 if effect != "none" else 1.0, validation)
    data = {"findings": [finding], "located": _located(validation),
            "noise": {c: {"std": 0.002, "cutoff_hz": 2.5} for c in CHANNELS},
            "candidates": CANDIDATES if effect != "none" else [],
            "model": {"base": "f16", "augmented_xml": "model/f16_diag/f16_diag.xml",
                      "terms": [] if effect == "none" else ["Cm_alphadot * alphadot * cbar / (2 V)"]},
            "inputs": {"identification": "rec/ident.csv", "validation": "rec/valid.csv" if validation else None,
                       "model": "f16"},
            "timing_s": {"total": 12.5}, "seed": None}
    (root / "series").mkdir(parents=True)
    (root / "findings.json").write_text(json.dumps(data))
    _series(1).to_parquet(root / "series" / "identification.parquet")
    if validation:
        _series(2).to_parquet(root / "series" / "validation.parquet")
    return root


def _images_are_png(html: str) -> int:
    sources = IMG.findall(html)
    for src in sources:
        assert src.startswith("data:image/png;base64,"), src[:40]
        assert base64.b64decode(src.split(",", 1)[1], validate=True).startswith(PNG_SIGNATURE)
    return len(sources)


@pytest.fixture(scope="module")
def alphadot_html(tmp_path_factory) -> tuple[Path, str]:
    out = _write_dir(tmp_path_factory.mktemp("alphadot"), "unsteady_alphadot", validation=True)
    path = write_diagnosis_report(out)
    return path, path.read_text()


def test_alphadot_report_names_the_finding(alphadot_html):
    path, html = alphadot_html
    assert path == path.parent / "report.html" and path.is_file()
    for needle in ("unsteady_alphadot", "Cm_alphadot", format_number(-2.9), format_number(0.2),
                   'id="section-verdict"', 'id="table-findings"', 'id="table-candidates"',
                   'id="section-before-and-after-identification"', 'id="section-before-and-after-validation"',
                   "model/f16_diag/f16_diag.xml"):
        assert needle in html, needle
    assert _images_are_png(html) >= 7
    assert html.count("<figcaption") == html.count("<img")
    assert (path.parent / "report.md").is_file()
    report = json.loads((path.parent / "report.json").read_text())
    assert report["numbers"]["findings"][0]["parameter"] == "Cm_alphadot"
    assert not list(path.parent.glob(".*.tmp"))


def test_candidates_are_sorted_by_abs_t_with_the_selected_highlighted(alphadot_html):
    report = json.loads((alphadot_html[0].parent / "report.json").read_text())
    table = next(t for s in report["sections"] for t in s["tables"] if t["title"] == "Candidates")
    effects = [row[table["columns"].index("effect")] for row in table["rows"]]
    assert effects == ["unsteady_alphadot", "nonlinear_alpha", "sensor_offset"]
    html = alphadot_html[1]
    assert '<td class="good" title="good">unsteady_alphadot</td>' in html


def test_none_report_says_so_and_has_no_validation(tmp_path):
    out = _write_dir(tmp_path, "none", validation=False)
    report = diagnosis_report(out)
    assert isinstance(report, Report) and report.summary[0].startswith("No effect found")
    html = html_text(report)
    assert "No effect found" in html and "max_ratio" in html
    assert 'id="table-findings"' not in html
    assert "section-before-and-after-validation" not in html
    assert "section-before-and-after-identification" in html
    assert _images_are_png(html) >= 3


def test_missing_pieces_do_not_crash(tmp_path):
    out = _write_dir(tmp_path, "unsteady_alphadot", validation=False)
    data = json.loads((out / "findings.json").read_text())
    for key in ("located", "noise", "candidates", "model", "timing_s"):
        data.pop(key)
    for f in data["findings"]:
        f.pop("fit_after")
    (out / "findings.json").write_text(json.dumps(data))
    frame = pd.read_parquet(out / "series" / "identification.parquet")
    frame.drop(columns=[c for c in frame if c.startswith(("after_", "coef_after_", "meas_q"))]).to_parquet(
        out / "series" / "identification.parquet")
    path = write_diagnosis_report(out)
    titles = [s["title"] for s in json.loads(path.with_suffix(".json").read_text())["sections"]]
    assert titles[-1] == "Before and after: identification"
    html = path.read_text()
    assert "Cm_alphadot" in html and "No candidate tests were recorded." in html
    _images_are_png(html)


def test_affected_channels_follow_the_findings():
    data = {"findings": [FINDING], "located": _located(False)}
    assert affected_coefficients(data) == ["Cm"]
    assert affected_channels(data, None)[:2] == ["q", "alpha"]
    offset = {"findings": [{"effect": "sensor_offset", "axis": None, "channel": "beta"}],
              "located": {"worst_axis": "Cn"}}
    assert affected_channels(offset, None) == ["beta"] and affected_coefficients(offset) == ["Cn"]
    assert affected_channels({"findings": [NONE], "located": _located(False)}, None)[0] == "q"


def test_none_report_shows_the_detection_limits(tmp_path):
    """findings.json's detection_limits become a table beside what was not checked, in
    percent of the model's value where there is one, and the 'none' sentence points to it."""
    out = _write_dir(tmp_path, "none", validation=False)
    data = json.loads((out / "findings.json").read_text())
    data["detection_limits"] = [
        {"effect": "coefficient_error", "parameter": "Cm_qhat", "units": "per rad", "limit": 0.584,
         "std_error": 0.117, "rule": "significance", "floors": {"significance": 0.584}, "model_value": -5.57,
         "relative_to_model": 0.105},
        {"effect": "sensor_bias", "parameter": "bias_q", "units": "rad/s", "limit": 0.00262, "std_error": 0.0002,
         "rule": "practical size", "floors": {"practical size": 0.00262}}]
    (out / "findings.json").write_text(json.dumps(data))
    report = diagnosis_report(out)
    assert "detection limits" in report.summary[0]
    table = next(t for s in report.sections for t in s.tables if t.title == "Detection limits")
    rows = table.frame.to_dict("records")
    assert rows[0]["parameter"] == "Cm_qhat" and rows[0]["of the model's value"] == "10 %"
    assert rows[1]["of the model's value"] == "—" and rows[1]["set by"] == "practical size"


def test_models_outside_the_aircraft_are_shown(tmp_path):
    """A structural mode (or turbulence) changes no aircraft term: the chosen-model section
    says the aircraft is unchanged and names the model outside it (model/sensors.json)."""
    from reports.diagnosis_report import model_section
    data = {"model": {"base": "f16", "augmented_xml": None, "terms": [],
                      "outside_the_aircraft": [{"effect": "structural_mode",
                                                "model": "second-order mode driven by de"}]}}
    lines = model_section(data, tmp_path).paragraphs
    assert any("No term was added to the aircraft" in s for s in lines)
    assert any(s.startswith("Modelled outside the aircraft, structural_mode: second-order mode driven by de")
               for s in lines)
