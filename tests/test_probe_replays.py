"""Kept probe draws replayed (tests/probe/: recordings made by an independent script, jsbsim and
numpy only): each was a false finding or a miss of the diagnosis, fixed by the rule its test
names. Split from test_independent_script.py so the two files run on separate workers."""
from __future__ import annotations

import pytest

from probe_replay import _diagnosed_probe, _found, _named_alone, _withheld_for


def test_a_mode_the_carry_puts_into_a_z_is_not_read_as_the_accelerometer_s_position(tmp_path):
    """The probe's seed 3454 (tests/probe/gen.py, jsbsim and numpy only): a T-37 (17,100 ft /
    423 ft/s, stabilator 2-1-1s at 25 Hz) whose accelerometer sits 5.3 ft aft and 1.7 ft below
    the c.g., as its metadata say, with a 4.5 Hz mode driven by the stabilator's rate in q and
    a_z. At 25 Hz the mode lies inside the common filter's band (6.1 Hz), and the carry to the
    c.g. put the gyro's modal q̇ times the arm into a_z, which the force mismatch read as the
    accelerometer 4.8 ft from where the metadata put it (t 38). The position it reads grows
    with the band (2.2 ± 0.3 ft below 3 Hz); a rigid offset does not
    (stepwise_axes._offset_by_band): not named."""
    truth, result = _diagnosed_probe(3454, tmp_path, calibrate=False)
    assert truth["aircraft"] == "T37" and truth["effect"] == "structural_mode"
    assert "x_accelerometer" not in [p for p, _ in _found(result)]
    offset = next(c for c in result["candidates"] if c["parameter"] == "x_accelerometer")
    assert "not a rigid offset" in offset["reason"], offset["reason"]


def test_a_mode_a_quiet_record_keeps_as_motion_is_named_and_nothing_beside_it(tmp_path):
    """The probe's seed 3518 (tests/probe/gen.py): a noise-free A-4 (9,100 ft / 659 ft/s,
    three-axis multisine at 100 Hz) with a 9.4 Hz mode driven by the stabilator in q and a_z.
    The common filter keeps everything to 37 Hz on a noise-free record, so the search above
    three times that found no band and the mode was missed; its in-band part was read as an α
    scale of −0.081 (t −8.6). The search takes the motion to end at 3 Hz
    (spectra.RIGID_BODY_CUTOFF_HZ) and names the mode; with its output taken out of q and a_z
    the kinematics no longer take the α scale (mode_model.withhold_sensor_errors_a_mode_makes)."""
    # calibrated, as the command line does: the in-band mode a 37 Hz filter keeps in a_z and q̇ also
    # enters as C_X,α and C_m,δe, which the loop sizes at nothing and withdraws
    truth, result = _diagnosed_probe(3518, tmp_path, calibrate_workers=1)
    assert truth["aircraft"] == "A4" and truth["effect"] == "structural_mode" and truth["noise_factor"] == 0.0
    _named_alone(result, truth, rel=0.02)
    scale = next(c for c in result["candidates"] if c["parameter"] == "scale_alpha")
    assert "mode's output taken out" in scale["reason"], scale["reason"]


def test_a_driven_mode_names_no_derivative_of_its_surface(tmp_path):
    """The probe's seed 3680 (tests/probe/gen.py): an F-4N (24,700 ft / 545 ft/s, three-axis
    sweeps at 40 Hz, q̇ recorded, the accelerometer's position in the metadata) with a 10.5 Hz
    mode driven by the stabilator in q, a_x and a_z. The mode was named and beside it C_X,δe
    −0.19 and C_m,δe −1.23 (t −11 and −8), the mode's quasi-static part below its resonance,
    confirmed by the validation maneuver, which rang the same mode. With the mode's output
    taken out of its channels the analysis names neither
    (mode_model.withhold_terms_a_mode_makes)."""
    truth, result = _diagnosed_probe(3680, tmp_path, calibrate=False)
    assert truth["aircraft"] == "F4N" and truth["effect"] == "structural_mode"
    _named_alone(result, truth, rel=0.02)
    for name in ("CX_de", "Cm_de"):
        term = next(c for c in result["candidates"] if c["parameter"] == name)
        assert "mode's output taken out" in term["reason"], term["reason"]


def test_a_vane_the_accelerometers_position_makes_is_not_named(tmp_path):
    """The probe's seed 3632 (tests/probe/gen.py): a c182 (5,200 ft / 173 ft/s, pitch sweep at
    50 Hz, mass channels with fuel burn, columns shuffled) with its accelerometer 8.8 ft ahead of
    the c.g. The force mismatch named the position (6.7 ± 0.3 ft) and the kinematics, whose α
    equation integrates the q̇·x/g in a_z into q·x/V, a vane 8.8 ft behind beside it (t −11.3).
    With the accelerometer at the named position the kinematics no longer take the vane
    (accelerometer_rules.withhold_vane_an_accelerometer_makes)."""
    truth, result = _diagnosed_probe(3632, tmp_path, calibrate=False)
    assert truth["aircraft"] == "c182" and truth["parameter"] == "x_accelerometer"
    _named_alone(result, truth)
    vane = next(c for c in result["candidates"] if c["parameter"] == "vane_alpha_x")
    assert "integrates into a vane" in vane["reason"], vane["reason"]


def test_an_undriven_gyro_s_noise_does_not_shrink_the_accelerometer_s_position(tmp_path):
    """The probe's seed 3753 (tests/probe/gen.py): an F-15 (12,300 ft / 821 ft/s, pitch doublets
    at 25 Hz, q̇ recorded) with its accelerometer 9.7 ft ahead of the c.g. The position's C_Y
    column x·ṙ, built on the yaw gyro's differentiated noise, outweighed C_Z's q̇·x and read
    the position at 2.4 ± 0.5 ft; C_Z,α and C_Z,δe changes were named in its place. With the
    undriven rates at their means (candidates.accelerometer_columns) the force mismatch reads
    10.2 ± 1.0 ft, which it cannot tell from a change of lift along α on this maneuver:
    neither is named (a miss, not a false finding)."""
    truth, result = _diagnosed_probe(3753, tmp_path, calibrate=False)
    assert truth["aircraft"] == "f15" and truth["parameter"] == "x_accelerometer" and truth["kind"] == "pitch"
    assert _found(result) == []
    position = next(c for c in result["candidates"] if c["parameter"] == "x_accelerometer")
    assert position["estimate"] == pytest.approx(truth["truth"], abs=2.0 * position["std_error"])


def test_a_slow_aircraft_s_airspeed_error_of_a_tenth_is_not_read_as_its_rate_derivatives(tmp_path):
    """The probe's seed 3859 (tests/probe/gen.py): a J-3 Cub (1,400 ft / 103 ft/s, lateral
    3-2-1-1s at 200 Hz, noise twice flight test's) with V 11.9 ft/s high, 11.5 % of V. The rates
    normalised by the biased V put −10 % of each rate term into the mismatch, and C_l,p̂ −0.054
    (t −45), C_n,p̂ and C_l,r̂ were named: the airspeed error that fits in their place was over
    the 10 % of V allowed an instrument. At least 10 kt is allowed now
    (kinematics.AIRSPEED_ERROR_FLOOR_FPS): none is named (the bias itself, t 3 in the
    kinematics, is missed)."""
    # calibrated, as the command line does: a C_Y,p̂ change of +0.029 also enters, which the loop withdraws
    truth, result = _diagnosed_probe(3859, tmp_path, calibrate_workers=1)
    assert truth["aircraft"] == "J3Cub" and truth["parameter"] == "bias_V"
    assert _found(result) == []
    term = next(c for c in result["candidates"] if c["parameter"] == "Cl_phat")
    assert "an airspeed error of" in term["reason"], term["reason"]


def test_a_slow_aircraft_s_airspeed_bias_is_named_and_the_model_trimmed_where_it_flew(tmp_path):
    """The probe's seed 3998: a noise-free J-3 Cub (2,900 ft / 103 ft/s, stabilator doublet) with
    V 8.8 ft/s high, 8.6 % of V. The bias was left out of the kinematic fit as implausible (over
    5 % of V; at least 10 kt is allowed now, kinematics.AIRSPEED_ERROR_FLOOR_FPS) and an α scale
    of −0.041, then a C_m,δe 2.3 % weaker than the model, were named: the model had been trimmed
    at the recorded airspeed, its propeller's thrust and slipstream those of a faster flight.
    Trimmed at the corrected airspeed (along.corrected_start) the bias alone is named."""
    truth, result = _diagnosed_probe(3998, tmp_path, calibrate_workers=1)
    assert truth["aircraft"] == "J3Cub" and truth["parameter"] == "bias_V" and truth["noise_factor"] == 0.0
    _named_alone(result, truth, rel=0.25)


def test_a_wing_mode_between_the_motion_and_three_times_its_cut_off_is_found(tmp_path):
    """The probe's seed 4078: a J-3 Cub (3,500 ft / 111 ft/s, pitch 3-2-1-1 at 50 Hz, noise half
    flight test's) whose q rings a 6.5 Hz mode at 0.8 deg/s. The motion ends at 3 Hz; searched
    from three times that the mode went unseen and nothing was found. From twice it
    (spectra.MOTION_POWER_FACTOR) it is named at its frequency."""
    truth, result = _diagnosed_probe(4078, tmp_path, calibrate=False)
    assert truth["aircraft"] == "J3Cub" and truth["parameter"] == "mode_frequency_hz"
    _named_alone(result, truth, rel=0.02)


def test_an_offset_accelerometer_s_echo_of_a_lateral_input_is_no_mode(tmp_path):
    """The probe's seed 4082: a J-3 Cub (3,800 ft / 100 ft/s, lateral doublets at 100 Hz) with its
    accelerometer 5.3 ft left of the c.g. The position was named right and beside it a 4.95 Hz
    "mode" in a_x (p 3e-8, the validation's too): the doublets' fifth harmonic read through ṙ·y,
    a_x being asked only about the stabilator's lines. An accelerometer echoes every surface now
    (spectra.ECHO_DRIVERS)."""
    truth, result = _diagnosed_probe(4082, tmp_path, calibrate=False)
    assert truth["aircraft"] == "J3Cub" and truth["parameter"] == "offset_y"
    _named_alone(result, truth, rel=0.25)


def test_the_drag_a_named_lift_change_carries_is_no_second_finding(tmp_path):
    """The probe's seed 4128: an F-4N (15,800 ft / 860 ft/s, pitch sweep at 100 Hz, noise 1.7
    times flight test's) with a C_Z α² of −25 concealed as lift. It was named (−23 ± 4) and beside
    it a C_X α² of −0.64 (t −7.9): the F-4N's induced drag, 0.14·C_L², follows the lift added.
    Beside the drag-due-to-lift column (term_rules.induced_drag_column) the C_X term stands at
    t 1.1, its factor k 0.16: the lift change is named alone."""
    truth, result = _diagnosed_probe(4128, tmp_path, calibrate=False)
    assert truth["aircraft"] == "F4N" and truth["parameter"] == "CZ_alpha2"
    _named_alone(result, truth, rel=0.25)
    cx = next(c for c in result["candidates"] if c["parameter"] == "CX_alpha2")
    assert "drag due to lift" in cx["reason"], cx["reason"]


def test_a_rate_lag_the_kinematics_give_to_its_attitude_is_no_aileron_delay(tmp_path):
    """The probe's seed 4167: an F-4N (15,000 ft / 583 ft/s, lateral 2-1-1s at 40 Hz) with p
    62 ms late. The kinematics gave the relative skew to φ (−60 ms, t −11.7; p's own 29 ± 16 ms)
    and an aileron delay of 64 ms was named. A lagging rate and its attitude leading are one skew
    to them (term_rules.RATE_ATTITUDE): the delay is withheld and nothing is named."""
    truth, result = _diagnosed_probe(4167, tmp_path, calibrate=False)
    assert truth["aircraft"] == "F4N" and truth["parameter"] == "skew_p"
    assert _found(result) == []
    delay = next(c for c in result["candidates"] if c["parameter"] == "tau_da")
    assert "phi leading p" in delay["reason"], delay["reason"]


@pytest.mark.parametrize("seed", [4355, 4369])
def test_a_shift_whose_stiffness_change_is_withheld_is_named_from_the_mistrim(tmp_path, seed):
    """The probe's seeds 4355 and 4369: a Cessna 172R (pitch, reference point 0.67 ft forward)
    and a 787-8 (three-axis, 3.07 ft forward), thrust not recorded. The stepwise entered C_m,α
    changes for the shifts' C_Z columns (t 32.5, 8.1), withheld because C_m's constant carries
    the mistrim of a shift of the same sign (−0.74, −3.18 ft), which a C_m,α change about trim
    does not make, and nothing was named. That shift is now the candidate in the change's place
    (stepwise_axes.withhold_stiffness_a_shift_makes): it alone is named, within 25 %."""
    truth, result = _diagnosed_probe(seed, tmp_path, calibrate=False)
    assert truth["parameter"] == "dx_moment_reference"
    _named_alone(result, truth, rel=0.25)
    _withheld_for(result, "Cm_alpha", "the shift is the candidate in its place")


def test_an_airspeed_correction_takes_the_stand_in_altitude_with_it(tmp_path):
    """The probe's seed 4453: a J-3 Cub (3,350 ft / 97 ft/s, lateral multisine at 100 Hz, no
    h channel) with V 8.0 ft/s low. The altitude stood in from q̄ and V was −2,780 ft, and with
    the airspeed corrected it stayed there: the model flown at that density, its propeller's
    power with it, had C_l,β, C_l,r̂, C_n,p̂ and C_n,δr named. The altitude is taken again from
    the corrected channels (along.corrected_recording): nothing is named."""
    truth, result = _diagnosed_probe(4453, tmp_path, calibrate=False)
    assert truth["aircraft"] == "J3Cub" and truth["parameter"] == "bias_V"
    assert [p for p, _ in _found(result)] in ([], ["bias_V"])


def test_a_gyro_skew_carries_the_accelerometer_to_the_cg_again(tmp_path):
    """The probe's seed 4544: a c172x (6,000 ft / 167 ft/s, lateral 3-2-1-1s at 50 Hz, 1.5 times
    the noise, the accelerometer declared 2.5 ft below the c.g.) with p 68 ms late had the skew
    named (65 ms) and a C_Y,δa change of +0.070 beside it: a_y was carried to the c.g. with the
    late ṗ. The skew's correction carries it again (prepare.recarried_accelerations), so the
    skew imitates the change and reaches C_Y (sensor_naming.withhold_imitated_by_named)."""
    truth, result = _diagnosed_probe(4544, tmp_path, calibrate=False)
    assert truth["aircraft"] == "c172x" and truth["parameter"] == "skew_p"
    _named_alone(result, truth, rel=0.25)
    _withheld_for(result, "CY_da", "the skew_p named")


def test_an_accelerometer_offset_rivalled_by_c_z_alpha_on_the_inertial_alpha(tmp_path):
    """The probe's seed 4448: an A-4 (17,600 ft / 598 ft/s, a 0.7° pitch 3-2-1-1 at 50 Hz, 1.14
    times the noise) with C_Z,α 0.81 more negative was named an accelerometer 10.4 ft aft
    (t −7.0): the α vane's wander is as large as the maneuver's α, so C_Z,α on the vane's α
    hardly fits (t +1.9 beside the position) and the clean q̇ of x·q̇ took its place. On the
    inertial α the position falls to t −2.4 (candidates.offset_rival): not named."""
    truth, result = _diagnosed_probe(4448, tmp_path, calibrate=False)
    assert truth["aircraft"] == "A4" and truth["parameter"] == "CZ_alpha"
    assert _found(result) == []
    _withheld_for(result, "x_accelerometer", "cannot tell it from CZ_alpha on the inertial α")


def test_a_term_the_unnamed_accelerometer_position_imitates_is_withheld(tmp_path):
    """The probe's seed 4560: an F-16 (21,100 ft / 595 ft/s, lateral 2-1-1s at 40 Hz, 1.38 times
    the noise, ṗ, q̇, ṙ recorded) with the accelerometer 6.9 ft to the right had a C_Y,p̂ change
    of −1.02 named (t −5.5): the force mismatches read the position (y 6.1 ± 0.3 ft, t 19), which
    x_accelerometer does not name, and beside it the change stands at t −1.9
    (accelerometer_rules.withhold_beside_the_accelerometer)."""
    truth, result = _diagnosed_probe(4560, tmp_path, calibrate=False)
    assert truth["aircraft"] == "f16" and truth["parameter"] == "offset_y"
    assert _found(result) == []
    _withheld_for(result, "CY_phat", "imitated by the accelerometer's position")


def test_a_rate_change_an_unoffered_airspeed_drift_would_make_is_not_named(tmp_path):
    """The probe's seed 4639: a T-37 (16,900 ft / 363 ft/s, a 0.18-1.5 Hz pitch sweep at 40 Hz,
    0.31 times the noise) with C_m ΔV/V +1.19 had a C_m,q̂ change of +2.9 named (t 9.0). The
    airspeed moved 0.2 %, 2.3 times its noise, so no ΔV/V term was offered; beside its column
    C_m,q̂ falls to t 1.7 and ΔV/V stands at 11.1 (term_rules.withhold_beside_an_unoffered_term):
    nothing is named, and the verdict says a term was withheld."""
    truth, result = _diagnosed_probe(4639, tmp_path, calibrate=False)
    assert truth["aircraft"] == "T37" and truth["parameter"] == "Cm_dV"
    assert _found(result) == []
    _withheld_for(result, "Cm_qhat", "a Cm_dV term, not offered because the airspeed never moved above its noise")
    assert result["findings"][0]["explanation"].startswith("No effect is named: ")


def test_no_lateral_accelerometer_arm_on_a_pitch_maneuver(tmp_path):
    """The probe's seed 4697: a noise-free c172p (6,600 ft / 173 ft/s, a pitch multisine at
    50 Hz) with q 44 ms late had the skew named and beside it an accelerometer 5.6 ft right of
    the c.g. (t 9), read off the propeller's slight yaw, ṙ·y in a_x. The maneuver drove neither
    p nor r, which every term of a lateral arm carries: not offered (kinematics.ARM_RATES)."""
    truth, result = _diagnosed_probe(4697, tmp_path, calibrate=False)
    assert truth["aircraft"] == "c172p" and truth["parameter"] == "skew_q"
    _named_alone(result, truth, rel=0.25)
    assert not any(c["parameter"] == "offset_y" for c in result["candidates"])


def test_skews_a_linearised_alpha_skew_leaves_are_not_named(tmp_path):
    """The probe's seed 4410: a noise-free F-4N (25,000 ft / 655 ft/s, three-axis 2-1-1s at
    100 Hz, metric units) with α 69 ms late had the skew named (66 ms, t 125) and beside it a_x
    and a_z skews of 66 and 71 ms (t 27, 19): the first-order skew column's leftover, τ²ẍ/2,
    which reaches the equations α shares with the accelerometers. With α shifted exactly they
    stand at t 0.2 and 0.1 (sensor_naming.withhold_left_by_a_linearised_skew): the α skew alone."""
    truth, result = _diagnosed_probe(4410, tmp_path, calibrate=False)
    assert truth["aircraft"] == "F4N" and truth["noise_factor"] == 0.0
    _named_alone(result, truth, rel=0.1)
    _withheld_for(result, "skew_ax", "first-order column's leftover")


def test_a_shift_read_off_a_mistrim_an_alpha_bias_would_make_is_not_named(tmp_path):
    """The probe's seed 4332: an A-4 (7,450 ft / 516 ft/s, pitch doublets at 25 Hz, 1.8 times
    the noise, thrust recorded without its line) with C_m,α −0.13 had a 0.17 ft shift named from
    C_m's constant −0.0035. The thrust's moment makes −0.0030 of it (the noise-free null's own
    constant) and the rest is what an α vane 0.07° low makes, a bias the kinematics put at
    −0.06° ± 0.04° and C_Z's constant allows (term_rules.withhold_shift_a_vane_bias_makes):
    nothing is named."""
    truth, result = _diagnosed_probe(4332, tmp_path, calibrate=False)
    assert truth["aircraft"] == "A4" and truth["parameter"] == "Cm_alpha"
    assert _found(result) == []
    _withheld_for(result, "dx_moment_reference", "nor C_Z's constant")


def test_a_control_change_an_unoffered_alphadot_term_would_make_is_not_named(tmp_path):
    """The probe's seed 4264: a c182 (pitch doublets, 1.8 times the noise) with C_m,α̇ −11.7. α
    never moved above its vane's noise, so no α̇ term was offered, and C_m,δe −0.55 was named
    (t 22.6) for what the kinematic α̇ column carries: beside it its t falls to 0.9
    (term_rules.withhold_beside_an_unoffered_term; a J-3 Cub's, seed 4316, the same way).
    Nothing is named, and the verdict says a term was withheld, not that the mismatch is noise.
    (Offering C_m's α̇ on q there named it, but also the model's own C_m,α̇, which the model
    along the inertial α leaves out, on a c172x null: the metric pitch multisine above.)"""
    truth, result = _diagnosed_probe(4264, tmp_path, calibrate=False)
    assert truth["parameter"] == "Cm_alphadot" and truth["kind"] == "pitch"
    assert _found(result) == []
    _withheld_for(result, "Cm_de", "not offered because α never moved above its noise")
    assert result["findings"][0]["explanation"].startswith("No effect is named: ")


@pytest.mark.parametrize("seed", [3769, 4169, 4197])
def test_a_sensor_error_a_mode_under_the_search_floor_makes_is_not_named(tmp_path, seed):
    """The probe's seeds 3769, 4169 and 4197: a noise-free T-37, an F-16 and an A-4 on lateral
    maneuvers with a mode driven by the aileron ringing q and a_z at 3.8, 4.0 and 4.7 Hz, under
    where the mode search starts (6 Hz, twice the motion's 3 Hz cut-off). An a_z skew of −68 ms and
    β biases of 0.67° and 0.28° were named. The band between the motion's cut-off and the floor
    shows the peak (spectra.sub_floor_peak); with it taken out as the aileron-driven mode the
    kinematics keep none of them (mode_model.withhold_sensor_errors_a_peak_makes)."""
    truth, result = _diagnosed_probe(seed, tmp_path, calibrate=False)
    assert truth["parameter"] == "mode_frequency_hz" and truth["kind"] == "lateral"
    assert _found(result) == []
    assert any("under the mode search's floor" in c["reason"] for c in result["candidates"])


def test_no_skew_of_a_rate_the_maneuver_did_not_drive(tmp_path):
    """The probe's seed 4016 (tests/probe/gen.py): a noise-free F-4N (20,300 ft / 650 ft/s,
    stabilator sweep at 50 Hz) with a 71 ms stabilator delay. The delay was named right and beside
    it an r skew of −27 ms (t −6.1), r moving only by the airframe's faint coupling: far above its
    noise (none), far under the smallest r bias worth naming. A skew of a state the maneuver did
    not drive now needs it to move three times that bias (kinematics.MIN_EXCITATION, PRACTICAL)."""
    truth, result = _diagnosed_probe(4016, tmp_path, calibrate=False)
    assert truth["aircraft"] == "F4N" and truth["parameter"] == "tau_de" and truth["noise_factor"] == 0.0
    _named_alone(result, truth, rel=0.05)


def test_no_skew_of_a_rate_a_noise_free_pitch_maneuver_did_not_drive(tmp_path):
    """The probe's seed 4035: a noise-free 737 (24,800 ft / 483 ft/s, stabilator sweep) with its
    moment reference 0.46 ft forward had an r skew of −96 ms named (t −6.6), r moving by the
    airframe's coupling alone; it is no candidate now (kinematics.MIN_EXCITATION, PRACTICAL),
    and nothing else is named."""
    truth, result = _diagnosed_probe(4035, tmp_path, calibrate=False)
    assert truth["aircraft"] == "737" and truth["kind"] == "pitch" and truth["noise_factor"] == 0.0
    assert [p for p, _ in _found(result)] in ([], [truth["parameter"]])
    skew_r = next((c for c in result["candidates"] if c["parameter"] == "skew_r"), None)
    assert skew_r is None or not skew_r["selected"]


def test_no_gyro_scale_where_an_untestable_vane_scale_explains_the_same(tmp_path):
    """The probe's seed 4046 (tests/probe/gen.py): a c172r (4,100 ft / 178 ft/s, pitch 2-1-1 at
    50 Hz, flight-test noise, no trim in the metadata) whose α vane reads 5.9 % low. α moves
    2.2 times its vane's noise, so an α scale is no candidate; a q-gyro scale of +4.6 % was named
    instead (kinematic t 4.4, C_m agreeing). Beside the α scale it falls to t 0.1: nothing is
    named, and the α scale is reported as not checked."""
    truth, result = _diagnosed_probe(4046, tmp_path, calibrate=False)
    assert truth["parameter"] == "scale_alpha" and "no_trim" in truth["conventions"]
    assert _found(result) == []
    scale_q = next(c for c in result["candidates"] if c["parameter"] == "scale_q")
    assert "cannot tell it from scale_alpha" in scale_q["reason"], scale_q["reason"]
    assert any("scale_alpha" in n["parameters"] for n in result["not_checked"])


def test_a_delay_on_a_surface_whose_samples_are_noisy_is_scanned(tmp_path):
    """The probe's seed 3637 (tests/probe/gen.py): an F-16 (27,400 ft / 716 ft/s, three-axis
    sweeps at 40 Hz, noise twice flight test's) with a 96 ms stabilator delay. Its 1° sweep stands
    under 5 times the stabilator sensor's sample noise, so the surface was not scanned for a delay
    and the delay went unseen (C_m,α̇ entered in its place); its filtered signal stands clear of
    the noise the filter passes (prepare.maneuver_driven), and the scan finds the delay. (The
    validation 3-2-1-1, 0.3° on the stabilator, cannot confirm it: left out here.)"""
    truth, result = _diagnosed_probe(3637, tmp_path, validation=False, calibrate=False)
    assert truth["aircraft"] == "f16" and truth["parameter"] == "tau_de"
    _named_alone(result, truth)


def test_gusts_an_accelerometer_position_makes_do_not_void_it(tmp_path):
    """The probe's seed 3592 (tests/probe/gen.py): a c172x (5,000 ft / 166 ft/s, lateral sweeps
    at 50 Hz, metric units) with its accelerometer 9.5 ft left of the c.g. The position's ṗ·y
    in a_z integrates to a 'gust' of 1.2 ft/s, and light gusts voided the sensor tests: the
    position the kinematics put at −10.0 ft (t −19.9) was not applied and nothing was named. On
    the channels corrected for it (gust_biases.POSITIONS) there are no gusts, and it is named."""
    truth, result = _diagnosed_probe(3592, tmp_path, calibrate=False)
    assert truth["aircraft"] == "c172x" and truth["parameter"] == "offset_y"
    _named_alone(result, truth)
