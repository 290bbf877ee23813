"""The whole diagnosis of one recording (and its validation maneuver) against a model, and
its output folder: findings.json, series/*.parquet, model/ (the augmented JSBSim aircraft)."""
from __future__ import annotations

import contextlib
import json
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd
from scipy import signal

from harness.atomic import jsonable, write_atomic, write_text_atomic
from harness.diagnosis import candidates as cand
from harness.diagnosis import levels, refine
from harness.diagnosis.along import interior
from harness.diagnosis.analysis import analyse
from harness.diagnosis.evidence import Analysis, Candidate
from harness.diagnosis.fits import coefficient_fit, output_fit
from harness.diagnosis.gust_rules import vane_wander
from harness.diagnosis.prepare import COEFFICIENTS, OUTPUTS, Prepared, prepare, undriven_reason, instruments_at_cg
from harness.diagnosis.sensor_naming import MEANS_TESTS, name_replicated
from harness.diagnosis.spectra import MODE_CHANNELS, gust_wind_ned
from harness.executors import LocalPool
from harness.recording_io import read_recording
from models.aircraft import MODELS, Aircraft, is_xml_model, nominal_root
from models.hidden import HiddenEffect, hidden_root
from models.flight import FlightError
from models.mass import MassProperties, mass_root
from models.replay import initial_condition, replay, steady_start
from models.trim import TrimError

SURFACES = ("de", "da", "dr")
_CHANNEL_COLUMNS = {"alpha": "alpha_rad", "beta": "beta_rad", "p": "p_rps", "q": "q_rps", "r": "r_rps",
                    "phi": "phi_rad", "theta": "theta_rad", "V": "V_fps", "ax": "ax_g", "ay": "ay_g", "az": "az_g"}
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
    "structural_mode": "A narrow spectral peak at {estimate:.2f} Hz in {channel} points to an unmodelled flexible "
                       "mode.",
    "turbulence": "The air-relative and inertial velocities disagree broadband (gust RMS about {estimate:.1f} ft/s): "
                  "the flight was in turbulence, which no deterministic model term can replay.",
}


EXPLAIN_LIGHT_TURBULENCE = (
    "The air-relative and inertial velocities disagree broadband, and the aerodynamics followed the air-relative "
    "angle (air share {air_share:.2f} ± {air_share_se:.2f} of the vane-against-inertial difference): the flight was "
    "in light turbulence (vertical gust RMS about {estimate:.1f} ft/s). Too light to bias the equation-error terms, "
    "which stand; the sensor tests, which need the kinematics to hold, do not.")


# A mismatch left at this many times its noise level is reported as unexplained (noise in
# the measured states alone leaves up to ~3.5 in the F-16's Cl).
UNEXPLAINED_RATIO = 5.0


class DiagnosisError(RuntimeError):
    """The diagnosis cannot run: the message names the input and the cause."""


def _aircraft(model: str) -> Aircraft:
    """A project model by name, or a JSBSim aircraft XML by path (flown as it is)."""
    if model in MODELS:
        return Aircraft(model)
    if not is_xml_model(model):
        raise DiagnosisError(f"--model {model!r} is neither one of the project's models {MODELS} "
                             "nor the path of a JSBSim aircraft XML (<name>.xml)")
    try:
        aircraft = Aircraft(str(Path(model).resolve()))
        aircraft.surfaces  # noqa: B018 - fails early, naming a surface the XML lacks
        nominal_root(aircraft.model)  # and a file its engines or systems need
    except (ValueError, OSError, ET.ParseError) as exc:
        raise DiagnosisError(f"--model {model}: {exc}") from exc
    return aircraft


def _effect_of(c: Candidate) -> HiddenEffect | None:
    """The model term a finding adds (None for what no deterministic term can add)."""
    e = c.effect
    coef = c.channel if c.channel in COEFFICIENTS else "Cm"
    if e == "unsteady_alphadot":
        return HiddenEffect(e, c.estimate, coefficient=coef)
    if e == "nonlinear_alpha":
        return HiddenEffect(e, c.estimate, coefficient=coef, power=int(c.parameter[-1]))
    if e == "coefficient_error":
        return HiddenEffect(e, c.details["change"], coefficient=coef, regressor=c.parameter.split("_", 1)[1])
    if e == "cross_coupling":
        return HiddenEffect(e, c.estimate, coefficient=coef, regressor="beta_abs" if c.parameter.endswith("_beta_abs")
                            else "")
    if e == "flight_condition_drift":
        return HiddenEffect(e, c.estimate, coefficient=coef)
    if e == "cg_offset":
        return HiddenEffect(e, c.estimate)
    if e == "control_delay":
        return HiddenEffect(e, max(c.estimate, 0.0), surface=c.channel)
    if e == "sensor_offset" and c.channel == "accelerometer":
        if "position_ft" in c.details:  # the force-mismatch fit: the whole vector
            pos = tuple(float(v) for v in c.details["position_ft"])
        else:  # the kinematic check: one component (offset_x, offset_y, offset_z)
            pos = tuple(float(c.estimate) if c.parameter == f"offset_{a}" else 0.0 for a in "xyz")
        return HiddenEffect(e, pos[0], position_ft=pos)
    if e in ("sensor_bias", "sensor_scale", "sensor_time_skew"):
        channel = c.channel if c.channel in _CHANNEL_COLUMNS else c.parameter.split("_", 1)[1]
        if channel in _CHANNEL_COLUMNS:
            return HiddenEffect(e, c.estimate, channel=channel)
    return None


def _terms_of(findings: list[Candidate], applied: dict[str, float]) -> tuple[HiddenEffect, ...]:
    """The model terms the findings add. A scale factor is estimated together with its
    channel's bias (the kinematic fit always carries the bias); when that bias was applied to
    the channels but is too small to be a finding itself, the scale's sensor model carries it
    too (the recorded angle is (1 + k)·x + b, not (1 + k)·x)."""
    out = []
    for f in findings:
        e = _effect_of(f)
        if e is None:
            continue
        out.append(e)
        bias = f"bias_{e.channel}"
        if e.effect == "sensor_scale" and bias in applied and not any(g.parameter == bias for g in findings) \
                and "offset" not in f.details:  # a scale read from the bias carries it (sensor_rules.scale_read_as_bias)
            out.append(HiddenEffect("sensor_bias", float(applied[bias]), channel=e.channel))
    return tuple(out)


def _findings(analysis: Analysis) -> list[Candidate]:
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


def _sim_channels(hist) -> dict[str, np.ndarray]:
    return {c: hist.channels[col] for c, col in _CHANNEL_COLUMNS.items()}


def _after_mismatch(a: Analysis, findings: list[Candidate]) -> tuple[dict[str, np.ndarray], dict[str, int]]:
    """The coefficient mismatch once the aerodynamic findings' terms are added (their
    estimated sizes, not refitted: on a validation maneuver this is a prediction)."""
    p = a.prepared
    after = {c: v.copy() for c, v in a.mismatch.items()}
    n_terms = {c: 0 for c in COEFFICIENTS}
    measured = {c: a.mismatch[c] + a.aero.coefficients[c] for c in COEFFICIENTS}
    for f in findings:
        if f.effect == "control_delay":
            s = f.channel
            for c in cand.SURFACE_AXES[s]:
                d = a.aero.derivatives.get(f"{c}_{s}", 0.0)
                if d:
                    x = p.smooth[s]
                    after[c] = after[c] - d * (np.interp(p.t - f.estimate, p.t, x) - x)
                    n_terms[c] += 1
            continue
        if f.channel not in COEFFICIENTS:
            continue
        terms = {t.parameter if t.effect != "coefficient_error" else t.parameter: t
                 for t in cand.library(p, f.channel, a.aero.derivatives, measured, a.aero.coefficients)}
        term = terms.get(f.parameter)
        if term is None:
            continue
        coef = f.details.get("change", f.estimate / term.scale)
        after[f.channel] = after[f.channel] - coef * term.column
        n_terms[f.channel] += 1
    return after, n_terms


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean((x - x.mean()) ** 2)))


def validation_check(av: Analysis, f: Candidate) -> dict | None:
    """What one identification finding, with its size as estimated, does to the validation
    maneuver's coefficient mismatch on its axes (a prediction: nothing is refitted).

    ``status`` is 'confirmed' (the mismatch RMS, summed over its axes in units of each axis's
    noise level, drops by 1 % or more), 'contradicted' (it rises by 1 % or more) or 'neutral'; None for a finding with no coefficient term (a
    sensor effect, a gust level, a spectral peak)."""
    if f.test in MEANS_TESTS.values():
        return _vane_means_check(av, f)
    if f.test.startswith("kinematic consistency") or f.parameter == "x_accelerometer":
        return _sensor_check(av, f)
    after, n_terms = _after_mismatch(av, [f])
    axes = [c for c in COEFFICIENTS if n_terms[c]]
    if not axes:
        return None
    why = untestable(av.prepared, f)
    if why:
        return {"status": "untested", "axes": axes, "reason": why}
    inner = interior(av.prepared)
    before_rms = {c: _rms(av.mismatch[c][inner]) for c in axes}
    after_rms = {c: _rms(after[c][inner]) for c in axes}
    w = _noise_weights(av, axes)
    ratio = sum(w[c] * after_rms[c] for c in axes) / max(sum(w[c] * before_rms[c] for c in axes), 1e-300)
    status = "confirmed" if ratio <= 0.99 else ("contradicted" if ratio >= 1.01 else "neutral")
    out = {"status": status, "axes": axes, "rms_before": before_rms, "rms_after": after_rms, "change": ratio - 1.0}
    rival = _rival_check(av, f, axes, {c: after[c][inner] for c in axes}, ratio - 1.0)
    if rival is not None:
        out["rival"] = rival
        if status == "confirmed" and rival["fits_as_well"]:
            out["status"] = "ambiguous"
            out["reason"] = _ambiguous_reason(rival, ratio - 1.0)
        elif rival["indistinct"]:
            out["reason"] = f"{rival['indistinct']}; the validation maneuver prefers it"
    return out


def untestable(pv: Prepared, f: Candidate) -> str:
    """Why the validation maneuver ``pv`` cannot test aerodynamic finding ``f`` ('' when it
    can): it drove each of the term's states, but not as the term needs (an α·β coupling
    where α and β never moved together, :func:`candidates.offered`). Predicted there, the
    term's column is its regressors' noise, and the validation RMS would judge the noise,
    not the term: a C_l α·β of −2 named at t −22 with the stabilator and rudder moved
    together was 'contradicted' (+13 %) by a sequential validation maneuver along the α
    vane's wander. Such a finding stands on the identification maneuver alone, as without a
    validation maneuver, and says so.

    A term on a state the validation maneuver did not drive at all is tested as before (and
    left unconfirmed by the noise it meets): the two maneuvers are then of different kinds, and
    the identification's own drive of that state may be incidental (on a lateral maneuver at
    25,000 ft / 500 ft/s a C_Z,α entered at t 5.5 where α moved with the lateral motion;
    passed untested, only the calibration in the loop withdrew it)."""
    if f.channel not in COEFFICIENTS:
        return ""
    measured = {c: np.zeros(pv.n) for c in COEFFICIENTS}
    term = next((t for t in cand.library(pv, f.channel, {}, measured) if t.parameter == f.parameter), None)
    if term is None or not set(term.sources) <= set(pv.driven):
        return ""
    _, skipped = cand.offered(pv, [term])
    if not skipped:
        return ""
    return f"the validation maneuver does not excite {f.parameter} ({skipped[0].details.get('not_offered', '')})"


def _ambiguous_reason(rival: dict, change: float) -> str:
    """Why a confirmed finding is left ``ambiguous`` by its rival (:func:`rival_fits_as_well`)."""
    m = 100 * rival["margin"]
    rms = f"RMS {rival['noise_levels_rival']:.3g} against {rival['noise_levels_own']:.3g} noise levels"
    if rival["indistinct"]:
        why = f"{rms}, a difference under {m:.0f} %, two standard errors of an RMS of this record"
    elif change <= -rival["margin"]:
        why = f"{rms}: better by more than {m:.0f} %, two standard errors of an RMS of this record"
    else:
        why = (f"{rms}; the finding itself lowers the validation RMS by {100 * -change:.0f} %, under the "
               f"{m:.0f} % that two standard errors of an RMS of this record allow")
    return (f"the validation maneuver is fitted about as well by {rival['parameter']} (its rival in the "
            f"identification fit: columns correlated {rival['correlation']:+.2f}; {why})")


def _undecided(f: Candidate) -> dict | None:
    """Without a validation maneuver: a finding the identification maneuver cannot tell from
    its rival is 'ambiguous' (not a finding); the others are not checked (None)."""
    why = (f.details.get("rival") or {}).get("indistinct")
    return {"status": "ambiguous", "reason": f"{why}; no validation maneuver to decide"} if why else None


def rms_margin(residual: np.ndarray, z: float = 2.0) -> float:
    """``z`` relative standard errors of an RMS estimated from a colored record: 1/√(2 n_eff),
    with n_eff = N (1 − ρ₁)/(1 + ρ₁) from the lag-one autocorrelation ρ₁ (Bartlett's
    first-order approximation for an AR(1) record)."""
    r = residual - residual.mean()
    rho = float(np.clip(np.dot(r[1:], r[:-1]) / max(float(np.dot(r, r)), 1e-300), -0.99, 0.99))
    n_eff = max(r.size * (1.0 - rho) / (1.0 + rho), 2.0)
    return z / np.sqrt(2.0 * n_eff)


def rival_fits_as_well(own: float, theirs: float, margin: float, indistinct: bool, change: float) -> bool:
    """Whether a finding's collinear rival predicts the validation maneuver as well as the
    finding does, so that the finding is left ``ambiguous``.

    Parameters
    ----------
    own, theirs : validation RMS of the mismatch with the finding's term, and with its rival's
        in its place (each sized as fitted alone on the identification maneuver), in noise levels.
    margin : two relative standard errors of the finding's validation RMS (:func:`rms_margin`).
    indistinct : the identification maneuver could not tell the two apart (the term's |t|
        beside its rival under the entry t).
    change : the finding's own relative change of the validation RMS (negative: a drop).

    A preference within the validation record's sampling error is no preference, so the
    burden follows the identification maneuver's verdict: a rival it could not set apart
    must do worse by more than ``margin`` for the finding to stand; one it did set apart
    overturns the finding only by doing better by more than ``margin`` -- when the validation
    maneuver supports the finding itself by more than ``margin``. Where the finding does not
    lower the validation RMS by that much, the validation maneuver has no verdict of its own
    on it and any preference for the rival leaves it ambiguous."""
    if indistinct:
        return theirs <= own * (1.0 + margin)
    if change <= -margin:
        return theirs <= own * (1.0 - margin)
    return theirs <= own


def _rival_check(av: Analysis, f: Candidate, axes: list[str], after: dict[str, np.ndarray],
                 change: float) -> dict | None:
    """The finding's strongest collinear rival (``details['rival']``, :mod:`rivals`), sized
    as fitted in its place on the identification maneuver, predicting the same validation
    axes; ``fits_as_well`` by :func:`rival_fits_as_well`."""
    r = f.details.get("rival")
    if not r:
        return None
    twin = Candidate(r["effect"], f.axis, r["axis"], r["parameter"], 0.0, 0.0, r["t_rival"], 0.0, "", f.test,
                     details={"change": r["coefficient"]})
    rival_after, _ = _after_mismatch(av, [twin])
    inner = interior(av.prepared)
    rival_rms = {c: _rms(rival_after[c][inner]) for c in axes}
    # summed over the axes in units of each axis's noise level, as validation_check does
    w = _noise_weights(av, axes)
    own = sum(w[c] * _rms(after[c]) for c in axes)
    theirs = sum(w[c] * rival_rms[c] for c in axes)
    margin = max(rms_margin(after[c]) for c in axes)
    indistinct = r.get("indistinct", "")
    return {"parameter": r["parameter"], "correlation": r["correlation"], "rms_after": rival_rms, "margin": margin,
            "noise_levels_own": own, "noise_levels_rival": theirs,
            "fits_as_well": rival_fits_as_well(own, theirs, margin, bool(indistinct), change),
            "indistinct": indistinct}


def _noise_weights(av: Analysis, axes: list[str]) -> dict[str, float]:
    """Each axis in units of its own noise level: summed raw, C_Y's mismatch (a_y noise)
    would outweigh a C_l or C_n change ten times smaller in coefficient units but larger in
    noise."""
    return {c: 1.0 / max(av.noise.get(c, 1.0), 1e-300) for c in axes}


# The |t| the same sensor parameter must reach, with the same sign, on the validation
# maneuver for a sensor finding to be kept (the same instrument flew both maneuvers).
SENSOR_CONFIRM_T = 3.0
# For a sensor finding named on two tests (kinematics below their entry t, and the coefficient
# mismatch; :mod:`harness.diagnosis.corroborate`), the validation maneuver's kinematic estimate
# need reach only this |t| when it agrees with the identification's within two standard errors.
CORROBORATED_CONFIRM_T = 2.0


def _sensor_check(av: Analysis, f: Candidate) -> dict:
    """A sensor finding tested on the validation maneuver: the instrument is the same, so its
    parameter, estimated there by the same kinematic check, must show with the same sign and
    |t| >= :data:`SENSOR_CONFIRM_T` ('confirmed'); of the opposite sign at that |t|,
    'contradicted'; else 'neutral'."""
    if "replication" in f.details:  # named on the two maneuvers' kinematics together
        v, sv = f.details["replication"]["validation"]
        return {"status": "confirmed", "axes": [], "estimate": float(v), "std_error": float(sv), "t": float(v / sv),
                "rule": "named on both maneuvers' kinematics (sensor_naming.name_replicated)"}
    twin = next((c for c in av.candidates if c.parameter == f.parameter), None)
    if twin is None:
        return {"status": "neutral", "axes": [], "estimate": None, "t": None,
                "reason": "the validation maneuver does not test this parameter"}
    same = np.sign(twin.estimate) == np.sign(f.estimate)
    status = _same_instrument_status(twin.estimate, twin.t, f.estimate)
    out = {"status": status, "axes": [], "estimate": float(twin.estimate), "std_error": float(twin.std_error),
           "t": float(twin.t)}
    if status == "neutral" and "offset" in f.details and "offset" not in twin.details:
        out = _offset_scale_check(av, f, twin) or out
        status = out["status"]
    kin = f.details.get("corroboration") or {}
    if status == "neutral" and kin.get("named") and same and abs(twin.t) >= CORROBORATED_CONFIRM_T:
        # named on two tests, each below the kinematic entry alone: the validation maneuver's
        # kinematic estimate must agree with the identification's, at a lower |t|
        apart = abs(twin.estimate - kin["kinematic"])
        if apart <= 2.0 * np.hypot(twin.std_error, kin["kinematic_std"]):
            out |= {"status": "confirmed", "rule": f"corroborated finding: same sign, |t| >= "
                    f"{CORROBORATED_CONFIRM_T:g} and within two standard errors of the identification's kinematic "
                    f"estimate ({kin['kinematic']:.4g} ± {kin['kinematic_std']:.2g})"}
    return out


def _offset_scale_check(av: Analysis, f: Candidate, twin: Candidate) -> dict | None:
    """A scale factor named on its offset and its excursions together
    (:func:`sensor_rules.scale_read_as_bias`), tested the same way on the validation maneuver:
    there too the offset at the mean (its bias read as k = b/x̄_true) and the excursions
    (the kinematic k, ``twin``) must agree within two standard errors; their
    inverse-variance mean is then the validation maneuver's estimate, judged as any sensor
    finding's (:func:`_same_instrument_status`). None when they disagree or there is no
    offset reading. (An F-16 at 22,000 ft and 600 ft/s with a 10 % α-vane scale: named at
    0.101 ± 0.007; the validation maneuver's excursions alone gave 0.048 ± 0.036, t 1.3,
    its offset 0.12 ± 0.013.)"""
    channel = f.parameter.split("_", 1)[1]
    reading = next((c.details["as_scale"] for c in av.candidates
                    if c.parameter == f"bias_{channel}" and "as_scale" in c.details), None)
    if reading is None or not twin.std_error > 0:
        return None
    k_off, se_off = reading["k"], reading["k_std"]
    if abs(k_off - twin.estimate) > 2.0 * np.hypot(se_off, twin.std_error):
        return None
    w = np.array([1.0 / se_off ** 2, 1.0 / twin.std_error ** 2])
    k = float(np.dot(w, [k_off, twin.estimate]) / w.sum())
    se = float(1.0 / np.sqrt(w.sum()))
    return {"status": _same_instrument_status(k, k / se, f.estimate), "axes": [], "estimate": k, "std_error": se,
            "t": k / se, "rule": f"the offset at the mean {channel} (k = {k_off:.3f} ± {se_off:.3f}) and the "
            f"excursions (k = {twin.estimate:.3f} ± {twin.std_error:.3f}) agree"}


def _vane_means_check(av: Analysis, f: Candidate) -> dict:
    """A vane bias named on the coefficient means (:func:`sensor_naming.name_vane_bias_from_means`),
    tested the same way on the validation maneuver: the same vane, so the same sign at
    |t| >= :data:`SENSOR_CONFIRM_T` there ('confirmed'), the opposite sign at that |t|
    ('contradicted'), else 'neutral'. Where the validation maneuver's kinematics gave the bias
    themselves (its means test is then not run), their estimate is the verdict
    (:func:`_sensor_check`), unless they also name a scale or skew of that vane: a scale
    factor reads as a bias at the trim α (8 % of 5.3° is 0.42°), and is then the likelier."""
    twin = next((c for c in av.candidates if c.parameter == f.parameter), None)
    means = (twin.details.get("vane_means") if twin is not None else None) or {}
    channel = f.parameter.split("_", 1)[1]
    # a scale (or skew) of the vane named there would explain the same offset at trim α
    rival = next((c.parameter for c in av.candidates if c.selected and c.parameter in
                  (f"scale_{channel}", f"skew_{channel}")), None)
    if not means:
        if rival is None and twin is not None and twin.test.startswith("kinematic consistency"):
            return _sensor_check(av, f) | {"rule": "the validation maneuver's kinematics gave this vane bias"}
        why = (f"the validation maneuver's kinematics name {rival}, which at trim reads as this bias" if rival else
               "the validation maneuver's coefficient means cannot tell this vane bias")
        return {"status": "neutral", "axes": [], "estimate": None, "t": None, "reason": why}
    v, sv = means["estimate"], means["std_error"]
    t = v / sv if sv > 0 else 0.0
    return {"status": _same_instrument_status(v, t, f.estimate), "axes": list(means["axes"]), "estimate": float(v),
            "std_error": float(sv), "t": float(t)}


def _same_instrument_status(there: float, t_there: float, here: float) -> str:
    """The validation maneuver's verdict on a sensor finding of size ``here``: the same test
    there gave ``there`` at ``t_there``; the same sign at |t| >= :data:`SENSOR_CONFIRM_T` is
    'confirmed', the opposite sign at that |t| 'contradicted', anything else 'neutral'."""
    if abs(t_there) < SENSOR_CONFIRM_T:
        return "neutral"
    return "confirmed" if np.sign(there) == np.sign(here) else "contradicted"


def _true_start(p: Prepared, added: tuple[HiddenEffect, ...]):
    """The initial condition with the found sensor errors of V, α and h undone (recorded =
    x + b, (1 + k)·x): the augmented model must start where the aircraft was, not where
    its instruments said it was."""
    ch = {c: p.smooth[c].copy() for c in ("V", "alpha") if c in p.smooth}
    if p.altitude is not None:
        ch["h"] = p.altitude.copy()
    for e in added:
        if e.channel in ch and e.effect == "sensor_bias":
            ch[e.channel] = ch[e.channel] - e.size
        elif e.channel in ch and e.effect == "sensor_scale":
            ch[e.channel] = ch[e.channel] / (1.0 + e.size)
    return initial_condition(p.t, ch["V"], ch["alpha"], ch.get("h"))


def _replay_surfaces(p: Prepared) -> dict[str, np.ndarray]:
    """The smoothed surfaces the replay is driven by, each starting at its raw start level
    (:func:`models.replay.steady_start`): the smoothed first sample carries the filter's end
    effects and the noise, which the replay would hold as a constant deflection."""
    return {s: steady_start(p.smooth[s], p.t, level_of=p.raw[s]) for s in SURFACES if s in p.smooth}


class Replayed(NamedTuple):
    """One replay of a maneuver: its outputs by quantity (None when it could not be flown),
    the surface-level offsets fitted (:mod:`harness.diagnosis.levels`, rad) and why it failed."""

    outputs: dict[str, np.ndarray] | None
    levels: dict[str, float]
    failed: str | None = None


def _fitted_replay(p: Prepared, fly) -> Replayed:
    """``fly`` (surfaces -> history) over ``p``'s surfaces with their levels fitted
    (:func:`levels.fit_levels`); a trim or flight error is reported, not raised."""
    surfaces = _replay_surfaces(p)
    bounds = {s: levels.level_bound(p.smooth[s], p.noise_std.get(s, 0.0), p.t) for s in surfaces}
    floors = {c: max(p.noise_std.get(c, 0.0), 1e-9) for c in OUTPUTS if c in p.smooth}
    try:
        fit = levels.fit_levels(lambda surf: _sim_channels(fly(surf)), surfaces, bounds, p.smooth, floors, interior(p))
    except (FlightError, TrimError) as exc:  # reported, not fatal: the coefficient analysis still stands
        return Replayed(None, {}, str(exc))
    return Replayed(fit.outputs, fit.offsets)


def _analysed(rec, role: str, aircraft: Aircraft) -> tuple[Prepared, Analysis, Replayed]:
    """One maneuver prepared, analysed and replayed as the model is (a unit of work a second
    process can take)."""
    p = prepare(rec, role)
    a = analyse(p, aircraft, initial_condition(p.t, p.smooth["V"], p.smooth["alpha"], p.altitude))
    return p, a, _replay_before(p, aircraft, a)


def _replay_before(p: Prepared, aircraft: Aircraft, analysis: Analysis) -> Replayed:
    """The model as given, replayed over one maneuver."""
    return _fitted_replay(p, lambda surf: replay(aircraft, analysis.ic, p.t, surf)[0])


def _maneuver(p: Prepared, aircraft: Aircraft, added: tuple[HiddenEffect, ...],
              findings: list[Candidate] | None, analysis: Analysis, before: Replayed | None = None,
              refs: dict | None = None):
    """Replays before/after and fits for one analysed maneuver; on the validation maneuver
    the identification's findings are applied as predictions. ``before`` reuses an earlier
    :func:`_replay_before` of the same maneuver; ``refs`` are the trim references of the added
    terms (default: the nominal model's trim at the maneuver's start, :func:`models.hidden.hidden_root`).
    Each replay fits its own surface levels (:mod:`harness.diagnosis.levels`)."""
    before = before if before is not None else _replay_before(p, aircraft, analysis)
    after = before
    winds = _turbulence_winds(p, analysis) if any(f.effect == "turbulence" for f in findings or []) else None
    if (added or winds is not None) and before.failed is None:
        augmented, start = Aircraft(aircraft.model, hidden=added), _true_start(p, added)
        after = _fitted_replay(p, lambda surf: replay(augmented, start, p.t, surf, wind_ned_fps=winds, refs=refs)[0])
    before_failed, diverged = before.failed, after.failed
    a = analysis
    before_mm = a.mismatch
    after_mm, n_terms = _after_mismatch(a, findings or [])
    inner = interior(p)
    nan = {c: np.full(p.n, np.nan) for c in _CHANNEL_COLUMNS}
    sim_b = before.outputs if before.outputs is not None else nan
    sim_a = after.outputs if after.outputs is not None else nan
    fit_b = {"outputs": output_fit(p.smooth, p.raw, sim_b, OUTPUTS, inner) if before_failed is None else {},
             "coefficients": coefficient_fit(before_mm, before_mm, {}, inner)}
    raw_after = _mode_notched(p, findings or [])
    fit_a = {"outputs": output_fit(p.smooth, raw_after, sim_a, OUTPUTS, inner) if diverged is None else {},
             "coefficients": coefficient_fit(before_mm, after_mm, n_terms, inner)}
    fit_b["surface_levels_deg"] = {k: float(np.degrees(v)) for k, v in before.levels.items()}
    fit_a["surface_levels_deg"] = {k: float(np.degrees(v)) for k, v in after.levels.items()}
    if before_failed is not None:
        fit_b["replay_failed"] = f"the model could not replay this maneuver: {before_failed}"
        fit_a["replay_failed"] = fit_b["replay_failed"]
    elif diverged is not None:
        fit_a["replay_failed"] = f"the augmented model could not replay this maneuver: {diverged}"
    series = {"t_s": p.t}
    for c in OUTPUTS:
        if c in p.raw:
            series[f"meas_{c}"] = p.raw[c]
            series[f"smooth_{c}"] = p.smooth[c]
            series[f"before_{c}"] = sim_b[c]
            series[f"after_{c}"] = sim_a[c]
    for c in COEFFICIENTS:
        series[f"coef_meas_{c}"] = a.mismatch[c] + a.aero.coefficients[c]
        series[f"coef_model_{c}"] = a.aero.coefficients[c]
        series[f"coef_after_{c}"] = a.aero.coefficients[c] + (a.mismatch[c] - after_mm[c])
    for s in SURFACES:
        if s in p.raw:
            series[s] = p.raw[s]
    return a, fit_b, fit_a, pd.DataFrame(series)


# Quality factor of the sensor model's notch for a structural mode (bandwidth f0/Q): wide
# enough for the mode's frequency uncertainty (a 2 s Welch segment resolves 0.5 Hz).
MODE_NOTCH_Q = 8.0


def _mode_notched(p: Prepared, findings: list[Candidate]) -> dict[str, np.ndarray]:
    """The recorded channels as the augmented sensor model sees them: a structural mode found
    becomes a notch (scipy.signal.iirnotch at its frequency, zero phase) in every rate and
    acceleration channel, so the raw fit after shows what the mode term removes. Returns
    ``p.raw`` unchanged when no mode was found."""
    modes = [f for f in findings if f.effect == "structural_mode"]
    if not modes:
        return p.raw
    out = dict(p.raw)
    fs = 1.0 / p.dt
    for f in modes:
        if not 0.0 < f.estimate < 0.5 * fs:
            continue
        b, a = signal.iirnotch(f.estimate, MODE_NOTCH_Q, fs=fs)
        for c in MODE_CHANNELS:
            if c in out:
                out[c] = signal.filtfilt(b, a, out[c])
    return out


def _turbulence_winds(p: Prepared, a: Analysis) -> dict[str, np.ndarray] | None:
    """The gusts this maneuver met, as a north-east-down wind for the replay: the body-axis
    gust histories the kinematic residuals give (:func:`spectra.gust_estimate`) rotated by
    the recorded attitude. A deterministic stand-in for a process-noise model: the augmented
    replay flies through the turbulence each maneuver's own kinematics reconstruct."""
    if a.gust is None or getattr(a.gust, "w_fps", None) is None:
        return None
    psi = p.smooth.get("psi", np.zeros(p.n))
    return gust_wind_ned(a.gust, p.smooth["phi"], p.smooth["theta"], psi)


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


def _focus_axis(findings: list[Candidate]) -> str | None:
    """The coefficient axis of the first aerodynamic or actuator finding (a delay: the axis
    its surface mainly drives)."""
    for f in findings:
        if f.channel in COEFFICIENTS:
            return f.channel
        if f.effect == "control_delay":
            return {"de": "Cm", "da": "Cl", "dr": "Cn"}.get(f.channel)
    return None


def _located(a: Analysis, fit_b: dict, name: str, focus: str | None = None) -> dict:
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
    ranked_axes, ranked_outs = _excited_axes(p, coefs), _excited_outputs(p, outs)
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


def _excited_axes(p: Prepared, names) -> list[str]:
    """The coefficient axes whose group the maneuver drove (all of them when none was)."""
    lon, lat = "de" in p.driven, any(s in p.driven for s in ("da", "dr"))
    keep = [c for c in names if (c in cand.LON and lon) or (c in cand.LAT and lat)]
    return keep or list(names)


def _excited_outputs(p: Prepared, names) -> list[str]:
    """The output channels whose group the maneuver drove (all of them when none was)."""
    lon, lat = "de" in p.driven, any(s in p.driven for s in ("da", "dr"))
    keep = [c for c in names if (c in _LON_OUTPUTS and lon) or (c in _LAT_OUTPUTS and lat)]
    return keep or list(names)


def _remaining(a: Analysis, fit_b: dict, fit_a: dict) -> dict:
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


def _finding_dict(c: Candidate, fits_b: dict, fits_a: dict, check: dict | None = None) -> dict:
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
    template = (EXPLAIN_VANE_MEANS if c.test in MEANS_TESTS.values() else
                EXPLAIN_LIGHT_TURBULENCE if c.details.get("light") else EXPLAIN[c.effect])
    share = c.details.get("air_share") or {}
    fmt["air_share"], fmt["air_share_se"] = share.get("share", float("nan")), share.get("std_error", float("nan"))
    try:
        text = template.format(**fmt)
    except (KeyError, ValueError):
        text = f"{c.effect}: {c.parameter} = {c.estimate:.4g} ± {c.std_error:.2g} {c.units}."
    if c.details.get("not_ruled_out"):  # an assumption the result rests on (term_rules._withhold_skewed_delay)
        text += f" Caveat: {c.details['not_ruled_out']}."
    evidence = {"test": c.test, "t": c.t, "explained_fraction": c.explained_fraction, "reason": c.reason}
    evidence.update({k: v for k, v in c.details.items() if k not in ("model_value",)})
    if check is not None:
        evidence["validation"] = check
        if check["status"] == "untested":  # an assumption the result rests on: the identification alone
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


def _none_finding(a: Analysis, fits_b: dict) -> dict:
    top = sorted(a.candidates, key=lambda c: -abs(c.t))[:5]
    ratios = {c: round(float(np.std(a.mismatch[c] - a.mismatch[c].mean()) / a.noise[c]), 2) for c in COEFFICIENTS}
    return {"effect": "none", "axis": None, "channel": None, "parameter": "", "estimate": 0.0, "std_error": 0.0,
            "units": "", "evidence": {
                "strongest_candidates": [{"effect": c.effect, "parameter": c.parameter, "t": c.t,
                                          "explained_fraction": c.explained_fraction, "reason": c.reason} for c in top],
                "entry_t": cand.T_IN, "mismatch_to_noise": ratios},
            "fit_before": fits_b, "fit_after": fits_b,
            "explanation": "No candidate effect is both significant against the noise the data themselves show "
                           f"and large enough to matter (at least {100 * cand.PRACTICAL_SHARE:.0f} % of its "
                           "coefficient's excursion): the mismatch is explained by measurement noise alone, within "
                           "what this maneuver could test (see not_checked)."}


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


def check_model_represents(a: Analysis, model: str) -> None:
    """Refuse a model that cannot stand for the recorded aircraft: its reference geometry
    differs from the recording's by more than :data:`GEOMETRY_FACTOR`, or its normal-force
    coefficient along the recorded states differs from the measured one by more than
    :data:`LIFT_FACTOR` (skipped when the measured mean is under 0.05, near zero lift).

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
    if abs(measured) < 0.05:
        return
    ratio = modelled / measured
    if not 1.0 / LIFT_FACTOR <= ratio <= LIFT_FACTOR:
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
    for name, why in a.kinematic.dropped.items():
        kind = name.split("_", 1)[0]
        effect = {"scale": "sensor_scale", "skew": "sensor_time_skew"}.get(kind, "sensor_" + kind)
        grouped.setdefault((effect, why), []).append(name)
    out = [{"effect": e, "parameters": sorted(dict.fromkeys(ps)), "reason": why} for (e, why), ps in grouped.items()]
    if a.gusty:
        out += [{"effect": e, "parameters": [], "reason": a.gusty}
                for e in ("sensor_bias", "sensor_scale", "sensor_time_skew", "sensor_offset")]
    if vane_wander(a.air, a.gusty):
        out.append({"effect": "coefficient_error", "parameters": ["terms in alpha, its powers and alphadot"],
                    "reason": a.gusty})
    out.append({"effect": "structural_mode", "parameters": [],
                "reason": f"only modes below {0.5 / p.dt:g} Hz (half the sample rate) can be seen"})
    if not validation_given:
        out.append({"effect": "(every finding)", "parameters": [],
                    "reason": "no validation maneuver was given: no finding was tested on a second maneuver"})
    return out


def assumptions(a: Analysis, aircraft: Aircraft, mass: str) -> list[dict]:
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
    if trim.held:
        for surface, info in trim.held.items():
            out.append({"item": f"model trim ({surface})", "missing": "-", "stood_in_by": info["reason"]})
    out.append({"item": "surface levels (replays)", "missing": "-",
                "stood_in_by": ("each surface moves by its recorded change from a start level fitted, per replay, "
                                "within the noise of its first 0.5 s (fit_before/fit_after: surface_levels_deg; "
                                "harness/diagnosis/levels.py)")})
    return out


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


def _with_recorded_mass(aircraft: Aircraft, rec) -> Aircraft:
    """The aircraft with the recording's mass and inertia (its first sample), as an XML copy."""
    try:
        mp = MassProperties.from_mapping(rec.mass_at(0))
        root, name = mass_root(aircraft.model, mp)
    except (KeyError, ValueError) as exc:
        raise DiagnosisError(f"--mass recording: {exc}") from exc
    return Aircraft(str(root / "aircraft" / name / f"{name}.xml"))


INCOMPLETE = "INCOMPLETE"
"""Marker file in a diagnosis folder while it is being written; a folder holding it was interrupted."""
_open_markers: dict[Path, int] = {}


def check_out_folder(out: str | Path) -> Path:
    """The diagnosis output folder, created; an error naming the file in the way if it cannot be."""
    from harness.atomic import ensure_folder
    try:
        return ensure_folder(out, "--out folder")
    except ValueError as exc:
        raise DiagnosisError(str(exc)) from None


@contextlib.contextmanager
def incomplete_marker(out: Path):
    """Mark ``out`` incomplete while the body runs; the outermost user removes the mark on success
    (so the command line keeps it until the report, written after :func:`diagnose`, is there too)."""
    key = Path(out).resolve()
    outer = key not in _open_markers
    created = not key.exists()
    if outer:
        check_out_folder(key)
        write_text_atomic(key / INCOMPLETE, "sidbench diagnose was writing this folder and did not finish "
                                            "(interrupted or failed): its contents are incomplete. Run it again.\n")
    _open_markers[key] = _open_markers.get(key, 0) + 1
    try:
        yield key
    except BaseException:
        if outer and [p.name for p in key.iterdir()] == [INCOMPLETE]:  # nothing written yet: leave nothing
            (key / INCOMPLETE).unlink(missing_ok=True)
            if created:
                key.rmdir()
        raise
    finally:
        _open_markers[key] -= 1
        if not _open_markers[key]:
            del _open_markers[key]
    if outer:
        (key / INCOMPLETE).unlink(missing_ok=True)


def diagnose(model: str, recording: str | Path, out: str | Path, validation: str | Path | None = None, *,
             mass: str = "model", calibrate: bool = True, calibrate_workers: int = 2) -> dict:
    """Diagnose ``recording`` against ``model``; write ``out``; return findings.json's content.

    ``mass='recording'`` flies the model with the recording's mass and inertia
    (:func:`models.mass.set_mass_properties`) instead of its own. ``calibrate`` refines the
    kept aerodynamic and delay terms with JSBSim in the loop as the last step
    (:mod:`harness.diagnosis.refine`; ``calibrate_workers`` processes fly its flights, 1: in
    this process); the calibrated sizes are kept only when they fit at least as well, and
    findings.json's ``calibration`` block says which and why.

    Raises
    ------
    DiagnosisError
        For an unknown model; recording, trim and flight errors name their cause themselves.
    """
    with incomplete_marker(Path(out)) as folder, contextlib.ExitStack() as stack:
        # a second process takes the validation maneuver's share (analysis, replays) meanwhile
        pool = stack.enter_context(LocalPool(1)) if validation is not None and calibrate_workers > 1 else None
        return _diagnose(model, recording, folder, validation, mass=mass, calibrate=calibrate,
                         workers=calibrate_workers, pool=pool)


def _fly_all(maneuvers: dict, aircraft: Aircraft, added: tuple[HiddenEffect, ...], modelled: list[Candidate],
             befores: dict, refs: dict | None = None, pool: LocalPool | None = None) -> dict:
    """:func:`_maneuver` for each role of ``maneuvers`` (role -> (prepared, analysis)), the
    model as given flown once (``befores``): role -> (analysis, fit before, fit after, series).
    With a ``pool``, the validation maneuver is flown in its process meanwhile."""
    pending = {role: pool.pool.submit(_maneuver, pm, aircraft, added, modelled, am, befores[role], refs)
               for role, (pm, am) in maneuvers.items() if pool is not None and role == "validation"}
    out = {role: _maneuver(pm, aircraft, added, modelled, am, befores[role], refs)
           for role, (pm, am) in maneuvers.items() if role not in pending}
    return out | {role: fut.result() for role, fut in pending.items()}


def _refine(model: str, recs: dict, aircraft: Aircraft, mass: str, workers: int, maneuvers: dict, befores: dict,
            modelled: list[Candidate], added: tuple[HiddenEffect, ...], flown: dict, pool: LocalPool | None = None):
    """The last step: calibrate the kept aircraft terms in the loop and keep the calibrated sizes
    only when they fit at least as well (:func:`refine.decide`).

    Returns
    -------
    (block, modelled, added, flown)
        findings.json's ``calibration`` block, and the findings, terms and flights to report:
        the calibrated ones when used, else those given.
    """
    from harness.calibrate import CalibrationError
    from harness.calibrate import calibrate as calibrate_in_loop
    pairs = refine.calibratable([(f, _effect_of(f)) for f in modelled])
    if not pairs:
        return ({"used": False, "reason": "no aerodynamic or delay term was added: nothing to calibrate"},
                modelled, added, flown)
    terms = [e for _, e in pairs]
    hold, hold_reason = refine.surface_hold(recs["identification"].meta)
    matched = refine.matched_outputs(terms, recs["identification"])
    block = {"used": False, "hold": hold, "hold_assumption": hold_reason, "workers": workers,
             "matched_outputs": list(matched)}
    try:
        cal = calibrate_in_loop(model, [recs["identification"]], refine.parameter_spec(terms),
                                validation=[recs["validation"]] if "validation" in recs else None, workers=workers,
                                mass=mass, hold=hold, outputs=matched)
    except (CalibrationError, FlightError, TrimError, RuntimeError, ValueError, OSError) as exc:
        # the last step never takes the diagnosis down: the equation-error sizes stand
        return block | {"reason": f"the calibration could not run: {type(exc).__name__}: {exc}"}, modelled, added, flown
    sizes = {a.name: float(v) for a, v in zip(cal.adjustments, cal.estimate)}
    refined = refine.refined_findings(pairs, sizes, dict(zip((a.name for a in cal.adjustments), cal.std_error)))
    modelled_cal = [refined[id(f)][0] if id(f) in refined else f for f in modelled]
    added_cal = refine.refined_terms(added, sizes)
    # the calibrated sizes belong to the calibration's term references (its unadjusted model's
    # trim at the recording's start): the augmented model is flown and written with them
    flown_cal = _fly_all(maneuvers, aircraft, added_cal, modelled_cal, befores, dict(cal.refs), pool)
    fits_ee = {r: v[2] for r, v in flown.items()}
    fits_cal = {r: v[2] for r, v in flown_cal.items()}
    used, reason, figures = refine.decide(cal, fits_ee, fits_cal, refine.affected_outputs(terms))
    block |= {"used": used, "reason": reason, **refine.calibration_detail(cal, terms, fits_ee, fits_cal), **figures,
              "findings": {f.parameter: refined[id(f)][1] for f in modelled if id(f) in refined}}
    if used:
        return block, modelled_cal, added_cal, flown_cal
    return block, modelled, added, flown


# A named aircraft term is withdrawn when the calibration (output error, JSBSim in the loop,
# used because it fits at least as well) sizes it within this many of its standard errors of
# no change. Measured on 2 Dec 2026 over both sweeps and the DHC-6 cases: every true finding
# the calibration refined stood at |z| >= 10; the one it did not support, a C_l,αβ
# the noise-free DHC-6 self-check drew from the propeller torque's change with airspeed
# (equation error -1.66 ± 0.29 per rad^2), at z = -1.1.
CALIBRATED_MIN_Z = 3.0


def _unsupported_in_the_loop(findings: list[Candidate], calibration: dict, checks: dict) -> list[Candidate]:
    """The findings the calibration, when used, sizes within :data:`CALIBRATED_MIN_Z` standard
    errors of no change; their ``checks`` entry says so (status 'unsupported')."""
    if not calibration.get("used"):
        return []
    sized = calibration.get("findings") or {}
    out = []
    for f in findings:
        own = sized.get(f.parameter)
        if not own or not own.get("std_error") or abs(own["size"]) >= CALIBRATED_MIN_Z * own["std_error"]:
            continue
        before = checks.get(id(f)) or {}
        checks[id(f)] = {**before, "status": "unsupported", "validation_status": before.get("status", "not checked"),
                         "reason": (f"the calibration (output error, JSBSim in the loop) sizes it "
                                    f"{own['size']:.3g} ± {own['std_error']:.2g}, within {CALIBRATED_MIN_Z:g} standard "
                                    f"errors of no change (equation error: {f.details.get('change', f.estimate):.3g}"
                                    f" ± {f.std_error:.2g}): the "
                                    "mismatch it fitted is not one the augmented model flies")}
        out.append(f)
    return out


def _diagnose(model: str, recording: str | Path, out: Path, validation: str | Path | None, *, mass: str,
              calibrate: bool = True, workers: int = 2, pool: LocalPool | None = None) -> dict:
    t0 = time.perf_counter()
    aircraft = _aircraft(model)
    rec = instruments_at_cg(read_recording(recording))
    if mass == "recording":
        aircraft = _with_recorded_mass(aircraft, rec)
    elif mass != "model":
        raise DiagnosisError(f"mass must be 'model' or 'recording', not {mass!r}")
    recs = {"identification": rec}
    if validation is not None:
        recs["validation"] = instruments_at_cg(read_recording(validation))
    pending = None
    if validation is not None and pool is not None:
        pending = pool.pool.submit(_analysed, recs["validation"], "validation", aircraft)
    p = prepare(rec, "identification")
    ic = initial_condition(p.t, p.smooth["V"], p.smooth["alpha"], p.altitude)
    a = analyse(p, aircraft, ic)
    check_model_represents(a, model)
    befores = {"identification": _replay_before(p, aircraft, a)}
    if validation is not None:
        pv, av, befores["validation"] = (pending.result() if pending is not None else
                                         _analysed(recs["validation"], "validation", aircraft))
    if validation is not None:  # sensor biases each maneuver only suspects, named on the two
        name_replicated(a, av)
    findings = _findings(a)
    checks: dict[int, dict | None] = {}
    unconfirmed: list[Candidate] = []
    if validation is not None:
        checks = {id(f): validation_check(av, f) for f in findings}
    else:
        av = None
        checks = {id(f): _undecided(f) for f in findings}
    # a finding is kept only when the validation maneuver confirms it (or cannot test it:
    # a gust level, a spectral peak, a coupling it does not excite, :func:`untestable`);
    # the others are reported apart, not as findings
    unconfirmed = [f for f in findings if (checks[id(f)] or {"status": "confirmed"})["status"]
                   not in ("confirmed", "untested")]
    findings = [f for f in findings if f not in unconfirmed]
    modelled = list(findings)
    added = _terms_of(modelled, a.applied)
    timing = {"analysis": time.perf_counter() - t0}
    # the recording as prepared (``a.prepared`` carries the sensor corrections; fits are
    # against what was recorded)
    maneuvers = {"identification": (p, a)} | ({"validation": (pv, av)} if av is not None else {})
    flown = _fly_all(maneuvers, aircraft, added, modelled, befores, pool=pool)
    calibration = {"used": False, "reason": "not asked for (calibrate=False, --no-calibrate)"}
    if calibrate:
        t1 = time.perf_counter()
        calibration, modelled, added, flown = _refine(model, recs, aircraft, mass, workers, maneuvers, befores,
                                                      modelled, added, flown, pool)
        withdrawn = _unsupported_in_the_loop(findings, calibration, checks)
        if withdrawn:  # the others are flown and calibrated again without it
            unconfirmed += withdrawn
            findings = [f for f in findings if f not in withdrawn]
            modelled = list(findings)
            added = _terms_of(modelled, a.applied)
            flown = _fly_all(maneuvers, aircraft, added, modelled, befores, pool=pool)
            calibration, modelled, added, flown = _refine(model, recs, aircraft, mass, workers, maneuvers, befores,
                                                          modelled, added, flown, pool)
        timing["calibration"] = time.perf_counter() - t1
    _, fb_id, fa_id, series_id = flown["identification"]
    fits_b, fits_a = {"identification": fb_id}, {"identification": fa_id}
    series = {"identification": series_id}
    located = _located(a, fb_id, "identification", _focus_axis(findings))
    located["remaining"] = _remaining(a, fb_id, fa_id)
    if findings:
        worst = max(_excited_axes(a.prepared, located["remaining"]), key=lambda c: located["remaining"][c]["ratio"])
        w = located["remaining"][worst]
        removed = f"{100 * w['removed']:.0f} % of it removed" if w["removed"] >= 0.005 else "none of it removed"
        if w["ratio"] >= UNEXPLAINED_RATIO:
            located["summary"] += (f" After the findings, the mismatch left in {worst} is still {w['ratio']:.1f} times "
                                   f"its noise level ({removed})"
                                   + (": no candidate term explains it." if w["removed"] < 0.2 else "."))
        else:
            located["summary"] += (f" After the findings, no axis's mismatch is above {UNEXPLAINED_RATIO:g} times its "
                                   f"noise level (largest: {worst}, {w['ratio']:.1f}).")
    if av is not None:
        av, fb_v, fa_v, series_v = flown["validation"]
        fits_b["validation"], fits_a["validation"] = fb_v, fa_v
        series["validation"] = series_v
        located["outputs"]["validation"] = _located(av, fb_v, "validation")["outputs"]["validation"]
    timing["total"] = time.perf_counter() - t0
    model_info = _write_model(out, aircraft, ic, added, _sensor_models(modelled),
                              calibration.get("references") if calibration["used"] else None)
    result = {
        "findings": [_with_calibration(_finding_dict(f, fits_b, fits_a, checks.get(id(f))), calibration)
                     for f in findings] or [_none_finding(a, fits_b)],
        "located": located,
        "not_confirmed": [_finding_dict(f, {}, {}, checks.get(id(f))) for f in unconfirmed],
        "calibration": calibration,
        "assumptions": assumptions(a, aircraft, mass) + _calibration_assumptions(calibration),
        "not_checked": not_checked(a, validation is not None),
        "noise": {c: {"std": p.noise_std[c], "cutoff_hz": p.cutoff_hz[c]} for c in p.noise_std},
        "candidates": [c.as_dict() for c in sorted(a.candidates, key=lambda c: -abs(c.t))],
        "model": model_info,
        "inputs": {"identification": str(recording), "validation": str(validation) if validation else None,
                   "model": model, "mass": mass},
        "common_filter_cutoff_hz": p.common_cutoff_hz,
        "timing_s": timing,
        "seed": None,
    }
    (out / "series").mkdir(parents=True, exist_ok=True)
    for name, df in series.items():
        write_atomic(out / "series" / f"{name}.parquet", lambda fh, df=df: df.to_parquet(fh, index=False))
    write_text_atomic(out / "findings.json", json.dumps(jsonable(result), indent=1))
    return result


def _with_calibration(d: dict, calibration: dict) -> dict:
    """A finding's dict with its calibrated size and standard error (``calibrated``: the size in
    the model when the calibration was used, else only reported), and a sentence in the
    explanation. When used, the calibrated size is the finding's ``estimate`` and
    ``std_error`` (and a coefficient error's ``change``): the equation-error ones move to
    ``equation_error``, their fits to ``fit_after_equation_error``."""
    own = (calibration.get("findings") or {}).get(d["parameter"])
    if own is None:
        return d
    d["calibrated"] = own | {"used": bool(calibration["used"])}
    if calibration["used"]:
        # the headline is the size the augmented model flies with; the equation-error one stays beside it
        d["equation_error"] = {"estimate": d["estimate"], "std_error": d["std_error"]}
        d["estimate"], d["std_error"] = float(own["estimate"]), float(own["std_error"])
        if "change" in d["evidence"]:
            d["equation_error"]["change"] = d["evidence"]["change"]
            d["evidence"]["change"] = float(own["size"])
        d["fit_after_equation_error"] = calibration["fit_after_equation_error"]
        d["explanation"] += (f" Refined with JSBSim in the loop: {own['estimate']:.4g} ± {own['std_error']:.2g}, the "
                             "size the augmented model flies with.")
    else:
        d["explanation"] += (f" Calibrated with JSBSim in the loop it would be {own['estimate']:.4g} ± "
                             f"{own['std_error']:.2g}; the equation-error size is kept ({calibration['reason']}).")
    return d


def _calibration_assumptions(calibration: dict) -> list[dict]:
    """The calibration step's assumption (how its replay holds the recorded surfaces)."""
    if "hold" not in calibration:
        return []
    return [{"item": "surfaces between samples (calibration)", "missing": "-",
             "stood_in_by": f"{calibration['hold']}: {calibration['hold_assumption']}"}]


def _sensor_models(findings: list[Candidate]) -> list[dict]:
    """Findings that become sensor- or atmosphere-side models rather than aircraft terms: a
    structural mode's notch and the turbulence's reconstructed gusts."""
    out = []
    for f in findings:
        if f.effect == "structural_mode":
            out.append({"effect": "structural_mode", "frequency_hz": float(f.estimate), "notch_q": MODE_NOTCH_Q,
                        "channels": [c for c in MODE_CHANNELS], "model": "second-order notch (scipy.signal.iirnotch), "
                        "zero phase, on the rate and acceleration channels"})
        if f.effect == "turbulence":
            out.append({"effect": "turbulence", "sigma_gust_fps": float(f.estimate),
                        "model": "the replay flies through the gusts each maneuver's kinematic residuals reconstruct "
                                 "(u, v, w integrated and high-passed at 0.05 Hz, rotated to north-east-down)"})
    return out


def _write_model(out: Path, aircraft: Aircraft, ic, added: tuple[HiddenEffect, ...],
                 other: list[dict] | None = None, refs: dict | None = None) -> dict:
    """Copy the augmented aircraft (XML) into ``out/model``; sensor effects (and a structural
    mode's notch, the turbulence model) are listed in ``sensors.json`` beside it (they change
    what the instruments record, or the air the aircraft flies through, not the aircraft)."""
    dest = out / "model"
    dest.mkdir(parents=True, exist_ok=True)
    terms = [e.describe() | {"parameter": e.parameter} for e in added]
    sensors = [t for t, e in zip(terms, added) if e.effect.startswith("sensor_")] + list(other or [])
    write_text_atomic(dest / "sensors.json", json.dumps(sensors, indent=1))
    if not any(not e.effect.startswith("sensor_") for e in added):
        return {"base": aircraft.model, "augmented_xml": None, "terms": terms,
                "note": "no aerodynamic or actuator term was added; the model's XML is unchanged"}
    root, name = hidden_root(Aircraft(aircraft.model, hidden=added), ic.condition(), refs)
    src = root / "aircraft" / name / f"{name}.xml"
    target = dest / f"{aircraft.name}-diagnosed.xml"
    write_atomic(target, lambda fh: fh.write(src.read_bytes()))
    return {"base": aircraft.model, "augmented_xml": str(target.relative_to(out)), "terms": terms,
            "note": ("a control delay is a property (sidbench/<surface>-delay-delta-rad) the sidbench flight loop "
                     "drives; the aerodynamic terms fly in any JSBSim")}


