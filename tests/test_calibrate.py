"""JSBSim in the loop (issue 15): the calibrated parameters, the XML they are written into, the
engine's step halving, the command line and its refusals."""
from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest

from harness.calibrate import CalibrationError, calibrate
from harness.calibrate.engine import gauss_newton
from harness.calibrate.problem import base_aircraft
from harness.cli import main
from harness.noise import apply_noise
from harness.noise_presets import preset
from harness.recording_io import read_recording, write_recording
from maneuvers.combine import Sequence
from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.multistep import multistep
from models.aircraft import Aircraft, new_fdm
from models.calibration_xml import adjusted_tree, parse_adjustment, with_actuator_delays
from models.jsbsim_root import write_root

TRUTH = {"aero/coefficient/Cnb:scale": 0.7, "Cm_alphadot": -3.0}
CONDITION = "h=10000,V=420"  # the gallery's condition (seed-5deg)
NOISE_SEEDS = (11, 12)       # identification, validation


def _truth_aircraft(folder: Path) -> Aircraft:
    """The F-16 with Cnb scaled by 0.7 and Cm_α̇ = −3 added (the calibration's own XML
    adjustments; loaded by path under the name f16, so it trims and flies as the F-16 does)."""
    base = base_aircraft("f16")
    adj = tuple(parse_adjustment(n) for n in TRUTH)
    tree = adjusted_tree(base.tree(), adj, tuple(TRUTH.values()), refs={}, surfaces=base.aircraft.surfaces)
    write_root(folder, "f16", tree, Path(base.source))
    return Aircraft(str(folder / "aircraft" / "f16" / "f16.xml"))


def _inputs() -> tuple[Sequence, Sequence]:
    ident = Sequence((multistep("3-2-1-1", "de", 2.0, 0.5), multistep("doublet", "dr", 3.0, 1.0)), gap_s=1.0,
                     name="identification")
    valid = Sequence((multistep("2-1-1-2", "de", 1.5, 0.7), multistep("2-1-1", "dr", 3.0, 0.7)), gap_s=1.0,
                     name="validation")
    return ident, valid


@pytest.fixture(scope="module")
def recordings(tmp_path_factory) -> dict[str, Path]:
    """Identification and validation recordings of the concealed aircraft, realistic noise, at
    50 Hz: the inputs' edges fall on samples, so ``--surfaces sample`` replays them exactly."""
    folder = tmp_path_factory.mktemp("calibrate")
    truth = _truth_aircraft(folder / "truth")
    out = {}
    for (role, inp), seed in zip(zip(("identification", "validation"), _inputs()), NOISE_SEEDS):
        rec = fly_maneuver(FlightSpec(input=inp, aircraft=truth, duration_s=max(12.0, inp.duration_s),
                                      sample_rate_hz=50.0, condition=CONDITION))
        out[role] = write_recording(apply_noise(rec, preset("realistic"), seed), folder / f"{role}.csv")
    return out


def test_known_answer_in_the_loop(recordings, tmp_path, capsys):
    """Must-show 1: Cnb × 0.7 and Cm_α̇ = −3 recovered within 2 standard errors; the validation
    RMS error of the affected channels falls by at least 50 %; the written files."""
    out = tmp_path / "cal"
    code = main(["calibrate", "--model", "f16", "--recording", str(recordings["identification"]),
                 "--validation", str(recordings["validation"]), "--parameters", ",".join(TRUTH), "--surfaces", "sample",
                 "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    doc = json.loads((out / "calibration.json").read_text())
    assert list(doc)[:8] == ["parameters", "outputs", "fit_before", "fit_after", "iterations", "converged",
                             "correlation", "correlation_names"]
    assert doc["converged"]
    for p in doc["parameters"]:
        assert set(p) == {"name", "start", "estimate", "std_error", "units"}
        assert abs(p["estimate"] - TRUTH[p["name"]]) <= 2 * p["std_error"], p
    before, after = doc["fit_before"]["validation"], doc["fit_after"]["validation"]
    for c in ("alpha", "q", "beta", "r"):  # Cm_α̇: the pitch response; Cnb: the Dutch roll
        assert after[c]["rms"] <= 0.5 * before[c]["rms"], (c, before[c], after[c])
        assert set(after[c]) == {"rms", "theil_u"}
    assert np.allclose(np.diag(doc["correlation"]), 1.0)
    assert doc["model"]["stock_check"]["flies"]
    assert (out / doc["model"]["xml"]).is_file()
    assert "<img" in (out / "report.html").read_text()


def test_calibrated_xml_flies_in_stock_jsbsim_with_an_actuator_delay(tmp_path):
    """A delay parameter becomes a JSBSim <actuator> delay: stock JSBSim, FCS on, sees the
    surface late by the delay (in whole frames) in what the aerodynamics read."""
    base = base_aircraft("f16")
    surfaces = base.aircraft.surfaces
    tree = with_actuator_delays(base.tree(), {"de": 0.1}, surfaces)
    write_root(tmp_path, "f16d", tree, Path(base.source))
    fdm = new_fdm(tmp_path, "f16d", 1 / 120)
    fdm["ic/h-sl-ft"], fdm["ic/vt-fps"] = 10_000.0, 420.0
    fdm.run_ic()
    seen, late = [], []
    for k in range(60):
        if k == 5:
            fdm["fcs/elevator-cmd-norm"] = 0.5
        fdm.run()
        seen.append(fdm[surfaces["de"]])
        late.append(fdm["sidbench/de-delayed-rad"])
    seen, late = np.array(seen), np.array(late)
    assert np.ptp(seen) > 0.05
    assert np.allclose(late[12:], seen[:-12], rtol=0, atol=1e-12)  # 0.1 s at 120 Hz: 12 frames


def test_scale_and_increment_change_the_function_as_defined(tmp_path):
    """f' = k·f; f' = f + Δ·q̄Sb for a yawing-moment term (models/calibration_xml.py)."""
    base = base_aircraft("f16")
    values = {}
    for tag, name, v in (("nominal", "aero/coefficient/Cnb:scale", 1.0), ("scaled", "aero/coefficient/Cnb:scale", 2.0),
                         ("incremented", "aero/coefficient/Cnb:increment", 0.01)):
        tree = adjusted_tree(base.tree(), (parse_adjustment(name),), (v,), refs={}, surfaces=base.aircraft.surfaces)
        write_root(tmp_path / tag, "f16x", tree, Path(base.source))
        fdm = new_fdm(tmp_path / tag, "f16x", 1 / 120)
        fdm["ic/h-sl-ft"], fdm["ic/vt-fps"], fdm["ic/beta-rad"], fdm["ic/alpha-rad"] = 10_000.0, 420.0, 0.05, 0.09
        fdm.run_ic()
        values[tag] = fdm["aero/coefficient/Cnb"]
        qsb = fdm["aero/qbar-psf"] * fdm["metrics/Sw-sqft"] * fdm["metrics/bw-ft"]
    assert values["scaled"] == pytest.approx(2 * values["nominal"], rel=1e-9)
    assert values["incremented"] - values["nominal"] == pytest.approx(0.01 * qsb, rel=1e-6)


def test_a_diverging_trial_halves_the_step_and_the_fit_goes_on():
    """Gauss-Newton on a toy 'simulator' that fails (returns its reason) beyond θ = 2.05:
    the first full step lands there, is halved, and the fit still reaches θ = 2."""
    t = np.linspace(0, 10, 400)
    rng = np.random.default_rng(5)
    z = [np.column_stack([2.0 * np.sin(t), 2.0 ** 2 * np.cos(t)]) + 0.01 * rng.standard_normal((400, 2))]

    def evaluate(points):
        return [["diverged at t = 3 s" if th[0] > 2.05 else np.column_stack([th[0] * np.sin(t), th[0] ** 2 * np.cos(t)])]
                for th in points]

    res = gauss_newton(evaluate, np.array([0.6]), np.array([1.0]), np.array([-np.inf]), z)
    assert res.converged
    assert res.theta[0] == pytest.approx(2.0, abs=3 * math.sqrt(res.cov[0, 0]))
    assert any("step halved" in n for n in res.notes)
    assert any("backward difference" in n for n in res.notes)


@pytest.mark.parametrize("params, needle", [
    ("aero/coefficient/Cnbb:scale", "no <function name='aero/coefficient/Cnbb'>"),
    ("Cm_alphadott", "did you mean Cm_alphadot"),
    ("aero/coefficient/Cnb:double", "'scale' or 'increment'"),
    ("Cm_alphadot=abc", "must be a number"),
    ("Cm_alphadot,Cm_alphadot", "given twice"),
    ("tau_dx", "tau_de, tau_da or tau_dr"),
])
def test_bad_parameters_are_refused_with_one_line(recordings, tmp_path, capsys, params, needle):
    code = main(["calibrate", "--model", "f16", "--recording", str(recordings["identification"]),
                 "--parameters", params, "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1, err


def test_a_recording_without_surfaces_is_refused(recordings, tmp_path):
    rec = read_recording(recordings["identification"])
    data = rec.data.drop(columns=[c for c in rec.data.columns if c.split("_")[0] in ("de", "da", "dr")])
    bare = type(rec)(data=data, meta=rec.meta, name="bare")
    with pytest.raises(CalibrationError, match="lacks the channels de|da|dr"):
        calibrate("f16", bare, "Cm_alphadot", workers=1)


def test_auto_takes_the_terms_the_diagnosis_added(recordings, tmp_path):
    """``--parameters auto=FINDINGS.json``: each aerodynamic or delay term of findings.json's
    model, started at its size; sensor terms are left to the diagnosis."""
    from harness.calibrate.auto import findings_parameters
    findings = {"model": {"terms": [
        {"effect": "unsteady_alphadot", "size": -2.5, "parameter": "Cm_alphadot"},
        {"effect": "control_delay", "size": 0.07, "surface": "de", "parameter": "tau_de"},
        {"effect": "sensor_bias", "size": 0.02, "channel": "alpha", "parameter": "bias_alpha"}]}}
    assert findings_parameters(findings) == ["Cm_alphadot=-2.5", "tau_de=0.07"]
    path = tmp_path / "findings.json"
    path.write_text(json.dumps({"model": {"terms": findings["model"]["terms"][2:]}}))
    with pytest.raises(CalibrationError, match="no aerodynamic or delay term"):
        calibrate("f16", recordings["identification"], f"auto={path}", workers=1)


def test_mass_and_reference_point_adjustments_reach_jsbsim(tmp_path):
    """iyy:scale multiplies the inertia JSBSim computes from the empty weight's (the fuel adds
    its own); cg_x and aero_rp_x move the c.g. and the aerodynamic reference point by inches."""
    base = base_aircraft("f16")
    read = {}
    for tag, values in (("nominal", (1.0, 0.0, 0.0)), ("changed", (2.0, 3.0, -4.0))):
        adj = tuple(parse_adjustment(n) for n in ("iyy:scale", "cg_x:increment", "aero_rp_x:increment"))
        tree = adjusted_tree(base.tree(), adj, values, refs={}, surfaces=base.aircraft.surfaces)
        write_root(tmp_path / tag, "f16m", tree, Path(base.source))
        fdm = new_fdm(tmp_path / tag, "f16m", 1 / 120)
        fdm["ic/h-sl-ft"], fdm["ic/vt-fps"] = 10_000.0, 420.0
        fdm.run_ic()
        read[tag] = {p: fdm[p] for p in ("inertia/iyy-slugs_ft2", "inertia/cg-x-in", "metrics/aero-rp-x-in",
                                          "inertia/empty-weight-lbs", "inertia/weight-lbs")}
    n, c = read["nominal"], read["changed"]
    assert c["metrics/aero-rp-x-in"] - n["metrics/aero-rp-x-in"] == pytest.approx(-4.0)
    share = n["inertia/empty-weight-lbs"] / n["inertia/weight-lbs"]
    assert c["inertia/cg-x-in"] - n["inertia/cg-x-in"] == pytest.approx(3.0 * share, rel=1e-6)
    assert c["inertia/iyy-slugs_ft2"] > 1.5 * n["inertia/iyy-slugs_ft2"]


def test_coloured_middle_matrix_equals_its_definition():
    """Σ_{o,o'} X_oᵀ T_oo' X_o' by FFT equals the double sum over samples with the residuals'
    all-lag auto- and cross-correlations ĉ_oo'(k) = (1/N) Σ_n v_o[n + k] v_o'[n]."""
    from harness.calibrate.engine import colored_middle
    rng = np.random.default_rng(2)
    n, p, no = 40, 3, 2
    S, v, R = rng.standard_normal((p, n, no)), rng.standard_normal((n, no)), np.array([0.5, 2.0])
    X = S / R
    want = np.zeros((p, p))
    for o in range(no):
        for o2 in range(no):
            c = {k: sum(v[m + k, o] * v[m, o2] for m in range(n) if 0 <= m + k < n) / n for k in range(-n + 1, n)}
            T = np.array([[c[i - j] for j in range(n)] for i in range(n)])
            want += X[:, :, o] @ T @ X[:, :, o2].T
    assert np.allclose(colored_middle([S], [v], R), want, rtol=1e-10, atol=1e-10)


SIDPAC = Path(__file__).resolve().parents[2] / "shared" / "data" / "sidpac"


@pytest.mark.skipif(not (SIDPAC / "totter_f1_017_data.mat").is_file(), reason="../shared flight data not present")
def test_twin_otter_directional_stability_cut_and_the_validation_flight_followed():
    """Must-show 4 in brief: the DHC6's C_n,β and C_l,β tables scaled on flight 017 (its mass),
    validated on 014: C_n,β comes down to about a fifth, and the β and r errors of the
    validation flight fall by more than half."""
    r = calibrate("dhc6", SIDPAC / "totter_f1_017_data.mat",
                  "aero/coefficient/Cnb:scale,aero/coefficient/Clb:scale",
                  validation=SIDPAC / "totter_f1_014_data.mat", mass="recording", workers=2, max_iterations=10)
    scale = dict(zip((a.name for a in r.adjustments), r.estimate))
    assert 0.15 < scale["aero/coefficient/Cnb:scale"] < 0.3
    for c in ("beta", "r"):
        assert r.fit_after["validation"][c]["rms"] < 0.5 * r.fit_before["validation"][c]["rms"]
