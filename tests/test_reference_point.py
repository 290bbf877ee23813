"""The 737's aerodynamic reference point, placed as the recording says (issue 12: recordings
made by someone else's script): the project flies it on the c.g., JSBSim ships it 1.2 ft aft
of and 4.9 ft above, and a stock 737's recording read against the project's placement drew a
false C_l,β (t −13 to −478) and a moment-reference offset (t 163)."""
from __future__ import annotations

import numpy as np
import pytest

from harness.diagnosis.prepare import prepare
from harness.diagnosis.reference_point import _arms, combined_ratio, reliabilities, significant_arms, told
from harness.diagnosis.run import diagnose
from harness.diagnosis.verdict import DiagnosisError
from harness.noise import apply_noise
from harness.noise_presets import preset
from harness.recording_io import read_recording, write_recording
from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.inputs import default_three_axis_input
from maneuvers.multistep import stabilator_2112
from models.aircraft import (AircraftError, Aircraft, library_xml, placement, reference_on_cg,
                             reference_point_alternative)
from models.hidden import HiddenEffect


def _recording(tmp_path, aircraft, inputs, seed=5, duration_s=None):
    spec = FlightSpec(aircraft=aircraft, input=inputs, **({"duration_s": duration_s} if duration_s else {}))
    rec = apply_noise(fly_maneuver(spec), preset("realistic"), seed=seed)
    clean = rec.data[[c for c in rec.data.columns if not c.startswith("truth_")]]
    meta = {k: v for k, v in rec.meta.items() if k not in ("truth", "simulation")}
    path = tmp_path / "rec.csv"
    write_recording(type(rec)(data=clean, meta=meta, name=path.stem), path)
    return path


def _placement(result):
    return next(a["stood_in_by"] for a in result["assumptions"] if a["item"] == "aerodynamic reference point")


def test_only_the_737_has_two_placements():
    a = Aircraft("737")
    assert reference_on_cg(a) and placement(a) == "cg"
    stock = reference_point_alternative(a)
    assert stock.aero_reference == "xml" and not reference_on_cg(stock) and stock.label == "737@rp-xml"
    assert reference_point_alternative(stock) == a
    assert reference_point_alternative(Aircraft("f16")) is None
    assert reference_point_alternative(Aircraft("dhc6")) is None
    # the package's 737 XML by path flies as it is; its alternative is the c.g.
    by_path = Aircraft(str(library_xml("737")))
    assert not reference_on_cg(by_path) and reference_on_cg(reference_point_alternative(by_path))
    with pytest.raises(AircraftError, match="unknown aerodynamic reference point"):
        Aircraft("737", aero_reference="nose")
    with pytest.raises(AircraftError, match="only for the nominal variant"):
        Aircraft("f16", "unstable", aero_reference="xml")


def test_a_moment_change_splits_exactly_into_its_arms_along_the_forces():
    rng = np.random.default_rng(0)
    forces = {f: rng.normal(size=400) for f in ("CX", "CY", "CZ")}
    change = 0.052 * forces["CX"] - 0.096 * forces["CZ"]  # ΔC_m = (Δz·C_X − Δx·C_Z)/c̄
    assert _arms(change, forces, ("CX", "CZ")) == pytest.approx({"CX": 0.052, "CZ": -0.096})
    # no y arm: C_l's part along C_Z is round-off, and a part far under the largest is left out
    arms = {"Cl": _arms(-0.05 * forces["CY"], forces, ("CY", "CZ")), "Cm": {"CX": 0.052, "CZ": -0.096},
            "Cn": {"CX": 0.0, "CY": 0.001}}
    kept = significant_arms(arms, forces, {"Cl": 94.7, "Cm": 12.3, "Cn": 94.7})
    assert set(kept["Cl"]) == {"CY"} and set(kept["Cm"]) == {"CX", "CZ"} and kept["Cn"] == {}


def test_a_group_tells_a_placement_only_when_it_rules_the_other_out():
    assert told(0.98, 0.04) == 1.0 and told(0.01, 0.03) == 0.0
    assert told(0.5, 0.2) is None  # near neither
    assert told(1.48, 0.37) is None  # nearer one, but only 4 s.e. from zero
    # a concealed effect on the same parts moves k off its placement: the nearer is told
    assert told(1.55, 0.03) == 1.0 and told(0.78, 0.04) == 1.0 and told(-0.76, 0.02) == 0.0
    k, se = combined_ratio({"Cl/CY": (1.0, 0.1), "Cm/CX": (0.0, 0.1), "Cm/CZ": (9.0, 0.01)}, ("Cl/CY", "Cm/CX"))
    assert k == pytest.approx(0.5) and se == pytest.approx(0.1 / np.sqrt(2))
    assert combined_ratio({"Cm/CZ": (1.0, 0.1)}, ("Cl/CY",)) is None


def test_a_stock_737_recording_is_read_against_the_stock_placement(tmp_path):
    """A three-axis recording of the 737 as JSBSim ships it: the placement is read from C_l's
    part along C_Y (k near one), and nothing is found; the project's placement forced on it
    finds the side force's roll as a C_l,β of about −0.09 − 0.055."""
    path = _recording(tmp_path, Aircraft("737", aero_reference="xml"), default_three_axis_input())
    result = diagnose("737", path, tmp_path / "auto", calibrate=False)
    assert [f["effect"] for f in result["findings"]] == ["none"]
    assert _placement(result).startswith(
        "at the XML's AERORP, as the recording's moments say (the parts no c.g. offset moves")
    forced = diagnose("737", path, tmp_path / "forced", calibrate=False, aero_reference="project")
    cl_beta = [f for f in forced["findings"] if f["parameter"] == "Cl_beta"]
    assert cl_beta and cl_beta[0]["estimate"] == pytest.approx(-0.145, abs=0.02)
    assert not any(a["item"] == "aerodynamic reference point" for a in forced["assumptions"])


def test_a_project_737_recording_keeps_the_cg_placement(tmp_path):
    path = _recording(tmp_path, Aircraft("737"), default_three_axis_input())
    result = diagnose("737", path, tmp_path / "out", calibrate=False)
    assert [f["effect"] for f in result["findings"]] == ["none"]
    assert _placement(result).startswith("on the c.g., as the recording's moments say")


@pytest.mark.parametrize("amplitude_deg", [1.0, 3.0])
def test_a_stock_737_pitch_maneuver_is_placed_by_the_whole_change(tmp_path, amplitude_deg):
    """On a pitch maneuver C_Y does not move: C_l's parts cannot tell, each moment's whole
    change can (no c.g. offset taken to be there), on the measured C_Z (the model's, along
    the noisy α vane, said 1.4 ± 0.4 on the seed's 1° 2-1-1-2). Nothing is found."""
    path = _recording(tmp_path, Aircraft("737", aero_reference="xml"), stabilator_2112(amplitude_deg),
                      duration_s=20.0)
    result = diagnose("737", path, tmp_path / "out", calibrate=False)
    assert [f["effect"] for f in result["findings"]] == ["none"]
    # the measured C_Z carries the maneuver far above a_z's noise
    p = prepare(read_recording(path), "identification")
    assert reliabilities(p, {"CZ": p.measured["CZ"]})["CZ"] > 0.95
    text = _placement(result)
    assert text.startswith("at the XML's AERORP, as the recording's moments say (each moment's whole change")


def test_a_cg_offset_does_not_move_the_placement_where_the_z_arm_tells(tmp_path):
    """A concealed c.g. offset of 1 ft on a stock 737's three-axis maneuver moves C_m's part
    along C_Z only: the z arm still says stock."""
    aircraft = Aircraft("737", aero_reference="xml", hidden=(HiddenEffect("cg_offset", 1.0),))
    path = _recording(tmp_path, aircraft, default_three_axis_input())
    result = diagnose("737", path, tmp_path / "out", calibrate=False)
    assert _placement(result).startswith("at the XML's AERORP")
    assert not [f for f in result["findings"] if f["parameter"] in ("Cl_beta", "Cn_beta", "CY_beta")]


def test_an_unknown_placement_is_refused(tmp_path):
    path = _recording(tmp_path, Aircraft("737"), stabilator_2112(), duration_s=8.0)
    with pytest.raises(DiagnosisError, match="aero_reference must be 'auto' or one of"):
        diagnose("737", path, tmp_path / "out", calibrate=False, aero_reference="nose")


def test_a_stock_737_with_its_cl_beta_changed_is_sized_against_the_stock_placement(tmp_path):
    """The evaluator's way of concealing a coefficient error: the constant in a copy of the
    737's XML (C_l,β −0.09 → −0.12). Its roll moves C_l's part along C_Y too (k ≈ 1.55), the
    nearer placement is the XML's, and the change is sized against it (−0.03)."""
    import os
    import shutil

    import jsbsim

    from independent_script import fly

    package = os.path.dirname(jsbsim.__file__)
    root = tmp_path / "root"
    (root / "aircraft").mkdir(parents=True)
    for d in ("engine", "systems"):
        os.symlink(os.path.join(package, d), root / d)
    shutil.copytree(os.path.join(package, "aircraft", "737"), root / "aircraft" / "737")
    xml = root / "aircraft" / "737" / "737.xml"
    text = xml.read_text()
    start = text.index('<function name="aero/coefficient/Clb">')
    end = text.index("</function>", start)
    xml.write_text(text[:start] + text[start:end].replace("<value>-0.09</value>", "<value>-0.12</value>")
                   + text[end:])
    rec = fly(tmp_path / "id.csv", "737", 25000.0, 700.0, 11, 50.0, "ms_lat", root=str(root))
    val = fly(tmp_path / "val.csv", "737", 25000.0, 700.0, 511, 50.0, "dbl3", root=str(root))
    result = diagnose("737", rec, tmp_path / "out", val, calibrate=False)
    assert _placement(result).startswith("at the XML's AERORP")
    [finding] = result["findings"]
    assert finding["parameter"] == "Cl_beta"
    model_value = float(finding["explanation"].split("the model has ")[1].split(" over")[0])
    assert finding["estimate"] - model_value == pytest.approx(-0.03, rel=0.25)
