"""Findings replicated on both maneuvers: the same instrument and airframe flew the
identification and the validation maneuver, so a sensor error shows in both records'
kinematics, and a structural mode in both records' spectra, with independent noise. A bias
each only suspects is named on the two together; a suspicion that withheld a coefficient term
and that the validation maneuver does not share is lifted; a mode the validation maneuver
rings and the identification shows where it rings is named."""
from __future__ import annotations

import numpy as np

from harness.diagnosis import corroborate
from harness.diagnosis.evidence import Analysis, Candidate
from harness.diagnosis.gust_rules import mode_candidate, voids_kinematics
from harness.diagnosis.kinematics import T_IN as KIN_T_IN
from harness.diagnosis.rivals import RIVAL_CORRELATION
from harness.diagnosis.sensor_rules import (AMBIGUOUS_T, kinematic_rival, kinematics_plausible, sensor_verdict,
                                            suspected_estimate)
from harness.diagnosis.spectra import FISHER_P, MODE_CONFIRM_P, peak_at, predicted_peak_p, untestable_at
from models.hidden import SENSOR_EFFECTS


# The |t| each maneuver's kinematic estimate must reach on its own for a sensor error below
# the identification's entry t to be named on the two together (:func:`name_replicated`):
# the suspicion level of the other sensor rules (:data:`AMBIGUOUS_T`).
REPLICATED_EACH_T = AMBIGUOUS_T
# The biases :func:`name_replicated` names: the inertial instruments' (accelerometers, rate
# gyros), each a constant added in its own kinematic equations. An air-data bias (the
# airspeed, a vane) enters them multiplied by the motion (an airspeed bias b puts q·b into
# the ẇ equation, −r·b into the v̇ one), so an error the kinematics leave out, the vane's
# noise passed through those products among them, repeats in both records as it would: an
# independent script's t6texan2 (11,900 ft / 378 ft/s, 30° bank, multisine on each axis and
# doublets, half the noise) had an airspeed bias of −12.9 ± 3.7 and −12.7 ± 2.4 ft/s on
# its two maneuvers and none recorded; five other noise draws of the same flights gave
# +1.1 to −13.9 (mean −5, scatter 5), the noise-free flights −0.01.
REPLICATED_BIASES = tuple(f"bias_{c}" for c in ("ax", "ay", "az", "p", "q", "r"))


def name_replicated(a: Analysis, av: Analysis) -> list[Candidate]:
    """Name the sensor biases that the identification's kinematics only suspect (|t| at least
    :data:`REPLICATED_EACH_T`, below the entry t) and the validation's show too (|t| at least
    as much, the same sign, sizes within two standard errors), when their inverse-variance
    combination reaches the kinematic entry t (:data:`kinematics.T_IN`): the same instrument
    flew both, and their kinematic residuals carry independent noise. Not when either record's
    kinematics are void (turbulence, light gusts, implausible estimates), when the
    identification's kinematics cannot tell the parameter from a rival
    (:func:`kinematic_rival` at the seed's pairwise limit, :data:`rivals.RIVAL_CORRELATION`:
    the project sweep's a_z bias of 0.025 g, t 4.7 and 6.3 on the two maneuvers, has a rival at
    r between 0.7 and 0.9), or when the combined size is not practical and precise
    (:func:`sensor_verdict`). Returns the candidates of ``a`` it selected.

    The inertial instruments' biases only (:data:`REPLICATED_BIASES`), and only when no
    other sensor error is named: the replication shows the two
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
                or c.parameter not in REPLICATED_BIASES
                or min(abs(c.t), abs(v.t)) < REPLICATED_EACH_T or np.sign(c.estimate) != np.sign(v.estimate)
                or c.std_error <= 0 or v.std_error <= 0):
            continue
        if abs(c.estimate - v.estimate) > 2.0 * np.hypot(c.std_error, v.std_error):
            continue
        est, se = corroborate.inverse_variance_mean([c.estimate, v.estimate], [c.std_error, v.std_error])
        if abs(est) / se < KIN_T_IN or kinematic_rival(kin, c.parameter, RIVAL_CORRELATION) is not None:
            continue
        if not sensor_verdict(c.parameter, est, se, True, kin, p, False, True)[0]:
            continue
        c.details["replication"] = {"identification": [c.estimate, c.std_error],
                                    "validation": [v.estimate, v.std_error], "combined": [est, se]}
        c.reason = (f"named on two maneuvers: the identification's kinematics suspect it (t = {c.t:.1f}, below "
                    f"the entry t) and the validation's agree (t = {v.t:.1f}, the sizes within two standard "
                    f"errors); together t = {est / se:.1f}")
        c.selected, c.estimate, c.std_error, c.t = True, est, se, est / se
        named.append(c)
    return named


# A sensor suspicion that withheld a term is lifted when the validation maneuver's kinematics
# put the same parameter at least this many combined standard errors from the
# identification's estimate (and do not suspect it themselves with the same sign): the three
# standard errors within which a suspicion withholds a term at all (term_rules.IMITATION_Z).
# At two, an independent script's T-6 in a 31° turn (8,300 ft / 346 ft/s, 3-2-1-1 on each
# axis at 100 Hz, twice the noise, no h) with its α vane reading 10 % high had the right
# suspicion (0.105 ± 0.018) lifted by the validation doublets' 0.041 ± 0.023, 2.2 apart, and
# a C_Z,α change of +0.92 named in its place.
UNREPLICATED_Z = 3.0


def lift_unreplicated_suspicions(a: Analysis, av: Analysis) -> list[Candidate]:
    """Name again the terms withheld only because the identification's kinematics suspected a
    sensor error that would imitate them (``details['suspicion']``,
    :func:`term_rules.withhold_ambiguous`), when the validation maneuver's kinematics rule
    that error out: the same instrument flew both maneuvers, so an error it has shows in
    both, while a suspicion at |t| 2.5-6 arises on null recordings too (noise, a vane's
    wander). Lifted when the validation's estimate of the parameter lies at least
    :data:`UNREPLICATED_Z` combined standard errors from the identification's and is not
    itself a suspicion of the same sign (|t| >= :data:`AMBIGUOUS_T`); a validation maneuver
    that cannot measure it (a large standard error) lifts nothing. Not when either record's
    kinematics are void (:func:`_kinematics_trusted`), nor when the coefficient mismatch
    itself reads the suspected vane scale (``details['shape']``,
    :func:`sensor_naming.withhold_vane_scale`), nor when another rival imitates the term too
    (``details['also_imitated_by']``: the rates' derivatives lagging the moments by JSBSim's
    Euler step; an independent script's T-6 null, 3-2-1-1 on each axis at 50 Hz, had a
    C_m,q̂ 2.5 over the model's, t 11, withheld for an a_z scale the validation then ruled
    out, and named, though the Euler lag, asked only of terms still selected, imitated it).
    Only a suspicion below the kinematic entry t (:data:`kinematics.T_IN`) is lifted: one at
    or above it is no suspicion of the size nulls make (a c172p in a 41° turn at 100 Hz with
    a_z 40 ms late: the skew at t 10, 40.6 ± 4 ms, withheld a C_Z,q̂ change of +14, which the
    validation doublets' −29 ± 21 ms lifted). The term is then judged on the validation
    maneuver as any finding. (An F-16 at 330 ft/s, lateral,
    C_n,β +0.04: entered at t 11.7 and withheld for an r-gyro scale of 0.088 ± 0.028, kinematic
    t 3.2, which the validation maneuver put at −0.055 ± 0.022.)
    Returns the candidates of ``a`` it selected."""
    if not (_kinematics_trusted(a) and _kinematics_trusted(av)):
        return []
    by_name = {c.parameter: c for c in a.candidates}
    lifted = []
    for c in a.candidates:
        suspicion = c.details.get("suspicion")
        if (c.selected or not suspicion or c.details.get("sensor_rival") != suspicion["parameter"]
                or "also_imitated_by" in c.details):
            continue
        name = suspicion["parameter"]
        if "shape" in getattr(by_name.get(name), "details", {}):
            continue
        here, there = _suspected_at(a, suspicion), suspected_estimate(av.kinematic, name)
        if (here is None or there is None or here[1] >= KIN_T_IN
                or (there[1] >= AMBIGUOUS_T and np.sign(there[0]) == np.sign(here[0]))):
            continue
        se_here, se_there = here[2], there[2]
        apart = float(np.hypot(se_here, se_there))
        if not (np.isfinite(apart) and apart > 0) or abs(here[0] - there[0]) < UNREPLICATED_Z * apart:
            continue
        c.details["suspicion_lifted"] = {"parameter": name, "identification": [here[0], se_here],
                                         "validation": [there[0], se_there]}
        c.reason = (f"entered; the kinematics suspected {name} ({here[0]:.3g} ± {se_here:.2g}, t = {here[1]:.1f}), "
                    f"which would imitate it, but the validation maneuver's put it at {there[0]:.3g} ± "
                    f"{se_there:.2g} (t = {there[1]:.1f}), {abs(here[0] - there[0]) / apart:.1f} standard errors "
                    "apart: the same instrument flew both, so the suspicion is lifted")
        c.selected = True
        lifted.append(c)
    return lifted


def _suspected_at(a: Analysis, suspicion: dict) -> tuple[float, float, float] | None:
    """The identification's estimate, |t| and standard error of a suspicion that withheld a
    term: the estimate it was made at when it was a contested suspect's rival brought in at its
    own size (``suspicion['at']``, :func:`term_rules.withhold_ambiguous`), else the kinematic
    fit's. (A T-6 in a 38° turn with a_z 40 ms late: the kinematic fit, beside the suspect it
    could not tell the skew from, read the skew −17 ± 20 ms; sized in that suspect's place,
    40 ± 5 ms, it withheld a C_Z,α̇ of +32, which the fit's estimate against the validation's
    54 ± 9 ms then lifted.)"""
    if "at" in suspicion:
        est, se = suspicion["at"]
        return est, abs(est) / se if se > 0 else 0.0, se
    return suspected_estimate(a.kinematic, suspicion["parameter"])


def _kinematics_trusted(a: Analysis) -> bool:
    """Whether a recording's kinematic consistency can judge its sensors: no turbulence
    named, no light gusts (:func:`light_gusts`), every supported estimate plausible."""
    turbulent = voids_kinematics(a.candidates)
    V0 = float(np.mean(a.prepared.smooth["V"]))
    return not turbulent and not a.gusty and kinematics_plausible(a.kinematic, V0, a.prepared)


def name_mode_on_both(a: Analysis, av: Analysis) -> Candidate | None:
    """Name the structural mode the validation maneuver's spectrum shows (p < :data:`FISHER_P`,
    not the echo of a surface's line) when the identification names no mode of its own and
    either shows it too, on the same channel within a bin of the same frequency (p <
    :data:`MODE_CONFIRM_P`, :func:`spectra.peak_at`), or could not have shown it: its record
    cannot tell at that frequency (:func:`spectra.untestable_at`), or its input carries too
    little power there to ring the mode above its noise (:func:`spectra.predicted_peak_p`,
    p ≥ :data:`MODE_CONFIRM_P`). The airframe flew both, and a maneuver whose stabilator
    hardly moves at the mode's frequency rings it too weakly to name alone: an 8 Hz mode on a
    three-axis maneuver at 15,000 ft / 550 ft/s, p = 1e-4 on the identification, 5e-53 on
    the validation (outside sweep, 4 Dec 2026); a multisine up to 2 Hz does not ring a 6 Hz
    mode at all, a 3-2-1-1 validation does at p = 1e-29 (probe 12). An identification that
    could have shown it and does not contradicts it: not named. The frequency is the
    validation's. Returns the candidate it named (replacing the identification's own), or
    None."""
    peak = av.peak
    if peak is None or peak.p_value >= FISHER_P:
        return None
    if any(c.selected and c.effect == "structural_mode" for c in a.candidates):
        return None
    p_id = peak_at(a.prepared, peak.channel, peak.frequency_hz)
    where = f"the validation's peak at {peak.frequency_hz:.2f} Hz in {peak.channel} (p = {peak.p_value:.2g})"
    why = ""
    if p_id < MODE_CONFIRM_P:
        reason = f"named on the two maneuvers: {where} and the identification's excess there (p = {p_id:.2g})"
    else:
        why = untestable_at(a.prepared, peak.channel, peak.frequency_hz)
        if not why:
            predicted = predicted_peak_p(a.prepared, av.prepared, peak.channel, peak.frequency_hz)
            if not predicted >= MODE_CONFIRM_P:  # it could have shown it (or no surface says it could not)
                return None
            why = (f"its input carries too little power at {peak.frequency_hz:.2f} Hz to ring the mode above its "
                   f"noise (expected p = {predicted:.2g})")
        reason = f"named on the validation maneuver alone: {where}; the identification cannot show it: {why}"
    c = mode_candidate(peak, True, reason)
    c.details["replicated"] = {"validation_p": peak.p_value, "identification_p": p_id, "identification_cannot": why}
    a.candidates[:] = [x for x in a.candidates if x.effect != "structural_mode"] + [c]
    return c
