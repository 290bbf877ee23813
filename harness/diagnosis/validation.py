"""Each finding tested on the validation maneuver: applied at its identified size to that
maneuver's coefficient mismatch (a prediction, nothing refitted), a rival that fits as well,
a coupling the maneuver does not excite, and the same sensor's verdict there."""
from __future__ import annotations

import numpy as np

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from harness.diagnosis import candidates as cand
from harness.diagnosis.along import interior
from harness.diagnosis.corroborate import inverse_variance_mean
from harness.diagnosis.evidence import Analysis, Candidate
from harness.diagnosis.prepare import COEFFICIENTS, Prepared
from harness.diagnosis.sensor_naming import MEANS_TESTS
from harness.diagnosis.sensor_rules import excursion_scale
from harness.diagnosis.spectra import MODE_CONFIRM_P, peak_at, untestable_at


def after_mismatch(a: Analysis, findings: list[Candidate]) -> tuple[dict[str, np.ndarray], dict[str, int]]:
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
    noise level, drops by 1 % or more, and the mismatch carries the predicted term at
    :data:`PREDICTION_T` standard errors, :func:`prediction_fit`), 'contradicted' (it rises by
    1 % or more) or 'neutral';
    None for a finding with no coefficient term (a sensor effect, a gust level, a spectral
    peak)."""
    if f.effect == "structural_mode":
        return _mode_check(av, f)
    if f.test in MEANS_TESTS.values():
        return _vane_means_check(av, f)
    if f.test.startswith("kinematic consistency") or f.parameter == "x_accelerometer":
        return _sensor_check(av, f)
    after, n_terms = after_mismatch(av, [f])
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
    prediction = prediction_fit(av, axes, after)
    out = {"status": status, "axes": axes, "rms_before": before_rms, "rms_after": after_rms, "change": ratio - 1.0,
           "prediction": prediction}
    if status == "confirmed" and not (prediction["t"] or 0.0) >= PREDICTION_T:
        out["status"] = "neutral"
        out["reason"] = (f"the validation maneuver's mismatch carries the predicted term {prediction['k']:.2f} ± "
                         f"{prediction['std_error']:.2f} times (t = {prediction['t']:.1f}, under {PREDICTION_T:g}): it "
                         "lowers the RMS by chance as much as by the term") if prediction["t"] is not None else \
            "the validation maneuver's mismatch cannot be fitted on the predicted term"
    rival = _rival_check(av, f, axes, after, ratio - 1.0)
    set_apart = rival is not None and f.details["rival"].get("under_collinearity", False)
    if rival is not None:
        # a rival the identification set apart is recorded, not judged by these RMS (rival_entered_instead)
        out["rival"] = rival | {"under_collinearity": set_apart}
    if rival is not None and not set_apart:
        if out["status"] == "confirmed" and rival["fits_as_well"] and not rival["joint_prefers_it"]:
            out["status"] = "ambiguous"
            out["reason"] = _ambiguous_reason(rival, ratio - 1.0)
        elif out["status"] == "confirmed" and rival["fits_as_well"]:
            j = rival["joint"]
            out["reason"] = (f"fitted on both predictions, the validation mismatch carries this one {j[0]['k']:.2f} "
                             f"± {j[0]['std_error']:.2f} times (t = {j[0]['t']:.1f}) and {rival['parameter']}'s "
                             f"{j[1]['k']:.2f} ± {j[1]['std_error']:.2f} (t = {j[1]['t']:.1f}): it prefers this one")
        elif rival["indistinct"] and out["status"] == "confirmed":
            out["reason"] = f"{rival['indistinct']}; the validation maneuver prefers it"
    if out["status"] == "confirmed":
        why = unreplicated(av, f) or rival_entered_instead(av, f)
        if why:
            out["status"], out["reason"] = "ambiguous", why
    return out


def rival_entered_instead(av: Analysis, f: Candidate) -> str:
    """Why a finding is not named whose collinear rival (``details['rival']``, :mod:`rivals`)
    the validation maneuver's own fit selects in its place ('' otherwise): the two maneuvers
    then disagree on which of the pair carries the mismatch, and the identification's choice
    is one maneuver's word against the other's. Asked of every rival kept, also one the
    identification set apart (correlated under the collinearity limit, the term standing
    beside it). A probe's F-15 (641 ft/s, three-axis 3-2-1-1 at 25 Hz) with C_m,α̇ −3 had
    C_m,q̂ −3.2 named (t −28; −6.8 beside C_m,α̇, which stood at 1.7 beside it, the columns
    correlated 0.88), its validation RMS 43 % lower; the validation maneuver's own fit entered
    C_m,α̇ (t −18) and not C_m,q̂, and noise-free the identification had entered both."""
    r = f.details.get("rival")
    if not r:
        return ""
    own = next((c for c in av.candidates if c.channel == f.channel and c.parameter == f.parameter), None)
    theirs = next((c for c in av.candidates if c.channel == r["axis"] and c.parameter == r["parameter"]), None)
    if theirs is None or not theirs.selected or (own is not None and own.selected):
        return ""
    return (f"the validation maneuver's own fit enters {r['parameter']} (t = {theirs.t:.1f}) in its place, its rival "
            f"in the identification fit (columns correlated {r['correlation']:+.2f}; beside it, t = "
            f"{r['t_term']:.1f}): the maneuvers disagree on which of the two carries the mismatch")


# A finding's prediction must stand in the validation maneuver's mismatch at this many
# standard errors for the maneuver to confirm it (:func:`prediction_fit`): a drop of its RMS
# by 1 % is no test where the term's part is within the noise. Both sweeps' confirmed findings
# (6 Dec 2026) stood at 3.0-60; an independent script's c172x null in a 22° turn (3-2-1-1 on
# each axis, 50 Hz) had a C_X α² of −0.80 (t −5.8) "confirmed" by a drop of 1.4 %, its
# prediction there 0.50 ± 0.44 times.
PREDICTION_T = 2.0


def prediction_fit(av: Analysis, axes: list[str], after: dict[str, np.ndarray]) -> dict:
    """The validation mismatch fitted on the finding's predicted part of it (the mismatch less
    ``after``, the term at its identified size), the axes stacked in units of their noise
    levels, each with a constant and its nuisance columns: ``k`` is 1 where the prediction is
    all there, 0 where none of it is; its colored standard error (seed Eq. 40) says whether
    the validation maneuver could tell."""
    return joint_prediction_fit(av, axes, [{c: av.mismatch[c] - after[c] for c in axes}])[0]


def joint_prediction_fit(av: Analysis, axes: list[str], parts: list[dict[str, np.ndarray]]) -> list[dict]:
    """:func:`prediction_fit` with several predicted parts (each per axis, full length) fitted
    together: one ``k`` each, with its colored standard error and t."""
    inner = interior(av.prepared)
    w = _noise_weights(av, axes)
    m = inner.stop - inner.start
    z = np.concatenate([w[c] * av.mismatch[c][inner] for c in axes])
    cols = [np.concatenate([w[c] * part[c][inner] for c in axes]) for part in parts]
    for i, c in enumerate(axes):
        own = [np.ones(m)] + [col[inner] for col in (av.nuisances or {}).get(c, {}).values() if np.ptp(col[inner]) > 0]
        cols += [np.concatenate([x if j == i else np.zeros(m) for j in range(len(axes))]) for x in own]
    try:
        theta, se, _ = colored_fit(z, cols, [f"c{i}" for i in range(len(cols))], constant=False)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return [{"k": None, "std_error": None, "t": None} for _ in parts]
    return [{"k": float(theta[i]), "std_error": float(se[i]), "t": float(theta[i] / se[i]) if se[i] > 0 else None}
            for i in range(len(parts))]


def unreplicated(av: Analysis, f: Candidate) -> str:
    """Why a term the identification could not tell from a moment-reference shift, which the
    mean of C_m then refuted (``details['refuted_rival']``, :func:`term_rules._refuted_shift`),
    is not named: the validation maneuver's own fit does not enter it ('' when it does, or the
    term had no such rival). Such a term stands on its own t alone, so it must stand on each
    maneuver: the validation's stepwise estimate of the same parameter, of the identification's
    sign, at |t| >= the entry t (:data:`candidates.T_IN`). A lowering of the validation RMS by
    1 % is no test of it: a C_n,αβ coupling of 2 on a three-axis maneuver at 427.4 ft/s read as
    a C_n,β change of −0.010 (t −6.3; the α of the lateral inputs lay below trim) lowered it by
    1.6 %, and the validation's own fit gave t −4.0; a C_n,β change of +0.05 at 30,000 ft gave
    t 29 and 12 (outside sweep and probe, 4 Dec 2026)."""
    refuted = f.details.get("refuted_rival")
    if not refuted or abs(refuted.get("t_term", 0.0)) >= cand.T_IN:
        return ""
    twin = next((c for c in av.candidates if c.effect == f.effect and c.parameter == f.parameter), None)
    t_v = twin.t if twin is not None else 0.0
    if np.sign(t_v) == np.sign(f.t) and abs(t_v) >= cand.T_IN:
        return ""
    return (f"the identification maneuver could not tell it from {refuted['parameter']} (columns correlated "
            f"{refuted['correlation']:+.2f}; beside it, t = {refuted['t_term']:.1f}), whose size the mean of C_m "
            f"refutes, so it rests on its own t; the validation maneuver's own fit gives t = {t_v:.1f} for it, under "
            f"the entry t of {cand.T_IN:g}")


def _mode_check(av: Analysis, f: Candidate) -> dict:
    """A structural mode on the validation maneuver: 'confirmed' when its spectrum shows the
    mode too, on the same channel within a bin of the frequency found (p <
    :data:`spectra.MODE_CONFIRM_P`, :func:`spectra.peak_at`), or when the mode was named on
    the two together (:func:`replication.name_mode_on_both`); 'untested' when it was named on
    the validation maneuver alone (nothing independent tests it), or a maneuver that
    does not ring the mode (a lateral one, for a mode the stabilator drives) cannot refute it,
    and one whose record cannot show it (:func:`spectra.untestable_at`) says why."""
    both = f.details.get("replicated")
    if both and both.get("identification_cannot"):  # named from this maneuver's own spectrum
        return {"status": "untested", "axes": [], "p_value": both["validation_p"],
                "reason": "it was named on the validation maneuver's own spectrum; the identification cannot show it"}
    p_v = both["validation_p"] if both else peak_at(av.prepared, f.channel, f.estimate)
    why = "" if both else untestable_at(av.prepared, f.channel, f.estimate)
    if why:
        return {"status": "untested", "axes": [], "reason": f"the validation maneuver cannot show the mode: {why}"}
    if p_v < MODE_CONFIRM_P:
        return {"status": "confirmed", "axes": [], "p_value": p_v,
                "reason": f"the validation maneuver's {f.channel} spectrum shows it too (p = {p_v:.2g})"}
    return {"status": "untested", "axes": [], "p_value": p_v,
            "reason": f"the validation maneuver's {f.channel} spectrum does not show it above its noise "
                      f"(p = {p_v:.2g}; a maneuver that does not ring the mode cannot test it)"}


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


def undecided(f: Candidate) -> dict | None:
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
    rival_after, _ = after_mismatch(av, [twin])
    joint = joint_prediction_fit(av, axes, [{c: av.mismatch[c] - after[c] for c in axes},
                                            {c: av.mismatch[c] - rival_after[c] for c in axes}])
    inner = interior(av.prepared)
    after = {c: after[c][inner] for c in axes}
    rival_rms = {c: _rms(rival_after[c][inner]) for c in axes}
    # summed over the axes in units of each axis's noise level, as validation_check does, each
    # residual less the validation maneuver's own nuisance columns
    w = _noise_weights(av, axes)
    own = sum(w[c] * _rms(_less_nuisances(av, c, after[c], inner)) for c in axes)
    theirs = sum(w[c] * _rms(_less_nuisances(av, c, rival_after[c][inner], inner)) for c in axes)
    margin = max(rms_margin(after[c]) for c in axes)
    indistinct = r.get("indistinct", "")
    return {"parameter": r["parameter"], "correlation": r["correlation"], "rms_after": rival_rms, "margin": margin,
            "noise_levels_own": own, "noise_levels_rival": theirs,
            "fits_as_well": rival_fits_as_well(own, theirs, margin, bool(indistinct), change),
            "indistinct": indistinct, "joint": joint, "joint_prefers_it": joint_prefers(joint)}


def joint_prefers(joint: list[dict]) -> bool:
    """Whether the validation mismatch, fitted on the finding's prediction and its rival's
    together (:func:`joint_prediction_fit`), keeps the finding's at :data:`PREDICTION_T`
    standard errors and the rival's under it: the maneuver tells the two apart where their
    RMS alone cannot (an RMS compared within two of its standard errors, :func:`rms_margin`,
    left true C_Z,α changes `ambiguous` beside C_Z α³ on probe doublets whose residuals'
    lag-one correlation made that margin 39-55 %)."""
    own, theirs = joint
    if own["t"] is None or theirs["t"] is None:
        return False
    return own["t"] >= PREDICTION_T and abs(theirs["t"]) < PREDICTION_T


def _less_nuisances(av: Analysis, axis: str, residual: np.ndarray, inner: slice) -> np.ndarray:
    """``residual`` (on ``inner``) less its least-squares fit on the maneuver's nuisance
    columns of ``axis`` (the α vane's noise column in C_m, :func:`stepwise_axes.vane_noise_columns`),
    as the stepwise fits them: a finding built on α carries the vane's noise as the model's
    slopes pass it into the mismatch, and would otherwise win a comparison with a rival built
    on another channel by removing that noise rather than the effect (probe 61: a 737 with 60 %
    less fuel, its c.g. 1.26 ft aft of the model's, read as C_m,α because the moment-reference
    shift's column, the measured C_Z, does not carry the vane's noise)."""
    cols = [col[inner] for col in (av.nuisances or {}).get(axis, {}).values() if np.ptp(col[inner]) > 0]
    w = getattr(av.gust, "w_fps", None)
    if axis == "Cm" and w is not None and "vane_alpha_noise" not in (av.nuisances or {}).get(axis, {}):
        cols.append(np.asarray(w, dtype=float)[inner])  # the vane's error, ungated here
    if not cols:
        return residual
    A = np.column_stack(cols + [np.ones(residual.size)])
    return residual - A @ np.linalg.lstsq(A, residual, rcond=None)[0]


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
                "rule": "named on both maneuvers' kinematics (replication.name_replicated)"}
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
    (the kinematic k, ``twin``, with the mismatch's shape where read:
    :func:`sensor_rules.excursion_scale`) must agree within two standard errors; their
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
    k_exc, se_exc = excursion_scale(twin)
    if abs(k_off - k_exc) > 2.0 * np.hypot(se_off, se_exc):
        return None
    k, se = inverse_variance_mean([k_off, k_exc], [se_off, se_exc])
    return {"status": _same_instrument_status(k, k / se, f.estimate), "axes": [], "estimate": k, "std_error": se,
            "t": k / se, "rule": f"the offset at the mean {channel} (k = {k_off:.3f} ± {se_off:.3f}) and the "
            f"excursions (k = {k_exc:.3f} ± {se_exc:.3f}) agree"}


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
