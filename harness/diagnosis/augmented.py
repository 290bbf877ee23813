"""The augmented model: the named effects as model terms and sensor models, the recordings
replayed before and after (a structural mode notched, turbulence as winds), the calibration
with JSBSim in the loop, and the augmented JSBSim aircraft written out."""
from __future__ import annotations

import json
from pathlib import Path
from dataclasses import replace
from typing import NamedTuple

import numpy as np
import pandas as pd

from harness.atomic import write_atomic, write_text_atomic
from harness.diagnosis import candidates as cand
from harness.diagnosis import levels, refine
from harness.diagnosis.along import interior
from harness.diagnosis.analysis import analyse
from harness.diagnosis.evidence import Analysis, Candidate
from harness.diagnosis.fits import coefficient_fit, output_fit
from harness.diagnosis.mode_model import driven_modes, mode_outputs, with_mode_band
from harness.diagnosis.prepare import COEFFICIENTS, OUTPUTS, Prepared, prepare
from harness.diagnosis.spectra import MODE_CHANNELS, MODE_NOTCH_Q, gust_wind_ned, notched
from harness.diagnosis.term_rules import IMITATION_SHARE
from harness.diagnosis.validation import after_mismatch
from harness.diagnosis.verdict import check_time_base
from harness.executors import LocalPool
from models.aircraft import Aircraft, placement, reference_point_alternative
from models.constants import SURFACES
from models.flight import FlightError
from models.hidden import HiddenEffect, hidden_root
from models.replay import initial_condition, replay, steady_start
from models.trim import TrimError


CHANNEL_COLUMNS = {"alpha": "alpha_rad", "beta": "beta_rad", "p": "p_rps", "q": "q_rps", "r": "r_rps",
                   "phi": "phi_rad", "theta": "theta_rad", "V": "V_fps", "ax": "ax_g", "ay": "ay_g", "az": "az_g"}


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
        channel = c.channel if c.channel in CHANNEL_COLUMNS else c.parameter.split("_", 1)[1]
        if channel in CHANNEL_COLUMNS:
            return HiddenEffect(e, c.estimate, channel=channel)
    return None


def terms_of(findings: list[Candidate], applied: dict[str, float]) -> tuple[HiddenEffect, ...]:
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
                and "offset" not in f.details:  # a scale read from the bias carries it (scale_read_as_bias)
            out.append(HiddenEffect("sensor_bias", float(applied[bias]), channel=e.channel))
    return tuple(out)


def _sim_channels(hist) -> dict[str, np.ndarray]:
    return {c: hist.channels[col] for c, col in CHANNEL_COLUMNS.items()}


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
    return initial_condition(p.t, ch["V"], ch["alpha"], ch.get("h"), phi=p.smooth.get("phi"))


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


def analysed(rec, role: str, aircraft: Aircraft) -> tuple[Prepared, Analysis, Replayed]:
    """One maneuver prepared, analysed and replayed as the model is (a unit of work a second
    process can take)."""
    p = prepare(rec, role)
    check_time_base(p)
    a = analyse(p, aircraft, initial_condition(p.t, p.smooth["V"], p.smooth["alpha"], p.altitude,
                                               phi=p.smooth.get("phi")))
    return p, a, replay_before(p, aircraft, a)


def replay_before(p: Prepared, aircraft: Aircraft, analysis: Analysis) -> Replayed:
    """The model as given, replayed over one maneuver."""
    return _fitted_replay(p, lambda surf: replay(aircraft, analysis.ic, p.t, surf)[0])


def fly_maneuver_pair(p: Prepared, aircraft: Aircraft, added: tuple[HiddenEffect, ...],
                      findings: list[Candidate] | None, analysis: Analysis, before: Replayed | None = None,
                      refs: dict | None = None):
    """Replays before/after and fits for one analysed maneuver; on the validation maneuver
    the identification's findings are applied as predictions. ``before`` reuses an earlier
    :func:`replay_before` of the same maneuver; ``refs`` are the trim references of the added
    terms (default: the nominal model's trim at the maneuver's start, :func:`models.hidden.hidden_root`).
    Each replay fits its own surface levels (:mod:`harness.diagnosis.levels`)."""
    before = before if before is not None else replay_before(p, aircraft, analysis)
    after = before
    winds = _turbulence_winds(p, analysis) if any(f.effect == "turbulence" for f in findings or []) else None
    if (added or winds is not None) and before.failed is None:
        augmented, start = replace(aircraft, hidden=added), _true_start(p, added)
        after = _fitted_replay(p, lambda surf: replay(augmented, start, p.t, surf, wind_ned_fps=winds, refs=refs)[0])
    before_failed, diverged = before.failed, after.failed
    a = analysis
    before_mm = a.mismatch
    after_mm, n_terms = after_mismatch(a, findings or [])
    inner = interior(p)
    nan = {c: np.full(p.n, np.nan) for c in CHANNEL_COLUMNS}
    sim_b = before.outputs if before.outputs is not None else nan
    sim_a = after.outputs if after.outputs is not None else nan
    modes = driven_modes(findings or [])
    sim_a = _with_modes(sim_a, p, modes)
    smooth = with_mode_band(p, p.smooth, modes)
    fit_b = {"outputs": output_fit(smooth, p.raw, sim_b, OUTPUTS, inner) if before_failed is None else {},
             "coefficients": coefficient_fit(before_mm, before_mm, {}, inner)}
    raw_after = _mode_notched(p, findings or [])
    fit_a = {"outputs": output_fit(smooth, raw_after, sim_a, OUTPUTS, inner) if diverged is None else {},
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
            series[f"smooth_{c}"] = smooth[c]  # with a modelled mode's band put back
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


def _with_modes(sim: dict[str, np.ndarray], p: Prepared, modes: list) -> dict[str, np.ndarray]:
    """The replay's outputs with each driven mode's response (:mod:`harness.diagnosis.mode_model`)
    added to the outputs it rings in."""
    if not modes:
        return sim
    out = dict(sim)
    for m in modes:
        for c, y in mode_outputs(m, p).items():
            if c in out:
                out[c] = out[c] + y
    return out


def _mode_notched(p: Prepared, findings: list[Candidate]) -> dict[str, np.ndarray]:
    """The recorded channels as the augmented sensor model sees them: a structural mode found
    that no recorded surface's response explains (no ``mode_model``) becomes a notch
    (scipy.signal.iirnotch at its frequency, zero phase) in every rate and acceleration
    channel, so the raw fit after shows what the mode term removes. Returns ``p.raw``
    unchanged when there is no such mode."""
    out = p.raw
    for f in findings:
        if f.effect == "structural_mode" and not f.details.get("mode_model"):
            out = notched(out, p.dt, f.estimate)
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


def fly_all(maneuvers: dict, aircraft: Aircraft, added: tuple[HiddenEffect, ...], modelled: list[Candidate],
            befores: dict, refs: dict | None = None, pool: LocalPool | None = None) -> dict:
    """:func:`fly_maneuver_pair` for each role of ``maneuvers`` (role -> (prepared, analysis)), the
    model as given flown once (``befores``): role -> (analysis, fit before, fit after, series).
    With a ``pool``, the validation maneuver is flown in its process meanwhile."""
    pending = {role: pool.pool.submit(fly_maneuver_pair, pm, aircraft, added, modelled, am, befores[role], refs)
               for role, (pm, am) in maneuvers.items() if pool is not None and role == "validation"}
    out = {role: fly_maneuver_pair(pm, aircraft, added, modelled, am, befores[role], refs)
           for role, (pm, am) in maneuvers.items() if role not in pending}
    return out | {role: fut.result() for role, fut in pending.items()}


def refine_in_the_loop(model: str, recs: dict, aircraft: Aircraft, mass: str, workers: int, maneuvers: dict,
                       befores: dict, modelled: list[Candidate], added: tuple[HiddenEffect, ...], flown: dict,
                       pool: LocalPool | None = None):
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
    # the calibration's copy is placed as the diagnosis's aircraft (reference_point.py)
    placed = placement(aircraft) if reference_point_alternative(aircraft) else "project"
    try:
        cal = calibrate_in_loop(model, [recs["identification"]], refine.parameter_spec(terms),
                                validation=[recs["validation"]] if "validation" in recs else None, workers=workers,
                                mass=mass, hold=hold, outputs=matched, aero_reference=placed)
    except (CalibrationError, FlightError, TrimError, RuntimeError, ValueError, OSError) as exc:
        # the last step never takes the diagnosis down: the equation-error sizes stand
        return block | {"reason": f"the calibration could not run: {type(exc).__name__}: {exc}"}, modelled, added, flown
    sizes = {a.name: float(v) for a, v in zip(cal.adjustments, cal.estimate)}
    refined = refine.refined_findings(pairs, sizes, dict(zip((a.name for a in cal.adjustments), cal.std_error)))
    modelled_cal = [refined[id(f)][0] if id(f) in refined else f for f in modelled]
    added_cal = refine.refined_terms(added, sizes)
    # the calibrated sizes belong to the calibration's term references (its unadjusted model's
    # trim at the recording's start): the augmented model is flown and written with them
    flown_cal = fly_all(maneuvers, aircraft, added_cal, modelled_cal, befores, dict(cal.refs), pool)
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


def unsupported_in_the_loop(findings: list[Candidate], calibration: dict, checks: dict) -> list[Candidate]:
    """The findings the calibration, when used, sizes within :data:`CALIBRATED_MIN_Z` standard
    errors of no change, or of the opposite sign to the equation error's size; their
    ``checks`` entry says so (status 'unsupported'). A reversed sign is the mark of a sensor
    error the equation error read as a term: a 10 % α-vane scale on a c172x pitch maneuver,
    which the kinematics could not see (k 0.03 ± 0.11), made the model along the vane a C_Z,α
    change of +0.96 (the slope times −k/(1+k)); the aircraft flown in the loop, matched on
    a_z, put it at −0.16 ± 0.02 (probe 38).

    The rules a term entered by are asked again at its calibrated size: it must still explain
    :data:`candidates.PRACTICAL_SHARE` of its coefficient's excursion (its equation-error share
    scaled by the sizes' ratio), and the sensor error the kinematics suspect must still imitate
    less than :data:`term_rules.IMITATION_SHARE` of it, and where the equation error's size lies
    more than :data:`CALIBRATED_MIN_Z` of its standard errors from the calibrated one, the
    calibrated size must still reach the entry t on the equation error's standard error (an
    independent script's 737 at 28,000 ft / 700 ft/s, a pitch multisine with twice its noise: a
    C_Z,α change of +1.44 ± 0.26 by equation error, drawn by the vanes' noise, calibrated to
    +0.195 and confirmed by chance on the validation maneuver). Noise-free three-axis recordings
    of the package's c182 and pa28, flown by an independent script, had named a C_m,δe change
    the calibration put at −0.0064 (equation error −0.022: 1 % of the model's −0.59) and a
    C_m,α̇ of 0.50 (equation error 1.73) that JSBSim's Euler half-step imitates up to 0.39."""
    if not calibration.get("used"):
        return []
    sized = calibration.get("findings") or {}
    out = []
    for f in findings:
        own = sized.get(f.parameter)
        if not own or not own.get("std_error"):
            continue
        ee = f.details.get("change", f.estimate)
        weak = abs(own["size"]) < CALIBRATED_MIN_Z * own["std_error"]
        unflown = weak or own["size"] * ee < 0  # a mismatch the augmented model does not fly
        why = (f"within {CALIBRATED_MIN_Z:g} standard errors of no change" if weak else
               "of the opposite sign" if unflown else _too_small_calibrated(f, own["size"], ee))
        if not why:
            continue
        before = checks.get(id(f)) or {}
        checks[id(f)] = {**before, "status": "unsupported", "validation_status": before.get("status", "not checked"),
                         "reason": (f"the calibration (output error, JSBSim in the loop) sizes it "
                                    f"{own['size']:.3g} ± {own['std_error']:.2g}, {why} (equation error: {ee:.3g}"
                                    f" ± {f.std_error:.2g}): " + (
                                        "the mismatch it fitted is not one the augmented model flies"
                                        if unflown else
                                        "at the size the augmented model flies it fails a rule it entered by"))}
        out.append(f)
    return out


def _too_small_calibrated(f: Candidate, size: float, ee: float) -> str:
    """Why a finding no longer passes its entry rules at its calibrated ``size`` (equation
    error ``ee``), or "" (:func:`unsupported_in_the_loop`)."""
    ratio = abs(size / ee) if ee else 1.0
    share = f.details.get("excursion_share")
    if share is not None and share * ratio < cand.PRACTICAL_SHARE:
        return f"so small that it explains {cand.share_below_practical(share * ratio)}"
    if f.std_error > 0 and abs(ee - size) > CALIBRATED_MIN_Z * f.std_error and abs(size) < cand.T_IN * f.std_error:
        return (f"so far under the equation error's size ({abs(ee - size) / f.std_error:.1f} of its standard errors) "
                f"that it would not have entered (t = {size / f.std_error:.1f} at the equation error's standard "
                "error)")
    suspect = f.details.get("sensor_suspect")
    if suspect and suspect["imitates_at_most"] >= IMITATION_SHARE * abs(size):
        return (f"so small that {suspect['parameter']}, which the kinematics do not rule out, would imitate "
                f"{suspect['imitates_at_most']:.2g} of it (half or more)")
    return ""


def with_calibration(d: dict, calibration: dict) -> dict:
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


def calibration_assumptions(calibration: dict) -> list[dict]:
    """The calibration step's assumption (how its replay holds the recorded surfaces)."""
    if "hold" not in calibration:
        return []
    return [{"item": "surfaces between samples (calibration)", "missing": "-",
             "stood_in_by": f"{calibration['hold']}: {calibration['hold_assumption']}"}]


def sensor_models(findings: list[Candidate]) -> list[dict]:
    """Findings that become sensor- or atmosphere-side models rather than aircraft terms: a
    structural mode's notch and the turbulence's reconstructed gusts."""
    out = []
    for f in findings:
        if f.effect == "structural_mode" and f.details.get("mode_model"):
            m = f.details["mode_model"]
            out.append({"effect": "structural_mode", **m,
                        "model": f"second-order mode driven by {m['surface']} (natural frequency "
                                 f"{m['frequency_hz']:.3g} Hz, damping {m['damping']:.3g}), added to "
                                 f"{', '.join(m['gains'])}: gains of "
                                 "s²H(s)u/ω² and sH(s)u/ω, H = ω²/(s² + 2ζωs + ω²), u the surface's Wiener estimate "
                                 "(harness/diagnosis/mode_model.py)"})
        elif f.effect == "structural_mode":
            out.append({"effect": "structural_mode", "frequency_hz": float(f.estimate), "notch_q": MODE_NOTCH_Q,
                        "channels": [c for c in MODE_CHANNELS], "model": "second-order notch (scipy.signal.iirnotch), "
                        "zero phase, on the rate and acceleration channels"})
        if f.effect == "turbulence":
            out.append({"effect": "turbulence", "sigma_gust_fps": float(f.estimate),
                        "model": "the replay flies through the gusts each maneuver's kinematic residuals reconstruct "
                                 "(u, v, w integrated and high-passed at 0.05 Hz, rotated to north-east-down)"})
    return out


def recording_start_references(p: Prepared, ic) -> dict[str, float]:
    """The recording's own first α, V and surface positions (rad, ft/s), in the keys of
    :data:`models.hidden.REFERENCE_KEYS`: what added terms are written about when the model
    cannot be trimmed at the recording's start."""
    return {"alpha": float(ic.alpha_rad), "dV": float(ic.V_fps),
            **{s: float(p.smooth[s][0]) if s in p.smooth else 0.0 for s in SURFACES}}


def write_model(out: Path, aircraft: Aircraft, ic, added: tuple[HiddenEffect, ...],
                other: list[dict] | None = None, refs: dict | None = None,
                start_refs: dict | None = None) -> dict:
    """Copy the augmented aircraft (XML) into ``out/model``; sensor effects (and a structural
    mode's notch, the turbulence model) are listed in ``sensors.json`` beside it (they change
    what the instruments record, or the air the aircraft flies through, not the aircraft).

    The added terms are written about the model's trim at the recording's start (``refs``
    when the calibration gave them). Where the model cannot be trimmed there (the replays
    could not be made either), they are written about ``start_refs``, the recording's own
    first α, V and surface positions, and the returned note says so."""
    dest = out / "model"
    dest.mkdir(parents=True, exist_ok=True)
    terms = [e.describe() | {"parameter": e.parameter} for e in added]
    sensors = [t for t, e in zip(terms, added) if e.effect.startswith("sensor_")] + list(other or [])
    write_text_atomic(dest / "sensors.json", json.dumps(sensors, indent=1))
    outside = {"outside_the_aircraft": list(other)} if other else {}
    if not any(not e.effect.startswith("sensor_") for e in added):
        return {"base": aircraft.model, "augmented_xml": None, "terms": terms, **outside,
                "note": "no aerodynamic or actuator term was added; the model's XML is unchanged"}
    where = ""
    try:
        root, name = hidden_root(replace(aircraft, hidden=added), ic.condition(), refs)
    except TrimError as exc:
        if start_refs is None:
            raise
        root, name = hidden_root(replace(aircraft, hidden=added), ic.condition(), {**start_refs, **(refs or {})})
        where = (f"; the model cannot be trimmed at the recording's start ({exc}), so the added terms are written "
                 "about the recording's first alpha, V and surface positions instead of the model's trim")
    src = root / "aircraft" / name / f"{name}.xml"
    target = dest / f"{aircraft.name}-diagnosed.xml"
    write_atomic(target, lambda fh: fh.write(src.read_bytes()))
    return {"base": aircraft.model, "augmented_xml": str(target.relative_to(out)), "terms": terms, **outside,
            "note": ("a control delay is a property (sidbench/<surface>-delay-delta-rad) the sidbench flight loop "
                     "drives; the aerodynamic terms fly in any JSBSim" + where)}
