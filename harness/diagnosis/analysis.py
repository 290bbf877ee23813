"""One recording set against the model: the replay, the coefficient mismatch, and every
candidate test, gathered into scored candidates."""
from __future__ import annotations

import numpy as np

from harness.diagnosis.accelerometer_rules import (note_refuted_positions, refuted_positions,
                                                   withhold_beside_the_accelerometer, withhold_the_positions_rival,
                                                   withhold_through_the_inertial_angles,
                                                   withhold_vane_an_accelerometer_makes)
from harness.diagnosis.airspeed_rules import withhold_on_the_airspeed
from harness.diagnosis.along import (ModelAlong, corrected_recording, corrected_start, inertial_beta, model_along,
                                     slope_function)
from harness.diagnosis.delay_rules import name_the_delay_the_terms_imitate
from harness.diagnosis.drift_rules import withhold_lateral_drift_a_slow_sideslip_makes
from harness.diagnosis.evidence import Analysis
from harness.diagnosis.gust_biases import gusts_without_biases, note_gusts_of_biases
from harness.diagnosis.gust_rules import (LIGHT_TURBULENCE_FACTOR, air_share_test, gust_verdict,
                                          gusts_of_an_airspeed_bias, light_gusts,
                                          spectral_candidates, turbulence_test, vane_wander, withhold_in_light_gusts,
                                          withhold_in_turbulence, withhold_vane_wander)
from harness.diagnosis.gusts import process_noise_model
from harness.diagnosis.kinematics import KinematicResult
from harness.diagnosis.prepare import COEFFICIENTS, Prepared
from harness.diagnosis.sensor_naming import (VANE_MEANS_AXES, kinematic_rivals, name_applied, name_corroborated,
                                             name_vane_bias_from_means, signature_ratios,
                                             withhold_delays_imitated_by_named, withhold_imitated_by_named,
                                             withhold_left_by_a_linearised_skew,
                                             withhold_scale_left_by_a_linearised_skew, withhold_vane_scale)
from harness.diagnosis.sensor_rules import (applied_sensor_values, biases_of_contested, contested_parameters,
                                            kinematic_candidates, kinematics_plausible, name_accelerometer_once,
                                            plausible_kinematic_check, scale_read_as_bias,
                                            steady_vane, withhold_biases_an_airspeed_bias_makes,
                                            withhold_offset_of_a_scaled_vane, withhold_scale_a_bias_would_make)
from harness.diagnosis.spectra import structural_peak
from harness.diagnosis.stepwise_axes import (aero_candidates, delay_scans, offset_candidate, pinned_shift,
                                             stepwise_fits, vane_noise_columns, withhold_on_moving_throttle,
                                             withhold_shift_within_thrust, withhold_stiffness_a_shift_makes,
                                             withhold_thrust_drift)
from harness.diagnosis.term_rules import (VANE_COLUMN_SENSORS, euler_lag_estimate, imitation, inertial_alpha_sensors,
                                          note_surface_scale, note_untested_coupling,
                                          withhold_off_the_integration_drift,
                                          withhold_alpha_power_off_the_inertial_alpha,
                                          withhold_alpha_slope_off_the_inertial_alpha, withhold_ambiguous,
                                          withhold_even_term_off_the_quiet_flight,
                                          withhold_explained_by_cg, withhold_explained_by_force_arm,
                                          withhold_explained_by_lift,
                                          withhold_force_drift_off_the_vane_wander,
                                          withhold_lateral_drift_off_the_vane,
                                          withhold_resting_on_an_uncertain_correction, withhold_rivals,
                                          withhold_beside_an_unoffered_term, withhold_shift_a_vane_bias_makes,
                                          withhold_the_shift_remainder)
from harness.diagnosis.wander_rules import withhold_within_the_unseen_wander
from models.aircraft import Aircraft, has_propeller
from models.replay import InitialCondition


def coefficient_noise(p: Prepared, mismatch: dict[str, np.ndarray]) -> dict[str, float]:
    """A noise level per axis: the RMS of the mismatch about a 1 s running mean (the part no
    slow deterministic effect explains), floored to stay positive."""
    k = max(3, int(round(1.0 / p.dt)))
    kernel = np.ones(k) / k
    out = {}
    for c, r in mismatch.items():
        hp = r - np.convolve(r, kernel, mode="same")
        out[c] = max(float(np.std(hp[k:-k])), 1e-9 * max(float(np.std(r)), 1e-12))
    return out


def _along_corrected(recorded: Prepared, kin: KinematicResult, values: dict[str, float], aircraft: Aircraft,
                     ic: InitialCondition) -> tuple[Prepared, ModelAlong, dict[str, np.ndarray], dict[str, dict],
                                                    InitialCondition]:
    """The recording corrected for the sensor ``values``, the model along it, its mismatch,
    the accelerometer position components the force mismatch there refutes
    (:func:`accelerometer_rules.refuted_positions`: those are taken out of ``values`` in
    place and the correction and the model made again without them), and the initial
    condition (:func:`corrected_start`)."""
    p = corrected_recording(recorded, kin, values)
    start = corrected_start(p, values, ic)
    along = model_along(p, aircraft, start)
    mismatch = along.mismatch()
    refuted = refuted_positions(p, mismatch, coefficient_noise(p, mismatch), values)
    if refuted:
        for name in refuted:
            values.pop(name)
        p = corrected_recording(recorded, kin, values)
        start = corrected_start(p, values, ic)
        along = model_along(p, aircraft, start)
        mismatch = along.mismatch()
    return p, along, mismatch, refuted, start


def analyse(p: Prepared, aircraft: Aircraft, ic: InitialCondition) -> Analysis:
    """Run every test on recording ``p`` against ``aircraft`` (module docstring)."""
    # 0. turbulence first: gusts make air-relative and inertial velocities differ, which
    # breaks the kinematic consistency the sensor tests rest on
    gust, turbulent = turbulence_test(p)
    V0 = float(np.mean(p.smooth["V"]))
    gusty = "" if turbulent else light_gusts(gust, p, V0)
    near = "" if turbulent or gusty else light_gusts(gust, p, V0, LIGHT_TURBULENCE_FACTOR)
    # 1. sensors: kinematic consistency says what the instruments did
    kin = plausible_kinematic_check(p)
    cleared = gusts_without_biases(p, kin, V0) if turbulent or gusty or near else None
    if cleared is not None:  # the 'gust' was the kinematic signature of constant instrument errors
        raw_gust, (gust, gust_biases) = gust, cleared
        turbulent, gusty, near = False, "", light_gusts(gust, p, V0, LIGHT_TURBULENCE_FACTOR)
    plausible = kinematics_plausible(kin, V0, p)
    contested = contested_parameters(kin, p)
    unapplied = set(contested) | biases_of_contested(kin, contested)
    sensor_values = {n: v for n, v in applied_sensor_values(kin, turbulent or bool(gusty), plausible, V0).items()
                     if n not in unapplied and steady_vane(n, p) is None}
    # 2. the model along the measured states
    recorded, (p, along, mismatch, refuted, ic) = p, _along_corrected(p, kin, sensor_values, aircraft, ic)
    states, surfaces, alphadot, aero, measured = along[:5]
    slope_of = slope_function(aircraft, ic, states, surfaces, alphadot, aero, along.weights)
    # 0'. gusts or vane error: the aerodynamics say which (no sensor value is applied in either)
    near = near if not sensor_values else ""  # a corrected recording is not asked again
    air = air_share_test(p, aircraft, ic, along, slope_of, gust, V0) if turbulent or gusty or near else None
    turbulent, light, gusty = gust_verdict(gust, air, turbulent, gusty, V0, near)
    airspeed = gusts_of_an_airspeed_bias(recorded, gust, V0) if turbulent or light else ""
    if airspeed:  # the 'gust' is an airspeed error's signature: neither named, the sensor tests void
        turbulent, light, gusty = False, False, airspeed
    cands = kinematic_candidates(kin, recorded, turbulent, plausible, gusty)
    withhold_biases_an_airspeed_bias_makes(cands, kin)
    note_refuted_positions(cands, refuted)
    noise = coefficient_noise(p, mismatch)
    # 3. accelerometer position from the force mismatches (removed from them when named)
    as_evaluated = dict(mismatch)
    off, off_candidate = offset_candidate(p, mismatch, noise, measured)
    cands.append(off_candidate)
    # 4. delay scans; 5. per-axis stepwise
    delays = delay_scans(p, mismatch, aero, noise)
    # the vane-against-inertial difference, after the sensor corrections when there were any
    wander_gust = turbulence_test(p)[0] if sensor_values else gust
    vane = vane_noise_columns(p, along, slope_of, V0, mismatch, wander_gust)
    propeller = has_propeller(aircraft.model)
    step = stepwise_fits(p, propeller, aero, measured, mismatch, delays, vane)
    cands += aero_candidates(step.selections, delays, p.dt, step.shares, step.ar_t)
    withhold_the_positions_rival(cands)
    name_the_delay_the_terms_imitate(cands, step, delays, p, mismatch)
    if not propeller:
        withhold_thrust_drift(cands, p, aero.trim)
    if step.pinned is not None:
        cands.append(pinned_shift(step.pinned, p, aero.trim))
    withhold_shift_within_thrust(cands, step, p, aero.trim, mismatch, measured)
    withhold_stiffness_a_shift_makes(cands, step, p, mismatch, measured, aero.trim)
    withhold_shift_a_vane_bias_makes(cands, step, p, kin, set(sensor_values), slope_of, mismatch, measured, aero.trim,
                                     V0)
    withhold_on_moving_throttle(cands, p, propeller)
    withhold_beside_the_accelerometer(cands, step.selections, p, as_evaluated, noise)
    # the rules that keep a term from being named when something else would imitate it
    withhold_explained_by_cg(cands, step.selections, mismatch, p)
    withhold_the_shift_remainder(cands, step, mismatch, p, measured)
    withhold_explained_by_lift(cands, step.selections, mismatch, p)
    withhold_explained_by_force_arm(cands, step.selections, mismatch, p, aero.trim)
    withhold_lateral_drift_off_the_vane(cands, step, p, aircraft, ic)
    withhold_lateral_drift_a_slow_sideslip_makes(cands, step, p, mismatch, slope_of)
    withhold_alpha_power_off_the_inertial_alpha(cands, step, p, mismatch)
    withhold_even_term_off_the_quiet_flight(cands, step, p, mismatch)
    withhold_force_drift_off_the_vane_wander(cands, step, p, mismatch, slope_of, wander_gust, V0)
    withhold_off_the_integration_drift(cands, step, p, mismatch)
    withhold_within_the_unseen_wander(cands, step, p, mismatch)
    withhold_rivals(cands, step.selections, step.nuisances, mismatch, p, slope_of, kin, set(sensor_values), V0,
                    measured)
    withhold_beside_an_unoffered_term(cands, step, mismatch, p)
    note_untested_coupling(cands, p)
    note_surface_scale(cands)
    column_sensors = {axis: VANE_COLUMN_SENSORS for axis, n in step.nuisances.items() if "vane_alpha_noise" in n}
    for axis, sensors in inertial_alpha_sensors(p).items():
        column_sensors[axis] = tuple(dict.fromkeys(column_sensors.get(axis, ()) + sensors))
    imitated = imitation(p, kin, aircraft, ic, mismatch, step, slope_of, V0, sensor_values)
    withhold_ambiguous(cands, kin, imitated, column_sensors, euler_lag_estimate(p, kin, sensor_values), contested)
    withhold_resting_on_an_uncertain_correction(cands, kin, sensor_values, imitated)
    withhold_on_the_airspeed(cands, p, kin, aircraft, ic, mismatch, step)
    if turbulent:
        withhold_in_turbulence(cands)
    else:
        if gusty:
            withhold_in_light_gusts(cands, gusty)
        if vane_wander(air, gusty):
            withhold_vane_wander(cands, gusty)
        signature = signature_ratios(cands, kin, p, aircraft, ic, mismatch, step)
        if plausible and not gusty:
            kinematic_rivals(cands, kin, p, signature, contested)
        withhold_vane_scale(cands, kin, step, signature, inertial_beta(p))
        withhold_alpha_slope_off_the_inertial_alpha(cands, step, p, mismatch)
        if plausible and not gusty:
            name_corroborated(cands, kin, p, signature, set(sensor_values), V0)
            for vane in VANE_MEANS_AXES:
                name_vane_bias_from_means(cands, kin, p, aircraft, ic, step, vane,
                                          sensor_values.get(f"bias_{vane}", 0.0))
            removed = {c: as_evaluated[c] - mismatch[c] for c in COEFFICIENTS}
            name_applied(cands, kin, recorded, p, aircraft, ic, mismatch, removed, step, sensor_values, V0)
            scale_read_as_bias(cands, recorded)
            withhold_scale_a_bias_would_make(cands, kin, recorded)
            withhold_scale_left_by_a_linearised_skew(cands, kin, recorded)
            withhold_left_by_a_linearised_skew(cands, kin, recorded)
            withhold_offset_of_a_scaled_vane(cands, kin, p, aircraft, ic, as_evaluated, noise, sensor_values)
            withhold_imitated_by_named(cands, imitated, set(sensor_values))
            withhold_delays_imitated_by_named(cands, kin, p, aircraft, ic, aero.derivatives, noise, set(sensor_values))
    name_accelerometer_once(cands)
    withhold_vane_an_accelerometer_makes(cands, kin, recorded, sensor_values)
    withhold_through_the_inertial_angles(cands, step.selections, p, kin, aircraft, ic, mismatch, sensor_values)
    # 6. spectra and gusts
    peak = structural_peak(p)
    cands += spectral_candidates(peak, gust, turbulent, light, air)
    if cleared is not None:
        note_gusts_of_biases(cands, raw_gust, gust_biases)
    if turbulent or light:  # the gust as a process-noise model: filter error against output error
        next(c for c in cands if c.effect == "turbulence").details["process_noise_model"] = process_noise_model(p)
    return Analysis(prepared=p, ic=ic, aero=aero, mismatch=mismatch, noise=noise, candidates=cands,
                    selections=step.selections, kinematic=kin, delay=delays, offset=off, gust=gust, peak=peak,
                    not_offered=step.not_offered, applied=dict(sensor_values), gusty=gusty, air=air,
                    nuisances=step.nuisances)
