"""The diagnosis's words: each finding's explanation and evidence, the located paragraph,
what the recording could not check and what was assumed, and a model that cannot
represent the recording refused (:class:`DiagnosisError`)."""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from harness.diagnosis import candidates as cand
from harness.diagnosis.along import ModelAlong, interior
from harness.diagnosis.evidence import Analysis, Candidate
from harness.diagnosis.gust_rules import NOT_IN_GUSTS, NOT_IN_TURBULENCE, vane_wander, voids_kinematics
from harness.diagnosis.kinematics import time_base_problem
from harness.diagnosis.prepare import COEFFICIENTS, Prepared, throttle_travel, undriven_reason
from harness.diagnosis.sensor_naming import MEANS_TESTS
from harness.diagnosis.sensor_rules import steady_vane, steady_vane_reason
from harness.diagnosis.stepwise_axes import NOT_WITH_THROTTLE
from models.aircraft import Aircraft, other_fcs_properties
from models.constants import SURFACES
from models.replay import TURN_BANK_MIN_DEG


EXPLAIN = {
    "unsteady_alphadot": "The {axis} mismatch follows the angle-of-attack rate: the model lacks an unsteady "
                         "(downwash-lag) term, estimated as {parameter} = {estimate:.3g} ± {std_error:.2g} {units}.",
    "control_delay": "The model responds to {channel} too early: the surface acts about {estimate:.3f} ± "
                     "{std_error:.3f} s after the recorded position (an actuator delay the model lacks).",
    "sensor_offset": "The accelerometer is not at the c.g.: its readings carry the rotational terms of a sensor "
                     "about {abs_estimate:.2f} ± {std_error:.2f} ft {ahead} it ({component}).",
    "nonlinear_alpha": "The {axis} mismatch curves with angle of attack: the model lacks a nonlinear term, "
                       "{parameter} = {estimate:.3g} ± {std_error:.2g} {units}.",
    "coefficient_error": "The model's {parameter} is off: the data say {estimate:.4g} ± {std_error:.2g} {units}, "
                         "the model has {model_value:.4g} over this maneuver ({model_at_trim:.4g} at its trim).",
    "cross_coupling": "The {axis} mismatch follows {product}: a coupling term {parameter} = "
                      "{estimate:.3g} ± {std_error:.2g} {units} is missing{even}.",
    "flight_condition_drift": "The {axis} mismatch trends with the airspeed change: {parameter} = {estimate:.3g} ± "
                              "{std_error:.2g} per unit dV/V.",
    "cg_offset": "The moment reference is {estimate:.2f} ± {std_error:.2f} ft away from where the model puts it "
                 "(the {axis} mismatch follows the force coefficient).",
    "sensor_bias": "The {channel} sensor reads {estimate:.4g} ± {std_error:.2g} {units} off: the kinematics of the "
                   "other channels disagree with it by a constant.",
    "sensor_scale": "The {channel} sensor has a scale-factor error k = {estimate:.3g} ± {std_error:.2g}.",
    "sensor_time_skew": "The {channel} channel lags the others by {estimate:.3f} ± {std_error:.3f} s.",
    "structural_mode": "A narrow spectral peak in {channel} points to an unmodelled flexible mode at {estimate:.2f} "
                       "Hz.",
    "turbulence": "The air-relative and inertial velocities disagree broadband (gust RMS about {estimate:.1f} ft/s): "
                  "the flight was in turbulence, which no deterministic model term can replay.",
}


EXPLAIN_LIGHT_TURBULENCE = (
    "The air-relative and inertial velocities disagree broadband, and the aerodynamics followed the air-relative "
    "angle (air share {air_share:.2f} ± {air_share_se:.2f} of the vane-against-inertial difference): the flight was "
    "in light turbulence (vertical gust RMS about {estimate:.1f} ft/s). Too light to bias the equation-error terms, "
    "which stand; the sensor tests, which need the kinematics to hold, do not.")


class DiagnosisError(RuntimeError):
    """The diagnosis cannot run: the message names the input and the cause."""


def chosen_findings(analysis: Analysis) -> list[Candidate]:
    """The selected candidates, most significant first; turbulence, when named, leads: it is
    the broadband mismatch every deterministic term is then fitted against. Light turbulence
    (the deterministic terms stand in it) follows them."""
    chosen = [c for c in analysis.candidates if c.selected]
    return sorted(chosen, key=lambda c: (_turbulence_rank(c), -abs(c.t)))


def _turbulence_rank(c: Candidate) -> int:
    """0 for turbulence (it leads), 2 for light turbulence (it follows), 1 for the others."""
    if c.effect != "turbulence":
        return 1
    return 2 if c.details.get("light") else 0


def structured_part(p: Prepared, mismatch: np.ndarray) -> np.ndarray:
    """The part of a coefficient mismatch that follows the maneuver: its least-squares fit
    on every state and input regressor (α, q̂, β, p̂, r̂, the surfaces, α̇c̄/2V) and a
    constant. Measurement noise hardly correlates with them, so this part stands out where
    the model is wrong, whatever the noise's colour."""
    reg = cand.regressors(p)
    cols = [reg[k] for k in sorted(reg) if np.ptp(reg[k]) > 0]
    cols.append(p.deriv["alpha"] * p.meta["geometry"]["cbar_ft"] / (2.0 * p.smooth["V"]))
    inner = interior(p)
    A = np.column_stack([c[inner] for c in cols] + [np.ones(inner.stop - inner.start)])
    theta, *_ = np.linalg.lstsq(A, mismatch[inner], rcond=None)
    fitted = A @ theta
    return fitted - fitted.mean()


def focus_axis(findings: list[Candidate]) -> str | None:
    """The coefficient axis of the first aerodynamic or actuator finding (a delay: the axis
    its surface mainly drives)."""
    for f in findings:
        if f.channel in COEFFICIENTS:
            return f.channel
        if f.effect == "control_delay":
            return {"de": "Cm", "da": "Cl", "dr": "Cn"}.get(f.channel)
    return None


def located_paragraph(a: Analysis, fit_b: dict, name: str, focus: str | None = None) -> dict:
    """Where model and recording part: per output channel and per axis, and in time and
    frequency for ``focus`` (the axis of the first finding; else the axis whose mismatch
    most follows the maneuver)."""
    p = a.prepared
    outs = {}
    for c, v in fit_b["outputs"].items():
        n = p.noise_std.get(c, 0.0)
        outs[c] = {**v, "noise_std": n, "ratio": v["rms"] / n if n > 0 else float("inf")}
    coefs = {}
    for c in COEFFICIENTS:
        r = a.mismatch[c] - np.mean(a.mismatch[c])
        structured = float(np.std(structured_part(p, a.mismatch[c])))
        coefs[c] = {"rms": float(np.std(r)), "noise_std": a.noise[c], "ratio": float(np.std(r)) / a.noise[c],
                    "structured_rms": structured, "structured_ratio": structured / a.noise[c],
                    "pse": fit_b["coefficients"][c]["pse"]}
    # the axis whose mismatch most follows the maneuver (the raw ratio ranks coloured noise
    # too: accelerometer noise makes the force axes look worst on a flight with no error),
    # among the axes the maneuver excited (a pitch maneuver's lateral mismatch is noise)
    ranked_axes, ranked_outs = excited_axes(p, coefs), _excited_outputs(p, outs)
    worst_axis = max(ranked_axes, key=lambda c: coefs[c]["structured_ratio"])
    worst_out = max(ranked_outs, key=lambda c: outs[c]["ratio"]) if ranked_outs else None
    axis = focus if focus in coefs else worst_axis
    r = np.zeros(p.n)
    r[interior(p)] = structured_part(p, a.mismatch[axis])
    # when: the 2 s window with the largest mismatch energy; where: the band holding most power
    w = max(1, int(round(2.0 / p.dt)))
    energy = np.convolve(r ** 2, np.ones(w), mode="valid")
    i = int(np.argmax(energy))
    spec = np.abs(np.fft.rfft(r)) ** 2
    f = np.fft.rfftfreq(r.size, p.dt)
    cum = np.cumsum(spec) / max(spec.sum(), 1e-300)
    band = [float(f[int(np.searchsorted(cum, 0.1))]), float(f[min(int(np.searchsorted(cum, 0.9)), f.size - 1)])]
    ranked = sorted(ranked_axes, key=lambda c: -coefs[c]["structured_ratio"])[:3]
    where = (f"the findings put it in {axis}" if focus in coefs else f"it is largest in {axis}")
    summary = ("Coefficient mismatch that follows the maneuver, in noise levels: "
               + ", ".join(f"{c} {coefs[c]['structured_ratio']:.1f}" for c in ranked)
               + f"; {where}, most between t = {p.t[i]:.1f} and {p.t[min(i + w, p.n - 1)]:.1f} s, with 80 % of "
               f"its power in {band[0]:.2f}-{band[1]:.2f} Hz.")
    if worst_out:
        summary += (f" Of the outputs, {worst_out} departs most from the model ({outs[worst_out]['ratio']:.1f} "
                    "times its noise).")
    return {"outputs": {name: outs}, "coefficients": {name: coefs}, "worst_output": worst_out, "worst_axis": worst_axis,
            "focus_axis": axis, "time_window_s": [float(p.t[i]), float(p.t[min(i + w, p.n - 1)])], "band_hz": band,
            "summary": summary}


_LON_OUTPUTS = ("alpha", "q", "theta", "V", "ax", "az")
_LAT_OUTPUTS = ("beta", "p", "r", "phi", "ay")


def excited_axes(p: Prepared, names) -> list[str]:
    """The coefficient axes whose group the maneuver drove (all of them when none was)."""
    lon, lat = "de" in p.driven, any(s in p.driven for s in ("da", "dr"))
    keep = [c for c in names if (c in cand.LON and lon) or (c in cand.LAT and lat)]
    return keep or list(names)


def _excited_outputs(p: Prepared, names) -> list[str]:
    """The output channels whose group the maneuver drove (all of them when none was)."""
    lon, lat = "de" in p.driven, any(s in p.driven for s in ("da", "dr"))
    keep = [c for c in names if (c in _LON_OUTPUTS and lon) or (c in _LAT_OUTPUTS and lat)]
    return keep or list(names)


def remaining_mismatch(a: Analysis, fit_b: dict, fit_a: dict) -> dict:
    """Per axis, the coefficient mismatch left after the findings' terms: RMS over the noise
    level, and the share of the mismatch RMS the terms removed."""
    out = {}
    for c in COEFFICIENTS:
        before, after = fit_b["coefficients"][c]["rms"], fit_a["coefficients"][c]["rms"]
        out[c] = {"rms": after, "ratio": after / a.noise[c], "removed": 1.0 - after / before if before > 0 else 0.0}
    return out


# Body axes: x forward, y out of the right wing, z down.
_OFFSET_WORDS = {"x": ("ahead of", "behind"), "y": ("right of", "left of"), "z": ("below", "above")}


def _offset_direction(parameter: str, estimate: float) -> tuple[str, str]:
    """The body axis an accelerometer-position parameter measures along (``offset_y`` → y;
    the force-mismatch fit's ``x_accelerometer`` → x) and the words for its sign."""
    axis = parameter[-1] if parameter.startswith("offset_") else "x"
    ahead, behind = _OFFSET_WORDS.get(axis, _OFFSET_WORDS["x"])
    return axis, ahead if estimate >= 0 else behind


# A vane bias named on the coefficient means (sensor_naming.name_vane_bias_from_means).
EXPLAIN_VANE_MEANS = ("The {channel} vane reads {estimate:.4g} ± {std_error:.2g} {units} off: the model evaluated "
                      "along it is off by its own slopes in that angle times one constant on every axis it reaches.")


# A flow-angle vane away from the c.g. (kinematics.sensor_parameters' vane_alpha_x, vane_beta_x).
EXPLAIN_VANE_OFFSET = ("The {channel} vane is not at the c.g.: it reads the flow of a point about {abs_estimate:.2f} ± "
                       "{std_error:.2f} ft {ahead} it ({component}), where the rotation adds {rotation} to the angle.")
_VANE_ROTATION = {"alpha": "−x·q/V", "beta": "x·r/V"}


def _process_noise_text(c: Candidate) -> str:
    """What the turbulence's process-noise models (``details['process_noise_model']``,
    harness.diagnosis.gusts) say: each fitted axis's gust σ and how much closer its Kalman
    filter follows the outputs than output error without the gust."""
    pm = c.details.get("process_noise_model") if c.effect == "turbulence" else None
    if not pm:
        return ""
    parts = []
    for key, words, sigma in (("short_period", "short period", "sigma_w"), ("lateral", "lateral motion", "sigma_v")):
        m = pm.get(key) or {}
        if not m.get("fitted"):
            continue
        se = m.get(f"{sigma}_std_error_fps")
        change = ", ".join(f"{o} {100 * v:+.0f} %" for o, v in m["change"].items())
        parts.append(f"on the {words}, σ = {m[f'{sigma}_fps']:.1f}" + (f" ± {se:.1f}" if se else "")
                     + f" ft/s (its Kalman filter against output error without the gust: {change})")
    if not parts:
        return ""
    return " The filter-error method fits a process-noise model (a first-order gust state) " + "; ".join(parts) + "."


def _mode_model_text(c: Candidate) -> str:
    """How a structural mode is modelled (``details['mode_model']``, harness.diagnosis.mode_model)."""
    if c.effect != "structural_mode" or "mode_model" not in c.details:
        return ""
    m = c.details["mode_model"]
    if not m:
        return (" No recorded surface's response explains it (something unrecorded rings it): the augmented "
                "sensor model notches it out of the rate and acceleration channels.")
    peak = c.details.get("spectral_peak_hz", [float("nan")])[0]
    text = (f" Fitted as a second-order mode driven by {m['surface']}: natural frequency {m['frequency_hz']:.2f} ± "
            f"{m['std_error_hz']:.2f} Hz (the spectral peak, where the resonance meets the input's spectrum, lies at "
            f"{peak:.2f} Hz), damping ratio {m['damping']:.3f}, ringing in {', '.join(m['gains'])}; the augmented "
            "model adds it to those outputs.")
    if m["fitted_on"] == "validation":
        text += (" The identification maneuver does not ring it well enough to fit, so it was fitted on the "
                 "validation maneuver: the validation fit after is a fit there, not a prediction.")
    return text


def finding_dict(c: Candidate, fits_b: dict, fits_a: dict, check: dict | None = None) -> dict:
    fmt = {"axis": c.axis, "channel": c.channel, "parameter": c.parameter, "estimate": c.estimate,
           "std_error": c.std_error, "units": c.units, "model_value": c.details.get("model_value", float("nan"))}
    if c.effect == "coefficient_error":
        fmt["model_value"] = c.estimate - c.details["change"]
        fmt["model_at_trim"] = c.details.get("model_at_trim", float("nan"))
    fmt["abs_estimate"] = abs(c.estimate)
    fmt["component"], fmt["ahead"] = _offset_direction(c.parameter, c.estimate)
    even = c.parameter.endswith("_beta_abs")
    fmt["product"] = "|beta|, an even function of sideslip" if even else "(alpha - alpha_trim)·beta"
    fmt["even"] = (" (or, as here, the model has one of opposite sign: a symmetric airframe's rolling and yawing "
                   "moments are odd in sideslip)") if even else ""
    fmt["rotation"] = _VANE_ROTATION.get(c.channel or "", "")
    template = (EXPLAIN_VANE_MEANS if c.test in MEANS_TESTS.values() else
                EXPLAIN_VANE_OFFSET if c.parameter.startswith("vane_") else
                EXPLAIN_LIGHT_TURBULENCE if c.details.get("light") else EXPLAIN[c.effect])
    share = c.details.get("air_share") or {}
    fmt["air_share"], fmt["air_share_se"] = share.get("share", float("nan")), share.get("std_error", float("nan"))
    try:
        text = template.format(**fmt)
    except (KeyError, ValueError):
        text = f"{c.effect}: {c.parameter} = {c.estimate:.4g} ± {c.std_error:.2g} {c.units}."
    both = c.details.get("replicated")
    if both and both.get("identification_cannot"):  # replication.name_mode_on_both: the validation's alone
        text += (f" The identification maneuver cannot show it ({both['identification_cannot']}); the validation "
                 f"maneuver's peak (p = {both['validation_p']:.2g}) names it: it rests on the validation maneuver "
                 "alone.")
    elif both:  # named on the two maneuvers
        text += (f" The identification maneuver rings it too weakly to name alone (p = {both['identification_p']:.2g} "
                 f"at that frequency); the validation maneuver's peak (p = {both['validation_p']:.2g}) names it.")
    text += _mode_model_text(c) + _process_noise_text(c)
    if c.details.get("not_ruled_out"):  # an assumption it rests on (term_rules: a skewed delay, an untested coupling)
        text += f" Caveat: {c.details['not_ruled_out']}."
    evidence = {"test": c.test, "t": c.t, "explained_fraction": c.explained_fraction, "reason": c.reason}
    evidence.update({k: v for k, v in c.details.items() if k not in ("model_value",)})
    if check is not None:
        evidence["validation"] = check
        if check["status"] == "untested" and not (both and both.get("identification_cannot")):
            # an assumption the result rests on: the identification alone
            why = check["reason"]
            text += f" {why[:1].upper()}{why[1:]}: it rests on the identification maneuver alone."
        if check["status"] == "contradicted" and "change" in check:
            text += (f" The validation maneuver contradicts it (its {', '.join(check['axes'])} mismatch grows by "
                     f"{100 * check['change']:.0f} % with the term), so it is not in the augmented model.")
        elif check["status"] == "contradicted":  # a sensor test: the same test there says the opposite
            text += (f" The validation maneuver contradicts it (the same test there gives {check['estimate']:.4g} ± "
                     f"{check['std_error']:.2g} {c.units}, t = {check['t']:.1f}), so it is not in the augmented model.")
    return {"effect": c.effect, "axis": c.axis if c.axis in ("pitch", "roll", "yaw", "lon", "lat") else None,
            "channel": c.channel, "parameter": c.parameter, "estimate": float(c.estimate),
            "std_error": float(c.std_error), "units": c.units, "evidence": evidence,
            "fit_before": fits_b, "fit_after": fits_a, "explanation": text}


def none_finding(a: Analysis, fits_b: dict) -> dict:
    top = sorted(a.candidates, key=lambda c: -abs(c.t))[:5]
    ratios = {c: round(float(np.std(a.mismatch[c] - a.mismatch[c].mean()) / a.noise[c]), 2) for c in COEFFICIENTS}
    return {"effect": "none", "axis": None, "channel": None, "parameter": "", "estimate": 0.0, "std_error": 0.0,
            "units": "", "evidence": {
                "strongest_candidates": [{"effect": c.effect, "parameter": c.parameter, "t": c.t,
                                          "explained_fraction": c.explained_fraction, "reason": c.reason} for c in top],
                "entry_t": cand.T_IN, "mismatch_to_noise": ratios},
            "fit_before": fits_b, "fit_after": fits_b, "explanation": _none_text(a.candidates)}


# How the rules that keep a significant candidate from being named for what would imitate it
# begin its reason (the others: "not entered", "below the entry t", too small to matter) ...
WITHHELD_REASONS = ("entered, but", "not named:", "fitted, but not named", "not applied or named")
# ... less the entered terms kept out for their size or their significance
# (stepwise_axes._impractical_reason, not_entered_reason, the delay scan's bounds).
NOT_WITHHELD_REASONS = ("entered, but too small to matter", "entered, but under", "entered, but the delay lies beyond",
                        "entered, but with the residual")


def _none_text(cands: list) -> str:
    """The ``none`` verdict's explanation: noise alone, or, where terms entered the fit but
    were withheld for what would imitate them, that the data could not tell which (the
    strongest of them with its reason), never that noise explains it."""
    withheld = sorted((c for c in cands if c.reason.startswith(WITHHELD_REASONS) and abs(c.t) >= cand.T_IN
                       and not c.reason.startswith(NOT_WITHHELD_REASONS)),
                      key=lambda c: -abs(c.t))
    if not withheld:
        return ("No candidate effect is both significant against the noise the data themselves show and large "
                f"enough to matter (at least {100 * cand.PRACTICAL_SHARE:.0f} % of its coefficient's excursion): "
                "the mismatch is explained by measurement noise alone, within what this maneuver could test "
                "(see not_checked).")
    first = withheld[0]
    why = first.reason.split(":", 1)[-1].strip()
    return (f"No effect is named: {len(withheld)} significant candidate{'s' if len(withheld) > 1 else ''} "
            f"{'were' if len(withheld) > 1 else 'was'} withheld because the data cannot tell "
            f"{'them' if len(withheld) > 1 else 'it'} from something else that would imitate "
            f"{'them' if len(withheld) > 1 else 'it'} (the strongest, {first.parameter} at t = {first.t:.1f}: {why}). "
            "A maneuver that separates the two is needed to say which; see not_checked for what this one "
            "could not test.")


# The factor by which the model's lift along the recorded states may differ from the
# measured before the model is refused as another aircraft. None of the effects of
# effects.md comes near it: a 3-degree alpha bias moves the F-16's lift by about 25 %; the
# Twin Otter against JSBSim's DHC6 differs by 6 %, an F-16 recording against the 737 by 49 %
# and the Twin Otter against the F-16 by a factor of 3.2.
LIFT_FACTOR = 1.5
# The factor by which the recording's reference geometry (S, b, c̄) may differ from the
# model's: coefficients are normalised by them, so a model of another size is another
# aircraft (the F-16's S is 300 ft², the 737's 1,171 ft², the Twin Otter's 420 ft² in both the
# SIDPAC file and JSBSim's DHC6).
GEOMETRY_FACTOR = 1.25


# How close to vertical (|θ| of 90°) a recording may pitch. The Euler-angle kinematics the
# diagnosis checks its sensors and its time column with (φ̇ = p + tanθ(q sinφ + r cosφ), ψ̇ =
# (q sinφ + r cosφ)/cosθ) are singular at the vertical, where φ and ψ flip by 180° in a
# sample: an F-16 pull-up that went over the top (θ to 90°, α to 132°) was refused as having
# a time column 1.36 times too slow. Within 5° of it tanθ amplifies the gyros' noise elevenfold.
MAX_PITCH_ATTITUDE_DEG = 85.0


def check_attitude_range(p: Prepared) -> None:
    """Refuse a recording that pitches within 90 − :data:`MAX_PITCH_ATTITUDE_DEG` degrees of
    the vertical: its Euler angles are singular there, and the kinematic checks cannot be made.

    Raises
    ------
    DiagnosisError
        Naming the maneuver, the largest |θ| and where it occurs.
    """
    theta = p.raw.get("theta")
    if theta is None or not theta.size:
        return
    i = int(np.argmax(np.abs(theta)))
    if np.degrees(abs(theta[i])) < MAX_PITCH_ATTITUDE_DEG:
        return
    raise DiagnosisError(
        f"the {p.name} recording pitches to theta = {np.degrees(theta[i]):.1f} deg (at t = {p.t[i]:.2f} s), within "
        f"{90 - MAX_PITCH_ATTITUDE_DEG:g} deg of the vertical, where Euler angles are singular (phi and psi flip by "
        "180 deg): the diagnosis's kinematic checks of the sensors and the time column rest on the Euler angles and "
        "cannot be made there. Give it the part of the record before the aircraft passes the vertical")


def check_time_base(p: Prepared) -> None:
    """Refuse a recording whose time column disagrees with its gyros
    (:func:`kinematics.time_base_problem`): every derivative the diagnosis takes would be off
    by the same factor, and each coefficient with it. A recording that pitches through the
    vertical is refused first, with that reason (:func:`check_attitude_range`).

    Raises
    ------
    DiagnosisError
        Naming the maneuver, the ratio found and what to check.
    """
    check_attitude_range(p)
    why = time_base_problem(p)
    if why:
        raise DiagnosisError(f"the {p.name} recording's time column cannot be right: {why}")


def _lift_represented(measured: float, modelled: float) -> bool:
    """The model's mean normal-force coefficient within :data:`LIFT_FACTOR` of the measured
    one, or the measured one under 0.05 (near zero lift, no ratio to judge)."""
    return abs(measured) < 0.05 or 1.0 / LIFT_FACTOR <= modelled / measured <= LIFT_FACTOR


def check_model_represents(a: Analysis, model: str, as_recorded: Callable[[], ModelAlong] | None = None) -> None:
    """Refuse a model that cannot stand for the recorded aircraft: its reference geometry
    differs from the recording's by more than :data:`GEOMETRY_FACTOR`, or its normal-force
    coefficient along the recorded states differs from the measured one by more than
    :data:`LIFT_FACTOR` (skipped when the measured mean is under 0.05, near zero lift) both
    along the channels as the analysis corrected them (``a``) and, where it applied sensor
    corrections, along them as recorded (``as_recorded()``, the model along the recording:
    :func:`along.model_along`). A correction applied below the kinematic entry t is the
    kinematics' suspicion, not the aircraft's: a probe's 737 (18,900 ft / 718 ft/s, no h
    channel, twice the usual noise) had an α bias of 1.9° applied at t 3.2, along which its
    lift fell to −0.123 against the recording's −0.271, and was refused as another aircraft;
    along the recorded α it is −0.270.

    Raises
    ------
    DiagnosisError
        Naming the model, both lift levels and why no effect explains the difference.
    """
    geometry = a.prepared.meta["geometry"]
    tp = a.aero.trim
    for key, value, label in (("S_ft2", tp.S_ft2, "wing area"), ("b_ft", tp.b_ft, "span"),
                              ("cbar_ft", tp.cbar_ft, "mean chord")):
        ratio = float(geometry[key]) / value if value > 0 else float("inf")
        if not 1.0 / GEOMETRY_FACTOR <= ratio <= GEOMETRY_FACTOR:
            raise DiagnosisError(
                f"--model {model} does not represent the recorded aircraft: the recording's {label} is "
                f"{float(geometry[key]):g} ({key}) where the model's is {value:g}, a factor of "
                f"{max(ratio, 1 / ratio):.2f} (beyond {GEOMETRY_FACTOR:g}): another aircraft, or another "
                "reference geometry for the coefficients")
    measured = float(np.mean(a.mismatch["CZ"] + a.aero.coefficients["CZ"]))
    modelled = float(np.mean(a.aero.coefficients["CZ"]))
    if _lift_represented(measured, modelled):
        return
    if a.applied and as_recorded is not None:
        recorded = as_recorded()
        if _lift_represented(float(np.mean(recorded.measured["CZ"])),
                             float(np.mean(recorded.aero.coefficients["CZ"]))):
            return
    ratio = modelled / measured
    trim = f" (and it cannot trim there: {a.aero.trim_failed})" if a.aero.trim_failed else ""
    raise DiagnosisError(
        f"--model {model} does not represent the recorded aircraft: along the recorded states its normal-force "
        f"coefficient averages {modelled:.3f} where the recording's is {measured:.3f} (a factor of "
        f"{max(ratio, 1 / ratio) if ratio > 0 else float('inf'):.2f}, beyond {LIFT_FACTOR:g}){trim}; no effect the "
        "diagnosis can name explains that much")


def not_checked(a: Analysis, validation_given: bool) -> list[dict]:
    """The effects (or their parameters) this recording cannot test, each with the reason:
    terms built on states or surfaces the maneuver did not drive, delays of surfaces that
    never moved, sensor scale factors and skews of channels that hardly move, what the
    sample rate hides, and the missing validation maneuver."""
    p = a.prepared
    grouped: dict[tuple[str, str], list[str]] = {}
    for rows in a.not_offered.values():
        for r in rows:
            why = r.get("reason") or undriven_reason(p, r["sources"])
            grouped.setdefault((r["effect"], why), []).append(r["parameter"])
    for s in SURFACES:
        if s in p.raw and s not in p.driven:
            grouped.setdefault(("control_delay", undriven_reason(p, [s])), []).append(f"tau_{s}")
    for vane in ("alpha", "beta"):
        if vane in p.raw and steady_vane(f"bias_{vane}", p):
            grouped.setdefault(("sensor_bias", steady_vane_reason(vane)), []).append(f"bias_{vane}")
    for name, why in sorted(a.kinematic.dropped.items()):  # in a fixed order, run to run
        kind = name.split("_", 1)[0]
        effect = {"scale": "sensor_scale", "skew": "sensor_time_skew"}.get(kind, "sensor_" + kind)
        grouped.setdefault((effect, why), []).append(name)
    out = [{"effect": e, "parameters": sorted(dict.fromkeys(ps)), "reason": why} for (e, why), ps in grouped.items()]
    if a.gusty:
        out += [{"effect": e, "parameters": [], "reason": a.gusty} for e in SENSOR_EFFECTS]
    out += in_turbulence(a)
    out += _withheld_for_throttle(a)
    if vane_wander(a.air, a.gusty):
        out.append({"effect": "coefficient_error", "parameters": ["terms in alpha, its powers and alphadot"],
                    "reason": a.gusty})
    out.append({"effect": "structural_mode", "parameters": [],
                "reason": f"only modes below {0.5 / p.dt:g} Hz (half the sample rate) can be seen"})
    if not validation_given:
        out.append({"effect": "(every finding)", "parameters": [],
                    "reason": "no validation maneuver was given: no finding was tested on a second maneuver"})
    return out


SENSOR_EFFECTS = ("sensor_bias", "sensor_scale", "sensor_time_skew", "sensor_offset")
IN_TURBULENCE = ("in turbulence the kinematic consistency (air-relative against inertial velocity) does not hold, "
                 "so no sensor error is named from it")


def in_turbulence(a: Analysis) -> list[dict]:
    """What turbulence left untested, when it is named (not light gusts, which ``a.gusty``
    covers): every sensor effect (the kinematic consistency does not hold) and every term fitted
    to the coefficient mismatch (the gust's rotational part is an unmeasured regressor), each
    listing the parameters that passed every other rule and were withheld for it, so that an
    error under the gusts is not silently dropped (probe 59: a q-gyro bias of 0.5 deg/s under
    Dryden severity 3 estimated at 0.0089 ± 0.0004 rad/s, t 25, beside the turbulence named).
    Gusts the air-share test did not affirm (``details['air_unaffirmed']``,
    :func:`gust_rules.spectral_candidates`) leave the same untested, unnamed."""
    if not voids_kinematics(a.candidates) or a.gusty:
        return []
    terms = sorted({c.effect for c in a.candidates if c.reason == NOT_IN_GUSTS} | {"coefficient_error"})
    return ([_withheld(a.candidates, e, NOT_IN_TURBULENCE, IN_TURBULENCE, "those listed passed every other rule")
             for e in SENSOR_EFFECTS]
            + [_withheld(a.candidates, e, NOT_IN_GUSTS, "terms fitted to the coefficient mismatch are " + NOT_IN_GUSTS,
                         "those listed entered and were withheld") for e in terms])


def _withheld_for_throttle(a: Analysis) -> list[dict]:
    """``not_checked`` entries when the throttle moved with no thrust channel: the terms of the
    axes its change enters, those withheld for it listed
    (:func:`~harness.diagnosis.stepwise_axes.withhold_on_moving_throttle`)."""
    if a.prepared.recording is None or throttle_travel(a.prepared.recording) is None:
        return []
    because = ("terms of CX and Cm (and of Cl and Cn behind a propeller) are not named: the throttle moved and "
               "thrust was not recorded; the model held thrust at trim, so their mismatch carries the thrust's change "
               "(record thrust_lbf)")
    effects = sorted({c.effect for c in a.candidates if c.reason == NOT_WITH_THROTTLE} | {"coefficient_error"})
    return [_withheld(a.candidates, e, NOT_WITH_THROTTLE, because, "those listed entered and were withheld")
            for e in effects]


def _withheld(cands: list[Candidate], effect: str, reason: str, because: str, listed: str) -> dict:
    """A ``not_checked`` entry: ``effect``'s candidates withheld for ``reason``, and why."""
    names = sorted(c.parameter for c in cands if c.effect == effect and c.reason == reason)
    return {"effect": effect, "parameters": names,
            "reason": because + (f"; {listed} (see candidates)" if names else "")}


def assumptions(a: Analysis, aircraft: Aircraft, mass: str, surfaces_note: dict | None = None) -> list[dict]:
    """What the diagnosis assumed: the recording's stand-ins (:attr:`Prepared.assumptions`),
    with the thrust value used, and the mass the model flew with."""
    out = [dict(x) for x in a.prepared.assumptions]
    for x in out:
        if x["item"] == "thrust" and "model's" in x["stood_in_by"]:
            x["stood_in_by"] += f": {a.aero.trim.thrust_lbf:.0f} lbf"
    out.append({"item": "model mass", "missing": "-",
                "stood_in_by": ("the recording's mass and inertia (first sample)" if mass == "recording" else
                                f"the model's own mass and inertia ({aircraft.name}"
                                + _mass_difference(a.prepared.mass, a.aero.trim)
                                + "); --mass recording flies it with the recording's")})
    trim = a.aero.trim
    if trim.method == "jsbsim-turn":
        out.append({"item": "model trim (bank)", "missing": "-",
                    "stood_in_by": f"the recording starts banked {math.degrees(trim.phi_rad):.0f}°: the model is "
                                   "trimmed in a steady coordinated turn there (JSBSim's turn trim), its engine at "
                                   "that turn's power"})
    elif abs(math.degrees(a.ic.phi_rad)) >= TURN_BANK_MIN_DEG:
        out.append({"item": "model trim (bank)", "missing": "-",
                    "stood_in_by": f"the recording starts banked {math.degrees(a.ic.phi_rad):.0f}°, but the model is "
                                   "trimmed wings level (no steady turn found there): its engine at level "
                                   "flight's power"})
    if trim.held:
        for surface, info in trim.held.items():
            out.append({"item": f"model trim ({surface})", "missing": "-", "stood_in_by": info["reason"]})
    out.append({"item": "surface levels (replays)", "missing": "-",
                "stood_in_by": ("each surface moves by its recorded change from a start level fitted, per replay, "
                                "within the noise of its first 0.5 s (fit_before/fit_after: surface_levels_deg; "
                                "harness/diagnosis/levels.py)")})
    held = surfaces_note or held_surfaces_assumption(aircraft, a.aero.trim)
    if held:
        out.append(held)
    out.append(STANDARD_ERRORS_ASSUMPTION)
    return out


def held_surfaces_assumption(aircraft: Aircraft, trim) -> dict | None:
    """The model's other FCS-driven surfaces its aerodynamics read, held where trim put them
    (:func:`models.aircraft.other_fcs_properties`), as an assumption: a recording flown with its
    FCS on may have moved them. The F-16 flown with its FCS on by an independent script
    (probe 53) moved its leading-edge flap at α = 5° and its flaperons with the aileron; the
    mismatch they made was named as C_Z,α̇, C_Z,q̂ and moment-reference terms."""
    props = other_fcs_properties(aircraft.model, aircraft.surfaces)
    if not props:
        return None
    positions = trim.configuration.get("positions", {})
    values = ", ".join(f"{p} {positions[p]:.3g}" if p in positions else p for p in props)
    return {"item": "other control surfaces", "missing": "their positions (not recording-format channels)",
            "stood_in_by": (f"held where the model's trim put them, its FCS disabled: {values}; a recording flown "
                            "with the FCS on may have moved them (the F-16's leading-edge flap switches at alpha "
                            "= 5 deg, its flaperons follow the aileron), and the mismatch they make would be read "
                            "as terms on alpha, the surfaces or the moment reference")}


# The diagnosis's standard errors and the t values its entry rules compare are seed Eq. 40's
# with Eq. 39's sample autocorrelation over all lags (estimators.colored). For a constant
# column that is known to be optimistic (README, "A constant's colored-residual standard
# error"); the rules were set against these values, so the output says so.
STANDARD_ERRORS_ASSUMPTION = {
    "item": "standard errors",
    "missing": "-",
    "stood_in_by": ("seed Eq. 40 with the residuals' sample autocorrelation (Eq. 39, all lags), stationary "
                    "residuals assumed; for a constant (a sensor bias, a coefficient offset) it is too small, by "
                    "about 2 when the sensor's error wanders slowly (tau about 1 s on a 30 s record); the entry "
                    "rules' t thresholds (5 and 6) were set against these values"),
}


# A recording's mass or inertia this far from the model's is named in the model-mass assumption.
MASS_NOTE_FRACTION = 0.02


def _mass_difference(recorded: dict, trim) -> str:
    """', the recording's mass 15 % below it, Iy 10 % below' for the ones that differ from the
    model's by :data:`MASS_NOTE_FRACTION` or more at the recording's start ('' when none does):
    the coefficients are measured with the recording's, the replays fly the model's."""
    words = []
    for key, label in (("mass_slug", "mass"), ("Ix_slugft2", "Ix"), ("Iy_slugft2", "Iy"), ("Iz_slugft2", "Iz")):
        model = float(getattr(trim, key))
        got = recorded.get(key)
        if got is None or model <= 0:
            continue
        rel = float(np.asarray(got, dtype=float).ravel()[0]) / model - 1.0
        if abs(rel) >= MASS_NOTE_FRACTION:
            words.append(f"{label} {100 * abs(rel):.0f} % {'above' if rel > 0 else 'below'} it")
    return (", the recording's " + ", ".join(words)) if words else ""
