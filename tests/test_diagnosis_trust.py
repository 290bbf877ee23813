"""The diagnosis on recordings it did not make (issue 12): nothing invented on what the
maneuver did not excite, nothing too small to matter, what it assumed and could not check,
and a model of another aircraft refused."""
from __future__ import annotations

import json

import pytest

from harness.diagnosis.run import DiagnosisError, diagnose
from harness.noise import apply_noise
from harness.noise_presets import preset
from harness.recording_io import write_recording
from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.inputs import default_lateral_input, default_three_axis_input
from maneuvers.multistep import stabilator_2112
from models.aircraft import Aircraft


def _write(rec, path):
    clean = rec.data[[c for c in rec.data.columns if not c.startswith("truth_")]]
    meta = {k: v for k, v in rec.meta.items() if k not in ("truth", "simulation")}
    write_recording(type(rec)(data=clean, meta=meta, name=path.stem), path)
    return path


def _effects(result):
    return [f["effect"] for f in result["findings"]]


@pytest.mark.parametrize("model", ["f16", "737"])
def test_noise_free_recording_of_the_model_itself_gives_none(model, tmp_path):
    rec = fly_maneuver(FlightSpec(aircraft=Aircraft(model), input=default_three_axis_input()))
    path = _write(rec, tmp_path / "clean.csv")
    result = diagnose(model, path, tmp_path / "out")
    assert _effects(result) == ["none"]
    # the stepwise still sees terms at large t on noise-free data: too small to matter
    small = [c for c in result["candidates"] if c["reason"].startswith("entered, but too small")]
    assert all(not c["selected"] for c in small)


def test_pitch_only_maneuver_names_no_lateral_term(tmp_path):
    """Realistic noise on β, p, r while only the stabilator moves: no lateral candidate is
    offered, the model is evaluated along a constant β, and not_checked says why."""
    rec = fly_maneuver(FlightSpec(input=stabilator_2112(), duration_s=20.0))
    noisy = apply_noise(rec, preset("realistic"), seed=3)
    result = diagnose("f16", _write(noisy, tmp_path / "pitch.csv"), tmp_path / "out")
    lateral = [f for f in result["findings"] if f.get("channel") in ("CY", "Cl", "Cn")]
    assert lateral == []
    reasons = {(n["effect"], n["reason"]) for n in result["not_checked"]}
    assert ("coefficient_error", "no lateral input (aileron and rudder never moved)") in reasons
    assert any(e == "cross_coupling" for e, _ in reasons)
    assert any(n["effect"] == "(every finding)" for n in result["not_checked"])  # no validation maneuver


def test_lateral_only_maneuver_names_no_pitch_term(tmp_path):
    rec = fly_maneuver(FlightSpec(input=default_lateral_input()))
    noisy = apply_noise(rec, preset("realistic"), seed=4)
    result = diagnose("f16", _write(noisy, tmp_path / "lat.csv"), tmp_path / "out")
    assert not [f for f in result["findings"] if f.get("channel") in ("CX", "CZ", "Cm")]
    assert any(n["effect"] == "unsteady_alphadot" and "stabilator" in n["reason"] for n in result["not_checked"])


def test_assumptions_name_the_stand_ins_for_missing_channels(tmp_path):
    rec = fly_maneuver(FlightSpec(input=default_three_axis_input(), condition="h=20000,V=600"))
    data = rec.data.drop(columns=["h_ft", "thrust_lbf"])
    meta = {k: v for k, v in rec.meta.items() if k not in ("truth", "simulation")}
    meta["trim"] = {k: v for k, v in meta["trim"].items() if k != "thrust_lbf"}
    path = tmp_path / "bare.csv"
    write_recording(type(rec)(data=data[[c for c in data.columns if not c.startswith("truth_")]], meta=meta,
                              name="bare"), path)
    result = diagnose("f16", path, tmp_path / "out")
    by_item = {a["item"]: a for a in result["assumptions"]}
    assert "ISA altitude" in by_item["altitude"]["stood_in_by"]
    # the density altitude of q̄ and V in JSBSim's standard atmosphere is the flown 20,000 ft
    assert abs(float(by_item["altitude"]["stood_in_by"].split("(")[1].split(" ft")[0]) - 20_000) < 50
    assert "model's trim thrust" in by_item["thrust"]["stood_in_by"] and "lbf" in by_item["thrust"]["stood_in_by"]
    assert "surface_levels_deg" in by_item["surface levels (replays)"]["stood_in_by"]
    assert _effects(result) == ["none"]  # a clean recording of the model, made elsewhere in the envelope
    written = json.loads((tmp_path / "out" / "findings.json").read_text())
    assert written["assumptions"] and written["not_checked"]


def test_model_of_another_aircraft_is_refused(tmp_path, shared_dir):
    rec = fly_maneuver(FlightSpec(input=default_three_axis_input()))
    path = _write(rec, tmp_path / "f16.csv")
    with pytest.raises(DiagnosisError, match="does not represent the recorded aircraft.*wing area"):
        diagnose("737", path, tmp_path / "out")
    with pytest.raises(DiagnosisError, match="does not represent the recorded aircraft"):
        diagnose("f16", shared_dir / "data" / "sidpac" / "totter_f1_017_data.mat", tmp_path / "out2")
    # same geometry, but the recorded aircraft is 2.2 times heavier: twice the lift at the same α
    heavy = type(rec)(data=rec.data, meta={**rec.meta, "mass": {k: 2.2 * v for k, v in rec.meta["mass"].items()}},
                      name="heavy")
    with pytest.raises(DiagnosisError, match="normal-force coefficient averages"):
        diagnose("f16", _write(heavy, tmp_path / "heavy.csv"), tmp_path / "out3")
    assert not (tmp_path / "out3" / "findings.json").exists()
