"""Turbulence and light gusts: the gust estimate's verdict, the air-share test that tells gusts
from vane error, the candidates the spectra give (structural mode, turbulence), and the
terms gusts or vane wander keep from being named."""
from __future__ import annotations

import numpy as np
from scipy.stats import linregress

from harness.diagnosis.along import ModelAlong, model_along, slope_function
from harness.diagnosis.candidates import VANE_ALPHA_RATE_AXES
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.kinematics import PRACTICAL, kinematic_residuals
from harness.diagnosis.prepare import Prepared, interior_slice
from harness.diagnosis.spectra import AirShare, FISHER_P, air_share, gust_estimate
from models.aircraft import Aircraft
from models.constants import G0_FPS2
from models.replay import InitialCondition


def turbulence_test(p: Prepared):
    """The gust estimate from the kinematic residual, and whether it says turbulence
    (:data:`GUST_RATIO` times what sensor noise gives and at least :data:`GUST_MIN_FPS`)."""
    gust = gust_estimate(kinematic_residuals(p.raw, p), p,
                         0.5 * (p.noise_std.get("az", 0.03) + p.noise_std.get("ay", 0.03)) * G0_FPS2)
    turbulent = gust.ratio_to_noise >= GUST_RATIO and max(gust.sigma_w_fps, gust.sigma_v_fps) >= GUST_MIN_FPS
    return gust, turbulent


def airspeed_bias_in_the_gust(p: Prepared, gust) -> tuple[float, float]:
    """``(b, R²)``: the vertical gust estimate (``gust.w_fps``, from ``p.raw``) fitted, with a
    constant, on the change an airspeed bias of 1 ft/s makes to it, over the interior.

    The w equation's residual takes V in w = V sin α cos β and in q·u: a bias b leaves
    b·(α̇ − q) there (wings level), whose integral, the "gust", is b times the change of the
    flight-path angle, −b·Δγ. An altitude channel sees the same bias in ḣ (b·sin γ); without
    one the two are one column."""
    raw = dict(p.raw)
    raw["V"] = raw["V"] + 1.0
    column = gust_estimate(kinematic_residuals(raw, p), p, 1.0).w_fps - gust.w_fps
    inner = interior_slice(p.n, p.dt)
    if np.ptp(column[inner]) <= 0 or np.ptp(gust.w_fps[inner]) <= 0:
        return 0.0, 0.0
    fit = linregress(column[inner], gust.w_fps[inner])
    return float(fit.slope), float(fit.rvalue) ** 2


def gusts_of_an_airspeed_bias(p: Prepared, gust, V0: float) -> str:
    """Why the gusts found are not named turbulence ('' when they may be): the vertical gust
    estimate follows an airspeed bias's signature (:func:`airspeed_bias_in_the_gust`), R² at
    least :data:`AIRSPEED_GUST_R2`, at a size under :data:`AIRSPEED_ERROR_SHARE` of the
    airspeed. Turbulence is independent of the maneuver; an airspeed error makes a "gust"
    that is the flight path's own change. An independent script's J3 Cub (1,400 ft / 106
    ft/s, pitch 3-2-1-1 at 50 Hz, no altitude channel) with the airspeed reading 10 ft/s high
    had light turbulence of 0.52 ft/s named (air share 0.95 ± 0.05): its gust followed the
    signature at R² 0.92 as a bias of 10.9 ft/s. On the two sweeps no recording reaches R² 0.5
    at such a size (turbulence of severity 1-4: 0.02-0.27, at 30-160 ft/s)."""
    b, r2 = airspeed_bias_in_the_gust(p, gust)
    if r2 < AIRSPEED_GUST_R2 or abs(b) > AIRSPEED_ERROR_SHARE * V0:
        return ""
    return (f"the vanes and the inertial channels disagree, but the vertical 'gust' ({gust.sigma_w_fps:.2f} ft/s) "
            f"follows the flight path's own change as an airspeed bias of {b:+.1f} ft/s would (R² = {r2:.2f}): not "
            "turbulence, and not named as an airspeed error either (the kinematics cannot tell it from a gust that "
            "follows the maneuver); it breaks the kinematic consistency the sensor tests rest on")


# The vertical gust is an airspeed error's signature (gusts_of_an_airspeed_bias) when the
# signature explains at least half its variance, at a size under a fifth of the airspeed
# (a pitot-static system further off is broken, not biased; lateral maneuvers' small w
# residuals follow the signature at R² 0.5-0.99 only as "biases" of 0.55-1.03 times V).
AIRSPEED_GUST_R2 = 0.5
AIRSPEED_ERROR_SHARE = 0.2


def air_share_test(p: Prepared, aircraft: Aircraft, ic: InitialCondition, along: ModelAlong, slope_of, gust,
                   V0: float) -> AirShare:
    """The air-share test (:func:`spectra.air_share`) on C_Z and the vertical gust, along
    the α vane's own record, with the model's C_Z,α from ``slope_of`` (:func:`slope_function`
    along ``along``): where the maneuver did not drive α the model holds it at its start or
    follows the inertial α (:func:`model_states`, :func:`along.undriven_inertial`), and is
    evaluated again along the vane for the test. (Along the inertial α the mismatch carries
    none of the vane's wander, whatever the difference e is, and the share reads 1: an
    independent script's 787-8, pitch sweep at 791 ft/s and 27,500 ft with twice the vanes'
    wander at 40 Hz, α under the vane's noise, q resampled 40 ms late and back, had
    turbulence of 4.8 ft/s named at an air share of 1.01 ± 0.03; along the vane 0.25.)"""
    vane_alpha = "alpha" in p.driven or "alpha" in p.moved
    if "alpha" not in along.states or np.ptp(along.states["alpha"]) == 0.0 or not vane_alpha:
        along = model_along(p, aircraft, ic, vanes=True)
        slope_of = slope_function(aircraft, ic, along.states, along.surfaces, along.alphadot, along.aero,
                                  along.weights)
    slope = slope_of("alpha")["CZ"]
    # an angle the maneuver neither drove nor moved is its vane's noise and wander, the very
    # error the test asks after: as a nuisance it took the vane error's place (an independent
    # script's 787-8, lateral multisine at 838 ft/s, twice the vanes' wander: air share
    # 1.09 ± 0.11, turbulence named; without it −0.02 ± 0.04)
    nuisances = [p.smooth[c] for c in ("alpha", "beta", "p", "q", "r") if c in p.smooth
                 and (c not in ("alpha", "beta") or c in p.driven or c in p.moved)]
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
    is_air = affirms_air(air)
    if near:
        return (False, True, near) if is_air else (turbulent, False, gusty)
    if _vane_error(air):
        sigma = max(gust.sigma_w_fps, gust.sigma_v_fps)
        return False, False, (f"the vanes and the inertial channels disagree by {np.degrees(air.angle_rad):.2f} deg "
                              f"RMS ({sigma:.1f} ft/s at {V0:.0f} ft/s), but the aerodynamics did not follow the "
                              f"vanes (air share {air.share:.2f} ± {air.std_error:.2f}): vane error, not turbulence, "
                              "and it breaks the kinematic consistency the sensor tests rest on")
    return turbulent, bool(gusty) and is_air, gusty


def affirms_air(air: AirShare | None) -> bool:
    """Whether the air-share test says air: a share of at least :data:`AIR_SHARE_MIN`,
    :data:`AIR_T` standard errors above none."""
    return air is not None and air.share >= AIR_SHARE_MIN and air.share >= AIR_T * air.std_error


def voids_kinematics(cands: list[Candidate]) -> bool:
    """Whether turbulence was named, or found and not affirmed as air
    (``details['air_unaffirmed']``, :func:`spectral_candidates`): either way the kinematic
    consistency does not hold."""
    return any(c.effect == "turbulence" and (c.selected or c.details.get("air_unaffirmed")) for c in cands)


def vane_wander(air: AirShare | None, gusty: str) -> bool:
    """Whether the air-share test put a vane-against-inertial difference large enough to
    void the sensor tests (``gusty``) on the vanes."""
    return bool(gusty) and air is not None and _vane_error(air)


def _vane_error(air: AirShare) -> bool:
    """The air share stands :data:`VANE_ERROR_Z` standard errors under :data:`AIR_SHARE_MIN`."""
    return air.share + VANE_ERROR_Z * air.std_error < AIR_SHARE_MIN


def withhold_vane_wander(cands: list[Candidate], why: str) -> None:
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


def withhold_in_light_gusts(cands: list[Candidate], why: str) -> None:
    """In gusts too light to name (:func:`light_gusts`) the coefficient terms stand (a C_m,q̂
    change is still named at Dryden severity 2), but not the accelerometer position fitted to
    the force mismatch: the gust's pitching part follows q̇ there (a DHC-6 null named an
    accelerometer 15 ft aft, t = 25); nor an α̇ term whose column is the inertial α̇
    (:data:`candidates.VANE_ALPHA_RATE_AXES` lists the axes built on the vane's instead): the
    aerodynamics see the air's α̇, which adds the gust's own rate ẇ_g/V, and the airframe's
    inertial α̇ answers that gust. A probe's J3 Cub (106 ft/s, pitch multisine) in gusts of
    2.8 ft/s (1.45° of angle) had C_m,α̇ +5.8 named (t 6.8) beside the light turbulence."""
    for c in cands:
        inertial_rate = c.effect == "unsteady_alphadot" and c.channel not in VANE_ALPHA_RATE_AXES
        if c.selected and (c.parameter == "x_accelerometer" or (inertial_rate and c.test.startswith("stepwise"))):
            c.selected = False
            c.reason = (f"not named: its α̇ is the inertial one (gyros and accelerometers), which lacks the gust's own "
                        f"rate ẇ_g/V that the aerodynamics see ({why})") if inertial_rate else f"not named: {why}"


# A mode is worth naming when the RMS its peak carries in the channel reaches this share of
# the smallest bias worth naming there (kinematics.PRACTICAL): a tenth of 0.15 deg/s on a
# gyro, of 0.015 g on an accelerometer. The sweeps' and probes' true modes carry 0.001-0.009
# rad/s in q and 0.014-0.02 g in a_z; a probe's noise-free c172x at 200 Hz, its values
# rounded to 8 digits, had a 75 Hz "mode" of 6e-10 g in a_y named (p 6e-20).
MODE_PRACTICAL_SHARE = 0.1


def mode_candidate(peak, selected: bool, reason: str) -> Candidate:
    """The structural-mode candidate of spectral peak ``peak`` (:class:`spectra.PeakTest`):
    its frequency, with −log10 p as its t and, as the share it explains, the peak's excess
    power over the variance of what the common filter leaves of the channel (the ordinate
    over its local median is kept as ``details['peak_over_median']``). Not selected when the
    peak's RMS is under :data:`MODE_PRACTICAL_SHARE` of the channel's practical bias."""
    floor = MODE_PRACTICAL_SHARE * PRACTICAL["bias"].get(peak.channel, 0.0)
    if selected and peak.amplitude < floor:
        selected = False
        reason = (f"not named, too small to matter: {peak.amplitude:.2g} RMS in {peak.channel}, under {floor:.2g} "
                  f"({MODE_PRACTICAL_SHARE:g} of the smallest bias worth naming there); the peak: {reason}")
    return Candidate("structural_mode", None, peak.channel, "mode_frequency_hz", peak.frequency_hz,
                     peak.std_error_hz, float(-np.log10(max(peak.p_value, 1e-300))), min(peak.share, 1.0), "Hz",
                     "residual-spectrum peak over its local median", selected, reason,
                     {"amplitude": peak.amplitude, "peak_over_median": peak.g})


def spectral_candidates(peak, gust, turbulent: bool, light: bool = False,
                        air: AirShare | None = None) -> list[Candidate]:
    """The structural-mode peak (named at p < :data:`FISHER_P`) and the gust level (named in
    turbulence the air-share test affirms, :func:`affirms_air`, and in light turbulence it
    confirms: then the part of the vertical gust that is air, σ_w √(1 − k)). Turbulence the
    test neither affirms nor refutes still voids the terms fitted to the mismatch
    (:func:`withhold_in_turbulence`) but is not named: on an independent script's 787-8 null
    (25,000 ft / 770 ft/s, lateral multisine, twice the vanes' noise and wander) the β vane's
    0.2° wander read as a 3.04 ft/s lateral gust, and C_Z's air share was 0.97 ± 0.27."""
    out = []
    if peak is not None:
        sel = peak.p_value < FISHER_P
        out.append(mode_candidate(peak, sel, f"peak p = {peak.p_value:.2g}" + (" (significant)" if sel else "")))
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
    named = light or (turbulent and affirms_air(air))
    if turbulent and not named:
        details["air_unaffirmed"] = True
        reason = (f"not named: the vanes and the inertial channels disagree by {sigma:.1f} ft/s RMS ({reason}), but "
                  "the aerodynamics tell neither air nor vane error (air share under "
                  f"{AIR_SHARE_MIN:g} or {AIR_T:g} standard errors); no term fitted to the mismatch is named either")
    # no share of the mismatch: the gust drives the flight, it is not a term fitted to the mismatch
    out.append(Candidate("turbulence", None, None, "sigma_gust_fps", sigma, sigma / 4.0, gust.ratio_to_noise,
                         float("nan"), "ft/s", "air-relative vs inertial velocity (integrated kinematic residual)",
                         named, reason, details))
    return out


NOT_IN_GUSTS = ("not named: in turbulence the aerodynamics see air-relative rates (the gust's rotational part, "
                "which no gyro measures) and the mismatch carries them through every alpha-, rate- and "
                "surface-correlated column; equation error cannot separate a model term from them (fit the "
                "recording with the filter-error method, estimate --method fe)")


def withhold_in_turbulence(cands: list[Candidate]) -> None:
    """In turbulence, deselect every term fitted to the coefficient mismatch (aerodynamic
    terms, control delays, the accelerometer position from the force mismatch, a
    moment-reference shift however it was read): the gust's rotational components are
    unmeasured regressors, correlated with α, α̇ and the rates (a Dryden pitch gust follows
    the derivative of the vertical gust), so the equation-error fit is biased there. The
    outside sweep's turbulent nulls named C_Z,α, C_Z,δe, C_m,α and a moment-reference shift
    at |t| 5-10 before this rule; a probe's F-16 (11,000 ft / 643 ft/s, three-axis sweeps,
    Dryden light) had a shift of 0.055 ± 0.004 ft read off C_m's mistrim (probe seed 3611)."""
    for c in cands:
        if c.selected and (c.test.startswith("stepwise") or c.test.startswith("delay scan")
                           or c.parameter == "x_accelerometer" or c.effect == "cg_offset"):
            c.selected = False
            c.reason = NOT_IN_GUSTS


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
