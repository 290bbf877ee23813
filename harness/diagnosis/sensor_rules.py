"""Sensor verdicts from the kinematic check: which estimates are applied and named, a scale
that reads as a bias, the rivals and refutations the kinematics give, and the kinematic
estimates the other rules consult."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError, partial_correlation
from harness.diagnosis import candidates as cand
from harness.diagnosis.along import corrected_recording, model_along
from harness.diagnosis.corroborate import inverse_variance_mean
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.exact_skew import skew_rival
from harness.diagnosis.gust_rules import NOT_IN_TURBULENCE
from harness.diagnosis.kinematics import KinematicResult, channel_share, is_plausible, is_practical, kinematic_check
from harness.diagnosis.kinematics import T_IN as KIN_T_IN
from harness.diagnosis.prepare import Prepared, clean_channels, interior_slice
from harness.diagnosis.stepwise_axes import practical_size
from models.aircraft import Aircraft
from models.replay import InitialCondition


def kinematics_plausible(kin: KinematicResult, V0: float, p: Prepared | None = None) -> bool:
    """Whether every kinematic estimate the data support (|t| >= :data:`APPLY_T`) is one an
    instrument could have; an unsupported one (a lateral bias on a pitch maneuver) says
    nothing about plausibility, and neither does an error of a vane whose angle the maneuver
    did not drive (:func:`undriven_vane`, given the recording ``p``)."""
    return all(is_plausible(n, kin.selection.params[n], V0) or kinematic_t(kin, n) < APPLY_T
               or (p is not None and undriven_vane(n, p))
               for n in kin.forced + kin.selection.names)


def undriven_vane(name: str, p: Prepared) -> bool:
    """Whether kinematic parameter ``name`` is an error of the α or β vane (bias, scale, skew,
    position) on a recording whose surfaces never drove that angle (``p.driven``). The vane's
    angle enters the kinematics through u = V cos α cos β, v = V sin β, w = V sin α cos β, so
    a constant error of a still angle shows only through the airspeed's changes (V̇·b in v̇
    for β): a Wald t there measures nothing an instrument did. On pitch maneuvers that made
    a β bias of −25° (t 3.3, a T-6) and 18° (t 3.0, the F-16 at 427 ft/s) "implausible", which
    voided every sensor test of the maneuver (the α bias of probe 21 was set apart as not
    confirmed: its validation maneuver's means test never ran)."""
    vane = _vane_of(name)
    return vane is not None and vane not in p.driven


def _vane_of(name: str) -> str | None:
    return next((v for v in ("alpha", "beta") if name.endswith(f"_{v}") or name.startswith(f"vane_{v}_")), None)


def steady_vane(name: str, p: Prepared) -> str | None:
    """The vane ('alpha' or 'beta') whose error kinematic parameter ``name`` is, when the
    recording never drove that angle (:func:`undriven_vane`) and no other kinematic channel
    records it; else None. A constant error of a still angle reaches the kinematics only as
    V̇·b (in v̇ for β, v = V sin β; in ẇ for α), and whatever else in that equation follows
    the airspeed's change reads as one. Nothing records the sideslip besides (no ground
    track); a still α's error also shows in the flight path (θ − α against the altitude's
    rate), so α counts only without an ``h`` channel. Such an estimate is not named from the
    kinematics (:func:`steady_vane_reason`): a c172x pitch-only null (8,000 ft / 200 ft/s, 5°
    stabilator multisine, the independent script's seed 133) gave a β bias of 3.1° at t 5.1.
    The coefficient means along the vane (:func:`sensor_naming.name_vane_bias_from_means`)
    are another test, and stay."""
    vane = _vane_of(name)
    if not undriven_vane(name, p) or (vane == "alpha" and "h" in p.raw):
        return None
    return vane


def steady_vane_reason(vane: str) -> str:
    """Why an error of the still ``vane`` is not named (:func:`steady_vane`)."""
    angle, eq = ("β", "v̇") if vane == "beta" else ("α", "ẇ")
    return (f"the maneuver never drove {angle}" + (" and no altitude was recorded" if vane == "alpha" else "")
            + f": a constant {angle}-vane error shows in the kinematics only through the airspeed's changes "
            f"(V̇·b in {eq}), which anything else in that equation that follows the airspeed imitates")


def applied_sensor_values(kin: KinematicResult, turbulent: bool, plausible: bool,
                          V0: float | None = None) -> dict[str, float]:
    """The sensor corrections applied before the model is evaluated. None in turbulence or
    when an estimate is implausible (the kinematics then disagree for another reason, and
    the parameters were estimated together); else only those with |t| >= :data:`APPLY_T` (a
    nuisance bias "below the entry t" may be a poorly determined 0.7 deg, and applying it
    would move the model), and, given the airspeed ``V0``, never an implausible one (an
    undriven vane's, which :func:`kinematics_plausible` leaves out of its verdict: an 18° β
    bias applied to a 737 pitch maneuver took the states off the model's tables)."""
    if turbulent or not plausible:
        return {}
    return {n: kin.selection.params[n] for n in kin.forced + kin.selection.names
            if kinematic_t(kin, n) >= APPLY_T and (V0 is None or is_plausible(n, kin.selection.params[n], V0))}


def sensor_verdict(name: str, est: float, se: float, entered: bool, kin: KinematicResult, p: Prepared,
                   turbulent: bool, plausible: bool, gusty: str = "") -> tuple[bool, str]:
    """Whether a kinematic estimate is named, and why (or why not): it must have entered,
    matter (practical size and share of its channel's excursion), be precise, and the
    kinematics must hold (no turbulence, no gusts that break them, plausible estimates)."""
    practical = is_practical(name, est, p.dt) and kinematic_share(kin, name, est, p) >= cand.PRACTICAL_SHARE
    precise = se <= max(0.5 * practical_size(name, p.dt), 0.25 * abs(est))
    # the estimate itself too (an undriven vane's is left out of the kinematics' verdict)
    plausible = plausible and is_plausible(name, est, float(np.mean(p.smooth["V"])))
    steady = steady_vane(name, p)
    sel = entered and practical and precise and not turbulent and not gusty and plausible and steady is None
    reason = ("significant, practical and precise" if sel else "below the entry t" if not entered else
              "within the instrument noise budget (practical size)" if not practical else
              "poorly determined" if not precise else NOT_IN_TURBULENCE if turbulent else
              f"not applied: {gusty}" if gusty else IMPLAUSIBLE if not plausible else
              f"not named: {steady_vane_reason(steady)}")
    return sel, reason


# The channels whose trim value is far from zero, where a scale factor shows as an offset:
# the α vane (k·α at the trim α) and the airspeed (k·V).
OFFSET_SCALE_CHANNELS = ("alpha", "V")


def scale_read_as_bias(cands: list[Candidate], p: Prepared) -> None:
    """Rename a bias of α or V that is a scale factor's offset. A reading (1 + k)·x stands
    k·x̄ off at the maneuver's mean x̄, which the kinematic fit (a bias always in it) or the
    coefficient means along the vane give as a bias b, and moves k times the excursions,
    which the kinematic fit gives as the scale k, and the coefficient mismatch, for a vane, as
    the model's own slopes times k on every axis that can tell (``details['shape']``,
    :func:`sensor_naming.withhold_vane_scale`). When the excursions suggest a scale (the
    kinematic |t| >= :data:`AMBIGUOUS_T`, or the mismatch's shape) and the offset says the
    same scale — k and b/x̄_true within two standard errors of their difference — the
    finding is the scale, sized as the inverse-variance mean of the offset's and the
    excursions' readings (:func:`excursion_scale`), and the bias is read as its offset. A
    true bias leaves k near zero. The bias must be named, or, when the mismatch's shape
    reads the excursions, significant (|t| >= the kinematic entry t): read as a scale it
    need not be a practical bias. (An F-16 at 20,000 ft and 450 ft/s with a 10 % α-vane
    scale was named a 0.63° α bias, b/x̄ = 0.100 ± 0.008 against k = 0.086 ± 0.022; at
    427.4 ft/s the means named a 0.47° bias ahead of the scale the kinematics had named. At
    25,000 ft and 700 ft/s an 8 % scale left a 0.25° bias, t 17, under the bias's practical
    size, the kinematic k at 0.066 ± 0.032 and the shape at 0.166 ± 0.044; nothing was
    named.) A scale the kinematics had not named is judged on the validation maneuver as a
    finding named on two tests (``details['corroboration']``: its kinematic k, same sign,
    |t| >= 2, within two standard errors). Every bias of α or V carries its reading as a
    scale, b/x̄_true (``details['as_scale']``), for that validation test
    (``validation._offset_scale_check``)."""
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
        if bias.selected and _scale_untold(scale, k_off, se_off):
            _withhold_bias_a_scale_would_make(bias, scale, k_off, se_off, float(np.mean(p.smooth["V"])), p.dt)
            continue
        if scale is None:
            continue
        shape = scale.details.get("shape")
        offset_read = bias.selected or (shape is not None and abs(bias.t) >= KIN_T_IN)
        if not offset_read or (abs(scale.t) < AMBIGUOUS_T and shape is None):
            continue
        V_mean = float(np.mean(p.smooth["V"]))
        k_exc, se_exc = excursion_scale(scale)
        if np.sign(k_off) != np.sign(k_exc) or abs(k_off - k_exc) > 2.0 * np.hypot(se_off, se_exc):
            if bias.selected:
                _withhold_bias_beside_a_scale(bias, scale, k_off, se_off, k_exc, se_exc, V_mean)
            continue
        k, se = inverse_variance_mean([k_off, k_exc], [se_off, se_exc])
        if not (is_plausible(scale.parameter, k, V_mean) and is_practical(scale.parameter, k, p.dt)):
            continue
        kin_k, kin_se, named = scale.estimate, scale.std_error, scale.selected
        scale.estimate, scale.std_error, scale.t, scale.selected = k, se, k / se, True
        words = f"k = {k_exc:.3f} ± {se_exc:.3f}" + (
            f": the kinematics {kin_k:.3f} ± {kin_se:.3f}, the mismatch's shape {shape['k']:.3f} ± "
            f"{shape['k_std']:.3f}" if shape is not None else "")
        scale.reason = (f"the offset at the mean {channel} (a bias of {bias.estimate:.4g}: k = {k_off:.3f} ± "
                        f"{se_off:.3f}) and the excursions ({words}) agree on a scale factor")
        scale.details["offset"] = {"bias": bias.estimate, "bias_std": bias.std_error, "mean_true": x_true,
                                   "k": k_off, "k_std": se_off, "excursion_k": k_exc, "excursion_k_std": se_exc}
        if not named:  # the kinematics alone had not named it: judged as named on two tests
            scale.details["corroboration"] = {"named": True, "kinematic": kin_k, "kinematic_std": kin_se}
        bias.selected = False
        bias.details["read_as"] = scale.parameter
        bias.reason = f"read as the offset of {scale.parameter} = {k:.3f} at the mean {channel} (k·x̄)"


def withhold_scale_a_bias_would_make(cands: list[Candidate], kin: KinematicResult, p: Prepared) -> None:
    """Withhold a scale of α or V the kinematics named alone because its bias had been left out
    of their fit as implausible (:func:`plausible_kinematic_check`: the two, nearly collinear
    where the channel hardly moves about its mean, had run to offsetting sizes), when that
    bias, read off the scale's offset k·x̄_true, is a plausible and practical one: the
    excursions could not tell them apart, and the offset is all either reading rests on.
    (An independent script's c172x at 4,000 ft and 160 ft/s with a 10 ft/s airspeed bias,
    a pitch multisine flown through its controls: a V scale of 0.050 ± 0.008 was named, the
    bias it reads as 8 ft/s.)"""
    V_mean = float(np.mean(p.smooth["V"]))
    for channel in OFFSET_SCALE_CHANNELS:
        scale = next((c for c in cands if c.selected and c.parameter == f"scale_{channel}"), None)
        dropped = kin.dropped.get(f"bias_{channel}", "")
        if scale is None or not dropped.startswith("implausible") or channel not in p.smooth:
            continue
        k = scale.estimate
        b = k * float(np.mean(p.smooth[channel])) / (1.0 + k)
        name = f"bias_{channel}"
        if not (is_plausible(name, b, V_mean) and is_practical(name, b, p.dt)):
            continue
        scale.selected = False
        scale.details["bias_rival"] = {"parameter": name, "offset_bias": b}
        scale.reason = (f"entered, but not named: {name} = {b:.3g} would make the same offset at the mean "
                        f"{channel}, and the kinematics could not fit the two together ({name} {dropped}): "
                        "scale or bias")


def _scale_untold(scale: Candidate | None, k_off: float, se_off: float) -> bool:
    """Whether the excursions cannot tell a bias from the scale its offset reads as: the scale
    was not offered (the channel hardly moved, :func:`kinematics.kinematic_check`) or, not
    named, its reading (:func:`excursion_scale`) lies within two standard errors of both no
    scale and the offset's ``k_off``."""
    if scale is None:
        return True
    if scale.selected or not scale.std_error > 0:
        return False
    k_exc, se_exc = excursion_scale(scale)
    return abs(k_exc) <= 2.0 * se_exc and abs(k_off - k_exc) <= 2.0 * np.hypot(se_off, se_exc)


def _withhold_bias_a_scale_would_make(bias: Candidate, scale: Candidate | None, k_off: float, se_off: float,
                                      V_mean: float, dt: float) -> None:
    """Withhold a bias of α or V that a plausible scale factor of the same instrument would make
    as well (k = b/x̄_true) when the excursions cannot tell the two (:func:`_scale_untold`):
    a reading (1 + k)·x stands k·x̄ off at the mean, and only the excursions, k times
    larger, set it apart from a bias. (An independent script's 737 at 18,000 ft and 560 ft/s
    with a 10 % α-vane scale, doublets at 25 Hz with twice its noise: α moved too little for
    a scale to be offered, and the offset was named a 0.39° α bias, k = 0.122 ± 0.014 read
    as a scale.) ``details['scale_rival']`` says what was weighed."""
    name = f"scale_{bias.channel}"
    if not (is_plausible(name, k_off, V_mean) and is_practical(name, k_off, dt)):
        return
    bias.selected = False
    exc = None if scale is None else excursion_scale(scale)
    bias.details["scale_rival"] = {"parameter": name, "offset_k": k_off, "offset_k_std": se_off,
                                   "excursion_k": None if exc is None else exc[0],
                                   "excursion_k_std": None if exc is None else exc[1]}
    told = (f"{bias.channel} moved too little for a scale to be fitted" if exc is None else
            f"its excursions read k = {exc[0]:.3f} ± {exc[1]:.3f}, within two standard errors of both")
    bias.reason = (f"entered, but not named: a scale factor of {k_off:.3f} ± {se_off:.3f} ({name}) would make the "
                   f"same offset at the mean {bias.channel}, and {told}: bias or scale")


def excursion_scale(scale: Candidate) -> tuple[float, float]:
    """A scale factor as the excursions read it: the kinematic estimate, combined (inverse
    variance) with the coefficient mismatch's shape along the vane when that was read
    (``details['shape']``, :func:`sensor_naming.withhold_vane_scale`); the two rest on
    independent data (the inertial channels' kinematics, the measured coefficients)."""
    shape = scale.details.get("shape")
    if shape is None or not scale.std_error > 0:
        return scale.estimate, scale.std_error
    return inverse_variance_mean([scale.estimate, shape["k"]], [scale.std_error, shape["k_std"]])


def _withhold_bias_beside_a_scale(bias: Candidate, scale: Candidate, k_off: float, se_off: float,
                                  k_exc: float, se_exc: float, V_mean: float) -> None:
    """Withhold a bias of α or V beside a scale of the same instrument that its excursions
    show (named, or kinematic |t| >= :data:`APPLY_T`) with the sign the offset, read as a
    scale (k = b/x̄_true, plausible), has, when the two do not agree on one scale factor
    (:func:`scale_read_as_bias`): a scale makes an offset k·x̄ as well, so the record
    cannot say whether the offset is a bias, the scale's, or both. (An F-16 at 420 ft/s with
    a 10 % α-vane scale, on a pitch multisine: its coefficient means gave an offset of
    0.50° = 0.105 ± 0.003 of the mean α, its excursions k = 0.072 ± 0.012 (t 5.9); it was
    named a 0.50° α bias. A probe's 737 at 29,600 ft and 655 ft/s with the same scale had
    the scale named on two tests, 0.075 ± 0.011, and a 0.38° bias, 0.103 ± 0.006, beside and
    ahead of it.) The reason and ``details['scale_rival']`` give the excursions'
    reading the agreement was tested on (``k_exc ± se_exc``, :func:`excursion_scale`)."""
    if (not scale.selected and abs(scale.t) < APPLY_T) or np.sign(scale.estimate) != np.sign(k_off) \
            or not is_plausible(scale.parameter, k_off, V_mean):
        return
    bias.selected = False
    bias.details["scale_rival"] = {"parameter": scale.parameter, "offset_k": k_off, "offset_k_std": se_off,
                                   "excursion_k": k_exc, "excursion_k_std": se_exc}
    shape = "" if "shape" not in scale.details else " with the mismatch's shape"
    shown = f"named, t = {scale.t:.1f}" if scale.selected else f"the kinematics t = {scale.t:.1f}"
    bias.reason = (f"entered, but not named: {scale.parameter} would make an offset too, and the excursions show one "
                   f"({shown}; k = {k_exc:.3f} ± {se_exc:.3f}{shape}) that does not agree "
                   f"with the offset read as a scale (k = {k_off:.3f} ± {se_off:.3f}): bias, scale or both")


def withhold_offset_of_a_scaled_vane(cands: list[Candidate], kin: KinematicResult, p: Prepared,
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
    corrected = corrected_recording(p, kin, {"scale_alpha": scale.estimate})
    along = model_along(corrected, aircraft, ic, inertial_from=p).mismatch()
    refit = cand.accelerometer_offset(p, {c: along[c] for c in ("CX", "CY", "CZ")}, noise)
    t = max(abs(v) for v in refit.t)
    if t >= cand.T_IN:
        return
    offset.selected = False
    offset.details["sensor_rival"] = "scale_alpha"
    offset.reason = (f"fitted, but not named: along the α corrected for the named scale_alpha = {scale.estimate:.3f} "
                     f"the force mismatch no longer asks for it (x = {refit.position_ft[0]:.2f} ± "
                     f"{refit.std_error_ft[0]:.2f} ft, largest |t| = {t:.1f})")


# The two tests that size the accelerometer's x position: the force mismatch's fit
# (:func:`stepwise_axes.offset_candidate`) and the kinematic check's (effects.md's sensor_offset).
ACCELEROMETER_X = ("x_accelerometer", "offset_x")


def name_accelerometer_once(cands: list[Candidate]) -> None:
    """One accelerometer, one position: when both tests of :data:`ACCELEROMETER_X` name it,
    the one at the larger |t| is kept and the other withheld, its size kept in the reason.
    (An independent script's J-3 Cub, pitch 3-2-1-1, the accelerometer 4 ft ahead: the force
    mismatch said 4.14 ± 0.25 ft and the kinematics, corroborated on the coefficients,
    3.34 ± 0.31; both were named, as two findings.)"""
    named = [c for c in cands if c.selected and c.parameter in ACCELEROMETER_X]
    if len(named) < 2:
        return
    keep = max(named, key=lambda c: abs(c.t))
    for c in named:
        if c is keep:
            continue
        apart = abs(c.estimate - keep.estimate) / max(float(np.hypot(c.std_error, keep.std_error)), 1e-300)
        c.selected = False
        c.details["named_as"] = keep.parameter
        c.reason = (f"not named again: the accelerometer's x position is named once, as {keep.parameter} "
                    f"({keep.estimate:.2f} ± {keep.std_error:.2f} ft, t = {keep.t:.1f}); this test puts it at "
                    f"{c.estimate:.2f} ± {c.std_error:.2f} ft ({apart:.1f} combined standard errors apart)")


def kinematic_candidates(kin: KinematicResult, p: Prepared, turbulent: bool, plausible: bool,
                         gusty: str = "") -> list[Candidate]:
    """The sensor candidates. The forced (nuisance) biases are tested one by one, not picked
    as the best of many: the aerodynamic entry t serves, with the practical-size and
    precision rules; the selected terms by the kinematic selection's own entry."""
    out = []
    for name in kin.forced:
        sp = kin.parameters[name]
        est, se = kin.selection.params[name], kin.selection.std_errors[name]
        t = est / se if se > 0 else 0.0
        entry = forced_entry_t(name, p)
        sel, reason = sensor_verdict(name, est, se, abs(t) >= entry, kin, p, turbulent, plausible, gusty)
        if reason == "below the entry t" and entry > cand.T_IN:
            reason = f"below the entry t ({entry:g}: {NO_FLIGHT_PATH})"
        out.append(Candidate(sp.effect, None, sp.channel, name, est, se, t, 0.0, sp.units,
                             "kinematic consistency (bias always fitted)", sel, reason))
    for term in kin.selection.terms:
        sp = kin.parameters[term.name]
        sel, reason = sensor_verdict(term.name, term.estimate, term.std_error, term.selected, kin, p, turbulent,
                                     plausible, gusty)
        out.append(Candidate(sp.effect, None, sp.channel, term.name, term.estimate, term.std_error, term.t, term.gain,
                             sp.units, "kinematic consistency", sel, reason))
    return out


def forced_entry_t(name: str, p: Prepared) -> float:
    """The entry t of a forced (nuisance) kinematic bias: the aerodynamic one
    (:data:`candidates.T_IN`), except the α vane's without an h channel, which takes the
    kinematic selection's (:data:`kinematics.T_IN`). The flight-path equation, ḣ against
    u sinθ − w cosφ cosθ, ties α to the attitude; without it an α bias reaches the residuals
    only through q·u and q·w, the columns of a pitch-rate skew or scale. An independent
    script's c172p (4,000 ft / 170 ft/s, 3-2-1-1 on each axis at 25 Hz, no h) read a 0.56° α
    bias at t 5.3 beside a one-sample q skew, 0.55° at t 4.5 on its null (0.24° at t 3.7
    with h)."""
    return KIN_T_IN if name == "bias_alpha" and "h" not in p.raw else cand.T_IN


NO_FLIGHT_PATH = "no h channel, so no flight-path equation ties α to the attitude"


def withhold_biases_an_airspeed_bias_makes(cands: list[Candidate], kin: KinematicResult) -> None:
    """Deselect the accelerometer biases (always fitted) that fall below the entry t once an
    airspeed bias is fitted beside them: an airspeed bias ΔV enters the kinematics through
    products with the rates (−r·ΔV in v̇, q·ΔV in ẇ), constants in a steady turn, where it is
    an a_y and an a_z bias in the turn's proportions. An independent script's c172p in a 30°
    banked turn (153 ft/s) with V 10 ft/s high named a_y and a_z biases of −0.030 g and
    +0.022 g (t −45 and 35; −r̄ΔV/g and q̄ΔV/g are −0.033 g and +0.019 g) where the airspeed
    bias stood at t 3.7. In level flight the rates are near zero and the columns apart."""
    if "bias_V" not in (kin.columns or {}):
        return
    t_beside = kinematic_t_beside(kin, "bias_V")
    if t_beside is None:
        return
    for c in cands:
        if c.selected and c.parameter in ("bias_ax", "bias_ay", "bias_az") and t_beside[c.parameter] < cand.T_IN:
            c.selected = False
            c.reason = (f"not named: beside an airspeed bias it falls to t = {t_beside[c.parameter]:.1f} (the "
                        "kinematics cannot tell them apart where the rates hold steady, as in a turn)")


def kinematic_t_beside(kin: KinematicResult, added: str | tuple[str, ...],
                       dropped: str = "") -> dict[str, float] | None:
    """Each parameter's |t| in the kinematic fit of the forced and selected terms (``dropped``
    left out) with ``added`` (one name or several) fitted beside them (colored-residual
    standard errors, no constant); None when the columns are dependent."""
    cols = kin.columns or {}
    added = (added,) if isinstance(added, str) else added
    names = [n for n in kin.forced + kin.selection.names if n in cols and n != dropped and n not in added]
    names += [n for n in added if n in cols]
    try:
        theta, se, _ = colored_fit(kin.start, [cols[n] for n in names], names, constant=False)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return None
    return {n: abs(theta[i] / se[i]) if se[i] > 0 else 0.0 for i, n in enumerate(names)}


def untestable_rival(kin: KinematicResult, name: str, V_fps: float,
                     t_min: float = cand.AMBIGUOUS_T) -> tuple[str, float] | None:
    """The scale or skew left out of the kinematic check because its channel hardly moves
    (:attr:`KinematicResult.untestable`) that takes sensor parameter ``name``'s place: beside
    it ``name`` falls under ``t_min`` and the rival stands at ``t_min`` or more, at a size an
    instrument could have (:func:`is_plausible`, at airspeed ``V_fps``). Returns the rival and
    ``name``'s |t| beside it (the rival taking most from it); None when there is none. The
    kinematic fit is that of the forced and selected terms with ``name`` and the rival added
    (colored-residual standard errors, no constant). A rival that only shares the column (an
    a_y skew beside a β scale on a lateral maneuver, a_y following β: −0.26 ± 0.40 s) is no
    explanation."""
    cols = kin.columns or {}
    if name not in cols:
        return None
    base = [n for n in kin.forced + kin.selection.names if n in cols and n != name]
    worst = None
    for rival, column in (kin.untestable or {}).items():
        if kin.parameters[rival].channel == kin.parameters[name].channel:
            continue
        try:
            theta, se, _ = colored_fit(kin.start, [cols[n] for n in base + [name]] + [column],
                                       base + [name, rival], constant=False)
        except (SingularRegressorsError, np.linalg.LinAlgError):
            continue
        t, t_rival = (abs(theta[k] / se[k]) if se[k] > 0 else 0.0 for k in (-2, -1))
        if (t < t_min <= t_rival and is_plausible(rival, float(theta[-1]), V_fps)
                and (worst is None or t < worst[1])):
            worst = (rival, float(t))
    return worst


# The |t| a kinematic estimate needs before it corrects the channels the model is evaluated on.
APPLY_T = 3.0


# A coefficient error on a regressor whose own sensor the kinematic check suspects at this
# |t| (a scale factor, skew or vane offset of that channel, even below its entry t) is not
# named: a scaled α (or β, q ...) reading is exactly a scaled derivative on α. A bias is not
# a rival: the regression's constant absorbs it (it imitates a derivative only through the
# model's nonlinearity).
AMBIGUOUS_T = cand.AMBIGUOUS_T


@dataclass(frozen=True)
class Contest:
    """A selected kinematic term's rival the kinematics cannot rule out: its name, their
    partial correlation, the term's |t| beside it, the rival's own estimate and |t| (fitted
    in the term's place, or as an exact shift) and why, where it is not the correlation."""

    rival: str
    correlation: float
    t_beside: float
    rival_estimate: tuple[float, float] | None = None
    why: str = ""


def kinematic_estimate(kin: KinematicResult, name: str) -> tuple[float, float] | None:
    """A kinematic parameter's estimate and |t|, whether it entered the fit (its final value)
    or not (its value when tried in the final model); None when it was not a candidate."""
    if name in kin.selection.params:
        return kin.selection.params[name], kinematic_t(kin, name)
    term = next((t for t in kin.selection.terms if t.name == name), None)
    return None if term is None else (term.estimate, abs(term.t))


def kinematic_std_error(kin: KinematicResult, name: str) -> float:
    """The standard error of a kinematic parameter :func:`kinematic_estimate` found."""
    if name in kin.selection.params:
        return float(kin.selection.std_errors.get(name, np.inf))
    term = next(t for t in kin.selection.terms if t.name == name)
    return float(term.std_error)


# The rate gyros are one instrument: a time skew of the unit (its clock, its filter, or a
# simulation that integrates the rotational rates apart from the rest) shows on all three.
# JSBSim integrates its rotational rates by rectangular Euler (its default): a script that
# reads the properties after each step records gyros the kinematics put 3-7 ms off the vanes,
# each of the three often below :data:`AMBIGUOUS_T` alone (an independent script's c172x null
# at 100 Hz: p −4.9 ± 1.4, q −4.2 ± 2.3, r −5.8 ± 2.5 ms; together −4.9 ± 1.1 ms, t 4.5).
GYROS = ("p", "q", "r")
GYRO_UNIT = "skew_pqr"
# Each member's estimate must lie within this many of its own standard errors of the unit's.
GYRO_AGREE_Z = 2.0


def unit_members(kin: KinematicResult, name: str) -> tuple[str, ...]:
    """The kinematic parameters suspicion ``name`` stands for: the gyros' own skews for
    :data:`GYRO_UNIT`, else ``name`` itself."""
    if name != GYRO_UNIT:
        return (name,)
    return tuple(f"skew_{g}" for g in GYROS if kinematic_estimate(kin, f"skew_{g}") is not None)


def suspected_estimate(kin: KinematicResult, name: str) -> tuple[float, float, float] | None:
    """A suspicion's estimate, |t| and standard error: a kinematic parameter's
    (:func:`kinematic_estimate`), or for :data:`GYRO_UNIT` the inverse-variance mean of the
    gyros' skews when at least two were tried and each lies within :data:`GYRO_AGREE_Z` of
    its standard errors of the mean (None otherwise)."""
    if name != GYRO_UNIT:
        found = kinematic_estimate(kin, name)
        return None if found is None else (found[0], found[1], kinematic_std_error(kin, name))
    members = unit_members(kin, name)
    if len(members) < 2:
        return None
    values = [kinematic_estimate(kin, m)[0] for m in members]
    errors = [kinematic_std_error(kin, m) for m in members]
    if not all(np.isfinite(e) and e > 0 for e in errors):
        return None
    mean, se = inverse_variance_mean(values, errors)
    if any(abs(v - mean) > GYRO_AGREE_Z * e for v, e in zip(values, errors)):
        return None
    return mean, abs(mean) / se, se


# How far (in combined standard errors) the kinematics' own estimate of a vane's scale may
# sit from the scale the coefficient mismatch asks for before they refute it. The mismatch's
# k and the kinematic one come from independent equations; on the project sweep a C_Z,α error
# asked for k = -0.069 ± 0.012 against a kinematic 0.003 ± 0.011 (4.5 apart), while a true
# 0.08 scale at 700 ft/s asked for 0.166 ± 0.024 against a kinematic 0.066 ± 0.032 (2.5).
VANE_REFUTE_Z = 3.5


def kinematics_refute(kin: KinematicResult, name: str, k: float, k_std: float) -> str:
    """Why the kinematics refute a vane scale ``k ± k_std`` the coefficient mismatch asks for:
    their own estimate of ``name`` sits more than :data:`VANE_REFUTE_Z` combined standard
    errors from it; an empty string when they do not (or cannot tell)."""
    found = kinematic_estimate(kin, name)
    if found is None or found[1] <= 0:
        return ""
    v, t = found
    se = abs(v) / t
    z = abs(k - v) / float(np.hypot(se, k_std))
    if not np.isfinite(z) or z < VANE_REFUTE_Z:
        return ""
    return (f"an {name.split('_', 1)[1]} vane scale of k = {k:.3f} ± {k_std:.3f} would imitate it, but the "
            f"kinematics put that scale at {v:.3f} ± {se:.3f} ({z:.1f} standard errors apart)")


def kinematic_rival(kin: KinematicResult, name: str, min_correlation: float | None = None
                    ) -> tuple[str, float, float, float, tuple | None] | None:
    """The unselected kinematic candidate most collinear with selected ``name`` (partial |r|,
    the forced biases and the other selected terms taken out, at least
    :data:`KINEMATIC_RIVAL_CORRELATION`, or ``min_correlation``), with the correlation, ``name``'s |t| beside it, the
    rival's |t| beside ``name`` (those terms in the fit) and the rival's own estimate and |t|
    in ``name``'s place (None when that fit fails); None when there is none. Beside ``name``
    the rival's estimate is what the two share out, not its size: an independent script's
    c172x with a_z 40 ms late had an α scale selected (t 6.8) and the a_z skew beside it at
    −3 ± 29 ms."""
    cols = kin.columns or {}
    if name not in cols:
        return None
    fixed = [n for n in kin.forced + kin.selection.names if n != name and n in cols]
    best = None
    for other, col in cols.items():
        if other in fixed or other == name or np.ptp(col) <= 0:
            continue
        r = partial_correlation(cols[name], col, [cols[n] for n in fixed])
        gate = KINEMATIC_RIVAL_CORRELATION if min_correlation is None else min_correlation
        if abs(r) >= gate and (best is None or abs(r) > abs(best[1])):
            best = (other, r)
    if best is None:
        return None
    try:
        theta, se, _ = colored_fit(kin.start, [cols[n] for n in fixed] + [cols[name], cols[best[0]]],
                                   fixed + [name, best[0]], constant=False)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return best[0], best[1], 0.0, 0.0, None
    j = len(fixed)
    t_own = float(abs(theta[j] / se[j])) if se[j] > 0 else 0.0
    t_rival = float(abs(theta[j + 1] / se[j + 1])) if se[j + 1] > 0 else 0.0
    try:
        theta, se, _ = colored_fit(kin.start, [cols[n] for n in fixed] + [cols[best[0]]], fixed + [best[0]],
                                   constant=False)
        alone = (float(theta[j]), float(abs(theta[j] / se[j]))) if se[j] > 0 else None
    except (SingularRegressorsError, np.linalg.LinAlgError):
        alone = None
    return best[0], best[1], t_own, t_rival, alone


# A kinematic candidate this correlated with a selected term (partial |r|) is asked as its rival
# (:func:`kinematic_rival`): from here its column at least doubles the term's variance
# (1 / (1 − r²) ≥ 2), and whether the term then stands is the t beside it, not r. The seed's
# pairwise limit of 0.9 (§III.G, :data:`rivals.RIVAL_CORRELATION`) is for white residuals; the
# kinematic residual is colored, and on an independent script's OV-10 (8,000 ft / 385 ft/s,
# three-axis multisine at 100 Hz) with p 40 ms late a φ skew was selected at t 8.3 beside which
# the p skew (r = 0.81) left it 1.8: named as −41 ms, the φ skew was a false finding.
KINEMATIC_RIVAL_CORRELATION = 0.7


def still_preferred(found: tuple) -> bool:
    """Beside its rival (:func:`kinematic_rival`'s ``found``) the data still prefer the selected
    term: it keeps |t| >= :data:`AMBIGUOUS_T` while the rival falls below it."""
    _, _, t_own, t_rival, _ = found
    return t_own >= AMBIGUOUS_T and t_rival < AMBIGUOUS_T


def rival_enters_alone(found: tuple) -> bool:
    """The rival, a time skew, fitted alone in the term's place (:func:`kinematic_rival`'s
    ``found``) would have entered (|t| >= the kinematic entry t): then the colored t of the two
    beside each other is no verdict, for the skew's first-order column lives in one equation (an
    a_z skew in ẇ's, the most coloured residual) and leaves out the τ²ẍ/2 of its exact shift
    (:mod:`exact_skew`). An independent script's T-37 (5,800 ft / 343 ft/s, pitch frequency
    sweep at 100 Hz) with a_z 40 ms late had an α scale of −0.098 named (t 10.1; beside the a_z
    skew t 5.0, the skew 0.3) while the skew alone stood at 36 ms, t 7.5; without the noise on
    V, h and θ that took the h equation's weight the skew was named (39.7 ms). Other rivals are
    left to the t beside each other: the Twin Otter's accelerometer position (t 4.0 beside a β
    vane ahead of the c.g., which alone stands at 6.9) is named by the kinematics as before."""
    alone = found[4]
    return found[0].startswith("skew_") and alone is not None and alone[1] >= KIN_T_IN


def contested_parameters(kin: KinematicResult, p: Prepared | None = None) -> dict[str, Contest]:
    """The selected kinematic terms the kinematics cannot tell from a rival
    (:func:`kinematic_rival`: |t| beside it below their entry t, unless it stays at least
    :data:`AMBIGUOUS_T` there while the rival falls below it), given the recording ``p``
    those a collinear time skew applied as the exact shift fits better
    (:func:`exact_skew.skew_rival`), and those still preferred beside a rival that would have
    entered alone (:func:`rival_enters_alone`): not applied to the channels, so that the
    coefficient mismatch can judge between the two (:func:`kinematic_rivals`)."""
    out = {}
    for n in kin.selection.names:
        found = kinematic_rival(kin, n)
        beside = found is not None and found[2] < KIN_T_IN
        if beside and not still_preferred(found):
            out[n] = Contest(*found[:3], rival_estimate=found[4])
            continue
        exact = skew_rival(kin, p, n) if p is not None else None
        if exact is not None:
            out[n] = Contest(exact.rival, exact.correlation, kinematic_t(kin, n), (exact.tau, exact.t),
                             f"the exact shift of {exact.rival} at {1000 * exact.tau:.1f} ms leaves less kinematic "
                             f"residual ({exact.rss_skew:.0f} against {exact.rss_term:.0f}) than its first-order "
                             "column lets the linearised fit see")
        elif beside and rival_enters_alone(found):
            out[n] = Contest(*found[:3], rival_estimate=found[4],
                             why=f"beside it t = {found[2]:.1f}; alone in its place {found[0]} stands at "
                                 f"t = {found[4][1]:.1f}")
    return out


def biases_of_contested(kin: KinematicResult, contested: dict[str, Contest]) -> set[str]:
    """The nuisance biases not applied beside a contested term: those that fall below
    :data:`APPLY_T` with its rival fitted in its place (an α scale factor shifts α's mean by
    k·ᾱ, which the α bias then takes). Applied while the term is not, such a bias moves the
    model along a part of an error the data may not have: the T-37 of
    :func:`rival_enters_alone`, its α scale contested, had the α bias of +0.14° that the scale
    left (t 7.5) applied, and along the α so shifted C_X's mismatch read a C_X,α change of +0.028
    (t 11.3); with the bias not applied C_X,α did not enter (t 1.8)."""
    out = set()
    for name, contest in contested.items():
        beside = kinematic_t_beside(kin, contest.rival, name) if contest.rival in (kin.columns or {}) else None
        if beside is not None:
            out |= {b for b in kin.forced if beside.get(b, np.inf) < APPLY_T}
    return out


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
               if not is_plausible(n, kin.selection.params[n], V0) and kinematic_t(kin, n) >= APPLY_T}
        bad -= set(kin.forced)  # the nuisance biases stay in every fit
        if not bad:
            return kin
        exclude |= bad
    return kin


def kinematic_share(kin: KinematicResult, name: str, value: float, p: Prepared) -> float:
    """The change a sensor parameter makes to its channel, as a share of the channel's
    excursion (:func:`kinematics.channel_share`): practical significance, as for the
    aerodynamic terms (a noise-free flight asks for a 2 ft β-vane offset at t = 69, a
    0.01 deg change in β)."""
    clean = clean_channels(p)
    return channel_share(kin.parameters[name], value, clean, p, interior_slice(p.n, p.dt))


def kinematic_t(kin: KinematicResult, name: str) -> float:
    se = kin.selection.std_errors.get(name, 0.0)
    return abs(kin.selection.params[name] / se) if se > 0 else 0.0


IMPLAUSIBLE = ("not applied: the kinematic fit asks for a sensor error larger than any instrument plausibly has "
               "(kinematics.PLAUSIBLE), so the channels disagree for another reason")
