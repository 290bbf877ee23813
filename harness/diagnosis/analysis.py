"""One recording set against the model: the replay, the coefficient mismatch, and every
candidate test, gathered into scored candidates."""
from __future__ import annotations

import functools
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from harness.diagnosis import candidates as cand
from harness.diagnosis import corroborate, rivals
from harness.diagnosis.gusts import process_noise_model
from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from harness.diagnosis.kinematics import T_IN as KIN_T_IN
from harness.diagnosis.kinematics import (KinematicResult, PRACTICAL, channel_share, corrected_channels,
                                          inertial_angles, is_plausible, is_practical, kinematic_check,
                                          kinematic_residuals)
from harness.diagnosis.prepare import COEFFICIENTS, Prepared, clean_channels, measured_coefficients
from harness.diagnosis.spectra import FISHER_P, AirShare, air_share, gust_estimate, structural_peak
from models.aircraft import Aircraft, has_propeller
from models.hidden import SENSOR_EFFECTS
from models.replay import AeroAlong, InitialCondition, aero_along
from models.constants import G0_FPS2, SURFACES


@dataclass
class Candidate:
    """A candidate effect with its test statistic (a row of the report's candidate table)."""

    effect: str
    axis: str | None
    channel: str | None
    parameter: str
    estimate: float
    std_error: float
    t: float
    explained_fraction: float
    units: str
    test: str
    selected: bool = False
    reason: str = ""
    details: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        d = {k: getattr(self, k) for k in ("effect", "axis", "channel", "parameter", "estimate", "std_error", "t",
                                            "explained_fraction", "units", "selected", "reason")}
        d["test"] = self.test
        return {k: (float(v) if isinstance(v, (np.floating,)) else v) for k, v in d.items()}


@dataclass
class Analysis:
    prepared: Prepared
    ic: InitialCondition
    aero: AeroAlong
    mismatch: dict[str, np.ndarray]
    noise: dict[str, float]          # per axis: the mismatch's noise level (high-frequency part)
    candidates: list[Candidate]
    selections: dict
    kinematic: KinematicResult
    delay: dict
    offset: cand.OffsetTest
    gust: object
    peak: object
    not_offered: dict = field(default_factory=dict)  # per axis: candidate parameters the maneuver did not excite
    applied: dict = field(default_factory=dict)      # sensor corrections applied before the model was evaluated
    gusty: str = ""  # why light gusts leave the kinematic (sensor) tests untrustworthy ('' when they do not)
    air: AirShare | None = None  # the air-share test, when the kinematics showed gusts


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


def analyse(p: Prepared, aircraft: Aircraft, ic: InitialCondition) -> Analysis:
    """Run every test on recording ``p`` against ``aircraft`` (module docstring)."""
    # 0. turbulence first: gusts make air-relative and inertial velocities differ, which
    # breaks the kinematic consistency the sensor tests rest on
    gust, turbulent = _turbulence(p)
    V0 = float(np.mean(p.smooth["V"]))
    gusty = "" if turbulent else light_gusts(gust, p, V0)
    near = "" if turbulent or gusty else light_gusts(gust, p, V0, LIGHT_TURBULENCE_FACTOR)
    # 1. sensors: kinematic consistency says what the instruments did
    kin = plausible_kinematic_check(p)
    plausible = _kinematics_plausible(kin, V0)
    contested = _contested(kin)
    sensor_values = {n: v for n, v in _sensor_values(kin, turbulent or bool(gusty), plausible).items()
                     if n not in contested}
    recorded, p = p, _corrected(p, kin, sensor_values)
    # 2. the model along the measured states
    along = model_along(p, aircraft, ic)
    states, surfaces, alphadot, aero, measured = along
    mismatch = along.mismatch()
    slope_of = _slope_function(aircraft, ic, states, surfaces, alphadot, aero)
    # 0'. gusts or vane error: the aerodynamics say which (no sensor value is applied in either)
    near = near if not sensor_values else ""  # a corrected recording is not asked again
    air = _air_share(p, aircraft, ic, along, slope_of, gust, V0) if turbulent or gusty or near else None
    turbulent, light, gusty = gust_verdict(gust, air, turbulent, gusty, V0, near)
    cands = _kinematic_candidates(kin, recorded, turbulent, plausible, gusty)
    noise = coefficient_noise(p, mismatch)
    # 3. accelerometer position from the force mismatches (removed from them when named)
    as_evaluated = dict(mismatch)
    off, off_candidate = _offset_candidate(p, mismatch, noise, measured)
    cands.append(off_candidate)
    # 4. delay scans; 5. per-axis stepwise
    delays = _delay_scans(p, mismatch, aero, noise)
    vane = _vane_noise_columns(p, along, slope_of, V0, mismatch, None if sensor_values else gust)
    step = _stepwise(p, has_propeller(aircraft.model), aero, measured, mismatch, delays, vane)
    cands += _aero_candidates(step.selections, delays, p.dt, step.shares)
    if step.pinned is not None:
        cands.append(_pinned_shift(step.pinned))
    # the rules that keep a term from being named when something else would imitate it
    _withhold_explained_by_cg(cands, step.selections, mismatch, p)
    _withhold_explained_by_lift(cands, step.selections, mismatch, p)
    _withhold_lateral_drift_off_the_vane(cands, step, p, aircraft, ic)
    _withhold_alpha_power_off_the_inertial_alpha(cands, step, p, mismatch)
    _withhold_rivals(cands, step.selections, step.nuisances, mismatch, p, slope_of, kin, set(sensor_values), V0)
    _withhold_ambiguous(cands, kin, _imitation(p, kin, aircraft, ic, mismatch, step))
    if turbulent:
        _withhold_in_turbulence(cands)
    else:
        if gusty:
            _withhold_in_light_gusts(cands, gusty)
        if vane_wander(air, gusty):
            _withhold_vane_wander(cands, gusty)
        signature = _signature_ratios(cands, kin, p, aircraft, ic, mismatch, step)
        if plausible and not gusty:
            _kinematic_rivals(cands, kin, p, signature, contested)
        _withhold_vane_scale(cands, kin, step, signature, inertial_beta(p))
        if plausible and not gusty:
            _name_corroborated(cands, kin, p, signature, set(sensor_values), V0)
            for vane in VANE_MEANS_AXES:
                _name_vane_bias_from_means(cands, kin, p, aircraft, ic, step, vane,
                                           sensor_values.get(f"bias_{vane}", 0.0))
            removed = {c: as_evaluated[c] - mismatch[c] for c in COEFFICIENTS}
            _name_applied(cands, kin, recorded, p, aircraft, ic, mismatch, removed, step, sensor_values, V0)
            _scale_read_as_bias(cands, recorded)
            _withhold_offset_of_a_scaled_vane(cands, kin, p, aircraft, ic, as_evaluated, noise, sensor_values)
    # 6. spectra and gusts
    peak = structural_peak(p)
    cands += _spectral_candidates(peak, gust, turbulent, light, air)
    if turbulent or light:  # the gust as a process-noise model: filter error against output error
        next(c for c in cands if c.effect == "turbulence").details["process_noise_model"] = process_noise_model(p)
    return Analysis(prepared=p, ic=ic, aero=aero, mismatch=mismatch, noise=noise, candidates=cands,
                    selections=step.selections, kinematic=kin, delay=delays, offset=off, gust=gust, peak=peak,
                    not_offered=step.not_offered, applied=dict(sensor_values), gusty=gusty, air=air)


def _turbulence(p: Prepared):
    """The gust estimate from the kinematic residual, and whether it says turbulence
    (:data:`GUST_RATIO` times what sensor noise gives and at least :data:`GUST_MIN_FPS`)."""
    gust = gust_estimate(kinematic_residuals(p.raw, p), p,
                         0.5 * (p.noise_std.get("az", 0.03) + p.noise_std.get("ay", 0.03)) * G0_FPS2)
    turbulent = gust.ratio_to_noise >= GUST_RATIO and max(gust.sigma_w_fps, gust.sigma_v_fps) >= GUST_MIN_FPS
    return gust, turbulent


def _air_share(p: Prepared, aircraft: Aircraft, ic: InitialCondition, along: ModelAlong, slope_of, gust,
               V0: float) -> AirShare:
    """The air-share test (:func:`spectra.air_share`) on C_Z and the vertical gust, along
    the α vane's own record, with the model's C_Z,α from ``slope_of`` (:func:`_slope_function`
    along ``along``): where the maneuver did not drive α the model holds it at its start
    (:func:`model_states`), and is evaluated again along the vane for the test."""
    if "alpha" not in along.states or np.ptp(along.states["alpha"]) == 0.0:
        along = model_along(p, aircraft, ic, vanes=True)
        slope_of = _slope_function(aircraft, ic, along.states, along.surfaces, along.alphadot, along.aero)
    slope = slope_of("alpha")["CZ"]
    nuisances = [p.smooth[c] for c in ("alpha", "beta", "p", "q", "r") if c in p.smooth]
    return air_share(-gust.w_fps / V0, slope, along.mismatch()["CZ"], nuisances, p.dt)


def gust_verdict(gust, air: AirShare | None, turbulent: bool, gusty: str, V0: float,
                 near: str = "") -> tuple[bool, bool, str]:
    """``(turbulent, light, gusty)`` once the air-share test has spoken.

    Turbulence stands only if the aerodynamics followed the vanes: an air share
    significantly under :data:`AIR_SHARE_MIN` (:func:`_vane_error`) says the kinematic
    residual is vane error (a wandering vane at high speed reaches the gust level a
    turbulence finding needs), and the recording is then treated as gusty (no sensor value
    applied, none named). Light gusts (:func:`light_gusts`) are named light turbulence when
    the share is at least :data:`AIR_SHARE_MIN` and :data:`AIR_T` standard errors above 0;
    so are gusts just under their angle (``near``: at :data:`LIGHT_TURBULENCE_FACTOR` times
    the vanes' noise, no sensor value applied), which then void the sensor tests as light
    gusts do; otherwise ``near`` changes nothing (the sensor tests stand there, as before)."""
    if air is None:
        return turbulent, False, gusty
    is_air = air.share >= AIR_SHARE_MIN and air.share >= AIR_T * air.std_error
    if near:
        return (False, True, near) if is_air else (turbulent, False, gusty)
    if _vane_error(air):
        sigma = max(gust.sigma_w_fps, gust.sigma_v_fps)
        return False, False, (f"the vanes and the inertial channels disagree by {np.degrees(air.angle_rad):.2f} deg "
                              f"RMS ({sigma:.1f} ft/s at {V0:.0f} ft/s), but the aerodynamics did not follow the "
                              f"vanes (air share {air.share:.2f} ± {air.std_error:.2f}): vane error, not turbulence, "
                              "and it breaks the kinematic consistency the sensor tests rest on")
    return turbulent, bool(gusty) and is_air, gusty


def vane_wander(air: AirShare | None, gusty: str) -> bool:
    """Whether the air-share test put a vane-against-inertial difference large enough to
    void the sensor tests (``gusty``) on the vanes."""
    return bool(gusty) and air is not None and _vane_error(air)


def _vane_error(air: AirShare) -> bool:
    """The air share stands :data:`VANE_ERROR_Z` standard errors under :data:`AIR_SHARE_MIN`."""
    return air.share + VANE_ERROR_Z * air.std_error < AIR_SHARE_MIN


def _withhold_vane_wander(cands: list[Candidate], why: str) -> None:
    """When the vane-against-inertial difference is vane error (:func:`vane_wander`), the
    model evaluated along the α vane carries C_α times that error, and the α columns carry
    it too (errors in variables): terms in α, its powers and α̇ are not named. A 0.4 deg
    wander at 700 ft/s named C_Z,α −2.47 (model −4.3) on a null of the outside sweep."""
    for c in cands:
        if c.selected and c.test.startswith("stepwise") and c.parameter.split("_", 1)[-1].startswith("alpha"):
            c.selected = False
            c.reason = f"not named: {why}"


def light_gusts(gust, p: Prepared, V0: float, factor: float | None = None) -> str:
    """Why gusts under the :data:`GUST_MIN_FPS` of a turbulence finding still leave the
    kinematic consistency the sensor tests rest on untrustworthy ('' when they do not): the
    kinematic residual stands :data:`GUST_RATIO` times above what sensor noise gives, and
    the gust angle it implies, σ/V, is at least :data:`GUST_ANGLE_FACTOR` (or ``factor``)
    times the white noise of the α and β vanes (counted at no less than
    :data:`VANE_NOISE_FLOOR_RAD`). The same gust is a larger angle the slower the aircraft:
    1.9 ft/s at 180 ft/s is 0.6 deg, six times a 0.1 deg vane's noise, and there (Dryden
    severity 2) the kinematics named an α-vane skew and position on a c172x null, and an
    accelerometer 15 ft aft on a DHC-6 null (outside sweep, 2 Dec 2026)."""
    sigma = max(gust.sigma_w_fps, gust.sigma_v_fps)
    vane = max(float(np.mean([p.noise_std.get(c, 0.0) for c in ("alpha", "beta")])), VANE_NOISE_FLOOR_RAD)
    angle = sigma / max(V0, 1e-9)
    if gust.ratio_to_noise < GUST_RATIO or angle < (GUST_ANGLE_FACTOR if factor is None else factor) * vane:
        return ""
    return (f"gusts of about {sigma:.1f} ft/s ({np.degrees(angle):.2f} deg of angle at {V0:.0f} ft/s, "
            f"{angle / vane:.1f} times the vanes' noise; under the {GUST_MIN_FPS:g} ft/s of turbulence) break the "
            "kinematic consistency the sensor tests rest on")


def _withhold_in_light_gusts(cands: list[Candidate], why: str) -> None:
    """In gusts too light to name (:func:`light_gusts`) the coefficient terms stand (a C_m,q̂
    change is still named at Dryden severity 2), but not the accelerometer position fitted to
    the force mismatch: the gust's pitching part follows q̇ there (a DHC-6 null named an
    accelerometer 15 ft aft, t = 25)."""
    for c in cands:
        if c.selected and c.parameter == "x_accelerometer":
            c.selected = False
            c.reason = f"not named: {why}"


def _kinematics_plausible(kin: KinematicResult, V0: float) -> bool:
    """Whether every kinematic estimate the data support (|t| >= :data:`APPLY_T`) is one an
    instrument could have; an unsupported one (a lateral bias on a pitch maneuver) says
    nothing about plausibility."""
    return all(is_plausible(n, kin.selection.params[n], V0) or _t_of(kin, n) < APPLY_T
               for n in kin.forced + kin.selection.names)


def _sensor_values(kin: KinematicResult, turbulent: bool, plausible: bool) -> dict[str, float]:
    """The sensor corrections applied before the model is evaluated. None in turbulence or
    when an estimate is implausible (the kinematics then disagree for another reason, and
    the parameters were estimated together); else only those with |t| >= :data:`APPLY_T` (a
    nuisance bias "below the entry t" may be a poorly determined 0.7 deg, and applying it
    would move the model)."""
    if turbulent or not plausible:
        return {}
    return {n: kin.selection.params[n] for n in kin.forced + kin.selection.names if _t_of(kin, n) >= APPLY_T}


def _sensor_verdict(name: str, est: float, se: float, entered: bool, kin: KinematicResult, p: Prepared,
                    turbulent: bool, plausible: bool, gusty: str = "") -> tuple[bool, str]:
    """Whether a kinematic estimate is named, and why (or why not): it must have entered,
    matter (practical size and share of its channel's excursion), be precise, and the
    kinematics must hold (no turbulence, no gusts that break them, plausible estimates)."""
    practical = is_practical(name, est, p.dt) and _kin_share(kin, name, est, p) >= cand.PRACTICAL_SHARE
    precise = se <= max(0.5 * _practical_size(name, p.dt), 0.25 * abs(est))
    sel = entered and practical and precise and not turbulent and not gusty and plausible
    reason = ("significant, practical and precise" if sel else "below the entry t" if not entered else
              "within the instrument noise budget (practical size)" if not practical else
              "poorly determined" if not precise else NOT_IN_TURBULENCE if turbulent else
              f"not applied: {gusty}" if gusty else IMPLAUSIBLE)
    return sel, reason


# The channels whose trim value is far from zero, where a scale factor shows as an offset:
# the α vane (k·α at the trim α) and the airspeed (k·V).
OFFSET_SCALE_CHANNELS = ("alpha", "V")


def _scale_read_as_bias(cands: list[Candidate], p: Prepared) -> None:
    """Rename a named bias of α or V that is a scale factor's offset. A reading (1 + k)·x
    stands k·x̄ off at the maneuver's mean x̄, which the kinematic fit (a bias always in it)
    or the coefficient means along the vane give as a bias b, and moves k times the
    excursions, which the kinematic fit gives as the scale k. When that k is named or
    suspect (|t| >= :data:`AMBIGUOUS_T`) and the two say the same scale — k and b/x̄_true
    within two standard errors of their difference — the finding is the scale, sized as
    their inverse-variance mean, and the bias is read as its offset. A true bias leaves k
    near zero. (An F-16 at 20,000 ft and 450 ft/s with a 10 % α-vane scale was named a 0.63°
    α bias, b/x̄ = 0.100 ± 0.008 against k = 0.086 ± 0.022; at 427.4 ft/s the means named a
    0.47° bias ahead of the scale the kinematics had named.) A scale the kinematics had not
    named is judged on the validation maneuver as a finding named on two tests
    (``details['corroboration']``: its kinematic k, same sign, |t| >= 2, within two standard
    errors). Every bias of α or V carries its reading as a scale, b/x̄_true
    (``details['as_scale']``), for that validation test (``run._offset_scale_check``)."""
    for channel in OFFSET_SCALE_CHANNELS:
        biases = [c for c in cands if c.parameter == f"bias_{channel}"]
        bias = next((c for c in biases if c.selected), biases[0] if biases else None)
        scale = next((c for c in cands if c.parameter == f"scale_{channel}"), None)
        if bias is None or channel not in p.smooth:
            continue
        x_true = float(np.mean(p.smooth[channel])) - bias.estimate
        if abs(x_true) <= 0.0:
            continue
        k_off, se_off = bias.estimate / x_true, bias.std_error / abs(x_true)
        bias.details["as_scale"] = {"k": k_off, "k_std": se_off, "mean_true": x_true}
        if not bias.selected or scale is None or abs(scale.t) < AMBIGUOUS_T:
            continue
        V_mean = float(np.mean(p.smooth["V"]))
        if np.sign(k_off) != np.sign(scale.estimate) or \
                abs(k_off - scale.estimate) > 2.0 * np.hypot(se_off, scale.std_error):
            _withhold_bias_beside_a_scale(bias, scale, k_off, se_off, V_mean)
            continue
        k_exc, se_exc, named = scale.estimate, scale.std_error, scale.selected
        w = np.array([1.0 / se_off ** 2, 1.0 / se_exc ** 2])
        k = float(np.dot(w, [k_off, k_exc]) / w.sum())
        se = float(1.0 / np.sqrt(w.sum()))
        if not (is_plausible(scale.parameter, k, V_mean) and is_practical(scale.parameter, k, p.dt)):
            continue
        scale.estimate, scale.std_error, scale.t, scale.selected = k, se, k / se, True
        scale.reason = (f"the offset at the mean {channel} (a bias of {bias.estimate:.4g}: k = {k_off:.3f} ± "
                        f"{se_off:.3f}) and the excursions (k = {k_exc:.3f} ± {se_exc:.3f}) agree on a scale factor")
        scale.details["offset"] = {"bias": bias.estimate, "bias_std": bias.std_error, "mean_true": x_true,
                                   "k": k_off, "k_std": se_off, "excursion_k": k_exc, "excursion_k_std": se_exc}
        if not named:  # the kinematics alone had not named it: judged as named on two tests
            scale.details["corroboration"] = {"named": True, "kinematic": k_exc, "kinematic_std": se_exc}
        bias.selected = False
        bias.details["read_as"] = scale.parameter
        bias.reason = f"read as the offset of {scale.parameter} = {k:.3f} at the mean {channel} (k·x̄)"


def _withhold_bias_beside_a_scale(bias: Candidate, scale: Candidate, k_off: float, se_off: float,
                                  V_mean: float) -> None:
    """Withhold a bias of α or V beside a scale of the same instrument that its excursions
    show (kinematic |t| >= :data:`APPLY_T`, not named) with the sign the offset, read as a
    scale (k = b/x̄_true, plausible), has, when the two do not agree on one scale factor
    (:func:`_scale_read_as_bias`): a scale makes an offset k·x̄ as well, so the record
    cannot say whether the offset is a bias, the scale's, or both. (An F-16 at 420 ft/s with
    a 10 % α-vane scale, on a pitch multisine: its coefficient means gave an offset of
    0.50° = 0.105 ± 0.003 of the mean α, its excursions k = 0.072 ± 0.012 (t 5.9); it was
    named a 0.50° α bias.)"""
    if scale.selected or abs(scale.t) < APPLY_T or np.sign(scale.estimate) != np.sign(k_off) \
            or not is_plausible(scale.parameter, k_off, V_mean):
        return
    bias.selected = False
    bias.details["scale_rival"] = {"parameter": scale.parameter, "offset_k": k_off, "offset_k_std": se_off,
                                   "excursion_k": scale.estimate, "excursion_k_std": scale.std_error}
    bias.reason = (f"entered, but not named: {scale.parameter} would make an offset too, and the excursions show one "
                   f"(k = {scale.estimate:.3f} ± {scale.std_error:.3f}, t = {scale.t:.1f}) that does not agree with "
                   f"the offset read as a scale (k = {k_off:.3f} ± {se_off:.3f}): bias, scale or both")


def _withhold_offset_of_a_scaled_vane(cands: list[Candidate], kin: KinematicResult, p: Prepared,
                                      aircraft: Aircraft, ic: InitialCondition, mismatch: dict[str, np.ndarray],
                                      noise: dict[str, float], applied: dict[str, float]) -> None:
    """Withhold an accelerometer position fitted to the force mismatches when an α-vane
    scale is named that was not applied to the channels the model was evaluated along: the
    model along the scaled α is off by C_Z,α·k·α, which in a short-period motion follows q̇
    as the position's q̇·x/g does. The position is fitted again on the mismatch along the
    corrected α (the model evaluated once more); below the entry t there, it is withheld.
    (At 427.4 ft/s a 10 % α scale drew a 6.9 ± 1.1 ft position beside it.) ``mismatch`` is
    the force mismatch as evaluated, before a named position's columns were taken out."""
    offset = next((c for c in cands if c.selected and c.parameter == "x_accelerometer"), None)
    scale = next((c for c in cands if c.selected and c.parameter == "scale_alpha"), None)
    if offset is None or scale is None or "scale_alpha" in applied or "scale_alpha" not in kin.parameters:
        return
    along = model_along(_corrected(p, kin, {"scale_alpha": scale.estimate}), aircraft, ic, inertial_from=p).mismatch()
    refit = cand.accelerometer_offset(p, {c: along[c] for c in ("CX", "CY", "CZ")}, noise)
    t = max(abs(v) for v in refit.t)
    if t >= cand.T_IN:
        return
    offset.selected = False
    offset.details["sensor_rival"] = "scale_alpha"
    offset.reason = (f"fitted, but not named: along the α corrected for the named scale_alpha = {scale.estimate:.3f} "
                     f"the force mismatch no longer asks for it (x = {refit.position_ft[0]:.2f} ± "
                     f"{refit.std_error_ft[0]:.2f} ft, largest |t| = {t:.1f})")


def _kinematic_candidates(kin: KinematicResult, p: Prepared, turbulent: bool, plausible: bool,
                          gusty: str = "") -> list[Candidate]:
    """The sensor candidates. The forced (nuisance) biases are tested one by one, not picked
    as the best of many: the aerodynamic entry t serves, with the practical-size and
    precision rules; the selected terms by the kinematic selection's own entry."""
    out = []
    for name in kin.forced:
        sp = kin.parameters[name]
        est, se = kin.selection.params[name], kin.selection.std_errors[name]
        t = est / se if se > 0 else 0.0
        sel, reason = _sensor_verdict(name, est, se, abs(t) >= cand.T_IN, kin, p, turbulent, plausible, gusty)
        out.append(Candidate(sp.effect, None, sp.channel, name, est, se, t, 0.0, sp.units,
                             "kinematic consistency (bias always fitted)", sel, reason))
    for term in kin.selection.terms:
        sp = kin.parameters[term.name]
        sel, reason = _sensor_verdict(term.name, term.estimate, term.std_error, term.selected, kin, p, turbulent,
                                      plausible, gusty)
        out.append(Candidate(sp.effect, None, sp.channel, term.name, term.estimate, term.std_error, term.t, term.gain,
                             sp.units, "kinematic consistency", sel, reason))
    return out


def _corrected(p: Prepared, kin: KinematicResult, values: dict[str, float]) -> Prepared:
    """The recording with its channels corrected for the sensor ``values`` (re-smoothed and
    re-differentiated); ``p`` itself when there are none."""
    if not values:
        return p
    ch = corrected_channels(p.raw, p, kin.parameters, values)
    smooth = {c: p.filt(x) for c, x in ch.items()}
    deriv = {c: p.differentiate(x) for c, x in ch.items()}
    k = max(1, int(round(0.5 / p.dt)))
    start = {c: float(np.mean(x[:k])) for c, x in smooth.items()}
    return replace(p, raw=ch, smooth=smooth, deriv=deriv, start=start)


def model_states(p: Prepared, inertial_from: Prepared | None = None, vane_beta: bool = False,
                 vanes: bool = False) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """The states and surfaces the model is evaluated along.

    A state the maneuver did not drive is held at its start: evaluated along its noise, the
    model would pass that noise on through its derivative (errors in variables), and the
    mismatch would then show the derivative itself as "wrong" (unless it drifted far from its
    start all the same, :attr:`Prepared.moved`: then holding it would be the larger error).
    Surfaces are measured with
    little noise: always as recorded (holding one that moves, say by a feedback loop, would
    be far worse than its noise). Airspeed and altitude are slow: their own optimal
    smoothing (a far lower cut-off than the common filter's) keeps their noise out of the
    model's coefficients (through q̂ = qc̄/2V, dynamic pressure and Mach-scheduled terms).

    A driven sideslip is the inertial one (:func:`kinematics.inertial_angles`: the v̇ equation
    integrated from a_y, the rates and attitude, placed on the vane by a constant and trend):
    a vane's slow wander survives any smoother and reaches the mismatch through C_n,β, C_l,β
    and C_Y,β, where it buried the outside sweep's lateral coefficient errors (C_l,β −0.02,
    C_n,β +0.03, C_n,r̂ −0.3, C_l,p̂ −0.1 at |t| 1.6–4.7; 5.9–22 along the inertial β). A β-vane
    scale then leaves the mismatch alone; the kinematic check names it. With ``vane_beta``
    the sideslip is the vane's; with ``vanes`` α and β are both the vanes' own smoothed
    records, driven or not (the vane-bias tests on the coefficient means)."""
    states = {k: p.smooth[k] for k in ("V", "alpha", "beta", "p", "q", "r", "phi", "theta") if k in p.smooth}
    for k in ("alpha", "beta", "p", "q", "r"):
        if k in states and k not in p.driven and k not in p.moved and not (vanes and k in ("alpha", "beta")):
            states[k] = np.full(p.n, p.start[k])
    if inertial_beta(p) and not (vane_beta or vanes):
        src = inertial_from or p
        states["beta"] = inertial_angles(clean_channels(src, INERTIAL_CHANNELS), src)["beta"]
    surfaces = {s: p.smooth[s] for s in SURFACES if s in p.smooth}
    if "V" in p.own_noise:
        states["V"] = p.raw["V"] - p.own_noise["V"]
    if p.altitude is not None:
        states["h"] = p.altitude
    return states, surfaces


class ModelAlong(NamedTuple):
    """The model evaluated along a recording's states (seed Eqs. 1-5 on both sides)."""

    states: dict[str, np.ndarray]
    surfaces: dict[str, np.ndarray]
    alphadot: np.ndarray | None
    aero: AeroAlong
    measured: dict[str, np.ndarray]

    def mismatch(self) -> dict[str, np.ndarray]:
        return {c: self.measured[c] - self.aero.coefficients[c] for c in COEFFICIENTS}


def model_along(p: Prepared, aircraft: Aircraft, ic: InitialCondition,
                inertial_from: Prepared | None = None, vane_beta: bool = False, vanes: bool = False) -> ModelAlong:
    """The measured coefficients and the model's along the states of :func:`model_states`
    (its inertial sideslip integrated from ``inertial_from``, default ``p``; the vane's
    sideslip with ``vane_beta``; both vanes' own records with ``vanes``)."""
    states, surfaces = model_states(p, inertial_from, vane_beta, vanes)
    alphadot = cand.alpha_rate(p) if "alpha" in p.driven or "alpha" in p.moved else None
    aero = aero_along(aircraft, ic, states, surfaces, alphadot)
    measured = measured_coefficients(p.smooth, p.deriv, p.meta, p.mass, thrust_stand_in(p, aero.trim.thrust_lbf))
    return ModelAlong(states, surfaces, alphadot, aero, measured)


# What the inertial sideslip is integrated from (kinematics.inertial_angles).
INERTIAL_CHANNELS = ("V", "alpha", "beta", "p", "q", "r", "phi", "theta", "ay", "az")


def inertial_beta(p: Prepared) -> bool:
    """Whether the model is evaluated along the inertial sideslip (:func:`model_states`)."""
    return "beta" in p.driven and all(c in p.raw for c in INERTIAL_CHANNELS)


def _inner(p: Prepared) -> slice:
    """The maneuver's interior: the first and last second are where the smoother is least
    accurate."""
    k = max(1, int(round(1.0 / p.dt)))
    return slice(k, p.n - k)


def _offset_candidate(p: Prepared, mismatch: dict[str, np.ndarray], noise: dict[str, float],
                      measured: dict[str, np.ndarray]) -> tuple[cand.OffsetTest, Candidate]:
    """The accelerometer position from the force mismatches: named when significant, at
    least 1.5 ft and at least 4 % of the force coefficients' excursion; when named, its
    columns are removed from ``mismatch`` (in place)."""
    off = cand.accelerometer_offset(p, mismatch, noise)
    x, sx = off.position_ft[0], off.std_error_ft[0]
    cols = cand.accelerometer_columns(p)
    inner = _inner(p)
    share = max(cand.contribution_share(sum(off.position_ft[i] * cols[a][c] for i, a in enumerate("xyz"))[inner],
                                        1.0, measured[c][inner]) for c in ("CX", "CY", "CZ"))
    sel = (max(abs(v) for v in off.t) >= cand.T_IN and abs(x) >= PRACTICAL["offset_ft"]
           and off.gain >= cand.MIN_GAIN / 2 and share >= cand.PRACTICAL_SHARE)
    if sel:
        for i, a in enumerate("xyz"):
            for c in ("CX", "CY", "CZ"):
                mismatch[c] = mismatch[c] - off.position_ft[i] * cols[a][c]
    return off, Candidate("sensor_offset", "lon", "accelerometer", "x_accelerometer", x, sx,
                          x / sx if sx > 0 else 0.0, off.gain, "ft", "force mismatch on ω̇×r + ω×(ω×r)", sel,
                          "significant and practical" if sel else
                          "not significant, under 1.5 ft, or under 4 % of the force coefficients' excursion",
                          {"position_ft": list(off.position_ft), "std_error_ft": list(off.std_error_ft),
                           "t_xyz": list(off.t)})


def _delay_scans(p: Prepared, mismatch: dict[str, np.ndarray], aero: AeroAlong,
                 noise: dict[str, float]) -> dict[str, cand.DelayScan]:
    """A delay scan per moved surface; a delay refined beyond the scanned range is not an
    actuator delay, and its column is not offered (it would stand in for another error)."""
    delays = {}
    for s in SURFACES:
        scan = cand.delay_scan(p, s, mismatch, aero.derivatives, noise)
        if scan is not None and scan.tau_s <= cand.DELAY_GRID_S[-1]:
            delays[s] = scan
    return delays


@dataclass(frozen=True)
class _Stepwise:
    selections: dict        # axis -> (ColoredSelection, {key: Term})
    nuisances: dict         # axis -> {name: column} always in the fit
    not_offered: dict       # axis -> terms not offered, with the reason
    shares: dict            # (axis, key) -> share of the coefficient's excursion
    pinned: CgMeanTest | None = None  # a moment-reference shift sized by C_m's mistrim


# The α vane's noise column enters C_m's fit where it is a material part of the mismatch:
# fitted alone (with a constant) it takes at least this share off C_m's mismatch RMS.
VANE_NOISE_SHARE = 0.15


def _vane_noise_columns(p: Prepared, along: ModelAlong, slope_of, V0: float, mismatch: dict[str, np.ndarray],
                        gust=None) -> dict[str, np.ndarray]:
    """The column −C_m,α·e that the α vane's own error passes into C_m's mismatch, e the
    vane's angle less the one the inertial channels integrate to (the kinematic residual's
    vertical "gust" over the airspeed, high-passed at :data:`spectra.GUST_HIGHPASS_HZ`); empty
    when the model is not evaluated along the vane (α held at its start) or when the column
    takes less than :data:`VANE_NOISE_SHARE` off C_m's mismatch RMS. ``gust`` is the gust
    estimate already made from these channels; None makes it again (after sensor corrections).

    The model evaluated along the vane passes the vane's error through its slopes (errors in
    variables); a Gauss-Markov wander is in the maneuver's band and survives the smoother. On a
    slow aircraft that is a large part of C_m's mismatch: on the outside sweep's c172x nulls at
    180 and 200 ft/s (0.1° white plus 0.1° wander at τ = 1 s) the column alone took 29-35 %
    off it, on the F-16 0-6 %. With it, the c172x's C_m ΔV/V drift of 0.02 is named (0.0212;
    missed before) and no other case of either sweep changed. Always in the fit it also named
    the c172x's 0.25 ft moment-reference shift (its column takes 13 %) but drew a C_m α³ in
    place of the DHC-6's 0.5 ft shift (5 %), hence the gate. Only C_m: the same column took
    40-50 % off C_Z's mismatch, and the cleaner C_Z showed a C_Z ΔV/V on F-16 nulls at 550
    and 700 ft/s and a C_Z,α̇ where a_z lagged (false findings). In gusts e is air, which the
    aerodynamics followed: the column then fits nothing (the air-share test,
    :func:`spectra.air_share`, is this fit on C_Z)."""
    if "alpha" not in along.states or np.ptp(along.states["alpha"]) == 0.0:
        return {}
    if gust is None:
        gust, _ = _turbulence(p)
    if gust.w_fps is None:
        return {}
    column = slope_of("alpha")["Cm"] * np.asarray(gust.w_fps, dtype=float) / V0   # −C_m,α·e, e = −w/V
    inner = _inner(p)
    z = mismatch["Cm"][inner]
    A = np.column_stack([column[inner], np.ones(z.size)])
    left = z - A @ np.linalg.lstsq(A, z, rcond=None)[0]
    share = 1.0 - float(np.std(left)) / max(float(np.std(z)), 1e-300)
    return {"Cm": column} if share >= VANE_NOISE_SHARE else {}


def _stepwise(p: Prepared, propeller: bool, aero: AeroAlong, measured: dict[str, np.ndarray],
              mismatch: dict[str, np.ndarray], delays: dict, vane: dict[str, np.ndarray] | None = None) -> _Stepwise:
    """Per-axis colored forward selection over the offered candidate terms (and the delay
    columns), with the thrust nuisance where thrust was not recorded and the α vane's noise
    column (:func:`_vane_noise_columns`) where the model follows the vane; drift terms that
    thrust or a propeller would imitate are not offered."""
    selections, nuisances, not_offered, shares, pools = {}, {}, {}, {}, {}
    inner = _inner(p)
    for axis in COEFFICIENTS:
        terms, skipped = cand.offered(p, cand.library(p, axis, aero.derivatives, measured, aero.coefficients))
        not_offered[axis] = [{"effect": t.effect, "parameter": t.parameter, "sources": list(t.sources)}
                             | ({"reason": t.details["not_offered"]} if "not_offered" in t.details else {})
                             for t in skipped]
        nuisance = _thrust_nuisance(p, axis, terms)
        if vane and axis in vane:
            nuisance["vane_alpha_noise"] = vane[axis]
        why = NO_THRUST_DRIFT if "thrust_dV" in nuisance else PROPELLER_DRIFT if (axis in cand.LAT and propeller) \
            else None
        if why:
            not_offered[axis] += [{"effect": t.effect, "parameter": t.parameter, "sources": list(t.sources),
                                   "reason": why} for t in terms if t.key == "dV"]
            terms = [t for t in terms if t.key != "dV"]
        extra = {f"delay_{s}": scan.columns[axis] for s, scan in delays.items() if axis in scan.columns}
        pools[axis] = (terms, extra)
        selections[axis] = _select(p, axis, mismatch, terms, extra, nuisance, measured, shares)
        nuisances[axis] = nuisance
    pinned = None
    for axis in ("Cm", "Cn"):  # C_m first: the test of either axis's shift is C_m's constant
        test = _cg_mean_test(p, axis, selections, nuisances, mismatch, measured)
        if test is None or not test.refuted:
            continue
        refit = (axis,)
        if test.pinned and pinned is None:
            # the shift the mistrim itself says: both its axes refitted with it taken out
            pinned, refit = test, ("Cm", "Cn")
            mismatch = _without_shift(p, mismatch, measured, test.dx_ft)
        for a in refit:
            terms, extra = pools[a]
            terms = [t for t in terms if t.effect != "cg_offset"]
            shares = {k: v for k, v in shares.items() if k[0] != a}
            selections[a] = _select(p, a, mismatch, terms, extra, nuisances[a], measured, shares)
            pools[a] = (terms, extra)
        not_offered[axis].append({"effect": "cg_offset", "parameter": "dx_moment_reference", "sources": ["alpha"],
                                  "reason": test.reason})
    return _Stepwise(selections, nuisances, not_offered, shares, pinned)


def _pinned_shift(test: CgMeanTest) -> Candidate:
    """The moment-reference shift C_m's mistrim says (:func:`_cg_mean_test`), a candidate
    named when significant (the entry t) and practical (the mistrim at least
    :data:`candidates.PRACTICAL_SHARE` of C_m's excursion)."""
    t = test.dx_ft / test.std_error_ft if test.std_error_ft > 0 else 0.0
    sel = abs(t) >= cand.T_IN and _practical(test.share)
    return Candidate("cg_offset", cand.AXIS_NAME["Cm"], "Cm", "dx_moment_reference", test.dx_ft, test.std_error_ft,
                     t, test.explained, "ft", "the mistrim of C_m (its constant over the mean of C_Z)", sel,
                     "entered" if sel else ("not entered" if abs(t) < cand.T_IN else _impractical_reason(test.share)),
                     {"mistrim_share": test.share})


def _without_shift(p: Prepared, mismatch: dict[str, np.ndarray], measured: dict[str, np.ndarray],
                   dx_ft: float) -> dict[str, np.ndarray]:
    """The mismatch less what a moment-reference shift of ``dx_ft`` puts in it: Δx·C_Z/c̄ in
    C_m and −Δx·C_Y/b in C_n (effects.md's cg_offset)."""
    geo = p.meta["geometry"]
    out = dict(mismatch)
    out["Cm"] = mismatch["Cm"] - dx_ft / geo["cbar_ft"] * measured["CZ"]
    out["Cn"] = mismatch["Cn"] + dx_ft / geo["b_ft"] * measured["CY"]
    return out


def _select(p: Prepared, axis: str, mismatch: dict[str, np.ndarray], terms: list, extra: dict,
            nuisance: dict, measured: dict[str, np.ndarray], shares: dict) -> tuple:
    """One axis's stepwise (:func:`candidates.axis_selection`), each term's share of the
    coefficient's excursion put in ``shares``; returns ``(selection, {key: Term})``."""
    inner = _inner(p)
    sel = cand.axis_selection(p, axis, mismatch[axis], terms, extra, forced=nuisance)
    by_key = {t.key: t for t in terms}
    for t in sel.terms:
        column = by_key[t.name].column if t.name in by_key else extra[t.name]
        shares[(axis, t.name)] = cand.contribution_share(column[inner], t.estimate, measured[axis][inner])
    return sel, by_key


# A moment-reference shift Δx moves C_m by Δx·C_Z/c̄ (effects.md), so also its mean: C_Z
# is about −C_L at trim, never near zero in level flight, and the shift mistrims the model by
# Δx·mean(C_Z)/c̄. On the outside sweep's 11 shifts (0.25–1 ft, F-16, c172x, DHC-6) C_m's
# mismatch mean was that to within 8 %; on its nulls it stayed under 0.006. A shift whose
# predicted mean C_m the recording's falls short of by more than this share of the
# prediction and :data:`CG_MEAN_Z` standard errors is refuted.
CG_MEAN_SHARE = 0.5
CG_MEAN_Z = 3.0


class CgMeanTest(NamedTuple):
    """A moment-reference shift the stepwise entered, against the mistrim of C_m."""

    refuted: bool     # the recorded mistrim falls short of the one the shift predicts
    reason: str
    dx_ft: float      # the shift the mistrim itself says, Δx = c̄·constant/mean(C_Z)
    std_error_ft: float
    pinned: bool      # refuted, yet the mistrim itself is a shift of the same sign (CG_MEAN_Z)
    share: float      # the mistrim over C_m's excursion (its practical size)
    explained: float  # the share of C_m's mismatch (mean square, its mean included) the shift takes off


def _cg_mean_test(p: Prepared, axis: str, selections: dict, nuisances: dict,
                  mismatch: dict[str, np.ndarray], measured: dict[str, np.ndarray]) -> CgMeanTest | None:
    """The moment-reference shift ``axis``'s stepwise entered, tested against the mean of
    C_m's mismatch (None when none entered): the shift Δx predicts a constant
    Δx·mean(C_Z)/c̄ in C_m beside C_m's other entered terms (a colored-residual fit with a
    constant, Eq. 5's standard errors); a shift read off C_n's C_Y column alone on a lateral
    maneuver is otherwise indistinguishable from C_n,β. Refuted when the constant falls
    short of the prediction; then, if the constant is itself a shift of the prediction's sign
    (:data:`CG_MEAN_Z` standard errors from zero), that shift is the one to name: the stepwise
    shared the C_Z column with terms that follow α (C_Z does), oversizing it."""
    sel, by_key = selections[axis]
    if "cg" not in sel.names:
        return None
    term = by_key["cg"]
    dx = sel.params["cg"] * term.scale
    inner = _inner(p)
    cbar = p.meta["geometry"]["cbar_ft"]
    cz = float(np.mean(measured["CZ"][inner]))
    if cz == 0.0:
        return None  # no lift on average (a zero-g arc): the mean says nothing of a shift
    predicted = dx * cz / cbar
    cm_sel, cm_terms = selections["Cm"]
    cols = [cm_terms[k].column[inner] for k in cm_sel.names if k in cm_terms and k != "cg"]
    cols += [c[inner] for c in nuisances.get("Cm", {}).values() if np.ptp(c[inner]) > 0]
    theta, se, _ = colored_fit(mismatch["Cm"][inner], cols, [f"x{i}" for i in range(len(cols))])
    mean, mean_se = float(theta[-1]), float(se[-1])
    # only a mistrim short of the prediction refutes: one beyond it (a larger shift, which the
    # other entered terms shared out) supports the shift
    short = abs(predicted) - mean * np.sign(predicted)
    dx_mean, se_mean = mean * cbar / cz, mean_se * cbar / abs(cz)
    share = abs(mean) / max(float(np.std(measured["Cm"][inner])), 1e-300)
    z = mismatch["Cm"][inner]
    explained = 1.0 - float(np.mean((z - dx_mean / cbar * measured["CZ"][inner]) ** 2)) / max(float(np.mean(z ** 2)),
                                                                                           1e-300)
    if short <= CG_MEAN_SHARE * abs(predicted) or short <= CG_MEAN_Z * mean_se:
        return CgMeanTest(False, "", dx_mean, se_mean, False, share, explained)
    pinned = mean * np.sign(predicted) >= CG_MEAN_Z * mean_se
    reason = (f"refuted by the mean of C_m: the shift of {dx:.3g} ft the {axis} mismatch suggests would mistrim "
              f"C_m by {predicted:+.2g}; C_m's mismatch has a constant of {mean:+.2g} ± {mean_se:.1g}")
    if pinned:
        reason += f", the mistrim of a {dx_mean:.3g} ± {se_mean:.2g} ft shift, named instead"
    return CgMeanTest(True, reason, dx_mean, se_mean, bool(pinned), share, explained)


def _slope_function(aircraft: Aircraft, ic: InitialCondition, states: dict[str, np.ndarray],
                    surfaces: dict[str, np.ndarray], alphadot: np.ndarray | None, aero: AeroAlong):
    """``slope_of(x)``: the model's ∂C/∂x along the states (:mod:`rivals`), evaluated on first
    use and kept."""
    slopes: dict[str, dict[str, np.ndarray]] = {}

    def slope_of(x: str) -> dict[str, np.ndarray]:
        if x not in slopes:
            shifted = dict(states)
            shifted[x] = np.asarray(states[x], dtype=float) + rivals.SLOPE_STEP_RAD
            moved = aero_along(aircraft, ic, shifted, surfaces, alphadot)
            slopes[x] = {c: (moved.coefficients[c] - aero.coefficients[c]) / rivals.SLOPE_STEP_RAD
                         for c in COEFFICIENTS}
        return slopes[x]
    return slope_of


def _spectral_candidates(peak, gust, turbulent: bool, light: bool = False,
                         air: AirShare | None = None) -> list[Candidate]:
    """The structural-mode peak (named at p < :data:`FISHER_P`) and the gust level (named in
    turbulence, and in light turbulence the air-share test confirms: then the part of the
    vertical gust that is air, σ_w √(1 − k))."""
    out = []
    if peak is not None:
        sel = peak.p_value < FISHER_P
        out.append(Candidate("structural_mode", None, peak.channel, "mode_frequency_hz", peak.frequency_hz,
                             peak.std_error_hz, float(-np.log10(max(peak.p_value, 1e-300))), peak.g, "Hz",
                             "residual-spectrum peak over its local median", sel,
                             f"peak p = {peak.p_value:.2g}" + (" (significant)" if sel else ""),
                             {"amplitude": peak.amplitude}))
    sigma = max(gust.sigma_w_fps, gust.sigma_v_fps)
    details = {"sigma_w_fps": gust.sigma_w_fps, "sigma_v_fps": gust.sigma_v_fps}
    reason = f"gust/noise ratio {gust.ratio_to_noise:.1f}"
    if air is not None:
        details["air_share"] = {"share": air.share, "std_error": air.std_error,
                                "angle_deg": float(np.degrees(air.angle_rad))}
        reason += f"; air share {air.share:.2f} ± {air.std_error:.2f}"
    if light:
        sigma = gust.sigma_w_fps * float(np.sqrt(min(max(air.share, 0.0), 1.0)))
        details["light"] = True
        reason += " (light turbulence: the aerodynamics followed the vanes' angle, the air's)"
    out.append(Candidate("turbulence", None, None, "sigma_gust_fps", sigma, sigma / 4.0, gust.ratio_to_noise, 0.0,
                         "ft/s", "air-relative vs inertial velocity (integrated kinematic residual)",
                         turbulent or light, reason, details))
    return out


def thrust_stand_in(p: Prepared, model_trim_thrust_lbf: float) -> float:
    """Thrust for Eqs. 1 and 4 when the recording has no thrust channel: constant at trim
    (recording-format.md), the metadata's trim thrust when given, else the model's."""
    given = (p.meta.get("trim") or {}).get("thrust_lbf")
    return float(given) if given is not None else float(model_trim_thrust_lbf)


def _refit_term(z: np.ndarray, others: list[np.ndarray], column: np.ndarray) -> tuple[float, float] | None:
    """``column``'s coefficient and t fitted on ``z`` beside ``others`` and a constant (Eq. 5's
    colored-residual standard error); None when the columns are dependent."""
    try:
        theta, se, _ = colored_fit(z, others + [column], [f"o{i}" for i in range(len(others))] + ["term"])
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return None
    k = len(others)
    return float(theta[k]), (float(theta[k] / se[k]) if se[k] > 0 else 0.0)


def _withhold_explained_by_cg(cands: list[Candidate], selections: dict, mismatch: dict[str, np.ndarray],
                              p: Prepared) -> None:
    """A moment-reference shift is one parameter acting on two axes (C_m through C_Z, C_n
    through C_Y). Once named on one, its share of the other axis's mismatch is known; a term
    selected on that other axis is kept only if it stays significant (|t| >= the entry t)
    with that share removed (a 1.5 ft shift otherwise reads as a C_n,β change too)."""
    cg = next((c for c in cands if c.selected and c.effect == "cg_offset"), None)
    if cg is None:
        return
    inner = _inner(p)
    for axis, (sel, by_key) in selections.items():
        if axis == cg.channel or "cg" not in by_key:
            continue
        z = mismatch[axis][inner] - cg.estimate / by_key["cg"].scale * by_key["cg"].column[inner]
        chosen = [k for k in sel.names if k in by_key and k != "cg"]
        for c in cands:
            key = next((k for k in chosen if by_key[k].parameter == c.parameter), None)
            if not c.selected or c.channel != axis or key is None:
                continue
            fit = _refit_term(z, [by_key[k].column[inner] for k in chosen if k != key], by_key[key].column[inner])
            if fit is None:
                continue  # the term's column is dependent on the others: nothing to re-test
            t = fit[1]
            if abs(t) < cand.T_IN:
                c.selected = False
                c.reason = (f"entered, but explained by the moment-reference shift named on {cg.channel} "
                            f"({cg.estimate:.3g} ft): with its share of the {axis} mismatch removed, t = {t:.1f}")


def lift_change_on_cx(delta_cz: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """The body-axis C_X that a change of lift carries when its C_Z share is ``delta_cz``:
    C_X = −C_D cos α + C_L sin α and C_Z = −C_D sin α − C_L cos α, so ΔC_L alone gives
    ΔC_Z = −ΔC_L cos α and ΔC_X = ΔC_L sin α = −ΔC_Z tan α."""
    return -np.asarray(delta_cz, dtype=float) * np.tan(np.asarray(alpha, dtype=float))


def _withhold_explained_by_lift(cands: list[Candidate], selections: dict, mismatch: dict[str, np.ndarray],
                                p: Prepared) -> None:
    """A named C_Z term may be a change of *lift* (how an aerodynamic table usually carries
    it, and how `models.hidden` conceals a C_Z error), which also puts −ΔC_Z tan α on C_X
    (:func:`lift_change_on_cx`): at α ≈ 8.5° a C_Z,α change of −0.6 leaves a C_X mismatch
    following α·sin α that the stepwise named as a C_X α³ (52 ± 9, t 5.5) on a probe at
    6,000 ft and 380 ft/s. A C_X term is kept only if it stays significant (|t| >= the
    entry t) with that share removed, as for a moment-reference shift's second axis."""
    named = [c for c in cands if c.selected and c.channel == "CZ" and c.test == "stepwise on the CZ mismatch"]
    if not named or "CZ" not in selections or "CX" not in selections:
        return
    sel_z, by_z = selections["CZ"]
    keys = [k for k in sel_z.names if k in by_z and any(by_z[k].parameter == c.parameter for c in named)]
    if not keys:
        return
    inner = _inner(p)
    delta_cz = sum(sel_z.params[k] * by_z[k].column for k in keys)
    z = mismatch["CX"][inner] - lift_change_on_cx(delta_cz, p.smooth["alpha"])[inner]
    sel, by_key = selections["CX"]
    chosen = [k for k in sel.names if k in by_key]
    for c in cands:
        key = next((k for k in chosen if by_key[k].parameter == c.parameter), None)
        if not c.selected or c.channel != "CX" or key is None:
            continue
        fit = _refit_term(z, [by_key[k].column[inner] for k in chosen if k != key], by_key[key].column[inner])
        if fit is None:
            continue
        t = fit[1]
        if abs(t) < cand.T_IN:
            c.selected = False
            c.reason = (f"entered, but explained by the C_Z change named ({', '.join(x.parameter for x in named)}) "
                        f"read as a change of lift, whose share of C_X is −ΔC_Z tan α: with it removed, "
                        f"t = {t:.1f}")


def _withhold_lateral_drift_off_the_vane(cands: list[Candidate], step: _Stepwise, p: Prepared, aircraft: Aircraft,
                                         ic: InitialCondition) -> None:
    """A drift term on a lateral axis (C ∝ ΔV/V) is judged along the β vane as well.

    The inertial sideslip the model follows (:func:`model_states`) is placed on the vane by a
    constant and a trend; what drift its integration keeps beyond a trend follows whatever
    else changes slowly, and reaches the lateral mismatch through the model's β slopes. A
    slow term is exactly what it imitates: on a probe at 10,000 ft / 427.4 ft/s (stabilator
    and rudder together, a C_n α·β of 2 making the aircraft dive 6 % faster) the inertial β
    drifted by 0.04° with the airspeed (correlation −0.72) and C_l ΔV/V and C_n ΔV/V entered
    at t −7.5 and 6.2 beside the right finding, where the noise-free flight's C_l mismatch
    is zero. The vane has no such drift (its wander is zero-mean), so the term, refitted with
    the axis's other entered terms and nuisances on the mismatch along the vane's own β, must
    keep the entry t and its sign."""
    chosen = [c for c in cands if c.selected and c.effect == "flight_condition_drift" and c.channel in cand.LAT]
    if not chosen or not inertial_beta(p):
        return
    inner = _inner(p)
    along_vane = model_along(p, aircraft, ic, vane_beta=True).mismatch()
    for c in chosen:
        sel, by_key = step.selections[c.channel]
        names = [k for k in sel.names if k in by_key]
        key = next((k for k in names if by_key[k].parameter == c.parameter), None)
        if key is None:
            continue
        others = [by_key[k].column[inner] for k in names if k != key]
        others += [v[inner] for v in step.nuisances.get(c.channel, {}).values() if np.ptp(v[inner]) > 0]
        fit = _refit_term(along_vane[c.channel][inner], others, by_key[key].column[inner])
        if fit is None:
            continue
        size, t = fit
        if abs(t) < cand.T_IN or np.sign(size) != np.sign(sel.params[key]):
            c.selected = False
            c.reason = (f"entered along the inertial sideslip, whose residual drift follows slow changes such as "
                        f"the airspeed's; along the β vane's own record t = {t:.1f}")


def _withhold_alpha_power_off_the_inertial_alpha(cands: list[Candidate], step: _Stepwise, p: Prepared,
                                                 mismatch: dict[str, np.ndarray]) -> None:
    """A named α² or α³ term must stay significant beside the linear α term when both are
    built on the inertial α (:func:`kinematics.inertial_angles`) rather than the vane's.

    The columns are built on the vane's α, whose wander is errors in variables: the linear
    column carries the wander in full and its coefficient is pulled toward zero, while a
    power of the perturbation hardly carries it near trim, where the wander dominates. On
    the package's T-37 (10,000 ft, 400 ft/s) and A4 (10,000 ft, 500 ft/s) a C_m,α change of
    −0.3 was named as a C_m α³ (−824 ± 40 and −557 ± 27), though the noise-free flights'
    mismatch is linear to 3e-7 and an α³ fits it a thousand times worse. The inertial α
    carries the accelerometers' noise instead, which the vane term does not share; the
    question asked of it is only which shape, with the axis's other entered terms and
    nuisances beside both columns."""
    chosen = [c for c in cands if c.selected and c.effect == "nonlinear_alpha" and c.channel in step.selections]
    if not chosen or not all(k in p.smooth for k in INERTIAL_CHANNELS):
        return
    inner = _inner(p)
    da = inertial_angles(clean_channels(p, INERTIAL_CHANNELS), p)["alpha"] - p.start["alpha"]
    for c in chosen:
        sel, by_key = step.selections[c.channel]
        key = next((k for k in sel.names if k in by_key and by_key[k].parameter == c.parameter), None)
        if key is None:
            continue
        power = 2 if key == "alpha2" else 3
        others = [by_key[k].column[inner] for k in sel.names if k in by_key and k not in (key, "alpha")]
        others += [v[inner] for v in step.nuisances.get(c.channel, {}).values() if np.ptp(v[inner]) > 0]
        fit = _refit_term(mismatch[c.channel][inner], others + [da[inner]], da[inner] ** power)
        if fit is None:
            continue
        if abs(fit[1]) < cand.T_IN:
            c.selected = False
            c.reason = (f"entered, but beside the linear α term, both built on the inertial α (free of the vane's "
                        f"wander, which favours a power of α), t = {fit[1]:.1f}")


def _thrust_nuisance(p: Prepared, axis: str, terms: list) -> dict[str, np.ndarray]:
    """Columns always in the fit of ``axis`` for what the thrust does outside the model's
    aerodynamics. Without a thrust channel (thrust held at trim), CX and Cm get the airspeed
    change: a jet's thrust changes with airspeed at a fixed throttle, in force and, through
    the thrust line's offset from the c.g. (5.1 in on JSBSim's F-16), in pitching moment; no
    other term may stand in for it. (With a thrust channel, Eqs. 1 and 4 use it, with the
    metadata's ``thrust_offset_ft``.)"""
    if axis not in ("CX", "Cm") or "thrust" in p.raw:
        return {}
    return {"thrust_dV": t.column for t in terms if t.key == "dV"}


def _kinematic_bias(kin: KinematicResult, channel: str, applied: set[str]) -> tuple[float, float]:
    """The kinematic estimate of a vane bias and its standard error (0 ± s.e. once the
    channels were corrected for it); an infinite s.e. when the check had no such bias."""
    name = f"bias_{channel}"
    if name not in kin.selection.params:
        return 0.0, np.inf
    se = kin.selection.std_errors.get(name, np.inf)
    return (0.0 if name in applied else kin.selection.params[name]), (se if se > 0 else np.inf)


def _withhold_rivals(cands: list[Candidate], selections: dict, nuisances: dict, mismatch: dict[str, np.ndarray],
                     p: Prepared, slope_of, kin: KinematicResult, applied: set[str], V0: float) -> None:
    """Deselect the aerodynamic terms the data cannot tell from a rival (:mod:`rivals`): a
    collinear candidate of the same axis, or a vane bias the kinematics cannot rule out. A
    term that survives keeps its strongest collinear rival in ``details['rival']`` for the
    validation maneuver to judge."""
    inner = _inner(p)
    for c in cands:
        if not c.selected or c.channel not in selections:
            continue
        sel, by_key = selections[c.channel]
        key = next((k for k, t in by_key.items() if t.parameter == c.parameter and k in sel.names), None)
        if key is None:
            continue
        z = mismatch[c.channel][inner]
        columns = {k: t.column[inner] for k, t in by_key.items()}
        pool = [k for k in columns if k not in sel.names]
        columns.update({k: col[inner] for k, col in nuisances.get(c.channel, {}).items() if np.ptp(col[inner]) > 0})
        others = [n for n in sel.names if n != key and n in columns]
        others += [k for k in nuisances.get(c.channel, {}) if k in columns]
        rival = rivals.strongest_rival(z, columns, key, others, pool)
        if rival is not None:
            rt = by_key[rival.key]
            c.details["rival"] = {"parameter": rt.parameter, "effect": rt.effect, "axis": c.channel,
                                  "correlation": rival.correlation, "t_term": rival.t_term,
                                  "t_rival": rival.t_rival, "coefficient": rival.swapped}
            if abs(rival.t_term) < cand.T_IN:
                # the identification maneuver cannot tell them apart: a finding only if the
                # validation maneuver prefers it (run.validation_check), never without one
                c.details["rival"]["indistinct"] = (
                    f"the identification maneuver cannot tell it from {rt.parameter} (columns correlated "
                    f"{rival.correlation:+.2f}; beside it, t = {rival.t_term:.1f})")
        for x in rivals.BIAS_SOURCES:
            if x not in by_key[key].sources:
                continue
            b = rivals.bias_rival(z, columns[key], [columns[n] for n in others], slope_of(x)[c.channel][inner], x,
                                  _kinematic_bias(kin, x, applied))
            if (b is not None and abs(b.t_term) < cand.T_IN and not b.ruled_out
                    and is_plausible(f"bias_{x}", b.bias_rad, V0)):
                c.selected = False
                c.details["sensor_rival"] = f"bias_{x}"
                c.reason = (f"entered, but not named: a {x} vane bias of {np.degrees(b.bias_rad):.2f} deg would "
                            f"imitate it through the model's nonlinearity (beside it, t = {b.t_term:.1f}), and the "
                            f"kinematics cannot rule that bias out ({_bias_text(b)})")
                break


def _bias_text(b: rivals.BiasRival) -> str:
    if not np.isfinite(b.kinematic_std):
        return f"they do not test a {b.channel} bias"
    return f"bias_{b.channel} = {np.degrees(b.kinematic):.2f} ± {np.degrees(b.kinematic_std):.2f} deg"


# The |t| a kinematic estimate needs before it corrects the channels the model is evaluated on.
APPLY_T = 3.0


# A coefficient error on a regressor whose own sensor the kinematic check suspects at this
# |t| (a scale factor, skew or vane offset of that channel, even below its entry t) is not
# named: a scaled α (or β, q ...) reading is exactly a scaled derivative on α. A bias is not
# a rival: the regression's constant absorbs it (it imitates a derivative only through the
# model's nonlinearity).
AMBIGUOUS_T = 2.5
AMBIGUOUS_KINDS = ("scale", "skew", "vane")
# The instrument each coefficient is measured with (seed Eqs. 1, 3-5): a skew of it imitates
# an α̇ or rate term of that coefficient (ΔC ≈ −τ dC/dt follows the rates), a scale every term.
DEPENDENT_SENSOR = {"CX": "ax", "CY": "ay", "CZ": "az", "Cl": "p", "Cm": "q", "Cn": "r"}


NOT_IN_GUSTS = ("not named: in turbulence the aerodynamics see air-relative rates (the gust's rotational part, "
                "which no gyro measures) and the mismatch carries them through every alpha-, rate- and "
                "surface-correlated column; equation error cannot separate a model term from them (fit the "
                "recording with the filter-error method, estimate --method fe)")


def _withhold_in_turbulence(cands: list[Candidate]) -> None:
    """In turbulence, deselect every term fitted to the coefficient mismatch (aerodynamic
    terms, control delays, the accelerometer position from the force mismatch): the gust's
    rotational components are unmeasured regressors, correlated with α, α̇ and the rates
    (a Dryden pitch gust follows the derivative of the vertical gust), so the equation-error
    fit is biased there. The outside sweep's turbulent nulls named C_Z,α, C_Z,δe, C_m,α and a
    moment-reference shift at |t| 5-10 before this rule."""
    for c in cands:
        if c.selected and (c.test.startswith("stepwise") or c.test.startswith("delay scan")
                           or c.parameter == "x_accelerometer"):
            c.selected = False
            c.reason = NOT_IN_GUSTS


# The rate each surface mainly drives: a time skew of that rate's channel makes the surface
# look late by the same amount.
SURFACE_RATE = {"de": "q", "da": "p", "dr": "r"}


def _kin_estimate(kin: KinematicResult, name: str) -> tuple[float, float] | None:
    """A kinematic parameter's estimate and |t|, whether it entered the fit (its final value)
    or not (its value when tried in the final model); None when it was not a candidate."""
    if name in kin.selection.params:
        return kin.selection.params[name], _t_of(kin, name)
    term = next((t for t in kin.selection.terms if t.name == name), None)
    return None if term is None else (term.estimate, abs(term.t))


def _kin_std_error(kin: KinematicResult, name: str) -> float:
    """The standard error of a kinematic parameter :func:`_kin_estimate` found."""
    if name in kin.selection.params:
        return float(kin.selection.std_errors.get(name, np.inf))
    term = next(t for t in kin.selection.terms if t.name == name)
    return float(term.std_error)


def _withhold_skewed_delay(c: Candidate, kin: KinematicResult) -> None:
    """Deselect a control delay the kinematics cannot tell from a time skew of the rate its
    surface drives: a gyro that lags imitates an actuator that lags (the coefficient measured
    from the lagging rate's derivative, less the model along the lagging rate, leaves the
    surface's term late by the same time). Withheld when the kinematic skew lies within two
    standard errors of the delay (both estimates' errors combined: they do not rule a skew of
    that size out), or shows (|t| >= :data:`AMBIGUOUS_T`, same sign) within 30 % of it. A
    skew the kinematics could not test (the rate hardly moves) leaves the delay named, with
    the caveat in ``details['not_ruled_out']``."""
    rate = SURFACE_RATE.get(c.channel, "")
    name = f"skew_{rate}"
    found = _kin_estimate(kin, name)
    if found is None:
        c.details["not_ruled_out"] = (f"a {rate}-gyro lag of the same size would look alike; the kinematic check did "
                                      f"not test one ({name} not offered)")
        return
    skew, t = found
    se_skew = _kin_std_error(kin, name)
    se_diff = float(np.hypot(c.std_error, se_skew))
    gap = abs(skew - c.estimate)
    shows = t >= AMBIGUOUS_T and np.sign(skew) == np.sign(c.estimate) and gap <= 0.3 * abs(c.estimate)
    if gap <= 2.0 * se_diff or shows:
        c.selected = False
        c.details["sensor_rival"] = name
        c.reason = (f"entered, but not named: the kinematics show the {rate} channel lagging by {skew:.3f} ± "
                    f"{se_skew:.3f} s ({name}, t = {t:.1f}), which "
                    + ("looks like this delay" if t >= AMBIGUOUS_T else "does not rule out a lag of this size"))


# A suspected sensor error withholds a term only if, anywhere within IMITATION_Z standard
# errors of its kinematic estimate, it would imitate at least IMITATION_SHARE of the term's
# change (in the change's direction).
IMITATION_Z = 3.0
IMITATION_SHARE = 0.5


def _imitation(p: Prepared, kin: KinematicResult, aircraft: Aircraft, ic: InitialCondition,
               mismatch: dict[str, np.ndarray], step: _Stepwise):
    """``imitated(c, name)``: the largest change of term ``c``'s parameter, in the direction of
    its own change, that sensor error ``name`` imitates anywhere within :data:`IMITATION_Z`
    standard errors of its kinematic estimate; None when it cannot be computed.

    The imitation is computed, not assumed: the channels are corrected by the kinematic
    estimate v, the measured and the model's coefficients evaluated again, and the mismatch's
    change fitted on the term's column beside the axis's other selected terms and a constant
    (ordinary least squares): δ per v, linear in the error's size. (A 2.3 % q-scale suspicion,
    kinematic t = 2.6, withheld a C_m,q̂ change of −5.9 on the model's −0.95 at 380 ft/s: such a
    scale imitates 0.4 at most.)"""
    inner = _inner(p)

    def imitated(c: Candidate, name: str) -> float | None:
        found = _kin_estimate(kin, name)
        sel, by_key = step.selections.get(c.channel, (None, {}))
        key = next((k for k, t in by_key.items() if t.parameter == c.parameter), None)
        change = c.details.get("change", c.estimate) if c.effect == "coefficient_error" else c.estimate
        if found is None or key is None or not found[0] or not change:
            return None
        v, t = found
        changed = model_along(_corrected(p, kin, {name: v}), aircraft, ic, inertial_from=p).mismatch()
        z = (mismatch[c.channel] - changed[c.channel])[inner]   # what an error of size v adds
        cols = [by_key[key].column[inner]] + [by_key[k].column[inner] for k in sel.names if k != key and k in by_key]
        A = np.column_stack(cols + [np.ones(z.size)])
        per_v = float(np.linalg.lstsq(A, z, rcond=None)[0][0]) / v
        sigma = abs(v) / t if t > 0 else np.inf
        ends = (v - IMITATION_Z * sigma, v + IMITATION_Z * sigma)
        return max(per_v * e * np.sign(change) for e in ends)
    return imitated


def _withhold_ambiguous(cands: list[Candidate], kin: KinematicResult, imitated=None) -> None:
    """Deselect coefficient errors the kinematics cannot tell from a sensor error on the
    channel they are built on (:data:`AMBIGUOUS_T`) and that the sensor error, at a size the
    kinematics allow, would imitate (``imitated``, :func:`_imitation`; half the change); the
    reason names the rival."""

    def explains(c: Candidate, rival: str, t: float) -> bool:
        if c.details.get("sensor_suspect", {}).get("parameter") == rival:
            return False  # asked already (the regressor's sensor and the coefficient's)
        size = None if imitated is None else imitated(c, rival)
        change = abs(c.details.get("change", c.estimate) if c.effect == "coefficient_error" else c.estimate)
        if size is None or size >= IMITATION_SHARE * change:
            return True
        c.details["sensor_suspect"] = {"parameter": rival, "imitates_at_most": size, "change": change}
        c.reason += (f"; the kinematics suspect {rival} (t = {t:.1f}), which would imitate at most {size:.2g} of "
                     f"this change of {change:.3g}")
        return False
    suspects: dict[str, tuple[str, float]] = {}
    for name, sp in kin.parameters.items():
        found = _kin_estimate(kin, name)
        if found is not None and name.split("_", 1)[0] in AMBIGUOUS_KINDS:
            t = found[1]
            if t >= AMBIGUOUS_T and t > suspects.get(sp.channel, ("", 0.0))[1]:
                suspects[sp.channel] = (name, t)
    for c in cands:
        if c.selected and c.effect == "control_delay":
            _withhold_skewed_delay(c, kin)
        if not (c.selected and c.effect == "coefficient_error"):
            continue
        channel = cand.REGRESSOR_SOURCE.get(c.parameter.split("_", 1)[1])
        if channel in suspects and explains(c, *suspects[channel]):
            rival, t = suspects[channel]
            c.selected = False
            c.details["sensor_rival"] = rival
            c.reason = (f"entered, but not named: the {channel} sensor itself may be in error ({rival}, "
                        f"kinematic t = {t:.1f}), which a wrong derivative on {channel} would imitate")
    for c in cands:  # the sensor the coefficient itself is measured with
        sensor = DEPENDENT_SENSOR.get(c.channel or "")
        if not (c.selected and sensor in suspects and c.test.startswith("stepwise")):
            continue
        rival, t = suspects[sensor]
        rate_term = c.effect == "coefficient_error" and c.parameter.split("_", 1)[1] in ("qhat", "phat", "rhat")
        if rival.startswith("skew") and not (c.effect == "unsteady_alphadot" or rate_term):
            continue  # a lag imitates terms that follow the coefficient's rate of change, not its level
        if not explains(c, rival, t):
            continue
        c.selected = False
        c.details["sensor_rival"] = rival
        c.reason = (f"entered, but not named: {c.channel} is measured with {sensor}, which may itself be in error "
                    f"({rival}, kinematic t = {t:.1f}): a lagging or scaled {sensor} imitates this term")


def _signature_ratios(cands: list[Candidate], kin: KinematicResult, p: Prepared, aircraft: Aircraft,
                      ic: InitialCondition, mismatch: dict[str, np.ndarray], step: _Stepwise):
    """``ratios(name, value, skip)``: per axis, the multiple of the mismatch change that
    correcting the channels by sensor parameter ``name`` = ``value`` makes (the model evaluated
    again along the corrected channels, :mod:`corroborate`), fitted beside the axis's named
    terms whose parameter is not in ``skip`` (and its nuisances)."""
    inner = _inner(p)

    @functools.cache
    def along_vane() -> dict[str, np.ndarray]:
        """The mismatch along the β vane (made when first asked)."""
        return model_along(p, aircraft, ic, vane_beta=True).mismatch()

    def ratios(name: str, value: float, skip: frozenset[str] = frozenset(), constant: bool = True) -> dict:
        # the inertial sideslip stays the one integrated from p: it is built from the same
        # instruments as the kinematic check, so letting it follow the correction would make
        # the two tests one
        if kin.parameters[name].channel == "beta" and inertial_beta(p):
            # a β-vane error cannot reach a mismatch along the inertial sideslip: its signature
            # is taken along the vane (whose slow wander the colored-residual fit allows for)
            changed = model_along(_corrected(p, kin, {name: value}), aircraft, ic, vane_beta=True).mismatch()
            return _axis_ratios(cands, step, inner, along_vane(), changed, skip, constant)
        changed = model_along(_corrected(p, kin, {name: value}), aircraft, ic, inertial_from=p).mismatch()
        return _axis_ratios(cands, step, inner, mismatch, changed, skip, constant)
    return ratios


def _axis_ratios(cands: list[Candidate], step: _Stepwise, inner: slice, base: dict[str, np.ndarray],
                 changed: dict[str, np.ndarray], skip: frozenset[str] = frozenset(), constant: bool = True) -> dict:
    """Per axis, :func:`corroborate.axis_ratio` of ``base`` on the change ``changed - base``,
    beside the axis's named terms (those in ``skip`` left out) and its nuisance columns (with
    a constant unless not ``constant``)."""
    out = {}
    for axis, (sel, by_key) in step.selections.items():
        kept = {c.parameter for c in cands if c.selected and c.channel == axis} - skip
        others = [by_key[k].column[inner] for k in sel.names if k in by_key and by_key[k].parameter in kept]
        others += [col[inner] for col in step.nuisances.get(axis, {}).values() if np.ptp(col[inner]) > 0]
        r = corroborate.axis_ratio(base[axis][inner], others, (changed[axis] - base[axis])[inner], constant)
        if r is not None:
            out[axis] = r
    return out


# The vane scale factor at which its signature is evaluated (the fit scales it).
PROBE_SCALE = 0.05


def _withhold_vane_scale(cands: list[Candidate], kin: KinematicResult, step: _Stepwise, signature,
                         inertial: bool = False) -> None:
    """Deselect coefficient errors on α or β that a scale error of that vane would imitate on
    every axis that can tell (:func:`corroborate.imitates`): the model evaluated along a
    scaled angle is off by each coefficient's own slope times the scaled excursion, so a
    vane scale looks like C_Z,α, C_m,α and C_X,α wrong in the model's own proportions, which
    no single coefficient error does. The kinematics cannot always see the scale (its
    column is nearly a bias's when the angle hardly moves about its mean). Not for β when the
    model follows the inertial sideslip (``inertial``): a vane scale cannot reach the mismatch
    then. A scale no vane plausibly has (:data:`kinematics.PLAUSIBLE`) imitates nothing."""
    for x in ("alpha",) + (() if inertial else ("beta",)):
        name = f"scale_{x}"
        chosen = [c for c in cands if c.selected and c.effect == "coefficient_error"
                  and cand.REGRESSOR_SOURCE.get(c.parameter.split("_", 1)[1]) == x]
        if not chosen or name not in kin.parameters:
            continue
        same = frozenset(c.parameter for c in cands if c.parameter.endswith(f"_{x}") and c.test.startswith("stepwise"))
        ag = corroborate.imitates(signature(name, PROBE_SCALE, same), t_aero=cand.T_IN)
        if ag is None or not is_plausible(name, ag.ratio * PROBE_SCALE, 1.0):
            continue
        refuted = _kinematics_refute(kin, name, ag.ratio * PROBE_SCALE, ag.std_error * PROBE_SCALE)
        if refuted:
            for c in chosen:
                c.details["vane_scale_refuted"] = refuted
            continue
        for c in chosen:
            c.selected = False
            c.details["sensor_rival"] = name
            each = ", ".join(f"{a.axis} {a.ratio * PROBE_SCALE:.3f} ± {a.std_error * PROBE_SCALE:.3f}" for a in ag.axes)
            c.reason = (f"entered, but not named: an {x} vane scale error of k = {ag.ratio * PROBE_SCALE:.3f} would "
                        f"explain the mismatch on every axis that can tell alike (k from {each}), in the model's own "
                        "proportions, which a wrong derivative on one axis does not")


# How far (in combined standard errors) the kinematics' own estimate of a vane's scale may
# sit from the scale the coefficient mismatch asks for before they refute it. The mismatch's
# k and the kinematic one come from independent equations; on the project sweep a C_Z,α error
# asked for k = -0.069 ± 0.012 against a kinematic 0.003 ± 0.011 (4.5 apart), while a true
# 0.08 scale at 700 ft/s asked for 0.166 ± 0.024 against a kinematic 0.066 ± 0.032 (2.5).
VANE_REFUTE_Z = 3.5


def _kinematics_refute(kin: KinematicResult, name: str, k: float, k_std: float) -> str:
    """Why the kinematics refute a vane scale ``k ± k_std`` the coefficient mismatch asks for:
    their own estimate of ``name`` sits more than :data:`VANE_REFUTE_Z` combined standard
    errors from it; an empty string when they do not (or cannot tell)."""
    found = _kin_estimate(kin, name)
    if found is None or found[1] <= 0:
        return ""
    v, t = found
    se = abs(v) / t
    z = abs(k - v) / float(np.hypot(se, k_std))
    if not np.isfinite(z) or z < VANE_REFUTE_Z:
        return ""
    return (f"an {name.split('_', 1)[1]} vane scale of k = {k:.3f} ± {k_std:.3f} would imitate it, but the "
            f"kinematics put that scale at {v:.3f} ± {se:.3f} ({z:.1f} standard errors apart)")


# The vane bias (rad) at which its signature on the coefficient means is evaluated (the fit
# scales it).
PROBE_VANE_BIAS = np.radians(0.5)
# Per vane: the axes its bias reaches through the model's slopes, and the test's name. For α
# the force axes' means also carry errors of the thrust's direction and level and of the mass,
# which an α bias's C_X and C_Z proportions can match: offered for α earlier, the test named
# an α bias of −1.87° on the 737's noise-free self-check from C_X and C_Z alone (its engines'
# thrust is not along body x). Offered again after the later rules (the vane's wander and the
# light-gust tests, the sensor-suspicion imitation size), it named the c172x's 1° α bias at
# 180 ft/s (1.036 ± 0.018°, on C_X, C_Z and C_m; the kinematics t 1.4), changed no other
# case, and left all 70 nulls and self-checks of the outside sweep and 11 of the project's
# `none` (the 737's self-check included). On 82 null and self-check recordings the β test
# agreed on no bias above 0.066° (practical: 0.15°).
VANE_MEANS_AXES = {"beta": cand.LAT, "alpha": cand.LON}
MEANS_TESTS = {"beta": "lateral coefficient means along the β vane",
               "alpha": "longitudinal coefficient means along the α vane"}


def birge_scaled(ag: corroborate.Agreement) -> float:
    """The common ratio's standard error, scaled by the Birge ratio √(χ²/(k − 1)) of the axes'
    scatter about it when that exceeds 1: the colored-residual errors of a constant are
    small, and the axes then disagree by more than they allow because the model's own slopes
    carry errors too (R. T. Birge, Phys. Rev. 40, 207 (1932), the calculation of errors by
    the method of least squares)."""
    k = len(ag.axes)
    if k < 2:
        return ag.std_error
    chi2 = sum(((a.ratio - ag.ratio) / a.std_error) ** 2 for a in ag.axes)
    return ag.std_error * max(1.0, float(np.sqrt(chi2 / (k - 1))))


def _name_vane_bias_from_means(cands: list[Candidate], kin: KinematicResult, p: Prepared, aircraft: Aircraft,
                               ic: InitialCondition, step: _Stepwise, channel: str, applied: float = 0.0) -> None:
    """Name a vane bias (``channel``; :data:`VANE_MEANS_AXES`) from the coefficients' means
    along the vane.

    The kinematics can all but miss a vane bias (β enters them through cos β: a 1° bias stood
    at t 1.3-1.5; a c172x's 1° α bias at 180 ft/s at t 1.4), and the stepwise fits' constants
    absorb what it does to the coefficients. But the model evaluated along a vane that reads
    x + b is off by each coefficient's own slope in x times b: one constant on C_Y, C_l and
    C_n (β) or C_X, C_Z and C_m (α) in the model's proportions. So each such axis's mismatch
    is fitted on the change a probe bias makes (:data:`PROBE_VANE_BIAS`), without a constant
    (beside the axis's named terms and nuisances), along the vanes' own records whether or not
    the maneuver moved them (held at a start sample, the test would measure that sample's
    noise); a kinematic estimate already applied to the channels (``applied``) is added
    back. The bias is named when the axes that can tell agree on it, significantly
    (:func:`corroborate.imitates`), and it is practical and precise (:func:`_sensor_verdict`).
    A constant model error on one axis (an asymmetry, a propeller's torque, a thrust or mass
    error, a moment-reference shift) does not match the slopes' proportions on all of them.
    The estimate is kept in ``details['vane_means']`` whether named or not, for the
    validation maneuver's check."""
    name = f"bias_{channel}"
    c = next((c for c in cands if c.parameter == name), None)
    if c is None or c.selected or name not in kin.parameters:
        return
    base = model_along(p, aircraft, ic, vanes=True).mismatch()
    changed = model_along(_corrected(p, kin, {name: PROBE_VANE_BIAS}), aircraft, ic, vanes=True).mismatch()
    ratios = {k: r for k, r in _axis_ratios(cands, step, _inner(p), base, changed, constant=False).items()
              if k in VANE_MEANS_AXES[channel]}
    ag = corroborate.imitates(ratios, t_aero=cand.T_IN)
    if ag is None:
        return
    # the channels were corrected by the kinematic estimate already applied: the means see the rest
    est, se = applied + ag.ratio * PROBE_VANE_BIAS, birge_scaled(ag) * PROBE_VANE_BIAS
    c.details["vane_means"] = {"estimate": est, "std_error": se, "applied_before": applied,
                               "axes": {a.axis: [a.ratio * PROBE_VANE_BIAS, a.std_error * PROBE_VANE_BIAS]
                                        for a in ag.axes}}
    # named only when the means alone, their scatter allowed for, stand at the entry t
    if abs(est - applied) < cand.T_IN * se or not _sensor_verdict(name, est, se, True, kin, p, False, True)[0]:
        return
    each = ", ".join(f"{a.axis} {np.degrees(a.ratio * PROBE_VANE_BIAS):.2f}° ± "
                     f"{np.degrees(a.std_error * PROBE_VANE_BIAS):.2f}°" for a in ag.axes)
    c.reason = (f"the model along the {'α' if channel == 'alpha' else 'β'} vane is off by its own slopes times one "
                f"constant on every axis that can tell ({each}); the kinematics alone: t = {c.t:.1f}")
    c.selected, c.estimate, c.std_error, c.t = True, est, se, est / se
    c.test = MEANS_TESTS[channel]


def _name_corroborated(cands: list[Candidate], kin: KinematicResult, p: Prepared, signature, applied: set[str],
                       V0: float) -> None:
    """Name a suspected sensor error (kinematic |t| >= :data:`AMBIGUOUS_T`, below the kinematic
    entry t), whether or not it kept a coefficient term from being named, when the coefficient
    mismatch independently shows the same error on every axis that can tell
    (:mod:`corroborate`). Its signature is the change in the mismatch when the channels are
    corrected by the kinematic estimate and the model is evaluated again. (Offered only to the
    suspects that had withheld a term, a 40 ms p-gyro skew at 700 ft/s, t = 3.7, and a 6 ft
    lateral accelerometer offset, t = 5.1, went unnamed; on the outside and project sweeps the
    wider offer named no wrong error.)"""
    suspects = sorted({c.details["sensor_rival"] for c in cands if not c.selected and "sensor_rival" in c.details}
                      | {c.parameter for c in cands if c.effect in SENSOR_EFFECTS and not c.selected
                         and c.reason == "below the entry t"})
    for name in suspects:
        sensor = next((c for c in cands if c.parameter == name), None)
        found = _kin_estimate(kin, name)
        if sensor is None or sensor.selected or found is None or name in applied:
            continue
        v, t = found
        if t < AMBIGUOUS_T or not is_plausible(name, v, V0):
            continue
        verdict = corroborate.corroborate(name, v, abs(v) / t, signature(name, v), t_aero=cand.T_IN)
        if not _name_if_corroborated(sensor, kin, p, verdict, t):
            continue
        for c in cands:
            if c.details.get("sensor_rival") == name:
                c.reason += f"; explained by the {name} named"


def _kinematic_rival(kin: KinematicResult, name: str) -> tuple[str, float, float, float] | None:
    """The unselected kinematic candidate most collinear with selected ``name`` (partial |r|,
    the forced biases and the other selected terms taken out, at least
    :data:`rivals.RIVAL_CORRELATION`), with the correlation, ``name``'s |t| beside it and the
    rival's |t| beside ``name`` (those terms in the fit); None when there is none."""
    cols = kin.columns or {}
    if name not in cols:
        return None
    fixed = [n for n in kin.forced + kin.selection.names if n != name and n in cols]
    F = np.column_stack([cols[n] for n in fixed]) if fixed else np.zeros((kin.start.size, 0))

    def partial(x: np.ndarray) -> np.ndarray:  # x with the fixed columns' part removed
        return x - F @ np.linalg.lstsq(F, x, rcond=None)[0] if fixed else x
    a = partial(cols[name])
    best = None
    for other, col in cols.items():
        if other in fixed or other == name or np.ptp(col) <= 0:
            continue
        b = partial(col)
        r = float(np.dot(a, b) / np.sqrt(np.dot(a, a) * np.dot(b, b))) if np.dot(b, b) > 0 else 0.0
        if abs(r) >= rivals.RIVAL_CORRELATION and (best is None or abs(r) > abs(best[1])):
            best = (other, r)
    if best is None:
        return None
    try:
        theta, se, _ = colored_fit(kin.start, [cols[n] for n in fixed] + [cols[name], cols[best[0]]],
                                   fixed + [name, best[0]], constant=False)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return best[0], best[1], 0.0, 0.0
    j = len(fixed)
    t_own = float(abs(theta[j] / se[j])) if se[j] > 0 else 0.0
    t_rival = float(abs(theta[j + 1] / se[j + 1])) if se[j + 1] > 0 else 0.0
    return best[0], best[1], t_own, t_rival


def _contested(kin: KinematicResult) -> dict[str, tuple[str, float, float]]:
    """The selected kinematic terms the kinematics cannot tell from a rival
    (:func:`_kinematic_rival`: |t| beside it below their entry t, unless it stays at least
    :data:`AMBIGUOUS_T` there while the rival falls below it): not applied to the channels, so
    that the coefficient mismatch can judge between the two (:func:`_kinematic_rivals`)."""
    out = {}
    for n in kin.selection.names:
        found = _kinematic_rival(kin, n)
        if found is None or found[2] >= KIN_T_IN:
            continue
        if found[2] >= AMBIGUOUS_T and found[3] < AMBIGUOUS_T:
            continue  # beside each other, the data still prefer this one
        out[n] = found[:3]
    return out


def _kinematic_rivals(cands: list[Candidate], kin: KinematicResult, p: Prepared, signature,
                      contested: dict[str, tuple[str, float, float]]) -> None:
    """A sensor error the kinematics name is kept only when they tell it from its most
    collinear rival (|t| >= their entry t beside it): on a pitch maneuver an α scale factor
    and an a_z skew both follow α̇ in the ẇ equation. When they cannot, the coefficient
    mismatch decides (:mod:`corroborate`: each rival's computed signature, at its own
    kinematic size, against every axis): the one it corroborates and the other not is named;
    otherwise neither is."""
    by_name = {c.parameter: c for c in cands}
    for c in [c for c in cands if c.selected and c.parameter in contested]:
        rival, r, t_beside = contested[c.parameter]
        other = by_name.get(rival)
        solo = _kin_estimate(kin, rival)
        verdicts = {}
        for name, (v, t) in ((c.parameter, (c.estimate, abs(c.t))), (rival, solo or (0.0, 0.0))):
            if v == 0.0 or t <= 0:
                verdicts[name] = None
                continue
            verdicts[name] = corroborate.corroborate(name, v, abs(v) / t, signature(name, v), t_aero=cand.T_IN)
        own, theirs = verdicts[c.parameter], verdicts[rival]
        c.details["kinematic_rival"] = {"parameter": rival, "correlation": r, "t_beside": t_beside,
                                        "own": own.as_dict() if own else None,
                                        "rival": theirs.as_dict() if theirs else None}
        if own is not None and own.named and not (theirs is not None and theirs.named):
            c.reason += (f"; the kinematics cannot tell it from {rival} (r = {r:+.2f}, beside it t = {t_beside:.1f}), "
                         "but the coefficient mismatch shows this one, not that")
            continue
        c.selected = False
        if theirs is not None and theirs.named and not (own is not None and own.named) and other is not None:
            c.reason = (f"not named: the kinematics cannot tell it from {rival} (r = {r:+.2f}, beside it t = "
                        f"{t_beside:.1f}), and the coefficient mismatch shows {rival}, not this")
            _name_if_corroborated(other, kin, p, theirs, solo[1])
            other.reason = theirs.reason + (f" (kinematic t = {solo[1]:.1f}; the kinematics alone cannot tell it "
                                            f"from {c.parameter})")
        else:
            c.reason = (f"not named: the kinematics cannot tell it from {rival} (r = {r:+.2f}, beside it t = "
                        f"{t_beside:.1f}), nor can the coefficient mismatch")
        _withhold_absorbed_biases(cands, kin, c.parameter, rival)


def _withhold_absorbed_biases(cands: list[Candidate], kin: KinematicResult, dropped: str, rival: str) -> None:
    """With the kinematic fit redone on ``rival`` in place of ``dropped`` (the two it cannot tell
    apart), a named bias whose |t| falls below the entry t is part of the rival's error (an α
    scale factor shifts α's mean by k·ᾱ, which a bias otherwise takes) and is not named."""
    cols = kin.columns or {}
    names = [n for n in kin.forced + kin.selection.names if n != dropped and n in cols] + [rival]
    try:
        theta, se, _ = colored_fit(kin.start, [cols[n] for n in names], names, constant=False)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return
    t_alt = {n: abs(theta[i] / se[i]) if se[i] > 0 else 0.0 for i, n in enumerate(names)}
    for c in cands:
        if c.selected and c.parameter in kin.forced and t_alt.get(c.parameter, np.inf) < cand.T_IN:
            c.selected = False
            c.reason = (f"not named: with {rival} in place of {dropped} (the kinematics cannot tell them apart) it "
                        f"falls to t = {t_alt[c.parameter]:.1f}: it may be part of {rival}")


def _name_applied(cands: list[Candidate], kin: KinematicResult, recorded: Prepared, p: Prepared,
                  aircraft: Aircraft, ic: InitialCondition, mismatch: dict[str, np.ndarray],
                  removed: dict[str, np.ndarray], step: _Stepwise, applied: dict[str, float], V0: float) -> None:
    """Name a sensor error that was applied to the channels (|t| >= :data:`APPLY_T`) but is
    below its entry t, when the coefficient mismatch corroborates it (:mod:`corroborate`):
    here the mismatch *without* the correction is fitted on the change the correction made
    (a 1.5 deg α bias that the correction took out of a C_m,α-like mismatch at t = 18)."""
    inner = _inner(p)
    for name, v in applied.items():
        sensor = next((c for c in cands if c.parameter == name), None)
        if sensor is None or sensor.selected or sensor.reason != "below the entry t":
            continue
        without = _corrected(recorded, kin, {k: x for k, x in applied.items() if k != name})
        base = {c: x - removed[c] for c, x in model_along(without, aircraft, ic, inertial_from=p).mismatch().items()}
        ratios = _axis_ratios(cands, step, inner, base, mismatch)
        _name_if_corroborated(sensor, kin, p, corroborate.corroborate(name, v, abs(v) / _t_of(kin, name), ratios,
                                                                      t_aero=cand.T_IN), _t_of(kin, name))


def _name_if_corroborated(sensor: Candidate, kin: KinematicResult, p: Prepared, verdict, t_kin: float) -> bool:
    """Select ``sensor`` at the verdict's combined size when the verdict names it and the size
    is practical; the verdict is kept in ``details['corroboration']`` either way."""
    sensor.details["corroboration"] = verdict.as_dict()
    practical = (is_practical(sensor.parameter, verdict.estimate, p.dt)
                 and _kin_share(kin, sensor.parameter, verdict.estimate, p) >= cand.PRACTICAL_SHARE)
    if not (verdict.named and practical):
        return False
    sensor.selected = True
    sensor.estimate, sensor.std_error = verdict.estimate, verdict.std_error
    sensor.t = verdict.estimate / verdict.std_error
    sensor.reason = verdict.reason + f" (kinematic t = {t_kin:.1f}, below their entry t alone)"
    return True


# The |t| each maneuver's kinematic estimate must reach on its own for a sensor error below
# the identification's entry t to be named on the two together (:func:`name_replicated`):
# the suspicion level of the other sensor rules (:data:`AMBIGUOUS_T`).
REPLICATED_EACH_T = AMBIGUOUS_T


def name_replicated(a: Analysis, av: Analysis) -> list[Candidate]:
    """Name the sensor biases that the identification's kinematics only suspect (|t| at least
    :data:`REPLICATED_EACH_T`, below the entry t) and the validation's show too (|t| at least
    as much, the same sign, sizes within two standard errors), when their inverse-variance
    combination reaches the kinematic entry t (:data:`kinematics.T_IN`): the same instrument
    flew both, and their kinematic residuals carry independent noise. Not when either record's
    kinematics are void (turbulence, light gusts, implausible estimates), when the
    identification's kinematics cannot tell the parameter from a rival
    (:func:`_kinematic_rival`), or when the combined size is not practical and precise
    (:func:`_sensor_verdict`). Returns the candidates of ``a`` it selected.

    Biases only, and only when no other sensor error is named: the replication shows the two
    records' noise to be independent, not their systematic errors. A real error the kinematic
    fit leaves out repeats in both records and pushes the columns that follow the same motion
    alike: beside a β-vane scale of 0.15 (named on the coefficient mismatch, not in the
    kinematic fit) both maneuvers asked for an r-gyro scale of −0.14 (t −5.4 and −5.8), and a
    noise-free DHC-6 flight of the model itself for an a_y scale of −0.07 (t −3.8 and −5.6;
    outside sweep, 2 Dec 2026). A constant is the one column a motion-following error does
    not imitate alike in two different maneuvers."""
    if not (_kinematics_trusted(a) and _kinematics_trusted(av)):
        return []
    if any(c.selected and c.effect in SENSOR_EFFECTS for c in a.candidates):
        return []
    p, kin = a.prepared, a.kinematic
    twins = {c.parameter: c for c in av.candidates if c.test.startswith("kinematic consistency")}
    named = []
    for c in a.candidates:
        v = twins.get(c.parameter)
        if (c.selected or v is None or c.reason != "below the entry t" or c.effect != "sensor_bias"
                or min(abs(c.t), abs(v.t)) < REPLICATED_EACH_T or np.sign(c.estimate) != np.sign(v.estimate)
                or c.std_error <= 0 or v.std_error <= 0):
            continue
        if abs(c.estimate - v.estimate) > 2.0 * np.hypot(c.std_error, v.std_error):
            continue
        w1, w2 = c.std_error ** -2, v.std_error ** -2
        est, se = (w1 * c.estimate + w2 * v.estimate) / (w1 + w2), (w1 + w2) ** -0.5
        if abs(est) / se < KIN_T_IN or _kinematic_rival(kin, c.parameter) is not None:
            continue
        if not _sensor_verdict(c.parameter, est, se, True, kin, p, False, True)[0]:
            continue
        c.details["replication"] = {"identification": [c.estimate, c.std_error],
                                    "validation": [v.estimate, v.std_error], "combined": [est, se]}
        c.reason = (f"named on two maneuvers: the identification's kinematics suspect it (t = {c.t:.1f}, below "
                    f"the entry t) and the validation's agree (t = {v.t:.1f}, the sizes within two standard "
                    f"errors); together t = {est / se:.1f}")
        c.selected, c.estimate, c.std_error, c.t = True, est, se, est / se
        named.append(c)
    return named


def _kinematics_trusted(a: Analysis) -> bool:
    """Whether a recording's kinematic consistency can judge its sensors: no turbulence
    named, no light gusts (:func:`light_gusts`), every supported estimate plausible."""
    turbulent = any(c.effect == "turbulence" and c.selected for c in a.candidates)
    V0 = float(np.mean(a.prepared.smooth["V"]))
    return not turbulent and not a.gusty and _kinematics_plausible(a.kinematic, V0)


KINEMATIC_PASSES = 4


def plausible_kinematic_check(p: Prepared) -> KinematicResult:
    """The kinematic check, refitted without the parameters whose estimates no instrument
    could have (:func:`kinematics.is_plausible`): nearly collinear pairs (an a_z bias and
    scale where a_z stays near -1 g) can run to offsetting absurd values and take the true
    sensor error with them. At most :data:`KINEMATIC_PASSES` fits; the last is returned."""
    V0 = float(np.mean(p.smooth["V"]))
    exclude: frozenset[str] = frozenset()
    for _ in range(KINEMATIC_PASSES):
        kin = kinematic_check(p, exclude=exclude)
        bad = {n for n in kin.forced + kin.selection.names
               if not is_plausible(n, kin.selection.params[n], V0) and _t_of(kin, n) >= APPLY_T}
        bad -= set(kin.forced)  # the nuisance biases stay in every fit
        if not bad:
            return kin
        exclude |= bad
    return kin


def _kin_share(kin: KinematicResult, name: str, value: float, p: Prepared) -> float:
    """The change a sensor parameter makes to its channel, as a share of the channel's
    excursion (:func:`kinematics.channel_share`): practical significance, as for the
    aerodynamic terms (a noise-free flight asks for a 2 ft β-vane offset at t = 69, a
    0.01 deg change in β)."""
    clean = clean_channels(p)
    k = max(1, int(round(1.0 / p.dt)))
    return channel_share(kin.parameters[name], value, clean, p, slice(k, p.n - k))


def _t_of(kin: KinematicResult, name: str) -> float:
    se = kin.selection.std_errors.get(name, 0.0)
    return abs(kin.selection.params[name] / se) if se > 0 else 0.0


IMPLAUSIBLE = ("not applied: the kinematic fit asks for a sensor error larger than any instrument plausibly has "
               "(kinematics.PLAUSIBLE), so the channels disagree for another reason")
PROPELLER_DRIFT = ("the propeller's torque, P-factor and slipstream change with airspeed at a fixed throttle, "
                   "outside the model's aerodynamic coefficients: a lateral drift term would fit them")
NO_THRUST_DRIFT = ("thrust was not recorded (held constant at trim): a drift in CX or Cm cannot be told from the "
                   "thrust's own change with airspeed (its force, and its moment about the c.g.)")
GUST_RATIO = 4.0     # the integrated kinematic residual over what sensor noise alone gives
GUST_MIN_FPS = 3.0   # and at least light turbulence's RMS gust
# Gusts below GUST_MIN_FPS still void the sensor tests when their angle σ/V is this many times
# the vanes' white noise (light_gusts): at Dryden severity 2 the c172x (180 ft/s) and DHC-6
# (230 ft/s) nulls reached 6 and 4 and made sensor findings; no recording without gusts on
# either sweep reaches 1.3, nor 1.6 with the vanes' wander doubled (0.2 deg).
GUST_ANGLE_FACTOR = 2.5
# The vanes' noise counted is at least this (rad), a typical vane's (the white preset's 0.1°),
# so that no gust angle under 0.25° voids the sensor tests: a recorder's own filtering can
# leave a real record's vanes a fraction of that noise (the Twin Otter's), and there the 0.4
# ft/s (0.09°) "gust" is the kinematics' other inconsistencies (its 0.11 g a_y offset), not
# air; a noise-free recording's 0.04 ft/s is no gust either.
VANE_NOISE_FLOOR_RAD = np.radians(0.1)
NOT_IN_TURBULENCE = "not applied: in turbulence the kinematic consistency does not hold"
# The air-share test (spectra.air_share): gusts are named when at least half the vane-vs-
# inertial angle difference is air, AIR_T standard errors above none; it is vane error when
# the share stands VANE_ERROR_Z standard errors under the half. Outside sweep (2 Dec 2026):
# pitch and three-axis nulls 0.0-0.65 (kinematic noise other than the vanes' puts it above
# 0); Dryden severity 2 at 180-330 ft/s 0.96-1.12; severity 3-4 0.9-1.3; vane wander of
# 0.2 deg at 700 ft/s -0.08 ± 0.03, of 0.4 deg 0.01 ± 0.02.
AIR_SHARE_MIN = 0.5
AIR_T = 4.0
VANE_ERROR_Z = 2.0
# Gusts this many times the vanes' noise (under GUST_ANGLE_FACTOR) are put to the air-share
# test too, and named light turbulence only when it says air: Dryden severity 2 at 330 ft/s
# stood at 2.49 times (air share 1.12 ± 0.14); no null without gusts reaches 1.7.
LIGHT_TURBULENCE_FACTOR = 2.0


def _practical_size(name: str, dt: float) -> float:
    kind, _, channel = name.partition("_")
    if kind == "bias":
        return PRACTICAL["bias"].get(channel, 1.0)
    if kind == "scale":
        return PRACTICAL["scale"]
    if kind == "skew":
        return PRACTICAL["skew_samples"] * dt
    return PRACTICAL["offset_ft"]


# The smallest transport delay worth naming, in samples: below it a delay cannot be told from
# sample timing (JSBSim-flown recordings show about +0.6 sample on every null flight).
PRACTICAL_DELAY_SAMPLES = 2.0


def _practical(share: float) -> bool:
    return share >= cand.PRACTICAL_SHARE


def _impractical_reason(share: float) -> str:
    return (f"entered, but too small to matter: it explains {100 * share:.1f} % of the coefficient's excursion "
            f"(under {100 * cand.PRACTICAL_SHARE:.0f} %)")


def _aero_candidates(selections: dict, delays: dict, dt: float,
                     shares: dict[tuple[str, str], float] | None = None) -> list[Candidate]:
    shares = shares or {}
    out: list[Candidate] = []
    delay_seen: dict[str, list] = {}
    cg_seen: list = []
    for axis, (sel, terms) in selections.items():
        for t in sel.terms:
            if t.name.startswith("delay_"):
                delay_seen.setdefault(t.name[6:], []).append((axis, t))
                continue
            term = terms[t.name]
            if term.effect == "cg_offset":
                cg_seen.append((axis, t, term))
                continue
            est, se = t.estimate * term.scale, abs(t.std_error * term.scale)
            if term.effect == "coefficient_error":
                est = term.details["model_value"] + t.estimate
            share = shares.get((axis, t.name), 0.0)
            sel = t.selected and _practical(share)
            reason = ("entered" if sel else _impractical_reason(share) if t.selected else "not entered")
            out.append(Candidate(term.effect, cand.AXIS_NAME[axis], axis, term.parameter, est, se, t.t, t.gain,
                                 term.units, f"stepwise on the {axis} mismatch", sel, reason,
                                 {"change": t.estimate, "model_over_maneuver": term.details["model_value"],
                                  "model_at_trim": term.details["trim_value"]}
                                 if term.effect == "coefficient_error" else {}))
    for s, rows in delay_seen.items():
        scan = delays[s]
        # significance from the stepwise entry of the delay column (its coefficient is τ);
        # size and standard error from the scan's linearised fit
        best = max(rows, key=lambda r: abs(r[1].t))[1]
        entered = any(t.selected and _practical(shares.get((a, t.name), 0.0)) for a, t in rows)
        inside = scan.tau_s <= cand.DELAY_GRID_S[-1]
        sel = entered and inside and scan.tau_s >= PRACTICAL_DELAY_SAMPLES * dt
        gain = max(t.gain for _, t in rows)
        out.append(Candidate("control_delay", "pitch" if s == "de" else ("roll" if s == "da" else "yaw"), s, f"tau_{s}",
                             scan.tau_s, scan.std_error, best.t, gain, "s", f"delay scan of {s} + stepwise", sel,
                             "entered" if sel else ("not entered" if not entered else
                                                    "entered, but the delay lies beyond the scanned 0-0.3 s: not an "
                                                    "actuator delay" if not inside else "entered, but under two samples"),
                             {"axes": [a for a, _ in rows], "scan_t": scan.t, "stepwise_t": best.t}))
    if cg_seen:
        axis, t, term = max(cg_seen, key=lambda r: abs(r[1].t))
        sel = any(r[1].selected and _practical(shares.get((r[0], r[1].name), 0.0)) for r in cg_seen)
        out.append(Candidate("cg_offset", cand.AXIS_NAME[axis], axis, term.parameter, t.estimate * term.scale,
                             abs(t.std_error * term.scale), t.t, t.gain, "ft", f"stepwise on the {axis} mismatch",
                             sel, "entered" if sel else (_impractical_reason(shares.get((axis, t.name), 0.0))
                                                         if t.selected else "not entered")))
    return out
