"""``sidbench estimate`` on one recording, start to finish: the statsmodels-like result, the
table with the truth, --json / --csv / --report, and the report as headless Chromium shows it."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from estimators.methods import make_estimator
from estimators.regressors import Equation
from harness.cli import main
from harness.recording_io import read_recording
from test_report_browser import CHECK_SCRIPT, _chromium, _parse

from reports.browser import dump_dom


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    d = tmp_path_factory.mktemp("estimate")
    assert main(["fly", "--maneuver", "2-1-1-2", "--out", str(d / "rec.csv")]) == 0
    return d


def test_results_read_like_statsmodels(flown):
    rec = read_recording(flown / "rec.csv")
    fit = make_estimator("ee-time").fit(rec, Equation("Cm", ("alpha", "qhat", "de")))
    assert isinstance(fit.params, pd.Series) and isinstance(fit.bse, pd.Series)
    assert list(fit.params.index) == ["Cm_alpha", "Cm_qhat", "Cm_de", "bias"]
    assert fit.params["Cm_alpha"] == fit.params[0] == fit.param("Cm_alpha")  # by name and, as before, by position
    assert fit.bse["Cm_de"] == pytest.approx(np.sqrt(fit.cov[2, 2]), rel=1e-12)
    ci = fit.conf_int(alpha=0.05)
    assert list(ci.columns) == ["lower", "upper"] and list(ci.index) == list(fit.names)
    from scipy import stats
    c = stats.t.isf(0.025, fit.n - 4)
    assert ci.loc["Cm_alpha", "upper"] - ci.loc["Cm_alpha", "lower"] == pytest.approx(2 * c * fit.bse["Cm_alpha"])
    assert np.allclose(np.asarray(fit.conf_int(k=2)), np.column_stack([fit.params - 2 * fit.bse,
                                                                        fit.params + 2 * fit.bse]))
    assert fit.tvalues["Cm_de"] == pytest.approx(fit.params["Cm_de"] / fit.bse["Cm_de"])
    assert fit.pvalues["Cm_de"] < 1e-10 and 0 <= fit.pvalues.min() and fit.pvalues.max() <= 1
    assert fit.rsquared == fit.r2 and fit.output_error is None
    assert " t " in fit.summary().splitlines()[1] + " "
    assert "error/se" in fit.summary(truth={"Cm_alpha": -0.08})


def test_output_error_extras_are_typed(flown):
    rec = read_recording(flown / "rec.csv")
    fit = make_estimator("oe").fit(rec, Equation("Cm", ("alpha", "qhat", "de")))
    oe = fit.output_error
    assert oe is not None and oe.converged and oe.iterations == fit.info["iterations"]
    assert oe.outputs == tuple(fit.dependent.split(",")) and oe.noise_covariance.shape == (len(oe.outputs),) * 2
    assert set(oe.rsquared) == set(oe.outputs) and oe.matrices["A"].shape[0] == oe.matrices["A"].shape[1]
    assert fit.pvalues.shape == fit.params.shape and fit.uses_normal


def test_estimate_writes_report_csv_and_json(flown, capsys):
    out = flown
    argv = ["estimate", "--recording", str(out / "rec.csv"), "--dependent", "Cm", "--regressors", "alpha,qhat,de",
            "--report", str(out / "report"), "--csv", str(out / "fit.csv"), "--json", str(out / "fit.json")]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "truth" in printed and "error/se" in printed  # a simulated recording: its truth in the table

    table = pd.read_csv(out / "fit.csv")
    assert list(table["parameter"]) == ["Cm_alpha", "Cm_qhat", "Cm_de", "bias"]
    meta = json.loads((out / "rec.meta.json").read_text())
    assert table.set_index("parameter").loc["Cm_de", "truth"] == pytest.approx(
        meta["truth"]["derivatives"]["Cm_de"]["local"], rel=1e-12)
    row = table.set_index("parameter").loc["Cm_alpha"]
    assert row["error_in_se"] == pytest.approx((row["estimate"] - row["truth"]) / row["std_error"], rel=1e-9)

    doc = json.loads((out / "fit.json").read_text())
    assert doc["regressors"] == ["alpha", "qhat", "de"]
    assert len(doc["residuals"]) == doc["n"] == len(doc["t_s"])
    assert {"method", "errors", "max_lag", "frequencies", "detrend", "reference", "angular_acceleration",
            "no_bias", "truth", "report", "csv", "json", "recording"} <= set(doc["options"])
    assert all("truth" in p and "t_value" in p and "ci95_lower" in p for p in doc["parameters"])

    html = out / "report" / "report.html"
    text = html.read_text(encoding="utf-8")
    assert "src=\"data:image/png;base64," in text and "http" not in text.split("<body")[1].split("Generated")[0]
    chromium = _chromium()
    probe = out / "report" / "probe.html"
    probe.write_text(text.replace("</body>", CHECK_SCRIPT + "</body>"), encoding="utf-8")
    body = _parse(dump_dom(probe, chromium=chromium)).body
    assert body.get("data-images") == "ok", body
    assert body.get("data-imagecount") == "4", body  # estimates, measured vs model, residual + PSD, regressors
    ids = _parse(dump_dom(html, chromium=chromium)).ids
    assert {"figure-estimates", "figure-measured-vs-model", "figure-residual", "figure-regressors",
            "table-estimates"} <= ids, ids


def test_report_of_flight_data_has_no_truth(flown, tmp_path):
    rec = read_recording(flown / "rec.csv")
    rec.meta.pop("truth", None)
    from harness.recording_io import write_recording
    write_recording(rec, tmp_path / "flight.csv")
    assert main(["estimate", "--recording", str(tmp_path / "flight.csv"), "--dependent", "Cm", "--regressors",
                 "alpha,qhat,de", "--method", "ee-freq", "--csv", str(tmp_path / "f.csv"),
                 "--report", str(tmp_path / "r")]) == 0
    table = pd.read_csv(tmp_path / "f.csv")
    assert "truth" not in table.columns and len(table) == 3
    assert "carries no truth" in (tmp_path / "r" / "report.html").read_text(encoding="utf-8")
