"""Sensor errors named on two independent tests: the coefficient signatures along the vanes
(a vane scale or bias), the coefficient means, kinematic rivals and values applied before the
model was evaluated (those replicated on both maneuvers: :mod:`replication`)."""
from __future__ import annotations

import functools

import numpy as np

from harness.diagnosis import corroborate
from harness.diagnosis import candidates as cand
from harness.diagnosis.along import corrected_recording, inertial_beta, interior, model_along
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.exact_skew import scale_beside_exact_skew, term_beside_exact_skew
from harness.diagnosis.kinematics import KinematicResult, is_plausible, is_practical
from harness.diagnosis.prepare import Prepared
from harness.diagnosis.sensor_rules import (AMBIGUOUS_T, GYROS, Contest, kinematic_estimate, kinematic_share,
                                            kinematic_t, kinematic_t_beside, unit_members, untestable_rival,
                                            kinematics_refute, sensor_verdict)
from harness.diagnosis.stepwise_axes import StepwiseFits
from harness.diagnosis.term_rules import DEPENDENT_SENSOR, IMITATION_SHARE, regressor_channel, term_change
from models.aircraft import Aircraft
from models.hidden import SENSOR_EFFECTS
from models.replay import InitialCondition


def signature_ratios(cands: list[Candidate], kin: KinematicResult, p: Prepared, aircraft: Aircraft,
                     ic: InitialCondition, mismatch: dict[str, np.ndarray], step: StepwiseFits):
    """``ratios(name, value, skip)``: per axis, the multiple of the mismatch change that
    correcting the channels by sensor parameter ``name`` = ``value`` makes (the model evaluated
    again along the corrected channels, :mod:`corroborate`), fitted beside the axis's named
    terms whose parameter is not in ``skip`` (and its nuisances)."""
    inner = interior(p)

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
            changed = model_along(corrected_recording(p, kin, {name: value}), aircraft, ic, vane_beta=True).mismatch()
            return _axis_ratios(cands, step, inner, along_vane(), changed, skip, constant, p)
        changed = model_along(corrected_recording(p, kin, {name: value}), aircraft, ic, inertial_from=p).mismatch()
        return _axis_ratios(cands, step, inner, mismatch, changed, skip, constant, p)
    return ratios


def _axis_ratios(cands: list[Candidate], step: StepwiseFits, inner: slice, base: dict[str, np.ndarray],
                 changed: dict[str, np.ndarray], skip: frozenset[str] = frozenset(), constant: bool = True,
                 p: Prepared | None = None) -> dict:
    """Per axis, :func:`corroborate.axis_ratio` of ``base`` on the change ``changed - base``,
    beside the axis's named terms (those in ``skip`` left out) and its nuisance columns (with
    a constant unless not ``constant``); the axis's other candidate terms are offered as the
    signature's imitators, and ``p``'s measured coefficients give its share."""
    out = {}
    for axis, (sel, by_key) in step.selections.items():
        kept = {c.parameter for c in cands if c.selected and c.channel == axis} - skip
        others = [by_key[k].column[inner] for k in sel.names if k in by_key and by_key[k].parameter in kept]
        others += [col[inner] for col in step.nuisances.get(axis, {}).values() if np.ptp(col[inner]) > 0]
        others += pinned_shift_columns(cands, p, axis, inner)
        offered = {t.parameter: t.column[inner] for k, t in by_key.items()
                   if t.parameter not in kept and np.ptp(t.column[inner]) > 0}
        excursion = float(np.std(p.measured[axis][inner])) if p is not None and axis in p.measured else np.nan
        r = corroborate.axis_ratio(base[axis][inner], others, (changed[axis] - base[axis])[inner], constant, offered,
                                   excursion)
        if r is not None:
            out[axis] = r
    return out


def pinned_shift_columns(cands: list[Candidate], p: Prepared | None, axis: str, inner: slice) -> list[np.ndarray]:
    """The column of a moment-reference shift named from C_m's mistrim
    (:func:`stepwise_axes.pinned_shift`) on ``axis``: C_Z for C_m, C_Y for C_n (effects.md's
    cg_offset). Such a shift is no term of the axes' stepwise fits, which were made with it
    taken out of the mismatch, so a fit beside their named terms must carry it itself: on an
    independent script's c172p in a 45° banked turn with the moment reference 9 in aft (named,
    0.60 ft), C_m followed a q skew's signature 2.8 ± 0.4 times the kinematics' −11 ms, the
    shift's C_Z column left in it, and a q skew of −17 ms was named beside the shift."""
    named = any(c.selected and c.effect == "cg_offset" and "mistrim_share" in c.details for c in cands)
    column = {"Cm": "CZ", "Cn": "CY"}.get(axis)
    if not named or p is None or column not in p.measured:
        return []
    return [p.measured[column][inner]]


# The vane scale factor at which its signature is evaluated (the fit scales it).
PROBE_SCALE = 0.05


def withhold_vane_scale(cands: list[Candidate], kin: KinematicResult, step: StepwiseFits, signature,
                        inertial: bool = False) -> None:
    """Deselect coefficient errors on α or β that a scale error of that vane would imitate on
    every axis that can tell (:func:`corroborate.imitates`): the model evaluated along a
    scaled angle is off by each coefficient's own slope times the scaled excursion, so a
    vane scale looks like C_Z,α, C_m,α and C_X,α wrong in the model's own proportions, which
    no single coefficient error does. The kinematics cannot always see the scale (its
    column is nearly a bias's when the angle hardly moves about its mean). Not for β when the
    model follows the inertial sideslip (``inertial``): a vane scale cannot reach the mismatch
    then. The axes asked are those the vane reaches through the model's slopes
    (:data:`VANE_MEANS_AXES`: C_X, C_Z, C_m for α; C_Y, C_l, C_n for β), as for its bias: on a
    pitch multisine at 420 ft/s with a 10 % α scale, C_l followed the α-scale signature 22 ±
    1.2 times (its α dependence runs through β, which hardly moved) and vetoed the agreement of
    C_X, C_Z and C_m on k = 0.087. A scale no vane plausibly has (:data:`kinematics.PLAUSIBLE`)
    imitates nothing. The common k (its error scaled by the axes' scatter,
    :func:`birge_scaled`) is kept on the scale's candidate (``details['shape']``): a reading
    of the vane's excursions independent of the kinematics, which
    :func:`sensor_rules.scale_read_as_bias` sets beside the offset. It is read too where the
    term was withheld already because the kinematics suspect that scale
    (``details['sensor_rival']``, :func:`term_rules.withhold_ambiguous`)."""
    for x in ("alpha",) + (() if inertial else ("beta",)):
        name = f"scale_{x}"
        on_x = [c for c in cands if c.effect == "coefficient_error"
                and cand.REGRESSOR_SOURCE.get(c.parameter.split("_", 1)[1]) == x]
        chosen = [c for c in on_x if c.selected]
        # a term withheld already for this scale (the kinematics suspect it) is read the same way
        if not (chosen or any(c.details.get("sensor_rival") == name for c in on_x)) or name not in kin.parameters:
            continue
        same = frozenset(c.parameter for c in cands if c.parameter.endswith(f"_{x}") and c.test.startswith("stepwise"))
        ratios = {k: r for k, r in signature(name, PROBE_SCALE, same).items() if k in VANE_MEANS_AXES[x]}
        ag = corroborate.imitates(ratios, t_aero=cand.T_IN)
        if ag is None or not is_plausible(name, ag.ratio * PROBE_SCALE, 1.0):
            continue
        refuted = kinematics_refute(kin, name, ag.ratio * PROBE_SCALE, ag.std_error * PROBE_SCALE)
        if refuted:
            for c in chosen:
                c.details["vane_scale_refuted"] = refuted
            continue
        each = ", ".join(f"{a.axis} {a.ratio * PROBE_SCALE:.3f} ± {a.std_error * PROBE_SCALE:.3f}"
                         for a in ag.axes)
        scale = next((c for c in cands if c.parameter == name), None)
        if scale is not None:  # the excursions' reading, for sensor_rules.scale_read_as_bias
            scale.details["shape"] = {"k": ag.ratio * PROBE_SCALE, "k_std": birge_scaled(ag) * PROBE_SCALE,
                                      "axes": each}
        for c in chosen:
            c.selected = False
            c.details["sensor_rival"] = name
            c.reason = (f"entered, but not named: an {x} vane scale error of k = {ag.ratio * PROBE_SCALE:.3f} would "
                        f"explain the mismatch on every axis that can tell alike (k from {each}), in the model's own "
                        "proportions, which a wrong derivative on one axis does not")


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


def name_vane_bias_from_means(cands: list[Candidate], kin: KinematicResult, p: Prepared, aircraft: Aircraft,
                              ic: InitialCondition, step: StepwiseFits, channel: str, applied: float = 0.0) -> None:
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
    (:func:`corroborate.imitates`), and it is practical and precise (:func:`sensor_verdict`).
    A constant model error on one axis (an asymmetry, a propeller's torque, a thrust or mass
    error, a moment-reference shift) does not match the slopes' proportions on all of them.
    The estimate is kept in ``details['vane_means']`` whether named or not, for the
    validation maneuver's check; a bias the kinematics named is sized on both
    (:func:`_size_on_both`)."""
    name = f"bias_{channel}"
    c = next((c for c in cands if c.parameter == name), None)
    if c is None or name not in kin.parameters:
        return
    by_kinematics = c.selected
    base = model_along(p, aircraft, ic, vanes=True).mismatch()
    changed = model_along(corrected_recording(p, kin, {name: PROBE_VANE_BIAS}), aircraft, ic, vanes=True).mismatch()
    ratios = {k: r for k, r in _axis_ratios(cands, step, interior(p), base, changed, constant=False, p=p).items()
              if k in VANE_MEANS_AXES[channel]}
    ag = corroborate.imitates(ratios, t_aero=cand.T_IN)
    if ag is None:
        return
    # the channels were corrected by the kinematic estimate already applied: the means see the rest
    est, se = applied + ag.ratio * PROBE_VANE_BIAS, birge_scaled(ag) * PROBE_VANE_BIAS
    c.details["vane_means"] = {"estimate": est, "std_error": se, "applied_before": applied,
                               "axes": {a.axis: [a.ratio * PROBE_VANE_BIAS, a.std_error * PROBE_VANE_BIAS]
                                        for a in ag.axes}}
    if by_kinematics:
        _size_on_both(c, est, se, ", ".join(f"{a.axis} {np.degrees(applied + a.ratio * PROBE_VANE_BIAS):.2f}°"
                                            for a in ag.axes))
        return
    # named only when the means alone, their scatter allowed for, stand at the entry t
    if abs(est - applied) < cand.T_IN * se or not sensor_verdict(name, est, se, True, kin, p, False, True)[0]:
        return
    each = ", ".join(f"{a.axis} {np.degrees(a.ratio * PROBE_VANE_BIAS):.2f}° ± "
                     f"{np.degrees(a.std_error * PROBE_VANE_BIAS):.2f}°" for a in ag.axes)
    c.reason = (f"the model along the {'α' if channel == 'alpha' else 'β'} vane is off by its own slopes times one "
                f"constant on every axis that can tell ({each}); the kinematics alone: t = {c.t:.1f}")
    c.selected, c.estimate, c.std_error, c.t = True, est, se, est / se
    c.test = MEANS_TESTS[channel]


def _size_on_both(c: Candidate, est: float, se: float, each: str) -> None:
    """Size a vane bias the kinematics named on the coefficient means along the vane as well,
    when the two agree within :data:`corroborate.AGREE_Z` standard errors (``each``: the axes'
    readings): their inverse-variance mean (two independent tests of one constant). The
    kinematics see a β-vane bias only through cos β and the cross terms: on an independent
    script's c172x (4,000 ft / 160 ft/s, lateral multisine) a 1° β bias was named at
    1.82° ± 0.35° on them; the means read it to ±0.01°."""
    if not (se > 0 and c.std_error > 0) or abs(est - c.estimate) > corroborate.AGREE_Z * np.hypot(se, c.std_error):
        return
    kin_est, kin_se = c.estimate, c.std_error
    c.estimate, c.std_error = corroborate.inverse_variance_mean([kin_est, est], [kin_se, se])
    c.t = c.estimate / c.std_error
    c.details["sized_on_both"] = {"kinematic": kin_est, "kinematic_std": kin_se, "means": est, "means_std": se}
    c.reason += (f"; sized with the coefficient means along the vane, which agree ({each}): kinematics "
                 f"{np.degrees(kin_est):.2f}° ± {np.degrees(kin_se):.2f}°, means {np.degrees(est):.2f}° ± "
                 f"{np.degrees(se):.2f}°")


def name_corroborated(cands: list[Candidate], kin: KinematicResult, p: Prepared, signature, applied: set[str],
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
    named = []
    for name in suspects:
        sensor = next((c for c in cands if c.parameter == name), None)
        found = kinematic_estimate(kin, name)
        if sensor is None or sensor.selected or found is None or name in applied:
            continue
        v, t = found
        if t < AMBIGUOUS_T or not is_plausible(name, v, V0):
            continue
        verdict = corroborate.corroborate(name, v, abs(v) / t, signature(name, v), t_aero=cand.T_IN,
                                          tolerance=corroborate.gyro_skew_tolerance(name, p.dt))
        if verdict.named and (rival := untestable_rival(kin, name, V0)) is not None:
            _withhold_beside_untestable(sensor, kin, verdict, t, *rival)
            continue
        if _name_if_corroborated(sensor, kin, p, verdict, t):
            named.append(sensor)
    withhold_corroborated_rivals(named, kin)
    for sensor in named:
        for c in cands:
            if sensor.selected and c.details.get("sensor_rival") == sensor.parameter:
                c.reason += f"; explained by the {sensor.parameter} named"


def _withhold_beside_untestable(sensor: Candidate, kin: KinematicResult, verdict, t_kin: float, rival: str,
                                t_beside: float) -> None:
    """Leave ``sensor`` unnamed, corroborated or not: the kinematics that suspected it (at
    ``t_kin``, under their entry t) cannot tell it from ``rival``, an error the maneuver cannot
    test (its channel hardly moves, :attr:`KinematicResult.untestable`), beside which it falls
    to ``t_beside``. Nor can the coefficient mismatch: a scaled α and a scaled q both follow
    the short period's C_m. A probe's c172r (178 ft/s, pitch 2-1-1, α moving 2.2 times its
    vane's noise) with its α vane reading 5.9 % low had a q-gyro scale of +4.6 % named
    (kinematic t 4.4, C_m agreeing); beside the α scale it stands at t 0.1."""
    sensor.details["corroboration"] = verdict.as_dict()
    sensor.details["untestable_rival"] = {"parameter": rival, "t_beside": t_beside}
    channel = kin.parameters[rival].channel
    sensor.reason = (f"not named: the coefficient mismatch corroborates it, but the kinematics (t = {t_kin:.1f}) "
                     f"cannot tell it from {rival}, which this maneuver cannot test ({channel} hardly moves): "
                     f"beside it this falls to t = {t_beside:.1f}")


def withhold_scale_left_by_a_linearised_skew(cands: list[Candidate], kin: KinematicResult, recorded: Prepared) -> None:
    """Deselect a named scale factor that falls below :data:`AMBIGUOUS_T` with its channel
    shifted exactly by the time skew the kinematics take on it
    (:func:`exact_skew.scale_beside_exact_skew`, on the ``recorded`` channels): it is the
    first-order skew column's leftover, τ²ẍ/2, a scale of the channel at one frequency, which
    the coefficient mismatch, corrected by the same column, shows too."""
    for c in cands:
        if not (c.selected and c.effect == "sensor_scale"):
            continue
        t = scale_beside_exact_skew(kin, recorded, c.parameter)
        if t is None or t >= AMBIGUOUS_T:
            continue
        channel = kin.parameters[c.parameter].channel
        c.selected = False
        c.details["beside_exact_skew_t"] = t
        c.reason = (f"not named: with {channel} shifted exactly by the skew_{channel} the kinematics take it stands "
                    f"at t = {t:.1f}; what it fitted is the first-order skew column's leftover (τ²ẍ/2, a scale of "
                    f"{channel} at one frequency), which the coefficient mismatch, corrected by the same column, "
                    f"shows too (it had been: {c.reason})")


def withhold_left_by_a_linearised_skew(cands: list[Candidate], kin: KinematicResult, recorded: Prepared) -> None:
    """Deselect a named kinematic sensor term that falls below :data:`AMBIGUOUS_T` with the
    channel of a stronger named time skew (a larger kinematic t) shifted exactly
    (:func:`exact_skew.term_beside_exact_skew`, on the ``recorded`` channels): it fitted the
    first-order skew column's leftover, τ²ẍ/2, which reaches every equation the skewed channel
    is in. (A scale of the skewed channel itself: :func:`withhold_scale_left_by_a_linearised_skew`.)
    A probe's noise-free F-4N (25,000 ft / 655 ft/s, three-axis 2-1-1s at 100 Hz) with α 69 ms
    late had the skew named (66 ms, t 125) and beside it a_x and a_z skews of 66 and 71 ms
    (t 27, 19), confirmed on the validation maneuver by the same leftover; with α shifted by
    exactly 69 ms nothing is found."""
    skews = sorted((c for c in cands
                    if c.selected and c.effect == "sensor_time_skew" and c.parameter in kin.parameters),
                   key=lambda c: -abs(c.t))
    for strong in skews:
        if not strong.selected:
            continue
        for c in cands:
            if not (c.selected and c is not strong and c.test == "kinematic consistency" and abs(c.t) < abs(strong.t)):
                continue
            t = term_beside_exact_skew(kin, recorded, c.parameter, strong.parameter)
            if t is None or t >= AMBIGUOUS_T:
                continue
            c.selected = False
            c.details["beside_exact_skew_t"] = t
            c.reason = (f"not named: with {kin.parameters[strong.parameter].channel} shifted exactly by the "
                        f"{strong.parameter} named it stands at t = {t:.1f}; what it fitted is that skew's first-order "
                        f"column's leftover (τ²ẍ/2), not an error of its own (it had been: {c.reason})")


def withhold_corroborated_rivals(named: list[Candidate], kin: KinematicResult) -> None:
    """Of two or more sensor errors named on the coefficient mismatch's corroboration
    (:func:`name_corroborated`, each below the kinematic entry t and each tried alone), keep
    only those that stay at :data:`AMBIGUOUS_T` or more fitted together in the kinematic
    check (:func:`sensor_rules.kinematic_t_beside`): each was corroborated as if the other were
    not there, and where the kinematics cannot tell them apart the mismatch a pair shares is
    read twice. A probe's J3 Cub (113 ft/s, pitch multisine, noise 2) with its accelerometer
    4 ft ahead had the position (kinematic t 4.5) and an a_z skew of −67 ms (5.4) both named;
    together they stand at 1.0 and −2.1 (a_z's reading of x·q̇ follows ȧ_z on a pitch
    maneuver)."""
    if len(named) < 2:
        return
    together = kinematic_t_beside(kin, tuple(c.parameter for c in named))
    if together is None:
        return
    for c in named:
        t = together.get(c.parameter, np.inf)
        if t >= AMBIGUOUS_T:
            continue
        others = ", ".join(o.parameter for o in named if o is not c)
        c.selected = False
        c.reason = (f"not named: the coefficient mismatch corroborates it, but the kinematics cannot tell it from "
                    f"{others}, also corroborated: fitted together it stands at t = {t:.1f} (under "
                    f"{AMBIGUOUS_T:g})")


def kinematic_rivals(cands: list[Candidate], kin: KinematicResult, p: Prepared, signature,
                     contested: dict[str, Contest]) -> None:
    """A sensor error the kinematics name is kept only when they tell it from its most
    collinear rival (|t| >= their entry t beside it): on a pitch maneuver an α scale factor
    and an a_z skew both follow α̇ in the ẇ equation; nor when a collinear time skew fits
    them better applied exactly (:mod:`exact_skew`). When they cannot, the coefficient
    mismatch decides (:mod:`corroborate`: each rival's computed signature, at its own
    kinematic size, against every axis): the one it corroborates and the other not is named;
    otherwise neither is."""
    by_name = {c.parameter: c for c in cands}
    for c in [c for c in cands if c.selected and c.parameter in contested]:
        contest = contested[c.parameter]
        rival, r, t_beside = contest.rival, contest.correlation, contest.t_beside
        other = by_name.get(rival)
        solo = contest.rival_estimate or kinematic_estimate(kin, rival)
        verdicts = {}
        for name, (v, t) in ((c.parameter, (c.estimate, abs(c.t))), (rival, solo or (0.0, 0.0))):
            if v == 0.0 or t <= 0:
                verdicts[name] = None
                continue
            verdicts[name] = corroborate.corroborate(name, v, abs(v) / t, signature(name, v), t_aero=cand.T_IN,
                                                     tolerance=corroborate.gyro_skew_tolerance(name, p.dt))
        own, theirs = verdicts[c.parameter], verdicts[rival]
        c.details["kinematic_rival"] = {"parameter": rival, "correlation": r, "t_beside": t_beside,
                                        "own": own.as_dict() if own else None,
                                        "rival": theirs.as_dict() if theirs else None}
        cannot = (f"the kinematics cannot tell it from {rival} (r = {r:+.2f}, "
                  + (contest.why if contest.why else f"beside it t = {t_beside:.1f}") + ")")
        if own is not None and own.named and not (theirs is not None and theirs.named):
            c.reason += f"; {cannot}, but the coefficient mismatch shows this one, not that"
            continue
        c.selected = False
        if theirs is not None and theirs.named and not (own is not None and own.named) and other is not None:
            c.reason = f"not named: {cannot}, and the coefficient mismatch shows {rival}, not this"
            _name_if_corroborated(other, kin, p, theirs, solo[1])
            other.reason = theirs.reason + (f" (kinematic t = {solo[1]:.1f}; the kinematics alone cannot tell it "
                                            f"from {c.parameter})")
        else:
            c.reason = f"not named: {cannot}, nor can the coefficient mismatch"
        _withhold_absorbed_biases(cands, kin, c.parameter, rival)


def _withhold_absorbed_biases(cands: list[Candidate], kin: KinematicResult, dropped: str, rival: str) -> None:
    """With the kinematic fit redone on ``rival`` in place of ``dropped`` (the two it cannot tell
    apart), a named bias whose |t| falls below the entry t is part of the rival's error (an α
    scale factor shifts α's mean by k·ᾱ, which a bias otherwise takes) and is not named."""
    t_alt = kinematic_t_beside(kin, rival, dropped) if rival in (kin.columns or {}) else None
    if t_alt is None:
        return
    for c in cands:
        if c.selected and c.parameter in kin.forced and t_alt.get(c.parameter, np.inf) < cand.T_IN:
            c.selected = False
            c.reason = (f"not named: with {rival} in place of {dropped} (the kinematics cannot tell them apart) it "
                        f"falls to t = {t_alt[c.parameter]:.1f}: it may be part of {rival}")


def name_applied(cands: list[Candidate], kin: KinematicResult, recorded: Prepared, p: Prepared,
                 aircraft: Aircraft, ic: InitialCondition, mismatch: dict[str, np.ndarray],
                 removed: dict[str, np.ndarray], step: StepwiseFits, applied: dict[str, float], V0: float) -> None:
    """Name a sensor error that was applied to the channels (|t| >= :data:`APPLY_T`) but is
    below its entry t, when the coefficient mismatch corroborates it (:mod:`corroborate`):
    here the mismatch *without* the correction is fitted on the change the correction made
    (a 1.5 deg α bias that the correction took out of a C_m,α-like mismatch at t = 18)."""
    inner = interior(p)
    for name, v in applied.items():
        sensor = next((c for c in cands if c.parameter == name), None)
        if sensor is None or sensor.selected or sensor.reason != "below the entry t":
            continue
        without = corrected_recording(recorded, kin, {k: x for k, x in applied.items() if k != name})
        base = {c: x - removed[c] for c, x in model_along(without, aircraft, ic, inertial_from=p).mismatch().items()}
        ratios = _axis_ratios(cands, step, inner, base, mismatch, p=p)
        verdict = corroborate.corroborate(name, v, abs(v) / kinematic_t(kin, name), ratios, t_aero=cand.T_IN,
                                          tolerance=corroborate.gyro_skew_tolerance(name, p.dt))
        _name_if_corroborated(sensor, kin, p, verdict, kinematic_t(kin, name))


def _name_if_corroborated(sensor: Candidate, kin: KinematicResult, p: Prepared, verdict, t_kin: float) -> bool:
    """Select ``sensor`` at the verdict's combined size when the verdict names it and the size
    is practical; the verdict is kept in ``details['corroboration']`` either way."""
    sensor.details["corroboration"] = verdict.as_dict()
    practical = (is_practical(sensor.parameter, verdict.estimate, p.dt)
                 and kinematic_share(kin, sensor.parameter, verdict.estimate, p) >= cand.PRACTICAL_SHARE)
    if not (verdict.named and practical):
        return False
    sensor.selected = True
    sensor.estimate, sensor.std_error = verdict.estimate, verdict.std_error
    sensor.t = verdict.estimate / verdict.std_error
    sensor.reason = verdict.reason + f" (kinematic t = {t_kin:.1f}, below their entry t alone)"
    return True


def withhold_imitated_by_named(cands: list[Candidate], imitated, applied: set[str]) -> None:
    """Deselect the aerodynamic terms a sensor error named on two tests (and not applied to
    the channels, ``applied``) imitates: half the term's change or more
    (:data:`term_rules.IMITATION_SHARE`) within :data:`term_rules.IMITATION_Z` standard errors of
    the error's named size (``imitated``, :func:`term_rules.imitation`, computed with the
    channels corrected). The error reaches the terms of the axes measured with its channel
    (:data:`term_rules.DEPENDENT_SENSOR`) and those whose regressor it is; it is preferred
    over the coefficient changes it imitates. (A c172x recording at 5,000 ft / 190 ft/s whose
    a_z lagged 50 ms through a first-order filter named the a_z skew, 42 ± 7 ms, on the
    kinematics and C_Z together, and beside it a C_Z,α̇ of +28 that the skew imitates.) An
    error of the α vane reaches every axis: the model is evaluated along the vane
    (:func:`along.model_states`), and its lateral derivatives vary with α. (A probe's F-15
    with its vane 1° high, 15,000 ft, doublets on each axis at 40 Hz, had the bias named on
    C_X, C_Z and C_m and beside it a C_l,β change of +0.0105 (t 14) and a C_n,p̂ of −0.060
    (t −20), the model's C_l,β and C_n,p̂ at the vane's α.) A rate gyro's error reaches the
    force axes too where the accelerometer is off the c.g.: the rates and their derivatives
    carry its readings there (:func:`prepare.recarried_accelerations`). (A probe's c172x,
    6,000 ft / 167 ft/s, lateral 3-2-1-1s, accelerometer 2.5 ft below the c.g., with p 68 ms
    late had the skew named and beside it a C_Y,δa change of +0.070, the late ṗ·z in a_y;
    probe seed 4544.)"""
    named = [c for c in cands if c.selected and c.effect in SENSOR_EFFECTS and c.parameter not in applied]
    for sensor in named:
        channel = sensor.channel
        for c in cands:
            reached = (channel == "alpha" or channel in (DEPENDENT_SENSOR.get(c.channel or ""), regressor_channel(c))
                       or (channel in GYROS and c.channel in cand.FORCE_AXES))
            if not (c.selected and reached and c.test.startswith("stepwise")):
                continue
            change = abs(term_change(c))
            size = imitated(c, sensor.parameter, (sensor.estimate, sensor.std_error))
            if size is None or size < IMITATION_SHARE * change:
                continue
            c.selected = False
            c.details["sensor_rival"] = sensor.parameter
            c.reason = (f"entered, but not named: the {sensor.parameter} named ({sensor.estimate:.3g} ± "
                        f"{sensor.std_error:.2g} {sensor.units}) imitates {size:.2g} of this change of {change:.3g}")


def withhold_delays_imitated_by_named(cands: list[Candidate], kin: KinematicResult, p: Prepared, aircraft: Aircraft,
                                      ic: InitialCondition, derivatives: dict[str, float], noise: dict[str, float],
                                      applied: set[str]) -> None:
    """Deselect a control delay that a sensor error named (and not applied to the channels,
    ``applied``) imitates: the delay scan (:func:`candidates.delay_scan`, ``derivatives`` the
    model's control derivatives) made again on the mismatch of the channels corrected by the
    error's named size finds a delay shorter by :data:`term_rules.IMITATION_SHARE` of it or
    more. A rate gyro's lag moves the measured moment (built from its derivative) late
    against the surfaces, as a surface delay does: an independent script's OV-10 (8,000 ft /
    385 ft/s, three-axis multisine at 100 Hz) with p 40 ms late named the p skew (40 ms) and
    an aileron delay of 44 ms (t 92) beside it. The time skew the kinematics show is
    preferred over the coefficient change it imitates."""
    named = [c for c in cands if c.selected and c.effect in SENSOR_EFFECTS and c.parameter not in applied]
    delays = [c for c in cands if c.selected and c.effect == "control_delay"]
    for sensor in named:
        if not delays:
            return
        members = [m for m in unit_members(kin, sensor.parameter) if m in kin.parameters]
        if not members:  # an error the channels cannot be corrected for (the force mismatch's accelerometer)
            continue
        corrected = corrected_recording(p, kin, {m: sensor.estimate for m in members})
        mismatch = model_along(corrected, aircraft, ic, inertial_from=p).mismatch()
        for c in list(delays):
            scan = cand.delay_scan(corrected, c.channel, mismatch, derivatives, noise)
            after = scan.tau_s if scan is not None else 0.0
            if c.estimate - after < IMITATION_SHARE * c.estimate:
                continue
            delays.remove(c)
            c.selected = False
            c.details["sensor_rival"] = sensor.parameter
            c.reason = (f"entered, but not named: the {sensor.parameter} named ({sensor.estimate:.3g} ± "
                        f"{sensor.std_error:.2g} {sensor.units}) imitates it: with the channels corrected for it the "
                        f"delay scan finds {1e3 * after:.0f} ms, not {1e3 * c.estimate:.0f} ms")
