"""The diagnosis's last step (issue 15): the terms it names, refined with JSBSim in the loop,
kept only when they fit at least as well as the equation-error sizes."""
from __future__ import annotations

import json
from types import SimpleNamespace

import pytest

from harness.calibrate.auto import findings_parameters
from harness.diagnosis.gallery import case, write_case
from harness.diagnosis.refine import affected_outputs, decide, matched_outputs, surface_hold, validation_rms_pair
from harness.diagnosis.run import diagnose
from models.hidden import HiddenEffect


def _validation_q(fits: dict) -> float:
    return fits["validation"]["outputs"]["q"]["rms"]


@pytest.fixture(scope="module")
def diagnosed(tmp_path_factory):
    """Two gallery cases (seed 1), diagnosed with the calibration step: Cm_α̇, whose calibrated
    size is kept, and the stabilator delay, whose calibrated size fits the validation q worse."""
    root = tmp_path_factory.mktemp("diagnose-calibrate")
    out = {}
    for name in ("unsteady_alphadot", "control_delay"):
        paths = write_case(case(name), root / "recordings", seed=1)
        out[name] = (diagnose("f16", paths["identification"], root / name, paths["validation"]), root / name)
    return out


def test_the_named_term_is_refined_in_the_loop_and_flown(diagnosed):
    result, folder = diagnosed["unsteady_alphadot"]
    cal = result["calibration"]
    assert cal["used"], cal["reason"]
    assert cal["hold"] == "sample"  # a simulated recording: its stepped surfaces held
    # the calibration matches the output the decision judges (q for a pitching moment term)
    assert cal["matched_outputs"] == ["q"] and set(cal["calibrator_fit"]["calibrated"]["identification"]) == {"q"}
    (p,) = cal["parameters"]
    assert p["name"] == "Cm_alphadot" and p["calibrated"] != p["equation_error"] and p["std_error"] > 0
    # the truth is -3: the calibrated size within 3 of its standard errors
    assert abs(p["calibrated"] + 3.0) <= 3.0 * p["std_error"]
    first = result["findings"][0]
    # the headline is the size the augmented model flies with; the identification's figure beside it
    assert first["estimate"] == p["calibrated"] and first["equation_error"]["estimate"] == p["equation_error"]
    assert first["calibrated"]["estimate"] == p["calibrated"] and first["calibrated"]["std_error"] == p["std_error"]
    # the model written and flown carries the calibrated size
    terms = json.loads((folder / "findings.json").read_text())["model"]["terms"]
    assert [t["size"] for t in terms if t["parameter"] == "Cm_alphadot"] == [p["calibrated"]]
    assert first["fit_after"] == cal["fit_after_calibration"]
    # never worse than the equation-error sizes: identification cost and validation q
    assert cal["identification_cost"]["calibrated"] <= cal["identification_cost"]["equation_error"]
    assert _validation_q(first["fit_after"]) <= _validation_q(first["fit_after_equation_error"])
    # an auto calibration from these findings still starts at the equation-error size
    assert findings_parameters(result) == [f"Cm_alphadot={p['equation_error']!r}"]


def test_a_calibration_that_predicts_worse_is_not_used(diagnosed):
    result, folder = diagnosed["control_delay"]
    cal = result["calibration"]
    col = validation_rms_pair(cal, "q")
    if col["calibrated"] > col["equation_error"]:
        assert not cal["used"] and "kept" in cal["reason"]
    after = _validation_q(result["findings"][0]["fit_after"])
    assert after == (col["calibrated"] if cal["used"] else col["equation_error"])
    assert after <= col["equation_error"]
    terms = json.loads((folder / "findings.json").read_text())["model"]["terms"]
    kept = cal["parameters"][0]["calibrated" if cal["used"] else "equation_error"]
    assert [t["size"] for t in terms if t["parameter"] == "tau_de"] == [kept]
    assert any(a["item"].startswith("surfaces between samples") for a in result["assumptions"])


def test_no_calibration_when_asked(tmp_path):
    paths = write_case(case("cg_offset"), tmp_path / "recordings", seed=1)
    result = diagnose("f16", paths["identification"], tmp_path / "d", paths["validation"], calibrate=False)
    assert result["calibration"]["used"] is False and "calibration" not in result["timing_s"]
    assert "calibrated" not in result["findings"][0]


def _fits(q: float) -> dict:
    return {"validation": {"outputs": {"q": {"rms": q}}}}


def _cal(before: float, after: float) -> SimpleNamespace:
    return SimpleNamespace(fit_before={"identification": {"q": {"rms": before}, "alpha": {"rms": 1.0}}},
                           fit_after={"identification": {"q": {"rms": after}, "alpha": {"rms": 1.0}}},
                           start=[1.0], estimate=[1.2])


@pytest.mark.parametrize("id_after, val_after, used", [(0.9, 0.9, True), (0.9, 1.0, True), (0.9, 1.1, False),
                                                        (1.1, 0.9, False), (None, 0.9, False)])
def test_decide_keeps_the_calibration_only_when_it_fits_at_least_as_well(id_after, val_after, used):
    cal = _cal(1.0, id_after) if id_after is not None else SimpleNamespace(
        fit_before={"identification": {"q": {"rms": 1.0}}}, fit_after={"identification": {"q": {"rms": None}}},
        start=[1.0], estimate=[1.2])
    ok, reason, figures = decide(cal, _fits(1.0), _fits(val_after), ["q"])
    assert ok is used and reason
    assert figures["judged_on"] == "validation"


def test_decide_does_not_claim_a_calibration_that_did_not_move():
    cal = _cal(1.0, 1.0)
    cal.estimate = [1.0]
    ok, reason, _ = decide(cal, _fits(1.0), _fits(1.0), ["q"])
    assert not ok and "did not move" in reason


def test_hold_from_the_metadata_and_the_outputs_a_term_drives():
    assert surface_hold({"simulation": {"aircraft": "f16"}})[0] == "sample"
    assert surface_hold({"source": "SIDPAC totter_f1_017"})[0] == "linear"
    terms = [HiddenEffect("control_delay", 0.05, surface="dr"), HiddenEffect("cross_coupling", 1.0, coefficient="Cl"),
             HiddenEffect("cg_offset", 0.5), HiddenEffect("nonlinear_alpha", 1.0, coefficient="CZ")]
    assert affected_outputs(terms) == ["r", "p", "q", "az"]


def test_the_calibration_matches_the_outputs_the_decision_judges():
    has = SimpleNamespace(has=lambda o: o in ("alpha", "q", "r", "az"))
    terms = [HiddenEffect("control_delay", 0.05, surface="dr"), HiddenEffect("cross_coupling", 1.0, coefficient="Cl"),
             HiddenEffect("cg_offset", 0.5), HiddenEffect("nonlinear_alpha", 1.0, coefficient="CZ")]
    assert matched_outputs(terms, has) == ("r", "q", "az")  # p not recorded: not matched
    # a recording with none of them: every output it has (the calibration's default)
    assert matched_outputs(terms[1:2], has) is None


def test_decide_weighs_an_unjudged_output_that_gets_worse_against_the_whole_maneuver():
    def fits(q, r):
        return {"validation": {"outputs": {"q": {"rms": q}, "r": {"rms": r}}}}
    ok, _, figures = decide(_cal(1.0, 0.9), fits(1.0, 1.0), fits(0.9, 1.019), ["q"])
    assert ok and figures["unjudged_raised"] == {}
    # r up 3 % but q down 10 %: the maneuver's cost over every output falls, so it is used
    ok, _, figures = decide(_cal(1.0, 0.9), fits(1.0, 1.0), fits(0.9, 1.03), ["q"])
    assert ok and set(figures["unjudged_raised"]) == {"r"}
    # r up 20 %, q down 10 %: the cost rises
    ok, reason, figures = decide(_cal(1.0, 0.9), fits(1.0, 1.0), fits(0.9, 1.2), ["q"])
    assert not ok and "raise the validation maneuver's r" in reason
    assert figures["validation_cost"]["calibrated"] > figures["validation_cost"]["equation_error"]


def test_one_process_gives_the_same_diagnosis(diagnosed, tmp_path):
    """The second process (validation analysed, replayed and flown meanwhile) changes nothing:
    with one process the findings, their fits and the calibration are the same numbers."""
    _, folder = diagnosed["unsteady_alphadot"]
    rec = json.loads((folder / "findings.json").read_text())["inputs"]
    diagnose("f16", rec["identification"], tmp_path / "alone", rec["validation"], calibrate_workers=1)
    one, two = (json.loads((f / "findings.json").read_text()) for f in (tmp_path / "alone", folder))
    assert json.dumps(one["findings"], sort_keys=True) == json.dumps(two["findings"], sort_keys=True)
    for key in ("used", "parameters", "fit_after_calibration", "fit_after_equation_error"):
        assert json.dumps(one["calibration"][key], sort_keys=True) == json.dumps(two["calibration"][key], sort_keys=True)
    assert two["calibration"]["workers"] == 2 and one["calibration"]["workers"] == 1
