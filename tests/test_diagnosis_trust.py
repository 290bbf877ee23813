"""The diagnosis on recordings it did not make (issue 12): nothing invented on what the
maneuver did not excite, nothing too small to matter, what it assumed and could not check,
and a model of another aircraft refused."""
from __future__ import annotations

import json

import numpy as np
import pytest

from harness.diagnosis.run import diagnose
from harness.diagnosis.verdict import DiagnosisError
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
    meta = {k: v for k, v in rec.meta.items() if k not in ("truth", "simulation", "thrust_offset_ft")}
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
    assert "through the c.g." in by_item["thrust line"]["stood_in_by"]  # the F-16's is 0.3 ft above it
    assert "Eq. 40" in by_item["standard errors"]["stood_in_by"]
    # the F-16's leading-edge flap and flaperons stay where trim put them: it was flown with its FCS off
    assert by_item["other control surfaces"]["choice"] == "held"
    assert "held where the model's trim put them" in by_item["other control surfaces"]["stood_in_by"]
    assert _effects(result) == ["none"]  # a clean recording of the model, made elsewhere in the envelope
    written = json.loads((tmp_path / "out" / "findings.json").read_text())
    assert written["assumptions"] and written["not_checked"]


def test_a_tentative_sensor_correction_does_not_make_the_model_another_aircraft():
    """verdict.check_model_represents: the lift test is asked again along the channels as
    recorded where the analysis applied sensor corrections (a probe's 737 with an α bias of
    1.9° applied at kinematic t 3.2: lift −0.123 along the corrected α, −0.270 along the
    recorded, the recording's −0.271); refused only when both are off."""
    from types import SimpleNamespace

    from harness.diagnosis.verdict import check_model_represents
    n = 100
    trim = SimpleNamespace(S_ft2=1171.0, b_ft=94.7, cbar_ft=12.31)
    a = SimpleNamespace(prepared=SimpleNamespace(meta={"geometry": {"S_ft2": 1171.0, "b_ft": 94.7, "cbar_ft": 12.31}}),
                        aero=SimpleNamespace(trim=trim, trim_failed="", coefficients={"CZ": np.full(n, -0.123)}),
                        mismatch={"CZ": np.full(n, -0.148)}, applied={"bias_alpha": 0.0333})
    recorded = lambda cz: (lambda: SimpleNamespace(measured={"CZ": np.full(n, -0.271)},
                                                   aero=SimpleNamespace(coefficients={"CZ": np.full(n, cz)})))
    check_model_represents(a, "737", recorded(-0.270))
    with pytest.raises(DiagnosisError, match="averages -0.123 where the recording's is -0.271"):
        check_model_represents(a, "737", recorded(-0.12))
    with pytest.raises(DiagnosisError, match="does not represent"):
        check_model_represents(SimpleNamespace(**{**vars(a), "applied": {}}), "737", recorded(-0.270))


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


def test_a_state_that_drifts_without_its_input_is_evaluated_along_not_fitted():
    """prepare.drifted_states: a state whose group's surface never moved is not driven (no
    term is built on it), but when its excursion from its start (a slow spiral: almost all
    trend) stands 25 times above the noise the common filter passes, the model is evaluated
    along it rather than at its start; a Gauss-Markov wander of the vane's size, and the
    1e-5 rad wiggle of a noise-free record, are not."""
    import numpy as np

    from harness.diagnosis.prepare import DRIVEN_FLOOR, drifted_states, filtered_noise_std, maneuver_driven
    n, dt = 1500, 0.02
    t = np.arange(n) * dt
    rng = np.random.default_rng(5)
    w = np.ones(n - 2) * 0.1  # the filter passes sigma * 0.1 of white noise
    sigma = np.radians(0.1)
    gm = np.zeros(n)
    for k in range(1, n):  # first-order Gauss-Markov, 0.1 deg, tau 1 s
        gm[k] = np.exp(-dt) * gm[k - 1] + np.sqrt(1 - np.exp(-2 * dt)) * sigma * rng.standard_normal()
    smooth = {"da": np.radians(2.0) * (np.abs(t - 3.0) < 1.0), "de": np.zeros(n),
              "alpha": np.radians(1.4) * t / t[-1],          # a spiral's slow α drift: all trend
              "q": gm,                                        # wander of a vane's size
              "theta": 1e-5 * np.sin(2 * np.pi * 0.3 * t),    # noise-free wiggle, below the floor
              "p": np.radians(5.0) * np.sin(2 * np.pi * 0.5 * t)}
    noise = {"alpha": sigma, "q": sigma, "theta": 0.0, "p": sigma, "da": 1e-4, "de": 1e-4}
    driven = maneuver_driven(smooth, noise, w, excited=("da",))
    assert "alpha" not in driven and "da" in driven and "p" in driven
    # the drift about its own trend is nothing: only its excursion from the start shows it
    a = smooth["alpha"]
    assert np.std(a - np.linspace(a[0], a[-1], n)) < 1e-12
    assert np.sqrt(np.mean((a - a[0]) ** 2)) > 25 * filtered_noise_std(sigma, w)
    moved = drifted_states(smooth, noise, w, start_samples=25, driven=driven)
    assert moved == ("alpha",)
    assert np.std(smooth["theta"]) < DRIVEN_FLOOR["theta"]


def test_a_term_the_calibration_sizes_at_nothing_is_withdrawn():
    """augmented.unsupported_in_the_loop: a used calibration that sizes a named term within 3
    standard errors of no change withdraws it (status 'unsupported', the validation status
    kept beside it); a term it sizes clearly, or an unused calibration, withdraws nothing."""
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.augmented import CALIBRATED_MIN_Z, unsupported_in_the_loop

    def cand(parameter, estimate):
        return Candidate("cross_coupling", "roll", "Cl", parameter, estimate, 0.29, -5.7, 0.5, "per rad^2",
                         "stepwise on the Cl mismatch", selected=True, reason="entered")

    weak, strong = cand("Cl_alpha_beta", -1.66), cand("Cn_beta_abs", 0.2)
    sized = {"Cl_alpha_beta": {"size": -0.0165, "std_error": 0.015}, "Cn_beta_abs": {"size": 0.19, "std_error": 0.01}}
    checks = {id(weak): {"status": "confirmed", "axes": ["Cl"]}}
    assert unsupported_in_the_loop([weak, strong], {"used": False, "findings": sized}, checks) == []
    assert unsupported_in_the_loop([weak, strong], {"used": True, "findings": sized}, checks) == [weak]
    assert checks[id(weak)]["status"] == "unsupported" and checks[id(weak)]["validation_status"] == "confirmed"
    assert f"within {CALIBRATED_MIN_Z:g} standard errors" in checks[id(weak)]["reason"]
    assert id(strong) not in checks


def test_a_term_that_fails_its_entry_rules_at_the_calibrated_size_is_withdrawn():
    """augmented.unsupported_in_the_loop: the practical share and the suspect's imitation are
    asked again at the calibrated size. A C_m,δe change of −0.022 explaining 13 % of C_m's
    excursion, calibrated to −0.0064 (3.8 %), and a C_m,α̇ of 1.73 calibrated to 0.50, of which
    the Euler half-step imitates up to 0.39, are withdrawn; a change calibrated to 80 % of its
    equation-error size stands."""
    from harness.diagnosis.augmented import unsupported_in_the_loop
    from harness.diagnosis.evidence import Candidate
    small = Candidate("coefficient_error", "pitch", "Cm", "Cm_de", -0.608, 0.0009, -24.4, 0.6, "per rad",
                      "stepwise on the Cm mismatch", selected=True, reason="entered",
                      details={"change": -0.022, "excursion_share": 0.13})
    imitated = Candidate("unsteady_alphadot", "pitch", "Cm", "Cm_alphadot", 1.73, 0.024, 73.0, 0.99, "per rad",
                         "stepwise on the Cm mismatch", selected=True, reason="entered",
                         details={"excursion_share": 0.3, "sensor_suspect": {"parameter": "euler_lag",
                                                                             "imitates_at_most": 0.39,
                                                                             "change": 1.73}})
    kept = Candidate("coefficient_error", "pitch", "Cm", "Cm_qhat", -8.5, 0.04, -30.0, 0.5, "per rad",
                     "stepwise on the Cm mismatch", selected=True, reason="entered",
                     details={"change": -5.5, "excursion_share": 0.2})
    sized = {"Cm_de": {"size": -0.0064, "std_error": 0.0009}, "Cm_alphadot": {"size": 0.50, "std_error": 0.034},
             "Cm_qhat": {"size": -4.4, "std_error": 0.05}}
    checks: dict = {}
    assert unsupported_in_the_loop([small, imitated, kept], {"used": True, "findings": sized}, checks) == [
        small, imitated]
    assert "3.8 % of the coefficient's excursion" in checks[id(small)]["reason"]
    assert "euler_lag" in checks[id(imitated)]["reason"] and "fails a rule it entered by" in checks[id(imitated)][
        "reason"]


def test_a_term_the_calibration_puts_far_under_its_entry_is_withdrawn():
    """augmented.unsupported_in_the_loop: a C_Z,α change of +1.44 ± 0.26 by equation error (the
    vanes' noise on a 737 record) that the calibration sizes at +0.195 ± 0.02 — 4.8 of the
    equation error's standard errors under it, and at t 0.75 on them — is withdrawn; one the
    calibration puts at 1.2 (under the equation error's size by less than 3 of its standard
    errors) stands."""
    from harness.diagnosis.augmented import unsupported_in_the_loop
    from harness.diagnosis.evidence import Candidate

    def cand():
        return Candidate("coefficient_error", "lon", "CZ", "CZ_alpha", -2.93, 0.26, 5.5, 0.35, "per rad",
                         "stepwise on the CZ mismatch", selected=True, reason="entered",
                         details={"change": 1.44, "excursion_share": 0.4})
    far, near = cand(), cand()
    checks: dict = {}
    assert unsupported_in_the_loop([far], {"used": True, "findings": {"CZ_alpha": {"size": 0.195, "std_error": 0.02}}},
                                   checks) == [far]
    assert "would not have entered" in checks[id(far)]["reason"]
    assert unsupported_in_the_loop([near], {"used": True, "findings": {"CZ_alpha": {"size": 1.2, "std_error": 0.02}}},
                                   checks) == []


def test_a_term_the_calibration_sizes_with_the_other_sign_is_withdrawn():
    """augmented.unsupported_in_the_loop: a coefficient change the equation error puts at +0.96
    and the calibration, clearly away from zero, at −0.16 ± 0.02 (an α-vane scale read as a
    C_Z,α change) is not one the aircraft flies: withdrawn, the reason saying so; the same
    sign at another size stands."""
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.augmented import unsupported_in_the_loop

    def cand(change):
        return Candidate("coefficient_error", "lon", "CZ", "CZ_alpha", -9.9 + change, 0.09, 10.6, 0.6, "per rad",
                         "stepwise on the CZ mismatch", selected=True, reason="entered", details={"change": change})

    reversed_, agreeing = cand(0.96), cand(0.96)
    checks = {}
    assert unsupported_in_the_loop([reversed_], {"used": True, "findings": {"CZ_alpha": {
        "size": -0.163, "std_error": 0.023}}}, checks) == [reversed_]
    assert "of the opposite sign" in checks[id(reversed_)]["reason"]
    assert unsupported_in_the_loop([agreeing], {"used": True, "findings": {"CZ_alpha": {
        "size": 0.70, "std_error": 0.023}}}, checks) == []


def test_the_model_mass_assumption_names_how_far_the_recording_is():
    """verdict._mass_difference: the recording's mass and inertias against the model's, named
    when 2 % or more apart (the coefficients use the recording's, the replays the model's)."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis.verdict import _mass_difference
    trim = SimpleNamespace(mass_slug=600.0, Ix_slugft2=9000.0, Iy_slugft2=55000.0, Iz_slugft2=63000.0)
    same = {"mass_slug": np.full(3, 600.0), "Ix_slugft2": np.full(3, 9050.0), "Iy_slugft2": 55000.0}
    assert _mass_difference(same, trim) == ""
    lighter = {"mass_slug": np.full(3, 510.0), "Iy_slugft2": np.full(3, 60500.0)}
    assert _mass_difference(lighter, trim) == ", the recording's mass 15 % below it, Iy 10 % above it"


def test_gusts_too_light_to_name_void_the_sensor_tests_on_a_slow_aircraft():
    """gust_rules.light_gusts: the same 1.9 ft/s gust is 0.6 deg at 180 ft/s (six times a
    0.1 deg vane's noise: the sensor tests are off, and the reason says why) and 0.15 deg at
    700 ft/s (1.5 times: they stand); a kinematic residual at the noise's level, or a
    noise-free recording's 0.04 ft/s, is no gust."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis.gust_rules import GUST_ANGLE_FACTOR, GUST_RATIO, light_gusts
    vane = np.radians(0.1)
    p = SimpleNamespace(noise_std={"alpha": vane, "beta": vane})
    gust = SimpleNamespace(sigma_w_fps=1.9, sigma_v_fps=1.2, ratio_to_noise=12.9)
    why = light_gusts(gust, p, 180.0)
    assert why.startswith("gusts of about 1.9 ft/s (0.60 deg") and "6.0 times the vanes' noise" in why
    assert light_gusts(gust, p, 700.0) == ""
    assert GUST_ANGLE_FACTOR * vane * 180.0 < 1.9 < GUST_ANGLE_FACTOR * vane * 700.0
    quiet = SimpleNamespace(sigma_w_fps=1.9, sigma_v_fps=1.2, ratio_to_noise=GUST_RATIO - 0.1)
    assert light_gusts(quiet, p, 180.0) == ""
    clean = SimpleNamespace(noise_std={"alpha": 0.0, "beta": 0.0})
    assert light_gusts(SimpleNamespace(sigma_w_fps=0.04, sigma_v_fps=0.0, ratio_to_noise=15.0), clean, 420.0) == ""


def test_an_alpha_beta_term_needs_alpha_and_beta_to_move_together():
    """candidates.joint_excitation: α then β, one after the other (a sequential three-axis
    maneuver), leaves their product nothing beyond what α and β carry themselves, and the
    α·β terms are not offered, with the reason; α and β moving at once (at two frequencies)
    offers them."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis.candidates import JOINT_SNR, Term, joint_excitation, offered
    n, dt = 1500, 0.02
    t = np.arange(n) * dt
    deg = np.pi / 180

    def recording(alpha, beta):
        smooth = {"alpha": 0.05 + alpha, "beta": beta, "p": np.zeros(n), "q": np.zeros(n), "r": np.zeros(n),
                  "V": np.full(n, 420.0), "de": np.zeros(n), "da": np.zeros(n), "dr": np.zeros(n)}
        return SimpleNamespace(smooth=smooth, start={k: float(v[0]) for k, v in smooth.items()}, dt=dt, n=n,
                               meta={"geometry": {"S_ft2": 300.0, "b_ft": 30.0, "cbar_ft": 11.32}},
                               noise_std={"alpha": 0.1 * deg, "beta": 0.1 * deg}, weights=np.full(n - 2, 0.3),
                               driven=("alpha", "beta", "de", "da"))
    pulse = lambda t0: 2 * deg * ((t >= t0) & (t < t0 + 2)) * np.sin(np.pi * (t - t0) / 2)  # noqa: E731
    apart = recording(pulse(3.0), pulse(12.0))
    together = recording(2 * deg * np.sin(2 * np.pi * 0.3 * t), 2 * deg * np.sin(2 * np.pi * 0.5 * t))
    assert joint_excitation(apart) < 1.0 < JOINT_SNR < joint_excitation(together)
    term = Term("alpha_beta", "cross_coupling", "Cl_alpha_beta", "per rad^2", np.zeros(n), sources=("alpha", "beta"))
    keep, skipped = offered(apart, [term])
    assert keep == [] and skipped[0].details["not_offered"].startswith("α and β never moved together")
    assert offered(together, [term])[0] == [term]


def test_vanes_at_the_positions_the_metadata_give_are_carried_to_the_cg():
    """prepare.vanes_at_cg: a vane r = (x, y, z) ft from the c.g. reads α + (p·y − q·x)/V and
    β + (r·x − p·z)/V; the metadata's positions undo it exactly (to first order, as the
    reading was made), move to meta['vanes_at_cg'], and a second call changes nothing; a
    recording without vane positions is returned as it is."""
    import numpy as np
    import pandas as pd

    from harness.diagnosis.prepare import vanes_at_cg
    from maneuvers.recording import Recording
    n = 50
    t = np.arange(n) * 0.02
    alpha, beta = 0.05 + 0.01 * np.sin(t), 0.002 * np.cos(t)
    p, q, r, V = 0.1 * np.sin(3 * t), 0.05 * np.cos(2 * t), 0.02 * np.sin(t), np.full(n, 400.0)
    xa, ya, xb, zb = 15.0, 1.0, 14.0, -2.0
    data = pd.DataFrame({"t_s": t, "V_fps": V, "alpha_rad": alpha + (p * ya - q * xa) / V,
                         "beta_rad": beta + (r * xb - p * zb) / V, "p_rps": p, "q_rps": q, "r_rps": r})
    meta = {"sensors": {"accelerometer_ft": [0.0, 0.0, 0.0], "alpha_vane_ft": [xa, ya, 0.0],
                        "beta_vane_ft": [xb, 0.0, zb]}}
    rec = vanes_at_cg(Recording(data=data, meta=meta, name="r"))
    assert np.allclose(rec.data["alpha_rad"], alpha, atol=1e-15) and np.allclose(rec.data["beta_rad"], beta, atol=1e-15)
    assert rec.meta["vanes_at_cg"] == {"alpha_vane_ft": [xa, ya, 0.0], "beta_vane_ft": [xb, 0.0, zb]}
    assert rec.meta["sensors"]["alpha_vane_ft"] == [0.0, 0.0, 0.0]
    again = vanes_at_cg(rec)
    assert again is rec
    plain = Recording(data=data, meta={"sensors": {"accelerometer_ft": [0.0, 0.0, 0.0]}}, name="r")
    assert vanes_at_cg(plain) is plain


def test_the_kinematics_refute_a_vane_scale_they_do_not_see():
    """sensor_rules.kinematics_refute: a C_Z,α error looks like an α-vane scale to the coefficient
    mismatch alone; the kinematics' own estimate of that scale, 4.5 combined standard errors
    away (the project sweep's C_Z,α case), refutes it; 2.5 apart (a true 0.08 scale at 700
    ft/s) does not; nor does a scale the kinematics never tried."""
    from types import SimpleNamespace

    from harness.diagnosis.sensor_rules import VANE_REFUTE_Z, kinematics_refute

    def kin(v, se):
        term = SimpleNamespace(name="scale_alpha", estimate=v, t=v / se)
        return SimpleNamespace(selection=SimpleNamespace(params={}, terms=[term]))
    assert VANE_REFUTE_Z == 3.5
    why = kinematics_refute(kin(0.0033, 0.011), "scale_alpha", -0.069, 0.0115)
    assert "kinematics put that scale at 0.003" in why
    assert kinematics_refute(kin(0.066, 0.032), "scale_alpha", 0.166, 0.024) == ""
    assert kinematics_refute(SimpleNamespace(selection=SimpleNamespace(params={}, terms=[])), "scale_alpha",
                             -0.069, 0.0115) == ""


def test_a_sensor_error_each_maneuver_only_suspects_is_named_on_the_two(monkeypatch):
    """replication.name_replicated: the same instrument flew both maneuvers, so an a_z bias the
    identification's kinematics put at 0.027 ± 0.0058 (t 4.7) and the validation's at
    0.027 ± 0.0042 (t 6.3 there, but below the entry t on the identification) is named at
    their inverse-variance combination; opposite signs, sizes more than two standard errors
    apart, a combined t under the entry t, or one maneuver below the suspicion level name
    nothing; nor a scale or an air-data bias (columns that follow the motion), nor anything
    when another sensor error is named."""
    from types import SimpleNamespace

    from harness.diagnosis import replication
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.replication import name_replicated
    monkeypatch.setattr(replication, "_kinematics_trusted", lambda a: True)
    monkeypatch.setattr(replication, "kinematic_rival", lambda kin, name, gate=None: None)
    monkeypatch.setattr(replication, "sensor_verdict", lambda *args: (True, ""))

    def analysis(v, se):
        c = Candidate("sensor_bias", None, "az", "bias_az", v, se, v / se, 0.0, "g", "kinematic consistency",
                      reason="below the entry t")
        return SimpleNamespace(candidates=[c], prepared=None, kinematic=None)

    def with_named_sensor(a):  # a scale named on the identification: its kinematic fit may lack it
        a.candidates.append(Candidate("sensor_scale", None, "beta", "scale_beta", 0.15, 0.013, 11.3, 0.0, "",
                                      "kinematic consistency", selected=True))
        return a

    a, av = analysis(0.027, 0.0058), analysis(0.0266, 0.0042)
    named = name_replicated(a, av)
    assert [c.parameter for c in named] == ["bias_az"] and a.candidates[0].selected
    w1, w2 = 0.0058 ** -2, 0.0042 ** -2
    assert a.candidates[0].estimate == pytest.approx((w1 * 0.027 + w2 * 0.0266) / (w1 + w2))
    assert a.candidates[0].std_error == pytest.approx((w1 + w2) ** -0.5)
    assert a.candidates[0].details["replication"]["validation"] == [0.0266, 0.0042]
    assert name_replicated(with_named_sensor(analysis(0.027, 0.0058)), analysis(0.0266, 0.0042)) == []
    scale = analysis(0.027, 0.0058)
    scale.candidates[0].effect = "sensor_scale"  # a column that follows the motion: not replicated
    assert name_replicated(scale, analysis(0.0266, 0.0042)) == []
    airspeed, airspeed_v = analysis(-12.9, 3.7), analysis(-12.7, 2.4)
    for x in (airspeed, airspeed_v):  # an air-data bias enters the kinematics times the motion
        x.candidates[0].parameter, x.candidates[0].channel = "bias_V", "V"
    assert name_replicated(airspeed, airspeed_v) == []
    for v, se in [(-0.0266, 0.0042),   # opposite sign
                  (0.06, 0.0042),      # (0.060 - 0.027) / hypot(.0058, .0042) = 4.6 > 2 standard errors apart
                  (0.0126, 0.0042),    # t 3: combined 0.018 ± 0.0034, t 5.3 < 6
                  (0.0266, 0.0133)]:   # t 2 on the validation: below the suspicion level
        a = analysis(0.027, 0.0058)
        assert name_replicated(a, analysis(v, se)) == [] and not a.candidates[0].selected


def test_a_sensor_suspicion_the_validation_maneuver_does_not_share_is_lifted(monkeypatch):
    """replication.lift_unreplicated_suspicions: a C_n,β term withheld because the
    identification's kinematics suspected an r-gyro scale of 0.088 ± 0.028 (t 3.2) is named
    again when the validation maneuver's kinematics put that scale at −0.055 ± 0.022 (4.0
    combined standard errors apart; a suspicion of the other sign there). A validation
    estimate of the same sign that is a suspicion itself, one within two standard errors, one
    the validation maneuver cannot measure, a term withheld for another reason, a scale the
    coefficient mismatch itself reads (details['shape']), or a suspicion at the kinematic
    entry t or above lift nothing."""
    from types import SimpleNamespace

    from harness.diagnosis import replication
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.replication import lift_unreplicated_suspicions
    monkeypatch.setattr(replication, "_kinematics_trusted", lambda a: True)

    def kin(v, t):
        return SimpleNamespace(selection=SimpleNamespace(params={}, terms=[
            SimpleNamespace(name="scale_r", estimate=v, t=t, std_error=abs(v) / t)]))

    def identification(details=None, shape=False):
        term = Candidate("coefficient_error", "yaw", "Cn", "Cn_beta", 0.257, 0.003, 11.7, 0.3, "per rad",
                         "stepwise on the Cn mismatch", False, "entered, but not named: ...",
                         details if details is not None else {"sensor_rival": "scale_r",
                                                              "suspicion": {"parameter": "scale_r", "t": 3.16}})
        scale = Candidate("sensor_scale", None, "r", "scale_r", 0.088, 0.028, 3.16, 0.0, "1",
                          "kinematic consistency", False, "below the entry t",
                          {"shape": {"k": 0.09, "k_std": 0.02}} if shape else {})
        return SimpleNamespace(candidates=[term, scale], kinematic=kin(0.088, 3.16))

    a = identification()
    assert lift_unreplicated_suspicions(a, SimpleNamespace(kinematic=kin(-0.0548, 2.52))) == [a.candidates[0]]
    assert a.candidates[0].selected and "suspicion is lifted" in a.candidates[0].reason
    assert a.candidates[0].details["suspicion_lifted"]["validation"][0] == pytest.approx(-0.0548)
    for there in (kin(0.05, 2.6),    # the same sign, a suspicion there too
                  kin(0.04, 1.8),    # (0.088 - 0.04) / hypot(0.028, 0.022) = 1.4: within two
                  kin(0.01, 0.05)):  # the validation cannot measure it (0.2 standard error)
        a = identification()
        assert lift_unreplicated_suspicions(a, SimpleNamespace(kinematic=there)) == [] and not a.candidates[0].selected
    for a in (identification(details={"sensor_rival": "scale_r"}), identification(shape=True)):
        assert lift_unreplicated_suspicions(a, SimpleNamespace(kinematic=kin(-0.0548, 2.52))) == []
    strong = identification()          # at the kinematic entry t or above: no suspicion a null makes
    strong.kinematic = kin(0.088, 6.5)
    assert lift_unreplicated_suspicions(strong, SimpleNamespace(kinematic=kin(-0.0548, 2.52))) == []


def test_a_suspicion_made_at_a_size_of_its_own_is_compared_at_that_size(monkeypatch):
    """replication._suspected_at: a suspicion that withheld a term at the size of a contested
    suspect's rival (``suspicion['at']``, term_rules.withhold_ambiguous) is compared with the
    validation's estimate at that size. A T-6 with a_z 40 ms late: the skew sized in its
    suspect's place at 40 ± 5 ms withheld C_Z,α̇ +32; the kinematic fit's −17 ± 20 ms beside
    the suspect lay 3.3 standard errors from the validation's 54 ± 9 ms and lifted it. At the
    suspicion's own size the validation agrees (a suspicion of the same sign): not lifted."""
    from types import SimpleNamespace

    from harness.diagnosis import replication
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.replication import _suspected_at, lift_unreplicated_suspicions
    monkeypatch.setattr(replication, "_kinematics_trusted", lambda a: True)

    def kin(v, se):
        return SimpleNamespace(selection=SimpleNamespace(params={}, terms=[
            SimpleNamespace(name="skew_az", estimate=v, t=v / se, std_error=se)]))

    def identification(at):
        suspicion = {"parameter": "skew_az", "t": 7.5} | ({"at": [0.0405, 0.0054]} if at else {})
        term = Candidate("unsteady_alphadot", "lon", "CZ", "CZ_alphadot", 32.2, 2.1, 15.5, 0.6, "per rad",
                         "stepwise on the CZ mismatch", False, "entered, but not named: ...",
                         {"sensor_rival": "skew_az", "suspicion": suspicion})
        return SimpleNamespace(candidates=[term], kinematic=kin(-0.0167, 0.0195))

    validation = SimpleNamespace(kinematic=kin(0.054, 0.0092))
    assert _suspected_at(identification(True), identification(True).candidates[0].details["suspicion"])[0] == 0.0405
    assert lift_unreplicated_suspicions(identification(False), validation) != []   # the fit's size: lifted
    a = identification(True)
    assert lift_unreplicated_suspicions(a, validation) == [] and not a.candidates[0].selected


def test_an_accelerometer_offset_is_explained_along_its_own_axis():
    """verdict._offset_direction: a lateral offset is 'right of' or 'left of' the c.g. (y), a
    vertical one 'below' or 'above' (z, body axes down), the force fit's x 'ahead of'."""
    from harness.diagnosis.verdict import _offset_direction
    assert _offset_direction("offset_y", 3.9) == ("y", "right of")
    assert _offset_direction("offset_y", -3.9) == ("y", "left of")
    assert _offset_direction("offset_z", 2.0) == ("z", "below")
    assert _offset_direction("x_accelerometer", -5.0) == ("x", "behind")


def test_the_accelerometer_columns_use_only_the_rates_the_maneuver_drove():
    """candidates.accelerometer_columns: on a pitch maneuver (q driven, p and r not) x enters
    C_Z as −q̇·x·m/(q̄S) with the undriven rates at their means, not their records (their
    noise's derivative would pull x toward zero), and y, none of whose rates (ṗ, ṙ) moved,
    is not fitted: its columns are zero."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis.candidates import accelerometer_columns
    n, dt = 500, 0.02
    t = np.arange(n) * dt
    rng = np.random.default_rng(3)
    q, qd = 0.1 * np.sin(2 * np.pi * t), 0.2 * np.pi * np.cos(2 * np.pi * t)
    noisy = {g: 0.002 * rng.normal(size=n) for g in "pr"}
    p = SimpleNamespace(n=n, driven=("de", "q", "alpha"), mass={"mass_slug": np.full(n, 2.0)},
                        meta={"geometry": {"S_ft2": 10.0}},
                        smooth={"p": noisy["p"], "q": q, "r": noisy["r"], "qbar": np.full(n, 100.0)},
                        deriv={"p": np.gradient(noisy["p"], dt), "q": qd, "r": np.gradient(noisy["r"], dt)})
    cols = accelerometer_columns(p)
    scale = 2.0 / (100.0 * 10.0)
    pm, rm = np.mean(noisy["p"]), np.mean(noisy["r"])
    np.testing.assert_allclose(cols["x"]["CZ"], (-qd + pm * rm) * scale, atol=1e-12)  # −q̇x + p·r·x
    np.testing.assert_allclose(cols["x"]["CY"], (pm * q) * scale, atol=1e-12)  # ṙ at zero: p·q·x only
    assert not any(np.any(cols["y"][c]) for c in ("CX", "CY", "CZ"))
    assert np.ptp(cols["z"]["CX"]) > 0  # q̇·z


def test_an_accelerometer_at_the_position_the_metadata_give_is_carried_to_the_cg():
    """prepare.accelerometer_to_cg: an accelerometer r = (x, y, z) ft from the c.g. reads
    a + [ω̇ × r + ω × (ω × r)]/g₀; with the position in the metadata the c.g. readings come
    back, the angular accelerations from the Savitzky-Golay derivative of the rates (to the
    window's cubic fit: sines of 0.5-1.5 Hz at 50 Hz), or the recorded pdot/qdot/rdot
    exactly; the position moves to meta['accelerometer_at_cg'] and a second call does nothing."""
    import numpy as np
    import pandas as pd

    from harness.diagnosis.prepare import accelerometer_to_cg
    from maneuvers.recording import Recording
    from models.constants import G0_FPS2
    n, dt = 1000, 0.02
    t = np.arange(n) * dt
    w = [2 * np.pi * f for f in (1.5, 1.0, 0.5)]
    p, q, r = 0.2 * np.sin(w[0] * t), 0.1 * np.cos(w[1] * t), 0.05 * np.sin(w[2] * t)
    pd_, qd, rd = 0.2 * w[0] * np.cos(w[0] * t), -0.1 * w[1] * np.sin(w[1] * t), 0.05 * w[2] * np.cos(w[2] * t)
    pos = np.array([10.0, 2.0, 3.0])
    om, omd = np.stack([p, q, r], axis=1), np.stack([pd_, qd, rd], axis=1)
    extra = (np.cross(omd, pos) + np.cross(om, np.cross(om, pos))) / G0_FPS2
    cg = {"ax_g": 0.02 * np.sin(t), "ay_g": 0.01 * np.cos(t), "az_g": -1.0 + 0.1 * np.sin(2 * t)}
    data = pd.DataFrame({"t_s": t, "p_rps": p, "q_rps": q, "r_rps": r,
                         **{c: cg[c] + extra[:, i] for i, c in enumerate(("ax_g", "ay_g", "az_g"))}})
    meta = {"sensors": {"accelerometer_ft": list(pos)}}
    rec = accelerometer_to_cg(Recording(data=data, meta=meta, name="r"))
    inner = slice(10, n - 10)  # the filter's ends
    for c in cg:  # the cubic fit's gain at 1.5 Hz is 0.999: under 1e-3 g here
        assert np.max(np.abs(rec.data[c].to_numpy()[inner] - cg[c][inner])) < 1e-3
    assert rec.meta["accelerometer_at_cg"] == list(pos) and rec.meta["sensors"]["accelerometer_ft"] == [0.0] * 3
    assert accelerometer_to_cg(rec) is rec
    measured = data.assign(pdot_rps2=pd_, qdot_rps2=qd, rdot_rps2=rd)
    exact = accelerometer_to_cg(Recording(data=measured, meta=meta, name="r"))
    for c in cg:
        assert np.allclose(exact.data[c], cg[c], atol=1e-12)


def test_surfaces_not_recorded_are_named_with_what_stood_in_for_them():
    """prepare._stand_ins: recording-format.md requires only the surfaces that moved; those
    left out are held at the model's trim deflection, and the assumptions say so."""
    import numpy as np

    from harness.diagnosis.prepare import _stand_ins
    raw = {c: np.zeros(3) for c in ("de", "thrust")}
    found = {a["item"]: a for a in _stand_ins(raw, {"sensors": {"accelerometer_ft": [0, 0, 0]}}, ())}
    assert found["surfaces not recorded"]["missing"] == "da, dr"
    assert "trim deflection" in found["surfaces not recorded"]["stood_in_by"]
    everything = {c: np.zeros(3) for c in ("de", "da", "dr", "thrust")}
    assert "surfaces not recorded" not in {a["item"] for a in _stand_ins(everything, {}, ())}


def test_the_angular_accelerations_the_moments_use_are_stated():
    """prepare._stand_ins: the moment coefficients always take the derivative of the
    common-filtered rates; recorded pdot/qdot/rdot are said to be unused for them (all three
    only carry a declared accelerometer position to the c.g.), and without them the
    derivative is named as the stand-in."""
    import numpy as np

    from harness.diagnosis.prepare import _stand_ins
    raw = {c: np.zeros(3) for c in ("de", "da", "dr", "thrust")}
    item = {a["item"]: a for a in _stand_ins(raw, {}, ())}["angular accelerations"]
    assert item["missing"] == "pdot, qdot, rdot channels" and "common-filtered rates" in item["stood_in_by"]
    item = {a["item"]: a for a in _stand_ins(raw, {}, ("pdot_rps2", "qdot_rps2", "rdot_rps2"))}["angular accelerations"]
    assert item["missing"] == "-" and "pdot, qdot, rdot are not used" in item["stood_in_by"]
    assert "accelerometer position" in item["stood_in_by"]
    item = {a["item"]: a for a in _stand_ins(raw, {}, ("qdot_rps2",))}["angular accelerations"]
    assert "qdot are not used" in item["stood_in_by"] and "accelerometer" not in item["stood_in_by"]


def test_a_beta_vane_bias_is_named_from_the_lateral_coefficient_means(tmp_path):
    """sensor_naming.name_vane_bias_from_means on the project sweep's β-vane bias of 1° (1.05° in
    the recording with the noise layer's own 0.05°): the kinematics hardly see it (t 1.5),
    the lateral means along the vane do, on C_Y, C_l and C_n alike; the validation maneuver
    (pitch only, β never driven) shows the same bias on its own means, and the augmented
    model's β fits it. Sizes within two standard errors or 2 % of the recording's bias."""
    import math

    from harness.diagnosis.sweep import cases, recorded_bias, run_case
    c = next(c for c in cases() if c.name == "bias_beta_1deg")
    row = run_case(c, tmp_path)
    assert row["a"] and row["b"] and row["d"], row
    result = json.loads((tmp_path / "diagnoses" / c.name / "findings.json").read_text())
    f = result["findings"][0]
    assert f["evidence"]["test"] == "lateral coefficient means along the β vane"
    assert set(f["evidence"]["vane_means"]["axes"]) == {"CY", "Cl", "Cn"}
    assert abs(f["estimate"] - recorded_bias(c)) <= max(2 * f["std_error"], 0.02 * recorded_bias(c))
    assert f["evidence"]["validation"]["status"] == "confirmed"
    assert f["explanation"].startswith("The beta vane reads 0.0184") and "kinematics" not in f["explanation"]
    assert math.degrees(recorded_bias(c)) == pytest.approx(1.05)


def test_a_sensor_finding_the_validation_contradicts_says_what_the_same_test_gave_there():
    """verdict.finding_dict: a sensor test's check carries no mismatch 'change' (a KeyError, an
    internal error, before); the text gives the estimate the same test made on the
    validation maneuver."""
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.verdict import finding_dict
    f = Candidate("sensor_bias", None, "beta", "bias_beta", 0.0184, 6e-5, 300.0, 0.0, "rad",
                  "lateral coefficient means along the β vane", selected=True)
    check = {"status": "contradicted", "axes": ["CY", "Cl", "Cn"], "estimate": -0.00698, "std_error": 4.3e-05,
             "t": -162.9}
    text = finding_dict(f, {}, {}, check)["explanation"]
    assert "the same test there gives -0.00698 ± 4.3e-05 rad, t = -162.9" in text


def test_a_vane_offset_is_explained_as_the_vane_not_the_accelerometer():
    """verdict.finding_dict: a vane_alpha_x finding was worded as an accelerometer away from
    the c.g.; it names the vane, the side and the rotation's term."""
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.verdict import finding_dict
    ahead = Candidate("sensor_offset", None, "alpha", "vane_alpha_x", 13.09, 1.26, 10.4, 0.1, "ft",
                      "kinematic consistency", selected=True)
    text = finding_dict(ahead, {}, {})["explanation"]
    assert text.startswith("The alpha vane is not at the c.g.") and "13.09 ± 1.26 ft ahead of it (x)" in text
    assert "−x·q/V" in text and "accelerometer" not in text
    behind = Candidate("sensor_offset", None, "beta", "vane_beta_x", -4.0, 0.5, -8.0, 0.1, "ft",
                       "kinematic consistency", selected=True)
    assert "4.00 ± 0.50 ft behind it (x)" in finding_dict(behind, {}, {})["explanation"]


def test_a_sensor_suspicion_withholds_only_what_it_could_imitate():
    """term_rules.withhold_ambiguous: a q-scale the kinematics suspect (t 2.6) withholds a
    C_m,q̂ change only when, at a size they allow, it would imitate at least half of it
    (``imitated``, term_rules.imitation); a change far beyond that is kept, with the suspect
    and its reach in ``details['sensor_suspect']``; where the imitation cannot be computed
    the term stays withheld."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate

    from harness.diagnosis.term_rules import IMITATION_SHARE, withhold_ambiguous
    kin = SimpleNamespace(parameters={"scale_q": SimpleNamespace(channel="q")},
                          selection=SimpleNamespace(params={}, terms=[SimpleNamespace(name="scale_q", estimate=-0.023,
                                                                                      t=-2.6)]))

    def term():
        return Candidate("coefficient_error", "pitch", "Cm", "Cm_qhat", -6.85, 0.19, -30.5, 0.8, "per rad",
                         "stepwise on the Cm mismatch", selected=True, reason="entered", details={"change": -5.9})

    kept, withheld, unknown = term(), term(), term()
    withhold_ambiguous([kept], kin, lambda c, name: 0.05)
    withhold_ambiguous([withheld], kin, lambda c, name: IMITATION_SHARE * 5.9)
    withhold_ambiguous([unknown], kin, lambda c, name: None)
    assert kept.selected and kept.details["sensor_suspect"] == {"parameter": "scale_q", "imitates_at_most": 0.05,
                                                                "change": 5.9}
    assert kept.reason == "entered; the kinematics suspect scale_q (t = 2.6), which would imitate at most 0.05 of " \
        "this change of 5.9"
    assert not withheld.selected and "scale_q, kinematic t = 2.6" in withheld.reason
    assert not unknown.selected and unknown.details["sensor_rival"] == "scale_q"


def test_a_suspects_contested_rival_is_asked_too():
    """term_rules.withhold_ambiguous: an α vane ahead of the c.g. that the kinematics cannot tell
    from an α lag (``contested``) brings the lag in as a suspect at its own estimate: a C_Z,α
    change the vane offset hardly imitates is withheld when the lag would imitate half of it,
    and kept (with both suspects in its reason) when neither would."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.sensor_rules import Contest
    from harness.diagnosis.term_rules import IMITATION_SHARE, withhold_ambiguous
    kin = SimpleNamespace(parameters={"vane_alpha_x": SimpleNamespace(channel="alpha"),
                                      "skew_alpha": SimpleNamespace(channel="alpha")},
                          selection=SimpleNamespace(params={}, terms=[
                              SimpleNamespace(name="vane_alpha_x", estimate=16.0, t=10.0),
                              SimpleNamespace(name="skew_alpha", estimate=0.04, t=2.0)]))
    contested = {"vane_alpha_x": Contest("skew_alpha", 0.91, 1.0, (0.088, 9.1))}
    asked = []

    def imitated(share_of_skew):
        def imitate(c, name, at=None):
            asked.append((name, at))
            return 0.05 if name == "vane_alpha_x" else share_of_skew * 0.69
        return imitate

    def term():
        return Candidate("coefficient_error", "lon", "CZ", "CZ_alpha", -4.99, 0.11, 6.4, 0.3, "per rad",
                         "stepwise on the CZ mismatch", selected=True, reason="entered", details={"change": 0.69})

    withheld, kept, alone = term(), term(), term()
    withhold_ambiguous([withheld], kin, imitated(IMITATION_SHARE), contested=contested)
    assert not withheld.selected and withheld.details["sensor_rival"] == "skew_alpha"
    assert ("skew_alpha", (0.088, 0.088 / 9.1)) in asked
    withhold_ambiguous([kept], kin, imitated(0.01), contested=contested)
    assert kept.selected and "vane_alpha_x (t = 10.0)" in kept.reason and "skew_alpha (t = 9.1)" in kept.reason
    assert kept.details["sensor_suspect"]["parameter"] == "vane_alpha_x"  # the one that reaches furthest (0.05)
    withhold_ambiguous([alone], kin, imitated(IMITATION_SHARE))  # without the contest only the vane is asked
    assert alone.selected and "skew_alpha" not in alone.reason


def test_the_vane_noise_column_enters_cm_only_where_it_is_a_material_part_of_the_mismatch(monkeypatch):
    """stepwise_axes.vane_noise_columns: the column −C_m,α·e (e = −w_gust/V from the kinematic
    residual) is offered to C_m's fit when, fitted alone, it takes at least VANE_NOISE_SHARE
    off the mismatch RMS (a mismatch that is mostly the vane's error passed through C_m,α),
    not when the mismatch is something else, nor when α is held at its start; C_X's column,
    −∂C_X/∂α·e, always while α is followed."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis import stepwise_axes
    rng = np.random.default_rng(7)
    n, V0 = 1500, 180.0
    w = rng.standard_normal(n)                        # the "gust": V times the vane-minus-inertial angle
    monkeypatch.setattr(stepwise_axes, "turbulence_test", lambda p: (SimpleNamespace(w_fps=w), False))
    p = SimpleNamespace(dt=0.02, n=n)
    along = SimpleNamespace(states={"alpha": np.linspace(0.0, 0.02, n)})
    slope = np.full(n, -1.2)
    cx_slope = 0.3 + 14.5 * np.linspace(-0.02, 0.02, n)  # a drag polar's: C_X,α + C_X''·Δα
    slopes = lambda x: {"Cm": slope, "CX": cx_slope}
    column = slope * w / V0                            # −C_m,α·e with e = −w/V
    vane_made = {"Cm": 0.9 * column + 0.3 * np.std(column) * rng.standard_normal(n)}
    other = {"Cm": np.std(column) * rng.standard_normal(n)}
    got = stepwise_axes.vane_noise_columns(p, along, slopes, V0, vane_made)
    assert set(got) == {"Cm", "CX"} and np.allclose(got["Cm"], column) and np.allclose(got["CX"], cx_slope * w / V0)
    assert set(stepwise_axes.vane_noise_columns(p, along, slopes, V0, other)) == {"CX"}
    held = SimpleNamespace(states={"alpha": np.zeros(n)})
    assert stepwise_axes.vane_noise_columns(p, held, slopes, V0, vane_made) == {}


def test_a_moment_reference_shift_is_refuted_by_a_mistrim_the_recording_lacks():
    """stepwise_axes._cg_mean_test: a shift Δx moves C_m by Δx·C_Z/c̄, its mean too. The shift a
    lateral C_n fit suggests (C_n ∝ C_Y looks like C_n,β) is refuted when C_m's constant
    falls short of Δx·mean(C_Z)/c̄ by more than CG_MEAN_SHARE of it and CG_MEAN_Z standard
    errors; the shift's own mistrim, or a larger one of the same sign, supports it. A short
    constant that is itself a shift of the same sign is that shift, pinned (c̄·constant/mean C_Z),
    when C_m's own stepwise entered the shift; one read off C_n is refuted only."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis.stepwise_axes import CG_MEAN_SHARE, _cg_mean_test
    rng = np.random.default_rng(3)
    n, cbar, b, dx = 1500, 11.32, 30.0, 0.6
    CZ = -0.5 + 0.01 * np.sin(np.linspace(0.0, 20.0, n))
    CY = 0.02 * np.sin(np.linspace(0.0, 13.0, n))
    p = SimpleNamespace(dt=0.02, n=n, meta={"geometry": {"cbar_ft": cbar, "b_ft": b}})
    inner = slice(50, n - 50)
    predicted = dx * float(np.mean(CZ[inner])) / cbar          # about −0.027
    cm_sel = SimpleNamespace(names=(), params={})
    cn_sel = SimpleNamespace(names=("cg",), params={"cg": dx / -b})
    selections = {"Cm": (cm_sel, {}), "Cn": (cn_sel, {"cg": SimpleNamespace(scale=-b, column=CY)})}
    noise = 1e-4 * rng.standard_normal(n)
    measured = {"CZ": CZ, "CY": CY, "Cm": 0.01 * np.sin(np.linspace(0.0, 9.0, n))}

    def verdict(cm_constant):
        mismatch = {"Cm": cm_constant + noise, "Cn": -dx / b * CY + noise}
        return _cg_mean_test(p, "Cn", selections, {}, mismatch, measured)

    none = verdict(0.0)                                                      # no mistrim at all
    assert none.refuted and not none.pinned and "refuted by the mean of C_m" in none.reason
    short = verdict(0.25 * (1.0 - CG_MEAN_SHARE) * predicted)               # far short, same sign
    assert short.refuted and not short.pinned                                # C_n's shift: refuted only
    entered_on_cm = {"Cm": (SimpleNamespace(names=("cg",), params={"cg": dx / cbar}),
                            {"cg": SimpleNamespace(scale=cbar, column=CZ)}),
                     "Cn": (SimpleNamespace(names=(), params={}), {})}
    mismatch = {"Cm": 0.25 * (1.0 - CG_MEAN_SHARE) * predicted + noise, "Cn": noise}
    pinned = _cg_mean_test(p, "Cm", entered_on_cm, {}, mismatch, measured)
    assert pinned.refuted and pinned.pinned and "named instead" in pinned.reason
    assert abs(pinned.dx_ft - 0.25 * (1.0 - CG_MEAN_SHARE) * dx) < 5 * pinned.std_error_ft + 1e-3
    assert not verdict(-predicted).pinned                                    # the other sign: refuted only
    assert not verdict(predicted).refuted                                    # the shift's own mistrim
    assert not verdict(1.6 * predicted).refuted                              # a larger one supports it
    assert _cg_mean_test(p, "Cm", selections, {}, {"Cm": noise}, measured) is None  # no shift entered


def test_a_vane_bias_named_on_the_means_is_confirmed_by_the_validation_kinematics():
    """validation._vane_means_check: where the validation maneuver's kinematics gave the vane bias
    themselves (so its coefficient-means test did not run), their estimate decides as for any
    sensor finding: the same sign at |t| >= SENSOR_CONFIRM_T confirms, the opposite sign at
    that |t| contradicts, a weaker one is neutral; not when they also name a scale of that
    vane, which reads as a bias at the trim α."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.validation import SENSOR_CONFIRM_T, _vane_means_check
    named = Candidate("sensor_bias", "lon", "alpha", "bias_alpha", 0.0173, 0.0006, 28.0, 0.0, "rad",
                      "longitudinal coefficient means along the α vane", True)

    def twin(estimate, t, test="kinematic consistency (bias always fitted)", details=None):
        c = Candidate("sensor_bias", "lon", "alpha", "bias_alpha", estimate, abs(estimate / t), t, 0.0, "rad", test,
                      True, details=details or {})
        return SimpleNamespace(candidates=[c])

    assert _vane_means_check(twin(0.0209, 5.25), named)["status"] == "confirmed"
    assert _vane_means_check(twin(-0.0209, -5.25), named)["status"] == "contradicted"
    assert _vane_means_check(twin(0.004, SENSOR_CONFIRM_T - 0.5), named)["status"] == "neutral"
    means = {"estimate": 0.0171, "std_error": 0.0005, "axes": ["CX", "CZ", "Cm"]}
    assert _vane_means_check(twin(0.0171, 34.2, named.test, {"vane_means": means}), named)["status"] == "confirmed"
    assert _vane_means_check(twin(0.0171, 34.2, "stepwise on the Cm mismatch"), named)["status"] == "neutral"
    scaled = twin(0.0085, 8.6)                     # the validation's kinematics also name an α scale:
    scaled.candidates.append(Candidate("sensor_scale", "lon", "alpha", "scale_alpha", 0.08, 0.009, 9.2, 0.0, "1",
                                       "kinematic consistency", True))
    assert _vane_means_check(scaled, named)["status"] == "neutral"   # at trim α a scale reads as a bias


def test_a_control_delay_the_kinematics_cannot_tell_from_a_gyro_skew_is_withheld():
    """term_rules._withhold_skewed_delay: a delay is named only when the kinematics rule out a
    lag of the rate its surface drives of the same size. The kinematics' q skew of
    0.057 ± 0.015 s (t 3.8, an F-16 multisine with a 40 ms q skew) and a weak 0.055 ± 0.026 s
    (t 2.1, a 737 aileron sweep with a 40 ms p skew) both lie within two standard errors of
    a 0.042 ± 0.0016 s delay: withheld. A skew of 0.002 ± 0.003 s (a true delay's kinematics)
    or one of the other sign rule it out; a skew not tested leaves the delay named, with the
    caveat."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate

    from harness.diagnosis.term_rules import _withhold_skewed_delay

    def kin(skew, se):
        return SimpleNamespace(selection=SimpleNamespace(params={}, terms=[SimpleNamespace(
            name="skew_q", estimate=skew, std_error=se, t=skew / se)]))

    def delay():
        return Candidate("control_delay", "pitch", "de", "tau_de", 0.042, 0.0016, 25.0, 0.9, "s",
                         "delay scan of de + stepwise", selected=True, reason="entered")

    shown, weak, ruled_out, opposite, untested = delay(), delay(), delay(), delay(), delay()
    _withhold_skewed_delay(shown, kin(0.057, 0.015))
    _withhold_skewed_delay(weak, kin(0.055, 0.026))
    _withhold_skewed_delay(ruled_out, kin(0.002, 0.003))
    _withhold_skewed_delay(opposite, kin(-0.057, 0.015))
    _withhold_skewed_delay(untested, SimpleNamespace(selection=SimpleNamespace(params={}, terms=[])))
    assert not shown.selected and shown.details["sensor_rival"] == "skew_q"
    assert "lagging by 0.057 ± 0.015 s (skew_q, t = 3.8), which looks like this delay" in shown.reason
    assert not weak.selected and "does not rule out a lag of this size" in weak.reason
    assert ruled_out.selected and opposite.selected
    assert untested.selected and "q-gyro lag" in untested.details["not_ruled_out"]
    from harness.diagnosis.verdict import finding_dict
    said = finding_dict(untested, {}, {})
    assert said["explanation"].endswith("Caveat: " + untested.details["not_ruled_out"] + ".")
    assert said["evidence"]["not_ruled_out"] == untested.details["not_ruled_out"]


def test_a_vane_bias_that_is_a_scale_factors_offset_is_named_as_the_scale():
    """sensor_rules.scale_read_as_bias: an α reading (1 + k)·α stands k·ᾱ off at the mean α,
    which the kinematic fit gives as a bias. With ᾱ 0.12 rad (0.011 of it the bias) a bias
    of 0.011 ± 0.0008 rad says k = 0.100 ± 0.007, and the scale tried beside it says
    0.086 ± 0.022 (t 3.9): one scale, named at their inverse-variance mean, the bias read as
    its offset. A scale of the other sign, or one the kinematics do not suspect (t under
    2.5), leaves the bias named; one of the same sign the excursions show (t >= 3) but far
    from the offset's k leaves neither named (sensor_rules._withhold_bias_beside_a_scale: bias,
    scale or both)."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate

    from harness.diagnosis.sensor_rules import scale_read_as_bias
    p = SimpleNamespace(smooth={"alpha": np.full(100, 0.121), "V": np.full(100, 450.0)}, dt=0.02)

    def pair(k, se_k):
        bias = Candidate("sensor_bias", None, "alpha", "bias_alpha", 0.011, 0.0008, 13.8, 0.0, "rad",
                         "kinematic consistency (bias always fitted)", True, "significant, practical and precise")
        scale = Candidate("sensor_scale", None, "alpha", "scale_alpha", k, se_k, k / se_k, 0.01, "1",
                          "kinematic consistency", False, "below the entry t")
        return bias, scale

    bias, scale = pair(0.086, 0.022)
    scale_read_as_bias([bias, scale], p)
    w = np.array([1 / (0.0008 / 0.11) ** 2, 1 / 0.022 ** 2])
    expected = float(np.dot(w, [0.1, 0.086]) / w.sum())
    assert scale.selected and not bias.selected and bias.details["read_as"] == "scale_alpha"
    assert scale.estimate == pytest.approx(expected) and scale.std_error == pytest.approx(1 / np.sqrt(w.sum()))
    assert scale.details["corroboration"] == {"named": True, "kinematic": 0.086, "kinematic_std": 0.022}
    for k, se in ((-0.086, 0.022), (0.05, 0.022)):
        bias, scale = pair(k, se)
        scale_read_as_bias([bias, scale], p)
        assert bias.selected and not scale.selected
    bias, scale = pair(0.30, 0.03)
    scale_read_as_bias([bias, scale], p)
    assert not bias.selected and not scale.selected
    assert bias.details["scale_rival"]["offset_k"] == pytest.approx(0.1)
    assert bias.details["scale_rival"]["excursion_k"] == pytest.approx(0.30)
    assert bias.details["as_scale"]["k"] == pytest.approx(0.1)  # the reading the validation test uses


def test_a_vane_bias_a_scale_would_make_is_withheld_when_the_excursions_cannot_tell():
    """sensor_rules._withhold_bias_a_scale_would_make: a bias of 0.011 rad at a mean α of
    0.121 rad reads as a scale of 0.100 ± 0.007. Where α moved too little for a scale to be
    offered, or the excursions' reading (0.02 ± 0.04) lies within two standard errors of both
    0 and 0.1, the bias is withheld (bias or scale); excursions that rule the scale out
    (0.002 ± 0.01) leave it named, as does an offset no plausible scale makes (k 0.7)."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.sensor_rules import scale_read_as_bias
    p = SimpleNamespace(smooth={"alpha": np.full(100, 0.121), "V": np.full(100, 450.0)}, dt=0.02)

    def bias(b=0.011):
        return Candidate("sensor_bias", None, "alpha", "bias_alpha", b, 0.0008, b / 0.0008, 0.0, "rad",
                         "kinematic consistency (bias always fitted)", True, "significant, practical and precise")

    def scale(k, se):
        return Candidate("sensor_scale", None, "alpha", "scale_alpha", k, se, k / se, 0.01, "1",
                         "kinematic consistency", False, "below the entry t")

    alone = bias()
    scale_read_as_bias([alone], p)
    assert not alone.selected and "moved too little" in alone.reason
    assert alone.details["scale_rival"]["offset_k"] == pytest.approx(0.1)
    assert alone.details["scale_rival"]["excursion_k"] is None
    vague = bias()
    scale_read_as_bias([vague, scale(0.02, 0.04)], p)
    assert not vague.selected and "bias or scale" in vague.reason
    ruled_out = bias()
    scale_read_as_bias([ruled_out, scale(0.002, 0.01)], p)
    assert ruled_out.selected
    large = bias(0.05)
    scale_read_as_bias([large], p)
    assert large.selected


def test_a_v_scale_named_because_its_bias_was_left_out_is_withheld_when_the_bias_is_plausible():
    """sensor_rules.withhold_scale_a_bias_would_make: V hardly moves about its mean, so a V
    bias and scale run to offsetting sizes together and the bias is left out as implausible;
    the scale named alone (0.05 at 160 ft/s) then reads as a bias of 7.6 ft/s, plausible
    (under 5 % of V): withheld. A scale whose bias was not left out, or whose offset no
    plausible bias makes (0.12: 17.1 ft/s, over 5 % and over 10 kt), stays named."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.sensor_rules import withhold_scale_a_bias_would_make
    p = SimpleNamespace(smooth={"V": np.full(100, 160.0), "alpha": np.full(100, 0.05)}, dt=0.02)
    left_out = SimpleNamespace(dropped={"bias_V": "implausible size in an earlier fit: refitted without it"})

    def scale(k):
        return Candidate("sensor_scale", None, "V", "scale_V", k, 0.008, k / 0.008, 0.03, "1",
                         "kinematic consistency", True, "significant, practical and precise")
    withheld = scale(0.05)
    withhold_scale_a_bias_would_make([withheld], left_out, p)
    assert not withheld.selected and "scale or bias" in withheld.reason
    assert withheld.details["bias_rival"]["offset_bias"] == pytest.approx(0.05 * 160.0 / 1.05)
    kept = scale(0.05)
    withhold_scale_a_bias_would_make([kept], SimpleNamespace(dropped={}), p)
    assert kept.selected
    large = scale(0.12)
    withhold_scale_a_bias_would_make([large], left_out, p)
    assert large.selected
    ten_knots = scale(0.08)  # 11.9 ft/s: over 5 % of V, under 10 kt (kinematics.AIRSPEED_ERROR_FLOOR_FPS)
    withhold_scale_a_bias_would_make([ten_knots], left_out, p)
    assert not ten_knots.selected


def test_a_vane_bias_the_kinematics_name_is_sized_on_the_coefficient_means_too():
    """sensor_naming._size_on_both: the kinematics' 0.0317 ± 0.006 rad and the means'
    0.0178 ± 0.0002 agree within three standard errors: the bias is their inverse-variance
    mean; means that disagree (0.06) leave the kinematic size."""
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.sensor_naming import _size_on_both

    def bias():
        return Candidate("sensor_bias", None, "beta", "bias_beta", 0.0317, 0.006, 5.3, 0.0, "rad",
                         "kinematic consistency (bias always fitted)", True, "significant, practical and precise")
    both = bias()
    _size_on_both(both, 0.0178, 0.0002, "CY 1.02°")
    w = np.array([1 / 0.006 ** 2, 1 / 0.0002 ** 2])
    assert both.estimate == pytest.approx(float(np.dot(w, [0.0317, 0.0178]) / w.sum()))
    assert both.std_error == pytest.approx(1 / np.sqrt(w.sum()))
    assert both.details["sized_on_both"]["kinematic"] == 0.0317 and "CY 1.02°" in both.reason
    apart = bias()
    _size_on_both(apart, 0.06, 0.0002, "CY 3.4°")
    assert apart.estimate == 0.0317 and "sized_on_both" not in apart.details


def test_a_vane_scale_is_read_on_the_axes_the_vane_reaches():
    """sensor_naming.withhold_vane_scale: an α-vane scale reaches the longitudinal axes
    through the model's slopes (C_X, C_Z, C_m agree here on k = 0.087); a C_l mismatch on a
    pitch maneuver that follows the signature ten times harder (22 ± 1.2 probe units) is not
    a witness (the α dependence of the lateral moments runs through β), so the shape is read
    and kept on the scale (details['shape']) — also where the term was withheld already for
    that scale (details['sensor_rival']), which it then leaves as it was."""
    from types import SimpleNamespace

    from harness.diagnosis.corroborate import AxisRatio
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.sensor_naming import PROBE_SCALE, withhold_vane_scale
    ratios = {"CX": AxisRatio("", 1.18, 0.50), "CZ": AxisRatio("", 1.66, 0.28), "Cm": AxisRatio("", 1.83, 0.165),
              "Cl": AxisRatio("", 22.1, 1.15), "CY": AxisRatio("", -49.0, 133.0), "Cn": AxisRatio("", -3.2, 25.0)}
    kin = SimpleNamespace(parameters={"scale_alpha": None},
                          selection=SimpleNamespace(params={}, terms=[SimpleNamespace(name="scale_alpha",
                                                                                      estimate=0.072, t=5.9)]))

    def run(withheld):
        term = Candidate("coefficient_error", "lon", "CZ", "CZ_alpha", -3.34, 0.5, 5.9, 0.1, "per rad",
                         "stepwise on the CZ mismatch", not withheld, "entered",
                         {"sensor_rival": "scale_alpha"} if withheld else {})
        scale = Candidate("sensor_scale", None, "alpha", "scale_alpha", 0.072, 0.012, 5.9, 0.0, "1",
                          "kinematic consistency", False, "below the entry t")
        withhold_vane_scale([term, scale], kin, None, lambda name, size, same: ratios)
        return term, scale

    term, scale = run(False)
    w = 1 / np.array([0.50, 0.28, 0.165]) ** 2
    k = PROBE_SCALE * float(np.dot(w, [1.18, 1.66, 1.83]) / w.sum())
    assert not term.selected and term.details["sensor_rival"] == "scale_alpha"
    assert scale.details["shape"]["k"] == pytest.approx(k)
    term, scale = run(True)
    assert scale.details["shape"]["k"] == pytest.approx(k) and term.reason == "entered"


def test_the_mismatchs_shape_reads_a_vane_scales_excursions_beside_its_offset():
    """sensor_rules.scale_read_as_bias with the coefficient mismatch's shape along the vane
    (details['shape'], sensor_naming.withhold_vane_scale): the excursions are read as the
    inverse-variance mean of the kinematic k (0.066 ± 0.032, t 2.1, under the suspicion t)
    and the shape's (0.166 ± 0.044), and a bias of t 17 that is no practical bias
    (unselected) is read as the scale's offset (k = 0.0043/0.0431 = 0.100 ± 0.006): the
    scale is named at the mean of the two readings. Without the shape the same bias and
    kinematic k name nothing; with a shape of the other sign, nothing either."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.sensor_rules import excursion_scale, scale_read_as_bias
    p = SimpleNamespace(smooth={"alpha": np.full(100, 0.0474), "V": np.full(100, 700.0)}, dt=0.02)

    def pair(shape):
        bias = Candidate("sensor_bias", None, "alpha", "bias_alpha", 0.0043, 0.00025, 17.2, 0.0, "rad",
                         "kinematic consistency (bias always fitted)", False,
                         "within the instrument noise budget (practical size)")
        scale = Candidate("sensor_scale", None, "alpha", "scale_alpha", 0.066, 0.032, 2.06, 0.01, "1",
                          "kinematic consistency", False, "below the entry t",
                          {} if shape is None else {"shape": {"k": shape, "k_std": 0.044, "axes": ""}})
        return bias, scale

    bias, scale = pair(0.166)
    w = np.array([1 / 0.032 ** 2, 1 / 0.044 ** 2])
    k_exc, se_exc = float(np.dot(w, [0.066, 0.166]) / w.sum()), 1 / np.sqrt(w.sum())
    assert excursion_scale(scale) == pytest.approx((k_exc, se_exc))
    scale_read_as_bias([bias, scale], p)
    x_true = 0.0474 - 0.0043
    k_off, se_off = 0.0043 / x_true, 0.00025 / x_true
    w = np.array([1 / se_off ** 2, 1 / se_exc ** 2])
    assert scale.selected and not bias.selected and bias.details["read_as"] == "scale_alpha"
    assert scale.estimate == pytest.approx(float(np.dot(w, [k_off, k_exc]) / w.sum()))
    assert scale.details["offset"]["excursion_k"] == pytest.approx(k_exc)
    assert scale.details["corroboration"] == {"named": True, "kinematic": 0.066, "kinematic_std": 0.032}
    for shape in (None, -0.166):
        bias, scale = pair(shape)
        scale_read_as_bias([bias, scale], p)
        assert not scale.selected and not bias.selected and "read_as" not in bias.details
    # a named bias (0.100 ± 0.003 read as a scale) beside excursions the kinematics (0.072 ±
    # 0.012, t 6) and the shape (0.087 ± 0.0068) read together as 0.083 ± 0.006: 2.5 standard
    # errors apart, so neither is named, and the reason gives the reading that was tested
    p = SimpleNamespace(smooth={"alpha": np.full(100, 0.0968), "V": np.full(100, 420.0)}, dt=0.02)
    bias = Candidate("sensor_bias", None, "alpha", "bias_alpha", 0.0088, 0.000264, 33.3, 0.0, "rad",
                     "kinematic consistency (bias always fitted)", True, "significant, practical and precise")
    scale = Candidate("sensor_scale", None, "alpha", "scale_alpha", 0.072, 0.012, 6.0, 0.01, "1",
                      "kinematic consistency", False, "below the entry t",
                      {"shape": {"k": 0.087, "k_std": 0.0068, "axes": ""}})
    k_exc, se_exc = excursion_scale(scale)
    scale_read_as_bias([bias, scale], p)
    assert not bias.selected and not scale.selected
    assert bias.details["scale_rival"]["excursion_k"] == pytest.approx(k_exc)
    assert f"k = {k_exc:.3f} ± {se_exc:.3f} with the mismatch's shape" in bias.reason


def test_a_scale_named_on_its_offset_is_tested_the_same_way_on_the_validation_maneuver():
    """validation._offset_scale_check: a scale named on its offset and excursions together is
    confirmed where the validation maneuver's offset (read as k = b/x̄_true, 0.12 ± 0.013)
    and excursions (0.048 ± 0.036, t 1.3: 'neutral' alone) agree: their inverse-variance
    mean, t >= 3 with the same sign. Where they disagree there is no verdict."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.validation import _offset_scale_check, _sensor_check

    def validation(k_exc, se_exc):
        bias = Candidate("sensor_bias", None, "alpha", "bias_alpha", 0.0068, 0.00074, 9.2, 0.0, "rad",
                         "kinematic consistency", True, "", {"as_scale": {"k": 0.12, "k_std": 0.013}})
        twin = Candidate("sensor_scale", None, "alpha", "scale_alpha", k_exc, se_exc, k_exc / se_exc, 0.0, "1",
                         "kinematic consistency", False, "below the entry t")
        return SimpleNamespace(candidates=[bias, twin]), twin

    found = Candidate("sensor_scale", None, "alpha", "scale_alpha", 0.101, 0.0068, 14.8, 0.0, "1",
                      "kinematic consistency", True, "", {"offset": {"k": 0.100}})
    av, twin = validation(0.048, 0.036)
    check = _sensor_check(av, found)
    w = np.array([1 / 0.013 ** 2, 1 / 0.036 ** 2])
    assert check["status"] == "confirmed"
    assert check["estimate"] == pytest.approx(np.dot(w, [0.12, 0.048]) / w.sum())
    av, twin = validation(-0.05, 0.02)  # the excursions disagree with the offset
    assert _offset_scale_check(av, found, twin) is None and _sensor_check(av, found)["status"] == "neutral"


def test_rms_margin_is_two_standard_errors_of_an_ar1_records_rms():
    """validation.rms_margin: 2/√(2 n_eff) with n_eff = N(1 − ρ)/(1 + ρ) (Bartlett). A seeded AR(1)
    record with ρ = 0.6 and N = 20,000 has n_eff = 5,000 and a margin of 0.02; the lag-one
    estimate's own error (√((1 − ρ²)/N) = 0.0057) moves it by under 2 %."""
    from harness.diagnosis.validation import rms_margin
    rng = np.random.default_rng(12)
    e = rng.standard_normal(20_000)
    x = np.empty_like(e)
    x[0] = e[0]
    for i in range(1, x.size):
        x[i] = 0.6 * x[i - 1] + e[i]
    assert rms_margin(x) == pytest.approx(0.02, rel=0.03)
    assert rms_margin(rng.standard_normal(20_000)) == pytest.approx(2 / np.sqrt(40_000), rel=0.03)


@pytest.mark.parametrize("own, theirs, indistinct, change, expected", [
    # the identification maneuver could not tell them apart: the rival must do worse by the margin
    (1.00, 1.25, True, -0.6, True), (1.00, 1.35, True, -0.6, False),
    # it set them apart and the validation supports the finding (drop 60 % > margin 30 %):
    # only a rival better by more than the margin overturns it
    (1.00, 0.99, False, -0.6, False), (1.00, 0.65, False, -0.6, True),
    # it set them apart but the validation drop (10 %) is within the margin: any preference counts
    (1.00, 0.99, False, -0.1, True), (1.00, 1.01, False, -0.1, False),
])
def test_a_rival_overturns_a_finding_by_the_validation_records_sampling_error(own, theirs, indistinct, change,
                                                                              expected):
    """validation.rival_fits_as_well with a margin of 30 % (two standard errors of the RMS). Measured
    cases: a C_m,α −0.15 at 18,000 ft / 420 ft/s, set apart from a moment-reference shift
    (|t| 5.2 beside it), lowers the validation RMS by 70 % and the shift by 1 % more: the
    finding stands. A C_m ΔV/V on a DHC-6 multisine null, set apart from a C_m α³, lowers
    the validation RMS by 5 % against a 53 % margin: the α³'s 3 % better fit leaves it
    ambiguous (it was a false finding when a distinct rival needed a significant win)."""
    from harness.diagnosis.validation import rival_fits_as_well
    assert rival_fits_as_well(own, theirs, 0.30, indistinct, change) is expected


def test_a_rival_comparison_is_made_without_the_vanes_noise():
    """validation._less_nuisances: a residual on C_m less its fit on the maneuver's nuisance
    columns and, where the stepwise's gate left it out, the α vane's error (the kinematic
    residual's vertical "gust"); other axes keep their own nuisances only. A finding built on
    α would otherwise win against a rival on another channel by removing the vane's noise the
    model's slopes pass into the mismatch (probe 61)."""
    from types import SimpleNamespace

    from harness.diagnosis.validation import _less_nuisances
    t = np.linspace(0.0, 20.0, 1001)
    w = np.sin(2.3 * t) + 0.3 * np.cos(0.7 * t)
    effect = np.sin(0.4 * t) ** 3
    av = SimpleNamespace(nuisances={"Cm": {}, "CZ": {}}, gust=SimpleNamespace(w_fps=w))
    inner = slice(50, -50)
    left = _less_nuisances(av, "Cm", (0.02 * w + effect + 0.1)[inner], inner)
    fitted = np.column_stack([w[inner], np.ones(left.size)])
    expected = effect[inner] - fitted @ np.linalg.lstsq(fitted, effect[inner], rcond=None)[0]
    assert np.allclose(left, expected, atol=1e-12)
    assert np.array_equal(_less_nuisances(av, "CZ", effect[inner], inner), effect[inner])
    gated = SimpleNamespace(nuisances={"Cm": {"vane_alpha_noise": 3.0 * w}}, gust=SimpleNamespace(w_fps=w))
    assert np.allclose(_less_nuisances(gated, "Cm", (0.02 * w + effect + 0.1)[inner], inner), expected, atol=1e-12)


def test_the_ambiguous_reason_says_which_rule_left_the_finding_undecided():
    from harness.diagnosis.validation import _ambiguous_reason
    rival = {"parameter": "Cm_de", "correlation": -0.93, "noise_levels_own": 1.60, "noise_levels_rival": 1.59,
             "margin": 0.41, "indistinct": ""}
    text = _ambiguous_reason(rival, -0.15)
    assert "Cm_de" in text and "lowers the validation RMS by 15 %, under the 41 %" in text
    assert "better by more than 41 %" in _ambiguous_reason(rival | {"noise_levels_rival": 0.9}, -0.6)
    assert "a difference under 41 %" in _ambiguous_reason(rival | {"indistinct": "t 3.1 beside it"}, -0.6)


def test_a_change_of_lift_puts_minus_delta_cz_tan_alpha_on_cx():
    """term_rules.lift_change_on_cx: a lift change ΔC_L rotated into body axes is
    ΔC_X = ΔC_L sin α, ΔC_Z = −ΔC_L cos α."""
    from harness.diagnosis.term_rules import lift_change_on_cx
    alpha = np.linspace(-0.1, 0.4, 11)
    d_cl = 0.6 * alpha + 0.01
    assert np.allclose(lift_change_on_cx(-d_cl * np.cos(alpha), alpha), d_cl * np.sin(alpha), atol=1e-15)


def _lift_case(extra_cx: float):
    """A C_Z,α change of −0.6 concealed as a lift change at α 8.5° ± 2°, its C_X share
    0.6 α sin α in C_X's mismatch, white noise 3e-4, plus ``extra_cx`` times a C_X column
    of its own (a sinusoid the lift change does not follow)."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate
    n, dt = 1500, 0.02
    t = np.arange(n) * dt
    alpha = 0.148 + 0.035 * np.sin(2 * np.pi * 0.3 * t) * np.sin(2 * np.pi * 0.05 * t)
    rng = np.random.default_rng(5)
    own = np.sin(2 * np.pi * 0.7 * t)
    cx = 0.6 * alpha * np.sin(alpha) + extra_cx * own + 3e-4 * rng.standard_normal(n)
    cz = -0.6 * alpha * np.cos(alpha) + 3e-4 * rng.standard_normal(n)
    term = lambda par, col: SimpleNamespace(parameter=par, column=col, scale=1.0)  # noqa: E731
    a3 = (alpha - alpha.mean()) ** 3
    slope = np.polyfit(alpha, cz, 1)[0]  # the C_Z,α change as the stepwise fits it (with a constant)
    selections = {"CZ": (SimpleNamespace(names=("alpha",), params={"alpha": slope}),
                         {"alpha": term("CZ_alpha", alpha)}),
                  "CX": (SimpleNamespace(names=("alpha3", "own"), params={}),
                         {"alpha3": term("CX_alpha3", a3), "own": term("CX_own", own)})}
    cands = [Candidate("coefficient_error", "normal", "CZ", "CZ_alpha", -4.1, 0.08, -7.0, 0.5, "per rad",
                       "stepwise on the CZ mismatch", True, "entered"),
             Candidate("nonlinear_alpha", "axial", "CX", "CX_alpha3", 50.0, 9.0, 5.6, 0.1, "per rad^3",
                       "stepwise on the CX mismatch", True, "entered"),
             Candidate("coefficient_error", "axial", "CX", "CX_own", extra_cx, 1e-5, 50.0, 0.5, "1",
                       "stepwise on the CX mismatch", bool(extra_cx), "entered")]
    measured = {"CZ": -(0.3 + 5.0 * alpha), "CX": np.full(n, -0.03)}
    return cands, selections, {"CX": cx, "CZ": cz}, SimpleNamespace(smooth={"alpha": alpha}, dt=dt, n=n,
                                                                    measured=measured)


def test_a_cx_term_that_a_named_lift_change_explains_is_withheld():
    """term_rules.withhold_explained_by_lift: the C_X α³ column takes the lift change's C_X
    share at |t| >= 5 (10.2 here, 5.5 on the probe), and falls under the entry t once that
    share is removed (4.6; the probe 3.4: the C_Z fit's straight line leaves cos α's
    curvature); a C_X term the lift change does not explain stays named."""
    from harness.diagnosis.along import interior
    from harness.diagnosis.term_rules import withhold_explained_by_lift
    from estimators.colored_stepwise import colored_fit
    cands, selections, mismatch, p = _lift_case(0.002)
    inner = interior(p)
    cols = [selections["CX"][1][k].column[inner] for k in ("own", "alpha3")]
    theta, se, _ = colored_fit(mismatch["CX"][inner], cols, ["own", "alpha3"])
    assert abs(theta[1] / se[1]) >= 5.0  # the lift change alone makes the α³ term significant
    withhold_explained_by_lift(cands, selections, mismatch, p)
    alpha3, own = cands[1], cands[2]
    assert not alpha3.selected and "change of lift" in alpha3.reason
    assert own.selected and own.reason == "entered"


@pytest.mark.parametrize("k", [0.14, -0.14])
def test_a_cx_term_the_drag_due_to_a_named_lift_change_explains_is_withheld(k):
    """term_rules.induced_drag_column: a C_Z α² change of −25 concealed as lift at α 1° ± 2°
    (C_L 0.09 + 3.6 Δα), the model's drag reading the total lift squared (k = 0.14) puts
    2k·C_L·ΔC_Z on C_X, which the stepwise takes as a C_X α² term; beside the column it falls
    under the entry t and is withheld, its k recovered. Drag falling with lift (k < 0) is no
    induced drag: the term stays named."""
    from types import SimpleNamespace

    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.term_rules import withhold_explained_by_lift
    n, dt = 1500, 0.02
    t = np.arange(n) * dt
    rng = np.random.default_rng(8)
    da = 0.035 * np.sin(2 * np.pi * 0.3 * t) * np.sin(2 * np.pi * 0.05 * t)
    alpha = 0.0175 + da
    cl = 0.09 + 3.6 * da
    dcz = -25.0 * da ** 2
    cx = -dcz * np.tan(alpha) + 2.0 * k * cl * dcz + 1e-5 * rng.standard_normal(n)  # the lift's share, its drag
    term = lambda par, col: SimpleNamespace(parameter=par, column=col, scale=1.0)  # noqa: E731
    selections = {"CZ": (SimpleNamespace(names=("alpha2",), params={"alpha2": -25.0}),
                         {"alpha2": term("CZ_alpha2", da ** 2)}),
                  "CX": (SimpleNamespace(names=("alpha2",), params={}), {"alpha2": term("CX_alpha2", da ** 2)})}
    cands = [Candidate("nonlinear_alpha", "normal", "CZ", "CZ_alpha2", -25.0, 1.0, -25.0, 0.5, "per rad^2",
                       "stepwise on the CZ mismatch", True, "entered"),
             Candidate("nonlinear_alpha", "axial", "CX", "CX_alpha2", 2.0 * k * 0.09 * -25.0, 0.01, -60.0, 0.5,
                       "per rad^2", "stepwise on the CX mismatch", True, "entered")]
    measured = {"CZ": -cl * np.cos(alpha), "CX": cl * np.sin(alpha)}
    p = SimpleNamespace(smooth={"alpha": alpha}, dt=dt, n=n, measured=measured)
    withhold_explained_by_lift(cands, selections, {"CX": cx, "CZ": -cl * np.cos(alpha) + dcz}, p)
    cx_term = cands[1]
    if k > 0:
        assert not cx_term.selected and "drag due to lift" in cx_term.reason
        assert cx_term.details["beside_induced_drag"]["k"] == pytest.approx(k, rel=0.05)
    else:
        assert cx_term.selected


def _drift_case(along_vane_size: float, monkeypatch):
    """A C_l ΔV/V term the stepwise entered along the inertial sideslip (size 0.004 in a
    mismatch with white noise 2e-5), and the mismatch along the β vane: the same term times
    ``along_vane_size`` / 0.004 plus the vane's wander through C_l,β (Gauss-Markov, 0.1°,
    τ = 1 s, times −0.1/rad)."""
    from types import SimpleNamespace

    from harness.diagnosis import term_rules
    from harness.diagnosis.evidence import Candidate
    n, dt = 1500, 0.02
    t = np.arange(n) * dt
    dv = 0.06 * np.sin(np.pi * t / t[-1]) ** 2
    rng = np.random.default_rng(9)
    wander = np.zeros(n)
    for i in range(1, n):
        wander[i] = wander[i - 1] * np.exp(-dt / 1.0) + 0.00175 * np.sqrt(1 - np.exp(-2 * dt)) * rng.standard_normal()
    vane = along_vane_size * dv - 0.1 * wander + 2e-5 * rng.standard_normal(n)
    monkeypatch.setattr(term_rules, "inertial_beta", lambda p: True)
    monkeypatch.setattr(term_rules, "model_along", lambda *a, **k: SimpleNamespace(mismatch=lambda: {"Cl": vane}))
    term = SimpleNamespace(parameter="Cl_dV", column=dv, scale=1.0)
    step = SimpleNamespace(selections={"Cl": (SimpleNamespace(names=("dV",), params={"dV": 0.004}), {"dV": term})},
                           nuisances={"Cl": {}})
    c = Candidate("flight_condition_drift", "roll", "Cl", "Cl_dV", 0.004, 0.0002, 20.0, 0.5, "per unit dV/V",
                  "stepwise on the Cl mismatch", True, "entered")
    p = SimpleNamespace(dt=dt, n=n)
    term_rules.withhold_lateral_drift_off_the_vane([c], step, p, None, None)
    return c


def test_a_lateral_drift_term_the_beta_vane_does_not_show_is_withheld(monkeypatch):
    """term_rules.withhold_lateral_drift_off_the_vane: a C_l ΔV/V entered along the inertial
    sideslip is refitted on the mismatch along the β vane. Where the vane's mismatch carries
    it (0.004, under the vane's wander) it stays named; where it does not (the inertial
    sideslip's own drift made it), it is withheld with the vane's t in its reason."""
    kept = _drift_case(0.004, monkeypatch)
    assert kept.selected and kept.reason == "entered"
    withheld = _drift_case(0.0, monkeypatch)
    assert not withheld.selected and "along the β vane's own record" in withheld.reason


def test_a_validation_maneuver_that_does_not_excite_a_term_leaves_it_untested():
    """validation.untestable: a sequential three-axis maneuver drives α and β but not together, so an
    α·β coupling is untested there while C_l,β is tested; on a stabilator-only maneuver (β, p,
    r not driven) a C_l,β or C_n α·β finding is tested as before (a maneuver of another kind;
    the noise it meets leaves the finding unconfirmed), and so is C_m,q̂."""
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.prepare import prepare
    from harness.diagnosis.validation import untestable

    def finding(channel, parameter, effect="coefficient_error"):
        return Candidate(effect, "roll", channel, parameter, 0.0, 1.0, 10.0, 0.5, "per rad",
                         f"stepwise on the {channel} mismatch", True, "entered")
    pitch = prepare(apply_noise(fly_maneuver(FlightSpec(input=stabilator_2112())), preset("realistic"), seed=5),
                    "validation")
    assert untestable(pitch, finding("Cl", "Cl_beta")) == ""
    assert untestable(pitch, finding("Cn", "Cn_alpha_beta", "cross_coupling")) == ""
    assert untestable(pitch, finding("Cm", "Cm_qhat")) == ""
    three = prepare(apply_noise(fly_maneuver(FlightSpec(input=default_three_axis_input())), preset("realistic"),
                                seed=6), "validation")
    assert untestable(three, finding("Cl", "Cl_beta")) == ""
    assert "never moved together" in untestable(three, finding("Cl", "Cl_alpha_beta", "cross_coupling"))


def _alpha_power_case(linear: float, cubic: float, monkeypatch):
    """A C_m mismatch ``linear``·Δα + ``cubic``·Δα³ (Δα up to ±1.2°, white noise 5e-5) in
    which the stepwise named an α³ term; the inertial α is the true one plus white noise
    (0.01°)."""
    from types import SimpleNamespace

    from harness.diagnosis import term_rules
    from harness.diagnosis.along import INERTIAL_CHANNELS
    from harness.diagnosis.evidence import Candidate
    n, dt = 1500, 0.02
    t = np.arange(n) * dt
    rng = np.random.default_rng(21)
    da = 0.021 * np.sin(2 * np.pi * 0.4 * t) * np.exp(-((t - 12) / 8) ** 2)
    alpha = 0.09 + da
    z = linear * da + cubic * da ** 3 + 5e-5 * rng.standard_normal(n)
    inertial = alpha + 0.00017 * rng.standard_normal(n)
    monkeypatch.setattr(term_rules, "inertial_alpha_change", lambda p: inertial - p.start["alpha"])
    term = SimpleNamespace(parameter="Cm_alpha3", column=da ** 3, scale=1.0)
    step = SimpleNamespace(selections={"Cm": (SimpleNamespace(names=("alpha3",), params={}), {"alpha3": term})},
                           nuisances={"Cm": {}})
    c = Candidate("nonlinear_alpha", "pitch", "Cm", "Cm_alpha3", -800.0, 40.0, -9.8, 0.5, "per rad^3",
                  "stepwise on the Cm mismatch", True, "entered")
    p = SimpleNamespace(dt=dt, n=n, smooth={k: alpha for k in INERTIAL_CHANNELS}, start={"alpha": 0.09})
    term_rules.withhold_alpha_power_off_the_inertial_alpha([c], step, p, {"Cm": z})
    return c


def test_an_alpha_power_the_inertial_alpha_calls_linear_is_withheld(monkeypatch):
    """term_rules.withhold_alpha_power_off_the_inertial_alpha: a C_m α³ named where the
    mismatch is linear in α (a C_m,α change of −0.3) is withheld once both shapes are fitted
    along the inertial α; a mismatch that is cubic (−800 per rad³, as large over the
    maneuver) keeps it."""
    linear = _alpha_power_case(-0.3, 0.0, monkeypatch)
    assert not linear.selected and "inertial α" in linear.reason
    cubic = _alpha_power_case(0.0, -800.0, monkeypatch)
    assert cubic.selected and cubic.reason == "entered"


def test_a_recorders_anti_alias_filter_is_the_noise_floors_shape():
    """prepare.recorder_noise_shape and the smoothing it feeds: white noise (σ 0.01) through
    a causal 4th-order Butterworth at half the Nyquist frequency before sampling, on a slow
    maneuver. Under the white-floor assumption the noise level comes out near zero (the
    cut-off lands where the filtered noise meets nothing); with the floor's own shape it is
    the recorded noise's level, within 15 % (its standard deviation over the record: σ times
    the filter's power gain over the band, √0.5 for an ideal half-band filter). The
    unfiltered record's floor is flat: no shape, the same smoothing as before."""
    from scipy import signal as sg

    from estimators.smoothing import optimal_fourier_smoother
    from harness.diagnosis.prepare import _own_smoothing, recorder_noise_shape
    rng = np.random.default_rng(12)
    fs, n = 50.0, 1500
    t = np.arange(n) / fs
    slow = 0.05 * np.sin(2 * np.pi * 0.3 * t) * np.exp(-((t - 12) / 6) ** 2)
    white = 0.01 * rng.standard_normal(n)
    b, a = sg.butter(4, 0.5)
    recorded_noise = sg.lfilter(b, a, white)
    raw = {c: slow + (sg.lfilter(b, a, 0.01 * rng.standard_normal(n)) if c != "alpha" else recorded_noise)
           for c in ("alpha", "beta", "p", "q", "r")}
    plain = optimal_fourier_smoother(raw["alpha"], 1 / fs)
    assert np.sqrt(plain.noise_variance) < 0.2 * np.std(recorded_noise[100:])
    shape = recorder_noise_shape(plain.coefficients ** 2, plain.frequencies_hz)
    assert shape is not None and shape[0] == 1.0 and shape[-1] < 0.01
    fits, filtered = _own_smoothing(raw, 1 / fs)
    assert set(filtered) == set(raw)
    assert np.sqrt(fits["alpha"].noise_variance) == pytest.approx(np.std(recorded_noise[100:]), rel=0.15)
    unfiltered = {c: slow + 0.01 * rng.standard_normal(n) for c in raw}
    fits, filtered = _own_smoothing(unfiltered, 1 / fs)
    assert filtered == []
    assert fits["alpha"].noise_variance == optimal_fourier_smoother(unfiltered["alpha"], 1 / fs).noise_variance


def test_a_moment_reference_shift_is_no_rival_when_cm_lacks_its_mistrim():
    """term_rules._refuted_shift: on a lateral maneuver the C_Y column a moment-reference shift
    puts in C_n follows β as C_n,β's does, so the shift rivals a C_n,β change. The shift the
    rival needs (its coefficient fitted in the term's place, times −b) also mistrims C_m by
    Δx·mean(C_Z)/c̄; when C_m's constant lacks it (stepwise_axes.shift_mistrim_test) the shift
    is refuted, not a rival. With the mistrim there, or for a rival of another effect, it stands."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis.rivals import Rival
    from harness.diagnosis.term_rules import _refuted_shift
    rng = np.random.default_rng(5)
    n, cbar, b, dx = 1500, 11.32, 30.0, 1.3
    CZ = -0.4 + 0.005 * np.sin(np.linspace(0.0, 20.0, n))
    CY = 0.02 * np.sin(np.linspace(0.0, 13.0, n))
    p = SimpleNamespace(dt=0.02, n=n, meta={"geometry": {"cbar_ft": cbar, "b_ft": b}})
    by_key = {"cg": SimpleNamespace(effect="cg_offset", scale=-b, column=CY),
              "beta": SimpleNamespace(effect="coefficient_error", scale=1.0, column=CY)}
    selections = {"Cm": (SimpleNamespace(names=(), params={}), {}), "Cn": (SimpleNamespace(names=("beta",)), by_key)}
    measured = {"CZ": CZ, "CY": CY, "Cm": 0.01 * np.sin(np.linspace(0.0, 9.0, n))}
    noise = 1e-4 * rng.standard_normal(n)
    rival = Rival("cg", -0.96, 2.9, -1.9, dx / -b)
    predicted = dx * float(np.mean(CZ)) / cbar                       # about −0.046
    untrimmed = {"Cm": noise, "Cn": -dx / b * CY + noise}
    why = _refuted_shift(rival, by_key, "Cn", p, selections, {}, untrimmed, measured)
    assert why.startswith("refuted by the mean of C_m") and "1.3 ft" in why
    mistrimmed = {"Cm": predicted + noise, "Cn": untrimmed["Cn"]}
    assert _refuted_shift(rival, by_key, "Cn", p, selections, {}, mistrimmed, measured) == ""
    other = Rival("beta", -0.96, 2.9, -1.9, 0.05)
    assert _refuted_shift(other, by_key, "Cn", p, selections, {}, untrimmed, measured) == ""
    assert _refuted_shift(None, by_key, "Cn", p, selections, {}, untrimmed, measured) == ""


def test_a_term_whose_shift_rival_was_refuted_must_enter_on_the_validation_too():
    """validation.unreplicated: a term the identification could not tell from a moment-reference
    shift (t beside it under the entry t), the shift then refuted by the mean of C_m, stands on
    its own t alone; it is named only when the validation maneuver's own fit enters the same
    parameter with the same sign (|t| >= candidates.T_IN). A term that set its rival apart, or
    had none refuted, is not asked."""
    from types import SimpleNamespace

    from harness.diagnosis.candidates import T_IN
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.validation import unreplicated
    refuted = {"parameter": "dx_moment_reference", "effect": "cg_offset", "correlation": -0.95, "t_term": -1.0,
               "reason": "refuted by the mean of C_m"}
    f = Candidate("coefficient_error", "yaw", "Cn", "Cn_beta", 0.2034, 0.002, -6.3, 0.27, "per rad",
                  "stepwise on the Cn mismatch", True, details={"change": -0.0127, "refuted_rival": refuted})

    def validation(t):
        twin = Candidate("coefficient_error", "yaw", "Cn", "Cn_beta", 0.2024, 0.0019, t, 0.1, "per rad",
                         "stepwise on the Cn mismatch", abs(t) >= T_IN)
        return SimpleNamespace(candidates=[twin])

    why = unreplicated(validation(-4.0), f)
    assert "t = -4.0" in why and "refutes" in why
    assert unreplicated(validation(-T_IN - 0.1), f) == ""
    assert unreplicated(validation(T_IN + 3.0), f) != ""                   # the other sign
    assert unreplicated(SimpleNamespace(candidates=[]), f) != ""          # not offered there
    apart = Candidate(f.effect, f.axis, f.channel, f.parameter, f.estimate, f.std_error, f.t, 0.27, f.units, f.test,
                      True, details={"refuted_rival": refuted | {"t_term": -T_IN - 1.0}})
    assert unreplicated(validation(0.0), apart) == ""
    plain = Candidate(f.effect, f.axis, f.channel, f.parameter, f.estimate, f.std_error, f.t, 0.27, f.units, f.test,
                      True)
    assert unreplicated(validation(0.0), plain) == ""


def test_a_shift_read_off_cn_is_set_apart_from_cn_beta_by_the_mistrim_of_cm():
    """term_rules._shift_set_apart: a moment-reference shift entered on C_n (its C_Y column
    follows β on a lateral maneuver, as C_n,β's does) is set apart from that rival when C_m's
    constant carries the mistrim Δx·mean(C_Z)/c̄ it predicts, itself a shift of the same sign
    CG_MEAN_Z standard errors from zero and practical; not without the mistrim, with one of the
    other sign, or for a shift read off C_m or a term of another effect."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.term_rules import _shift_set_apart
    rng = np.random.default_rng(7)
    n, cbar, b, dx = 1500, 11.32, 30.0, 1.0
    CZ = -0.4 + 0.005 * np.sin(np.linspace(0.0, 20.0, n))
    CY = 0.02 * np.sin(np.linspace(0.0, 13.0, n))
    p = SimpleNamespace(dt=0.02, n=n, meta={"geometry": {"cbar_ft": cbar, "b_ft": b}})
    selections = {"Cm": (SimpleNamespace(names=(), params={}), {})}
    measured = {"CZ": CZ, "CY": CY, "Cm": 0.01 * np.sin(np.linspace(0.0, 9.0, n))}
    noise = 1e-4 * rng.standard_normal(n)
    predicted = dx * float(np.mean(CZ)) / cbar                         # about −0.035
    shift = Candidate("cg_offset", "yaw", "Cn", "dx_moment_reference", dx, 0.09, -11.2, 0.4, "ft",
                      "stepwise on the Cn mismatch", True)

    def apart(c, cm_constant):
        return _shift_set_apart(c, p, selections, {}, {"Cm": cm_constant + noise}, measured)

    why = apart(shift, predicted)
    assert why.startswith("C_m's mean carries the mistrim") and "1 ft from the Cn mismatch" in why
    assert apart(shift, 0.0) == ""                                     # no mistrim: refuted, not apart
    assert apart(shift, -predicted) == ""                              # the other sign
    on_cm = Candidate("cg_offset", "pitch", "Cm", "dx_moment_reference", dx, 0.09, 11.2, 0.4, "ft",
                      "stepwise on the Cm mismatch", True)
    assert apart(on_cm, predicted) == ""
    cn_beta = Candidate("coefficient_error", "yaw", "Cn", "Cn_beta", 0.25, 0.002, 20.0, 0.4, "per rad",
                        "stepwise on the Cn mismatch", True)
    assert apart(cn_beta, predicted) == ""


def test_a_still_surface_whose_end_samples_are_off_has_not_moved():
    """prepare.interior_motion and maneuver_driven: the smoothed signal ends on the raw end
    samples, so a surface still but for its noise, whose first and last samples happen to lie
    two noise levels off in opposite directions, deviates from the line through its ends by
    the line itself. Measured on the interior about its least-squares line it has not moved
    (a pitch maneuver's aileron: a C_l,δa "finding" was the model's derivative times the
    aileron's noise, taken back by the regression); a real doublet still has."""
    import numpy as np

    from harness.diagnosis.prepare import about_trend, interior_motion, interior_slice, maneuver_driven
    n, dt = 1500, 0.02
    t = np.arange(n) * dt
    rng = np.random.default_rng(11)
    w = np.ones(n - 2) * 0.2
    sigma = np.radians(0.05)
    ramp = np.exp(-t / 0.2) - np.exp(-(t[-1] - t) / 0.2)       # ends pinned at -2 and +2 sigma
    still = -2.0 * sigma * ramp + 0.2 * sigma * rng.standard_normal(n)
    doublet = np.radians(1.0) * (np.sign(np.sin(np.pi * (t - 5.0))) * ((t > 5.0) & (t < 7.0)))
    inner = interior_slice(n, dt)
    assert inner == slice(50, n - 50)
    assert about_trend(still) > 5.0 * 0.2 * sigma                # the old measure: 'moved'
    assert interior_motion(still[inner]) < 0.5 * sigma
    smooth = {"da": still[inner], "de": doublet[inner]}
    noise = {"da": sigma, "de": sigma}
    assert maneuver_driven(smooth, noise, w, excited=()) == ("de",)


def test_a_beta_derivative_says_an_untested_coupling_would_read_as_it(monkeypatch):
    """term_rules.note_untested_coupling: where α and β were both driven but never moved
    together (candidates.joint_excitation under JOINT_SNR, so no α·β coupling was offered), a
    named β derivative carries the caveat that a coupling k reads as its change at the α the
    sideslip was flown at, k = change / Δα, Δα the β²-weighted mean of α − α₀; not where they
    moved together or α was not driven, nor on other terms."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis import candidates as cand
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.term_rules import note_untested_coupling
    n, dt = 1500, 0.02
    t = np.arange(n) * dt
    beta = np.radians(2.0) * np.sin(2 * np.pi * 0.4 * t) * (t > 15.0)
    alpha = np.radians(-0.5) * (t > 14.0)                     # the lateral inputs flown 0.5 deg low
    monkeypatch.setattr(cand, "regressors", lambda p: {"alpha": alpha, "beta": beta})
    together = {"value": cand.JOINT_SNR - 2.0}
    monkeypatch.setattr(cand, "joint_excitation", lambda p: together["value"])
    p = SimpleNamespace(n=n, dt=dt, driven=("de", "da", "dr", "alpha", "beta", "q", "p", "r"))

    def named(parameter, channel="Cl"):
        return Candidate("coefficient_error", "roll", channel, parameter, -0.124, 0.002, 7.7, 0.4, "per rad",
                         f"stepwise on the {channel} mismatch", True, details={"change": 0.0144})

    c, other = named("Cl_beta"), named("Cl_phat")
    note_untested_coupling([c, other], p)
    k = c.details["coupling_alternative"]["coupling"]
    assert abs(k - 0.0144 / np.radians(-0.5)) < 1e-9 and "-0.50° of α" in c.details["not_ruled_out"]
    assert "coupling_alternative" not in other.details
    together["value"] = cand.JOINT_SNR + 1.0                  # they moved together: the coupling was offered
    offered = named("Cl_beta")
    note_untested_coupling([offered], p)
    assert "not_ruled_out" not in offered.details
    lateral = SimpleNamespace(n=n, dt=dt, driven=("da", "dr", "beta", "p", "r"))
    together["value"] = 0.0
    alone = named("Cl_beta")
    note_untested_coupling([alone], lateral)                  # α not driven: no term is built on it
    assert "not_ruled_out" not in alone.details


def test_the_model_follows_the_unfiltered_states_and_the_inertial_sideslip(monkeypatch):
    """along.model_states: the model is evaluated along the recorded states as they are,
    unfiltered, the driven sideslip the inertial one (also unfiltered), the undriven rates
    held at their start and the airspeed its own smoothing; its coefficients then pass
    through the common filter (along.filtered), as the measured ones did. (Until 4 Dec 2026
    the inertial angle kept its channels' own bandwidth while the vane states were filtered:
    on an F-16 lateral maneuver at 3,000 ft / 260 ft/s, common cut-off 0.3-0.7 Hz, the C_l
    mismatch followed β at +0.030 per rad where C_l,β was 0.03 low.)"""
    from types import SimpleNamespace

    from harness.diagnosis import along
    n, dt = 1000, 0.02
    t = np.arange(n) * dt
    sine = 0.01 * np.sin(2 * np.pi * 0.6 * t)
    ones = np.ones(n)
    raw = {c: ones.copy() for c in along.INERTIAL_CHANNELS} | {"de": 0.02 * ones}
    p = SimpleNamespace(smooth={k: 0.5 * raw[k] for k in raw}, driven=("beta", "p", "r"), moved=(),
                        start={k: 0.25 for k in raw}, n=n, raw=raw, own_noise={"V": 0.1 * ones},
                        altitude=None, filt=lambda x: 0.5 * np.asarray(x))
    monkeypatch.setattr(along, "inertial_angles", lambda ch, src: {"alpha": ones, "beta": sine})
    states, surfaces = along.model_states(p)
    assert np.array_equal(states["beta"], sine) and np.array_equal(states["p"], raw["p"])
    assert np.array_equal(states["q"], np.full(n, 0.25)) and np.allclose(states["V"], 0.9)
    assert np.array_equal(surfaces["de"], raw["de"])
    # the vane's own sideslip (vane_beta) is the recorded one
    assert np.array_equal(along.model_states(p, vane_beta=True)[0]["beta"], raw["beta"])


def test_the_smallest_delay_named_is_a_time_and_at_least_one_and_a_half_samples():
    """stepwise_axes.practical_delay: 40 ms (three times the 13 ms a noise-free self-check
    shows at 50 Hz) and no less than 1.5 samples: 40 ms at 50, 100 and 200 Hz (two samples
    gave 10 ms at 200 Hz, where a self-check shows 5 ms), 60 ms at 25 Hz and 75 ms at 20 Hz
    (two samples gave 100 ms, over an 80 ms actuator delay)."""
    from harness.diagnosis.stepwise_axes import practical_delay
    for rate, floor in ((50.0, 0.04), (100.0, 0.04), (200.0, 0.04), (25.0, 0.06), (20.0, 0.075)):
        assert practical_delay(1.0 / rate) == pytest.approx(floor)
    assert practical_delay(1.0 / 20.0) < 0.08 < 2.0 / 20.0


def test_a_heading_recorded_wrapped_is_read_as_the_continuous_angle(tmp_path):
    """A heading in [0, 2π) that crosses north steps by 2π (recording-format.md fixes ψ's
    unit, not its range). The diagnosis reads the bank and heading unwrapped
    (prepare.WRAPPED_ANGLES): the same noise level and the same smoothed motion as the
    heading recorded continuous (before, the step made ψ's noise level 2.2 rad)."""
    from harness.diagnosis.gallery import case, write_case
    from harness.diagnosis.prepare import prepare
    from harness.recording_io import read_recording
    rec = read_recording(write_case(case("none"), tmp_path, seed=3)["identification"])
    t = rec.data["t_s"].to_numpy()
    psi = rec.data["psi_rad"].to_numpy() + np.linspace(-0.05, 0.05, t.size)  # a turn through north
    rec.data["psi_rad"] = psi
    continuous = prepare(rec)
    rec.data["psi_rad"] = np.mod(psi, 2.0 * np.pi)
    assert np.ptp(rec.data["psi_rad"]) > 6.0
    wrapped = prepare(rec)
    assert wrapped.noise_std["psi"] == pytest.approx(continuous.noise_std["psi"], rel=1e-9)
    shift = wrapped.smooth["psi"] - continuous.smooth["psi"]
    assert np.allclose(shift, 2.0 * np.pi * round(shift[0] / (2.0 * np.pi)), rtol=0, atol=1e-9)


def test_an_error_of_a_vane_the_maneuver_did_not_drive_says_nothing_of_plausibility():
    """sensor_rules.kinematics_plausible with the recording: on a pitch maneuver (β, p, r not
    driven) a β-vane bias of 18° at t 3 (it shows only through the airspeed's changes) no
    longer makes the kinematics implausible; the same estimate on a maneuver that drove β
    does, and so does an implausible gyro bias on the pitch maneuver (a rate bias shows in
    the Euler-angle equations whatever the maneuver). The implausible estimate is never
    applied."""
    from types import SimpleNamespace

    from harness.diagnosis.sensor_rules import kinematics_plausible, undriven_vane

    def kin(params):
        sel = SimpleNamespace(params=params, std_errors={k: abs(v) / 3.04 for k, v in params.items()}, names=())
        return SimpleNamespace(selection=sel, forced=tuple(params))

    pitch = SimpleNamespace(driven=("alpha", "q", "V", "de"))
    lateral = SimpleNamespace(driven=("beta", "p", "r", "da", "dr"))
    assert undriven_vane("bias_beta", pitch) and undriven_vane("vane_beta_x", pitch)
    assert not undriven_vane("bias_alpha", pitch) and not undriven_vane("bias_q", pitch)
    assert undriven_vane("scale_alpha", lateral) and not undriven_vane("bias_beta", lateral)
    beta = kin({"bias_alpha": 0.0135, "bias_beta": 0.315})
    assert not kinematics_plausible(beta, 427.4)
    assert kinematics_plausible(beta, 427.4, pitch)
    assert not kinematics_plausible(beta, 427.4, lateral)
    assert not kinematics_plausible(kin({"bias_q": 0.3}), 427.4, pitch)
    # and the implausible estimate itself is never applied to the channels (an 18° β bias took
    # a 737 pitch null's states off the model's tables)
    from harness.diagnosis.sensor_rules import applied_sensor_values
    assert applied_sensor_values(beta, False, True, 427.4) == {"bias_alpha": 0.0135}


def test_the_rate_gyros_common_skew_pools_their_own():
    """sensor_rules.suspected_estimate: the three rate gyros' skews, each a weak suspicion
    (an independent c172x null at 100 Hz: p −4.9 ± 1.4, q −4.2 ± 2.3, r −5.8 ± 2.5 ms), give
    their inverse-variance mean and its t for the unit (1/√Σσ⁻²). One gyro that departs from
    the mean by more than GYRO_AGREE_Z of its standard errors, or a single gyro tried, gives
    no unit; any other parameter is the kinematic check's own estimate."""
    from types import SimpleNamespace

    from harness.diagnosis.sensor_rules import GYRO_AGREE_Z, GYRO_UNIT, suspected_estimate, unit_members

    def kin(**skews):
        return SimpleNamespace(selection=SimpleNamespace(params={}, std_errors={}, terms=[
            SimpleNamespace(name=f"skew_{g}", estimate=v, t=v / s, std_error=s) for g, (v, s) in skews.items()]))

    k = kin(p=(-4.9e-3, 1.4e-3), q=(-4.2e-3, 2.3e-3), r=(-5.8e-3, 2.5e-3))
    w = np.array([1.4e-3, 2.3e-3, 2.5e-3]) ** -2.0
    mean = float(np.dot(w, [-4.9e-3, -4.2e-3, -5.8e-3]) / w.sum())
    v, t, se = suspected_estimate(k, GYRO_UNIT)
    assert v == pytest.approx(mean) and se == pytest.approx(w.sum() ** -0.5) and t == pytest.approx(abs(mean) / se)
    assert 4.0 < t < 5.0 and unit_members(k, GYRO_UNIT) == ("skew_p", "skew_q", "skew_r")
    assert suspected_estimate(k, "skew_q") == pytest.approx((-4.2e-3, 4.2 / 2.3, 2.3e-3))
    apart = kin(p=(-4.9e-3, 1.0e-3), q=(+4.0e-3, 1.0e-3))   # each 4.45 standard errors from the mean
    assert GYRO_AGREE_Z < 4.45 and suspected_estimate(apart, GYRO_UNIT) is None
    assert suspected_estimate(kin(q=(-4.2e-3, 2.3e-3)), GYRO_UNIT) is None


def _jet_drift_case(estimate: float, raw: dict | None = None):
    from types import SimpleNamespace
    from harness.diagnosis.evidence import Candidate
    p = SimpleNamespace(meta={"geometry": {"S_ft2": 300.0, "b_ft": 30.0, "cbar_ft": 11.32}}, raw=raw or {})
    trim = SimpleNamespace(thrust_lbf=2000.0, thrust_offset_ft=-0.3, qbar_psf=160.0)
    c = Candidate("flight_condition_drift", "pitch", "Cm", "Cm_dV", estimate, 0.0005, estimate / 0.0005, 0.1,
                  "per unit dV/V", "stepwise on the Cm mismatch", True, "entered")
    return p, trim, c


def test_the_thrust_moment_bound_is_lapse_times_thrust_times_its_offset_over_qbar_s_cbar():
    """|ΔC_m| per unit ΔV/V ≤ THRUST_LAPSE_MAX · T · |z_T| / (q̄ S c̄), with the larger of the
    model's and the metadata's thrust-line offsets; without the metadata's offset Eq. 4 leaves
    the whole moment in the measured C_m, and q̄ ∝ V² adds QBAR_PER_DV to the lapse."""
    from harness.diagnosis.stepwise_axes import QBAR_PER_DV, THRUST_LAPSE_MAX, thrust_moment_bound
    p, trim, _ = _jet_drift_case(0.0)
    moment = 2000.0 * 0.3 / (160.0 * 300.0 * 11.32)
    assert thrust_moment_bound(p, trim) == pytest.approx((THRUST_LAPSE_MAX + QBAR_PER_DV) * moment)
    p.meta["thrust_offset_ft"] = 0.5
    assert thrust_moment_bound(p, trim) == pytest.approx(THRUST_LAPSE_MAX * 2000.0 * 0.5 / (160.0 * 300.0 * 11.32))


@pytest.mark.parametrize("estimate, named", [(0.003, False), (-0.003, False), (0.02, True)])
def test_a_jet_pitch_drift_without_thrust_is_named_only_beyond_what_the_thrust_could_imitate(estimate, named):
    """Without a thrust channel a jet's C_m ΔV/V term is offered (its thrust moment is small),
    and named only two standard errors beyond the bound (0.0044 here); with thrust recorded
    the rule stays out of the way."""
    from harness.diagnosis.stepwise_axes import withhold_thrust_drift
    p, trim, c = _jet_drift_case(estimate)
    withhold_thrust_drift([c], p, trim)
    assert c.selected is named
    assert c.details["thrust_bound"] == pytest.approx(0.0044, abs=1e-4)
    assert "could imitate a C_m drift of up to 0.0044" in c.reason
    assert c.reason.startswith("not named") != named
    p, trim, c = _jet_drift_case(estimate, raw={"thrust": np.zeros(3)})
    withhold_thrust_drift([c], p, trim)
    assert c.selected and "thrust_bound" not in c.details


@pytest.mark.parametrize("name, driven, channels, vane", [
    ("bias_beta", ("alpha", "q", "de"), ("h",), "beta"),       # a pitch maneuver: β still
    ("vane_beta_x", ("alpha", "q", "de"), ("h",), "beta"),
    ("bias_beta", ("beta", "p", "r", "da"), ("h",), None),      # β driven
    ("bias_alpha", ("beta", "p", "r", "da"), ("h",), None),     # α still, but the flight path records it
    ("bias_alpha", ("beta", "p", "r", "da"), (), "alpha"),      # α still and no altitude
    ("bias_q", ("alpha", "q", "de"), (), None)])
def test_a_still_angle_s_error_is_untestable_where_only_the_airspeed_change_shows_it(name, driven, channels, vane):
    """steady_vane: a constant error of an angle the maneuver never drove reaches the
    kinematics only as V̇·b; β always (no ground track), α only without an altitude record."""
    from types import SimpleNamespace
    from harness.diagnosis.sensor_rules import steady_vane, steady_vane_reason
    p = SimpleNamespace(driven=driven, raw={c: None for c in channels})
    assert steady_vane(name, p) == vane
    if vane:
        assert "never drove" in steady_vane_reason(vane) and "V̇·b" in steady_vane_reason(vane)


def test_the_augmented_model_is_written_where_the_model_cannot_be_trimmed(tmp_path):
    """augmented.write_model: a model that cannot be trimmed at the recording's start (its
    replays could not be made) still gets its augmented XML, the added terms written about the
    recording's own first α, V and surface positions, and the note says so (a pa28 recording
    at 190 ft/s, which the package's pa28 cannot fly level, had stopped the whole diagnosis
    with the trim's error at this last step). Without those references the trim's error stands."""
    from models.aircraft import Aircraft
    from models.hidden import HiddenEffect, hidden_root
    from models.replay import InitialCondition
    from models.trim import TrimError

    from harness.diagnosis.augmented import write_model
    aircraft, ic = Aircraft(), InitialCondition(h_ft=10_000.0, V_fps=90.0, alpha_rad=0.2)
    added = (HiddenEffect("coefficient_error", 0.5, coefficient="CZ", regressor="alpha"),)
    start = {"alpha": 0.2, "dV": 90.0, "de": -0.05, "da": 0.0, "dr": 0.0}
    info = write_model(tmp_path, aircraft, ic, added, start_refs=start)
    assert "cannot be trimmed at the recording's start" in info["note"] and "cannot trim" in info["note"]
    assert (tmp_path / info["augmented_xml"]).is_file()
    with pytest.raises(TrimError):
        write_model(tmp_path / "again", aircraft, ic, added)
    root, name = hidden_root(Aircraft(hidden=added), ic.condition(), start)  # every reference given: no trim
    assert (root / "aircraft" / name / f"{name}.xml").is_file()


def test_a_recording_through_the_vertical_is_refused_for_that_reason():
    """verdict.check_attitude_range: a record whose pitch attitude comes within 5 deg of the
    vertical is refused naming the attitude and the time (the Euler kinematics are singular
    there; an F-16 pull-up that went over the top had been refused for its time column)."""
    from types import SimpleNamespace

    import numpy as np

    from harness.diagnosis.verdict import DiagnosisError, check_attitude_range
    t = np.arange(0, 10, 0.02)
    level = SimpleNamespace(name="identification", t=t, raw={"theta": np.radians(30 * np.sin(t))})
    check_attitude_range(level)
    over = SimpleNamespace(name="identification", t=t, raw={"theta": np.radians(89.7 * np.sin(t / 2))})
    with pytest.raises(DiagnosisError, match=r"theta = 89\.7 deg \(at t = 3\.14 s\), within 5 deg of the vertical"):
        check_attitude_range(over)


def _throttle_recording(throttle, thrust: bool = False):
    import pandas as pd
    from maneuvers.recording import Recording
    n = len(throttle)
    data = pd.DataFrame({"t_s": np.arange(n) * 0.02, "throttle_1": np.asarray(throttle, dtype=float)})
    if thrust:
        data["thrust_lbf"] = 2000.0
    return Recording(data=data, meta={}, name="r")


def test_a_moved_throttle_without_thrust_contradicts_the_constant_thrust_stand_in():
    """throttle_travel gives the throttle's 1st-99th percentile range when it moved more than
    THROTTLE_STEADY with no thrust channel; a held throttle (or thrust recorded) gives None,
    and one spike does not count as travel."""
    from harness.diagnosis.prepare import THROTTLE_STEADY, _stand_ins, throttle_travel
    moved = np.r_[np.full(200, 0.3), np.full(200, 0.6), np.full(200, 0.3)]
    assert throttle_travel(_throttle_recording(moved)) == pytest.approx((0.3, 0.6))
    assert throttle_travel(_throttle_recording(moved, thrust=True)) is None
    held = np.full(600, 0.7) + np.random.default_rng(1).normal(scale=0.002, size=600)
    held[300] = 1.0
    assert throttle_travel(_throttle_recording(held)) is None
    assert throttle_travel(_throttle_recording(np.linspace(0.5, 0.5 + 0.9 * THROTTLE_STEADY, 600))) is None
    entry = _stand_ins({}, {}, ("t_s", "throttle_1"), (0.3, 0.6))[0]
    assert entry["item"] == "thrust" and "moved from 0.30 to 0.60" in entry["contradicted_by"]
    assert "contradicted_by" not in _stand_ins({}, {}, ("t_s",))[0]


@pytest.mark.parametrize("propeller", [False, True])
def test_terms_a_thrust_change_imitates_are_withheld_when_the_throttle_moved_unrecorded(propeller):
    """With the throttle moving and no thrust channel, candidates on C_X and C_m (terms, a
    moment-reference shift, the stabilator's delay) are withheld, and behind a propeller C_l
    and C_n's too; C_Z's and sensor candidates stay; a held throttle withholds nothing."""
    from types import SimpleNamespace
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.stepwise_axes import NOT_WITH_THROTTLE, withhold_on_moving_throttle

    def cands():
        return [Candidate("coefficient_error", "lon", ch, f"{ch}_x", 0.1, 0.01, 10.0, 0.5, "-", test, True, "entered")
                for ch, test in (("CX", "stepwise on the CX mismatch"), ("Cm", "stepwise on the Cm mismatch"),
                                 ("de", "delay scan of de + stepwise"), ("CZ", "stepwise on the CZ mismatch"),
                                 ("Cn", "stepwise on the Cn mismatch"), ("q", "kinematic"))]
    moved = np.r_[np.full(300, 0.3), np.full(300, 0.6)]
    p = SimpleNamespace(recording=_throttle_recording(moved))
    cs = cands()
    withhold_on_moving_throttle(cs, p, propeller)
    withheld = {c.channel for c in cs if not c.selected}
    assert withheld == ({"CX", "Cm", "de", "Cn"} if propeller else {"CX", "Cm", "de"})
    assert all(c.reason == NOT_WITH_THROTTLE for c in cs if not c.selected)
    cs = cands()
    withhold_on_moving_throttle(cs, SimpleNamespace(recording=_throttle_recording(np.full(600, 0.6))), propeller)
    assert all(c.selected for c in cs)


@pytest.mark.parametrize("cz_std_error, caveat", [(0.05, True), (0.01, False)])
def test_a_named_control_derivative_says_a_surface_position_scale_would_read_as_it(cz_std_error, caveat):
    """A C_m,δe change f = −10 % is a δe position scale k = −f/(1 + f) = +0.111 unless another
    δe derivative moved by other than f of its model value beyond SURFACE_SCALE_Z standard
    errors: C_Z,δe changed −0.04 where the scale predicts +0.04 (model −0.4) is 1.6 standard
    errors off at ±0.05 (the caveat stays) and 8 at ±0.01 (the scale is ruled out)."""
    from harness.diagnosis.evidence import Candidate
    from harness.diagnosis.term_rules import note_surface_scale

    def coefficient(name, model, change, se, selected):
        return Candidate("coefficient_error", "pitch", name.split("_")[0], name, model + change, se, change / se, 0.3,
                         "per rad", "stepwise", selected, "entered",
                         {"change": change, "model_over_maneuver": model, "model_at_trim": model})
    cm = coefficient("Cm_de", -0.5, 0.05, 0.003, True)
    cz = coefficient("CZ_de", -0.4, -0.04, cz_std_error, False)
    note_surface_scale([cm, cz, coefficient("Cm_alpha", -0.3, 0.05, 0.003, True)])
    scale = cm.details["surface_scale"]
    assert scale["scale"] == pytest.approx(0.1 / 0.9) and scale["fraction"] == pytest.approx(-0.1)
    assert scale["tested_by"]["CZ_de"]["scale_predicts"] == pytest.approx(0.04)
    assert scale["ruled_out"] is not caveat
    assert ("de position-sensor scale error of +0.111" in cm.details.get("not_ruled_out", "")) is caveat
    assert "surface_scale" not in cz.details


def test_variance_inflation_is_one_over_one_minus_r_squared_and_a_geared_surface_keeps_its_trim_derivative():
    """Two regressors correlated r have VIF 1/(1 − r²) each (exactly, for sample correlation
    r); a column the others reproduce exactly is infinite. effective_derivatives then leaves
    a regressor beyond COLLINEAR_VIF out, so library() falls back on its trim derivative."""
    from harness.diagnosis.candidates import COLLINEAR_VIF, variance_inflation
    rng = np.random.default_rng(3)
    x = rng.normal(size=2000)
    y = 0.6 * x + 0.8 * rng.normal(size=2000)
    r = np.corrcoef(x, y)[0, 1]
    vif = variance_inflation(np.column_stack([x, y, np.ones_like(x)]))
    assert vif == pytest.approx([1.0 / (1.0 - r * r)] * 2, rel=1e-9)
    geared = np.column_stack([x, 0.5 * x, y, np.ones_like(x)])
    assert np.all(variance_inflation(geared)[:2] > 1e12) and variance_inflation(geared)[2] < COLLINEAR_VIF


def test_a_geared_surface_gets_no_effective_derivative_of_its_own(monkeypatch):
    """With the rudder geared to the aileron (dr = 0.5 da) the model's C_n regressed on β, p̂,
    r̂, δa, δr cannot split δa from δr: effective_derivatives gives β, p̂ and r̂ their values
    and leaves δa and δr out (library() then takes their trim derivatives)."""
    from types import SimpleNamespace
    from harness.diagnosis import candidates
    rng = np.random.default_rng(5)
    n = 1500
    reg = {k: rng.normal(size=n) for k in ("beta", "phat", "rhat", "da")}
    reg["dr"] = 0.5 * reg["da"]
    monkeypatch.setattr(candidates, "regressors", lambda p: reg)
    model = 0.2 * reg["beta"] - 0.3 * reg["phat"] - 0.8 * reg["rhat"] + 0.005 * reg["da"] - 0.04 * reg["dr"]
    got = candidates.effective_derivatives(SimpleNamespace(n=n, dt=0.02), "Cn", model)
    assert set(got) == {"Cn_beta", "Cn_phat", "Cn_rhat"}
    assert got["Cn_beta"] == pytest.approx(0.2) and got["Cn_rhat"] == pytest.approx(-0.8)


def _long_record_case(shift: bool):
    """A 90 s record at 50 Hz whose stabilator moves over 1-21 s; the C_X mismatch is either a
    level that differs between the maneuver and the quiet flight after it (``shift``) or a
    true α² term, with white noise."""
    from types import SimpleNamespace
    from harness.diagnosis.evidence import Candidate
    rng = np.random.default_rng(7)
    t = np.arange(4500) * 0.02
    on = (t > 1.0) & (t < 21.0)
    de = np.where(on, 0.05 * np.sin(2 * np.pi * 0.5 * t), 0.0)
    alpha = np.where(on, 0.02 * np.sin(2 * np.pi * 0.5 * t + 0.3), 0.0)
    z = (np.where(t < 22.0, -0.0004, 0.0) if shift else -3.0 * alpha ** 2) + rng.normal(scale=1e-4, size=t.size)
    p = SimpleNamespace(n=t.size, dt=0.02, driven=("alpha", "q", "de"), smooth={"de": de}, start={"de": 0.0})
    term = SimpleNamespace(column=alpha ** 2, parameter="CX_alpha2")
    step = SimpleNamespace(selections={"CX": (SimpleNamespace(names=["alpha2"]), {"alpha2": term})}, nuisances={})
    c = Candidate("nonlinear_alpha", "lon", "CX", "CX_alpha2", -3.0, 0.5, -6.0, 0.1, "per rad^2",
                  "stepwise on the CX mismatch", True, "entered")
    return p, step, {"CX": z}, c


@pytest.mark.parametrize("shift", [True, False])
def test_an_alpha_square_must_hold_inside_the_maneuver_window_of_a_long_record(shift):
    """maneuver_window is 1 s before to 8 s after the inputs (0-29 s of 90 s); a level shift
    between the maneuver and the quiet flight after it, which an α² column fits over the whole
    record, has no α² shape inside it (withheld), a true α² keeps its t there (named); a
    maneuver filling 70 % of the record gives no window."""
    from harness.diagnosis.term_rules import maneuver_window, withhold_even_term_off_the_quiet_flight
    p, step, mismatch, c = _long_record_case(shift)
    window = maneuver_window(p)
    assert window.start * p.dt == pytest.approx(0.0, abs=0.1) and window.stop * p.dt == pytest.approx(29.0, abs=0.1)
    withhold_even_term_off_the_quiet_flight([c], step, p, mismatch)
    assert c.selected is not shift
    assert ("only beside the quiet flight" in c.reason) is shift
    p.smooth["de"], p.n = p.smooth["de"][:1500], 1500
    assert maneuver_window(p) is None


def test_the_model_goes_through_the_common_filter_after_its_nonlinear_terms(monkeypatch):
    """along.filtered: the model's coefficients along the raw states, through the common
    filter, are the measured side's own operation (the filter of what the aerodynamics did),
    so a drag polar's α² leaves no mismatch; the model of the filtered α leaves the power the
    filter removed, filt(α²) − filt(α)², which an α² column fits (the c172x's C_X α² of the
    along.model_states docstring)."""
    from estimators.smoothing import sine_series_filter
    from harness.diagnosis.along import filtered
    from models.replay import AeroAlong
    n, dt = 2001, 0.02
    t = np.arange(n) * dt
    freqs = np.arange(1, n - 1) / (2 * (n - 1) * dt)        # sine-series frequencies, Hz
    weights = np.clip((1.1 - freqs) / 0.6, 0.0, 1.0)         # a Wiener-like taper from 0.5 to 1.1 Hz
    rng = np.random.default_rng(5)
    # a pitch maneuver's α about trim: content in and beyond the taper (0.3-2 Hz), 1.3° RMS
    alpha = 0.03 + sum(a * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
                       for a, f in ((0.015, 0.3), (0.01, 0.7), (0.008, 1.0), (0.006, 1.5), (0.004, 2.0)))
    k = 7.0                                                  # the polar's curvature, per rad²
    measured = sine_series_filter(k * alpha ** 2, weights)   # Eq. 1 on filtered accelerations
    from types import SimpleNamespace

    from harness.diagnosis import along
    from harness.diagnosis.prepare import COEFFICIENTS
    trim = SimpleNamespace(thrust_lbf=0.0)
    model = filtered(AeroAlong({"CX": k * alpha ** 2}, {}, {}, trim), weights).coefficients["CX"]
    assert np.allclose(model, measured, atol=1e-12)
    # along.model_along itself: the model (a drag polar in the state it is given) along the
    # recorded α, then the filter; the measured side the filter of the true polar
    zero = np.zeros(n)
    monkeypatch.setattr(along, "aero_along", lambda aircraft, ic, states, surfaces, alphadot: AeroAlong(
        {c: k * states["alpha"] ** 2 if c == "CX" else zero for c in COEFFICIENTS}, {}, {}, trim))
    monkeypatch.setattr(along, "measured_coefficients", lambda *args: {c: measured if c == "CX" else zero
                                                                        for c in COEFFICIENTS})
    monkeypatch.setattr(along, "thrust_stand_in", lambda p, thrust: 0.0)
    p = SimpleNamespace(raw={"alpha": alpha}, smooth={"alpha": sine_series_filter(alpha, weights)},
                        deriv={"alpha": zero}, driven=("alpha",), moved=(), start={"alpha": 0.03}, n=n,
                        own_noise={}, altitude=None, weights=weights, meta={}, mass=None)
    assert np.allclose(along.model_along(p, None, None).mismatch()["CX"], 0.0, atol=1e-12)
    old = k * sine_series_filter(alpha, weights) ** 2       # the model of the filtered α
    inner = slice(250, n - 250)
    da = sine_series_filter(alpha, weights)[inner] - 0.03
    A = np.column_stack([np.ones(da.size), da, da ** 2])
    fit = lambda z: np.linalg.lstsq(A, z[inner], rcond=None)[0][2]
    assert abs(fit(measured - model)) < 1e-9
    assert fit(measured - old) < -0.05 * k                   # the artifact the old order left (-14 % of k)




def test_the_mass_assumption_names_only_the_keys_the_recording_leaves_constant():
    """The assumption names the mass keys that stand in as metadata constants: every one when
    no mass channel is recorded, the rest when only some are (an independent script's
    recording with the inertias as channels and the mass in its metadata was reported as
    having no mass channels at all)."""
    from harness.diagnosis.prepare import _stand_ins
    from maneuvers.format_rules import MASS_KEYS
    raw = {s: np.zeros(3) for s in ("thrust", "de", "da", "dr")}
    meta = {"thrust_offset_ft": 0.0, "sensors": {"accelerometer_ft": [0.0, 0.0, 0.0]}}
    mass = {a["item"]: a for a in _stand_ins(raw, meta, ("t_s",))}["mass and inertia"]
    assert mass["missing"] == "mass channels" and "metadata's constants" in mass["stood_in_by"]
    inertias = MASS_KEYS[1:]
    mass = {a["item"]: a for a in _stand_ins(raw, meta, ("t_s",) + inertias)}["mass and inertia"]
    assert mass["missing"] == "mass_slug channels"
    assert all(k in mass["stood_in_by"] for k in inertias)
    assert "mass and inertia" not in {a["item"] for a in _stand_ins(raw, meta, ("t_s",) + MASS_KEYS)}
