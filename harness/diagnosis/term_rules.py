"""The rules that keep an aerodynamic term from being named when something else would
imitate it: a moment-reference shift, a change of lift, a slow lateral drift, a power of the
wandering α vane, a rival term, a sensor error or a gyro skew."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import butter, filtfilt

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from harness.diagnosis import rivals
from harness.diagnosis import candidates as cand
from harness.diagnosis.along import (corrected_recording, inertial_beta, interior, model_along,
                                     rate_derivatives_advanced, undriven_inertial)
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.gust_rules import turbulence_test
from harness.diagnosis.kinematics import T_IN as KIN_T_IN
from harness.diagnosis.kinematics import KinematicResult, inertial_alpha_change, is_plausible
from harness.diagnosis.prepare import Prepared
from harness.diagnosis.sensor_rules import (AMBIGUOUS_T, GYRO_UNIT, GYROS, kinematic_estimate, kinematic_std_error,
                                            kinematic_t, suspected_estimate, unit_members)
from harness.diagnosis.stepwise_axes import (CG_MEAN_Z, StepwiseFits, constant_beside_terms, shift_mistrim_test,
                                            thrust_mistrim_bound, vane_error_column)
from models.aircraft import Aircraft
from models.constants import SURFACES
from models.replay import InitialCondition
from models.trim import TrimPoint


def _refit_term(z: np.ndarray, others: list[np.ndarray], column: np.ndarray) -> tuple[float, float] | None:
    """``column``'s coefficient and t fitted on ``z`` beside ``others`` and a constant (Eq. 5's
    colored-residual standard error); None when the columns are dependent."""
    try:
        theta, se, _ = colored_fit(z, others + [column], [f"o{i}" for i in range(len(others))] + ["term"])
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return None
    k = len(others)
    return float(theta[k]), (float(theta[k] / se[k]) if se[k] > 0 else 0.0)


def withhold_explained_by_cg(cands: list[Candidate], selections: dict, mismatch: dict[str, np.ndarray],
                             p: Prepared) -> None:
    """A moment-reference shift is one parameter acting on two axes (C_m through C_Z, C_n
    through C_Y). Once named on one, its share of the other axis's mismatch is known; a term
    selected on that other axis is kept only if it stays significant (|t| >= the entry t)
    with that share removed (a 1.5 ft shift otherwise reads as a C_n,β change too)."""
    cg = next((c for c in cands if c.selected and c.effect == "cg_offset"), None)
    if cg is None:
        return
    inner = interior(p)
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


def withhold_the_shift_remainder(cands: list[Candidate], step: StepwiseFits, mismatch: dict[str, np.ndarray],
                                 p: Prepared, measured: dict[str, np.ndarray]) -> None:
    """A moment-reference shift named at the size C_m's mistrim says
    (:func:`stepwise_axes.pinned_shift`) leaves, where that mistrim fell short of the shift
    (the model's own mistrim, the thrust's moment, share the constant), the rest of the shift
    in C_m's excursions, where a term C_Z's column imitates (C_Z follows α) takes it. A C_m
    term the refit entered beside the pinned shift is kept only if it stays significant
    (|t| >= the entry t) with the shift C_m's excursions read without it (the C_Z column
    fitted beside the other entered terms, a constant free) taken out; a same-signed larger
    shift would otherwise leave it there. (A probe's Cessna 172 at 4,800 ft and 180 ft/s,
    pitch doublets, with a 0.5 ft shift: the mistrim said 0.35 ft, the excursions 0.54 ft, and
    C_m,α −0.17 was named beside the 0.35 ft, what 0.15 ft more makes through C_Z,α; beside
    0.54 ft, t 0.7.)"""
    shift = next((c for c in cands if c.selected and c.parameter == "dx_moment_reference" and c.channel == "Cm"
                  and c.test.startswith("the mistrim")), None)
    if shift is None or step.pinned is None or "Cm" not in step.selections:
        return
    inner = interior(p)
    cz, cbar = measured["CZ"][inner], p.meta["geometry"]["cbar_ft"]
    z = mismatch["Cm"][inner] - shift.estimate / cbar * cz
    sel, by_key = step.selections["Cm"]
    chosen = [k for k in sel.names if k in by_key and k != "cg"]
    nuisance = [c[inner] for c in step.nuisances.get("Cm", {}).values() if np.ptp(c[inner]) > 0]
    for c in cands:
        key = next((k for k in chosen if by_key[k].parameter == c.parameter), None)
        if not c.selected or c.channel != "Cm" or key is None:
            continue
        others = [by_key[k].column[inner] for k in chosen if k != key] + nuisance
        more = _refit_term(z, others, cz)
        if more is None or np.sign(more[0]) != np.sign(shift.estimate):
            continue
        fit = _refit_term(z - more[0] * cz, others, by_key[key].column[inner])
        if fit is not None and abs(fit[1]) < cand.T_IN:
            dx = shift.estimate + more[0] * cbar
            c.selected = False
            c.details["shift_remainder"] = {"mistrim_dx_ft": shift.estimate, "excursion_dx_ft": dx, "t": fit[1]}
            c.reason = (f"entered beside the moment-reference shift C_m's mistrim sized ({shift.estimate:.3g} ft), "
                        f"but C_m's excursions without this term read a {dx:.3g} ft shift, and beside that t = "
                        f"{fit[1]:.1f}: the mistrim may fall short of the shift, and the record cannot tell the rest "
                        "from this term")


def lift_change_on_cx(delta_cz: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """The body-axis C_X that a change of lift carries when its C_Z share is ``delta_cz``:
    C_X = −C_D cos α + C_L sin α and C_Z = −C_D sin α − C_L cos α, so ΔC_L alone gives
    ΔC_Z = −ΔC_L cos α and ΔC_X = ΔC_L sin α = −ΔC_Z tan α."""
    return -np.asarray(delta_cz, dtype=float) * np.tan(np.asarray(alpha, dtype=float))


def withhold_explained_by_lift(cands: list[Candidate], selections: dict, mismatch: dict[str, np.ndarray],
                               p: Prepared) -> None:
    """A named C_Z term may be a change of *lift* (how an aerodynamic table usually carries
    it, and how `models.hidden` conceals a C_Z error), which also puts −ΔC_Z tan α on C_X
    (:func:`lift_change_on_cx`): at α ≈ 8.5° a C_Z,α change of −0.6 leaves a C_X mismatch
    following α·sin α that the stepwise named as a C_X α³ (52 ± 9, t 5.5) on a probe at
    6,000 ft and 380 ft/s. A C_X term is kept only if it stays significant (|t| >= the
    entry t) with that share removed, as for a moment-reference shift's second axis, and
    beside the drag due to lift that the lift change carries (:func:`induced_drag_column`, its
    factor k fitted, between 0 and :data:`MAX_INDUCED_DRAG_FACTOR`): a model whose drag reads
    its total lift squared (JSBSim's ``aero/cl-squared``) drags more with the lift added. A
    probe's F-4N (15,800 ft / 860 ft/s, pitch sweep) with a C_Z α² of −25 concealed as lift
    had it named (−23 ± 4) and beside it a C_X α² of −0.64 (t −7.9): 2·0.14·C_L·ΔC_Z, the F-4N's
    C_D,i = 0.14·C_L² at C_L ≈ 0.09 (probe seed 4128)."""
    named = [c for c in cands if c.selected and c.channel == "CZ" and c.test == "stepwise on the CZ mismatch"]
    if not named or "CZ" not in selections or "CX" not in selections:
        return
    sel_z, by_z = selections["CZ"]
    keys = [k for k in sel_z.names if k in by_z and any(by_z[k].parameter == c.parameter for c in named)]
    if not keys:
        return
    inner = interior(p)
    delta_cz = sum(sel_z.params[k] * by_z[k].column for k in keys)
    z = mismatch["CX"][inner] - lift_change_on_cx(delta_cz, p.smooth["alpha"])[inner]
    drag = induced_drag_column(delta_cz, p)[inner]
    sel, by_key = selections["CX"]
    chosen = [k for k in sel.names if k in by_key]
    names = ", ".join(x.parameter for x in named)
    for c in cands:
        key = next((k for k in chosen if by_key[k].parameter == c.parameter), None)
        if not c.selected or c.channel != "CX" or key is None:
            continue
        others = [by_key[k].column[inner] for k in chosen if k != key]
        fit = _refit_term(z, others, by_key[key].column[inner])
        if fit is None:
            continue
        t = fit[1]
        if abs(t) < cand.T_IN:
            c.selected = False
            c.reason = (f"entered, but explained by the C_Z change named ({names}) read as a change of lift, whose "
                        f"share of C_X is −ΔC_Z tan α: with it removed, t = {t:.1f}")
            continue
        polar = _beside_induced_drag(z, others, drag, by_key[key].column[inner])
        if polar is not None and abs(polar[1]) < cand.T_IN and 0.0 < polar[0] <= MAX_INDUCED_DRAG_FACTOR:
            c.selected = False
            c.details["beside_induced_drag"] = {"k": polar[0], "t": polar[1]}
            c.reason = (f"entered, but explained by the C_Z change named ({names}) read as a change of lift, which "
                        f"the drag due to lift follows (ΔC_D = 2k·C_L·ΔC_L, k = {polar[0]:.3g}): beside it, "
                        f"t = {polar[1]:.1f}")


# The largest induced-drag factor k of C_D = C_D0 + k·C_L² a wing plausibly has: 1/(π e A)
# with an aspect ratio A of 1 and an Oswald factor e of 0.5 (a slender delta; transport
# wings lie near 0.04, fighters 0.1-0.3).
MAX_INDUCED_DRAG_FACTOR = 0.64


def induced_drag_column(delta_cz: np.ndarray, p: Prepared) -> np.ndarray:
    """The body-axis C_X, per unit induced-drag factor k, that a lift change carries through
    the drag due to lift (C_D = C_D0 + k·C_L², so ΔC_D = 2k·C_L·ΔC_L): ΔC_L = −ΔC_Z/cos α
    (:func:`lift_change_on_cx`), ΔC_X = −ΔC_D cos α = 2k·C_L·ΔC_Z, C_L = −C_Z cos α + C_X sin α
    from the recording's measured coefficients."""
    a = np.asarray(p.smooth["alpha"], dtype=float)
    lift = -p.measured["CZ"] * np.cos(a) + p.measured["CX"] * np.sin(a)
    return 2.0 * lift * np.asarray(delta_cz, dtype=float)


def _beside_induced_drag(z: np.ndarray, others: list[np.ndarray], drag: np.ndarray,
                         column: np.ndarray) -> tuple[float, float] | None:
    """The induced-drag factor k (:func:`induced_drag_column`'s coefficient) and ``column``'s t
    fitted together on ``z`` beside ``others`` and a constant; None when dependent."""
    try:
        theta, se, _ = colored_fit(z, others + [drag, column], [f"o{i}" for i in range(len(others))] + ["k", "term"])
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return None
    j = len(others)
    return float(theta[j]), (float(theta[j + 1] / se[j + 1]) if se[j + 1] > 0 else 0.0)


def reference_arm_ft(trim) -> tuple[float, float]:
    """The model's aerodynamic reference point from its c.g. in body axes (x forward, z down),
    ft, from the trim's structural positions (x aft, z up, in)."""
    return (-(trim.aero_rp_in[0] - trim.cg_in[0]) / 12.0, -(trim.aero_rp_in[2] - trim.cg_in[2]) / 12.0)


def moment_of_force_change(delta: dict[str, np.ndarray], arm_ft: tuple[float, float], geometry: dict) -> dict:
    """The moment coefficients about the c.g. that force-coefficient changes ``delta``
    (``CX``, ``CY``, ``CZ``) make when they act at a reference point ``arm_ft`` = (x, z) from
    it (body axes, no y part): r × F, ΔC_l = −z ΔC_Y/b, ΔC_m = (z ΔC_X − x ΔC_Z)/c̄,
    ΔC_n = x ΔC_Y/b (:mod:`reference_point`)."""
    x, z = arm_ft
    cx, cy, cz = (delta.get(k, 0.0) for k in ("CX", "CY", "CZ"))
    b, c = geometry["b_ft"], geometry["cbar_ft"]
    return {"Cl": -z * cy / b, "Cm": (z * cx - x * cz) / c, "Cn": x * cy / b}


def withhold_explained_by_force_arm(cands: list[Candidate], selections: dict, mismatch: dict[str, np.ndarray],
                                    p: Prepared, trim) -> None:
    """A force term named on a model whose aerodynamic reference point is away from its c.g.
    moves the moments about the c.g. as well: the changed force acts at the reference point
    (:func:`moment_of_force_change`; a C_Z term read as lift carries its C_X share too,
    :func:`lift_change_on_cx`). A moment term is kept beside it only if, with that moment
    removed, it stays significant (|t| >= the entry t) and keeps more than half its change
    (:data:`IMITATION_SHARE`; the arm is the model's, and a tiny standard error leaves the
    few per cent a c.g. or arm error puts beside it significant). An independent
    script's 737 (its reference point as its XML has it, 4.9 ft above and 1.2 ft aft of its
    loaded c.g.) with C_Y,β −0.25 per rad named C_Y,β −0.254 and, first, C_l,β −0.014: the
    side force's roll about the c.g., −0.052 ΔC_Y. A force term left unnamed only because
    the force mismatch cannot tell it from the accelerometer's position (``sensor_rival``)
    counts too: a position error moves no moment, so a moment mismatch its arm explains is
    that force's, not a second change (a probe's T-37, its reference point 0.73 ft above the
    c.g., with C_Y,β −0.25 at noise 1 had C_Y,β withheld beside a position of −3.7 ft and
    named C_l,β −0.006 in its place: −0.0216 ΔC_Y,β)."""
    named = {axis: [c for c in cands
                    if (c.selected or c.details.get("sensor_rival") == "x_accelerometer") and c.channel == axis
                    and c.test == f"stepwise on the {axis} mismatch"]
             for axis in ("CX", "CY", "CZ")}
    arm = reference_arm_ft(trim)
    if not any(named.values()) or not any(arm):
        return
    delta = {}
    for axis, terms in named.items():
        if not terms or axis not in selections:
            continue
        sel, by_key = selections[axis]
        keys = [k for k in sel.names if k in by_key and any(by_key[k].parameter == c.parameter for c in terms)]
        if keys:
            delta[axis] = sum(sel.params[k] * by_key[k].column for k in keys)
    if "CZ" in delta:
        delta["CX"] = delta.get("CX", 0.0) + lift_change_on_cx(delta["CZ"], p.smooth["alpha"])
    moments = moment_of_force_change(delta, arm, p.meta["geometry"])
    inner = interior(p)
    forces = ", ".join(c.parameter + ("" if c.selected else " (entered; unnamed beside the accelerometer's position)")
                       for terms in named.values() for c in terms)
    for axis, moment in moments.items():
        if axis not in selections or not np.ndim(moment) or not np.any(moment):
            continue
        z = mismatch[axis][inner] - moment[inner]
        sel, by_key = selections[axis]
        chosen = [k for k in sel.names if k in by_key]
        for c in cands:
            key = next((k for k in chosen if by_key[k].parameter == c.parameter), None)
            if not c.selected or c.channel != axis or key is None:
                continue
            fit = _refit_term(z, [by_key[k].column[inner] for k in chosen if k != key], by_key[key].column[inner])
            change = sel.params[key]
            if fit is None or (abs(fit[1]) >= cand.T_IN and abs(fit[0]) > (1.0 - IMITATION_SHARE) * abs(change)):
                continue
            c.selected = False
            c.reason = (f"entered, but explained by the force change ({forces}) acting at the model's "
                        f"aerodynamic reference point, {arm[0]:+.2f} ft forward and {arm[1]:+.2f} ft down of the "
                        f"c.g.: with its moment removed, {fit[0]:+.3g} (t = {fit[1]:.1f}) of {change:+.3g} is left")


def withhold_force_drift_off_the_vane_wander(cands: list[Candidate], step: StepwiseFits, p: Prepared,
                                             mismatch: dict[str, np.ndarray], slope_of, gust, V0: float) -> None:
    """A drift term on a force axis (C_X or C_Z ∝ ΔV/V) must hold beside the α vane's own
    error passed through the model's slope, −∂C/∂α·e (e the vane's angle less the inertial
    one, :func:`stepwise_axes.vane_error_column` for that axis).

    The model is evaluated along the vane, so the vane's wander is in the force mismatch
    times the model's C_Z,α (errors in variables). A Gauss-Markov wander is slow, and over a
    30 s record it may follow the airspeed's slow change by chance: an independent script's
    c172x null drew a C_Z ΔV/V of −0.23 (t 7). The column is not kept in C_Z's fit (it drew
    false findings there, :func:`stepwise_axes.vane_noise_columns`); it is asked here only of
    a drift term, slow as the wander is. C_X's fit holds it already (a term there entered
    beside it)."""
    if gust is None or gust.w_fps is None:
        return
    inner = interior(p)
    for c in cands:
        if not (c.selected and c.effect == "flight_condition_drift" and c.channel in ("CX", "CZ")
                and c.channel in step.selections and "vane_alpha_noise" not in step.nuisances.get(c.channel, {})):
            continue
        sel, by_key = step.selections[c.channel]
        key = next((k for k in sel.names if k in by_key and by_key[k].parameter == c.parameter), None)
        if key is None:
            continue
        wander = vane_error_column(slope_of, gust, V0, c.channel)
        others = [by_key[k].column[inner] for k in sel.names if k in by_key and k != key]
        others += [v[inner] for v in step.nuisances.get(c.channel, {}).values() if np.ptp(v[inner]) > 0]
        fit = _refit_term(mismatch[c.channel][inner], others + [wander[inner]], by_key[key].column[inner])
        if fit is not None and abs(fit[1]) < cand.T_IN:
            c.selected = False
            c.reason = (f"entered, but the α vane's wander passed through the model's ∂{c.channel}/∂α would "
                        f"imitate it (beside that column, t = {fit[1]:.1f})")


# Below this frequency the α vane's error column is mostly the inertial integration's own
# drift: the accelerometers' white noise, integrated, is a random walk whose spectrum rises as
# 1/f² down to the gust estimate's high-pass (:data:`spectra.GUST_HIGHPASS_HZ`, 0.05 Hz),
# while a vane's Gauss-Markov wander (τ about 1 s) is flat there.
VANE_COLUMN_CHECK_HZ = 0.1


def terms_beside_the_vane_column(cands: list[Candidate], step: StepwiseFits):
    """The selected terms of the axes fitted with the α vane's error column
    (``vane_alpha_noise``, :func:`stepwise_axes.vane_noise_columns`): for each, the candidate,
    its axis's selection and terms by key, the term's key and the axis's nuisance columns."""
    for c in cands:
        nuisances = step.nuisances.get(c.channel or "", {})
        if not (c.selected and "vane_alpha_noise" in nuisances and c.channel in step.selections):
            continue
        sel, by_key = step.selections[c.channel]
        key = next((k for k in sel.names if k in by_key and by_key[k].parameter == c.parameter), None)
        if key is not None:
            yield c, sel, by_key, key, nuisances


def withhold_off_the_integration_drift(cands: list[Candidate], step: StepwiseFits, p: Prepared,
                                       mismatch: dict[str, np.ndarray]) -> None:
    """A term entered beside the α vane's error column (``vane_alpha_noise``,
    :func:`stepwise_axes.vane_noise_columns`) must hold (|t| >= the entry t) with that column
    high-passed at :data:`VANE_COLUMN_CHECK_HZ`.

    The column is the vane's angle less the one the gyros and accelerometers integrate to.
    Its slowest part is that integration's drift, which the mismatch does not carry; fitted
    (at about one), the column puts the drift into the fit, and over a 25 s record a drift
    follows a slow shape by chance. An independent script's c172x null (seed 4, 100 Hz) drew
    a C_m α² of 3.3 (t 5.4): without the column t 0.1, with it high-passed at 0.1 Hz t 1.8;
    that record's inertial angle alone, noise-free vane, fitted α² at R² 0.4."""
    inner = interior(p)
    b, a = butter(2, VANE_COLUMN_CHECK_HZ, btype="highpass", fs=1.0 / p.dt)
    for c, sel, by_key, key, nuisances in terms_beside_the_vane_column(cands, step):
        others = [by_key[k].column[inner] for k in sel.names if k in by_key and k != key]
        others += [v[inner] for n, v in nuisances.items() if n != "vane_alpha_noise" and np.ptp(v[inner]) > 0]
        quick = filtfilt(b, a, nuisances["vane_alpha_noise"])
        fit = _refit_term(mismatch[c.channel][inner], others + [quick[inner]], by_key[key].column[inner])
        if fit is not None and abs(fit[1]) < cand.T_IN:
            c.selected = False
            c.reason = (f"entered, but only beside the α vane's error column's slowest part, the inertial "
                        f"integration's own drift (with the column high-passed at {VANE_COLUMN_CHECK_HZ:g} Hz, "
                        f"t = {fit[1]:.1f})")


def withhold_lateral_drift_off_the_vane(cands: list[Candidate], step: StepwiseFits, p: Prepared, aircraft: Aircraft,
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
    inner = interior(p)
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


def _beside_the_inertial_alpha(chosen: list[Candidate], step: StepwiseFits, p: Prepared):
    """For each named term of ``chosen``: ``(term, key, others, da)``, ``others`` the interior
    columns of its axis's other entered terms but the linear α and its nuisances, ``da`` the
    interior inertial α (:func:`kinematics.inertial_angles`, from each channel's own
    smoothing) less the vane's α at the start. Empty without the channels it is integrated
    from."""
    full = inertial_alpha_change(p) if chosen else None
    if full is None:
        return []
    inner = interior(p)
    da = full[inner]
    out = []
    for c in chosen:
        sel, by_key = step.selections[c.channel]
        key = next((k for k in sel.names if k in by_key and by_key[k].parameter == c.parameter), None)
        if key is None:
            continue
        others = [by_key[k].column[inner] for k in sel.names if k in by_key and k not in (key, "alpha")]
        others += [v[inner] for v in step.nuisances.get(c.channel, {}).values() if np.ptp(v[inner]) > 0]
        out.append((c, key, others, da))
    return out


def withhold_alpha_power_off_the_inertial_alpha(cands: list[Candidate], step: StepwiseFits, p: Prepared,
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
    inner = interior(p)
    for c, key, others, da in _beside_the_inertial_alpha(chosen, step, p):
        power = 2 if key == "alpha2" else 3
        fit = _refit_term(mismatch[c.channel][inner], others + [da], da ** power)
        if fit is not None and abs(fit[1]) < cand.T_IN:
            c.selected = False
            c.reason = (f"entered, but beside the linear α term, both built on the inertial α (free of the vane's "
                        f"wander, which favours a power of α), t = {fit[1]:.1f}")


def withhold_alpha_slope_off_the_inertial_alpha(cands: list[Candidate], step: StepwiseFits, p: Prepared,
                                                mismatch: dict[str, np.ndarray]) -> None:
    """A named change of a longitudinal α derivative must stay significant when its column is
    built on the inertial α (:func:`kinematics.inertial_angles`) rather than the vane's.

    The model evaluated along the vane passes the vane's error e through its slope, so the
    mismatch carries −C_α·e, and the vane's α, which carries e too, fits it: errors in
    variables, a change of −C_α·var(e)/var(α) where the vane's noise is a fair share of the
    α excursions (C_m has the vane-noise column for it, :func:`stepwise_axes.vane_noise_columns`;
    C_X and C_Z do not). The inertial α does not carry e. (A probe's MD-11 null at 22,000 ft
    and 712 ft/s, a pitch sweep at 50 Hz with twice the usual noise, was named C_Z,α −0.27 at
    t 16; at the usual noise, or without noise, nothing.) Asked after the vane-scale test
    (:func:`sensor_naming.withhold_vane_scale`), since a vane's scale or bias is an error the
    inertial α does not carry either, and not in turbulence, where the vane's α is the air's
    and the inertial α lacks the gusts (in light gusts it lacks their share too: a true change
    may then be withheld, the safe side)."""
    chosen = [c for c in cands if c.selected and c.effect == "coefficient_error" and c.channel in step.selections
              and c.parameter == f"{c.channel}_alpha"]
    inner = interior(p)
    for c, _, others, da in _beside_the_inertial_alpha(chosen, step, p):
        fit = _refit_term(mismatch[c.channel][inner], others, da)
        if fit is not None and abs(fit[1]) < cand.T_IN:
            c.selected = False
            c.reason = (f"entered, but built on the inertial α (free of the vane's noise, which the model along the "
                        f"vane passes into the mismatch through its slope), t = {fit[1]:.1f}")


def withhold_even_term_off_the_quiet_flight(cands: list[Candidate], step: StepwiseFits, p: Prepared,
                                            mismatch: dict[str, np.ndarray]) -> None:
    """A named term even in its state (α², |β|: :data:`EVEN_TERMS`) must stay significant
    refitted on the maneuver's own window (:func:`maneuver_window`) when the record runs on
    well past the inputs.

    Such a column has a mean wherever the maneuver moves its state and almost none in the
    quiet flight after it, so over a record much longer than its maneuver it fits any
    difference between the mismatch's level during the maneuver and after it, a slow drift
    that the colored standard error (Eq. 40, estimated over the whole record as if the
    residuals were stationary) does not cover. Inside the window only the term's shape
    within the maneuver carries it, beside the axis's other entered terms and nuisances.
    Probe 70: a c172x null, a 20 s pitch multisine in a 90 s record, was named C_X α² −2.8
    (t −5.6; another seed −4.2, t −6.1): white gyro noise alone on its noise-free flight
    gave −2.4 at t −6.9."""
    window = maneuver_window(p)
    if window is None:
        return
    for c in cands:
        if not (c.selected and c.channel in step.selections):
            continue
        sel, by_key = step.selections[c.channel]
        key = next((k for k in sel.names if k in by_key and by_key[k].parameter == c.parameter), None)
        if key not in EVEN_TERMS:
            continue
        others = [by_key[k].column[window] for k in sel.names if k in by_key and k != key]
        others += [v[window] for v in step.nuisances.get(c.channel, {}).values() if np.ptp(v[window]) > 0]
        fit = _refit_term(mismatch[c.channel][window], others, by_key[key].column[window])
        if fit is None or abs(fit[1]) < cand.T_IN:
            c.selected = False
            c.reason = ("entered, but only beside the quiet flight after the maneuver: refitted on the maneuver's "
                        f"{(window.stop - window.start) * p.dt:.0f} s of a {p.n * p.dt:.0f} s record, "
                        + (f"t = {fit[1]:.1f}" if fit is not None else "its column is dependent there"))


EVEN_TERMS = ("alpha2", "beta_abs")


def maneuver_window(p: Prepared) -> slice | None:
    """The samples from :data:`WINDOW_BEFORE_S` before the first to :data:`WINDOW_AFTER_S`
    after the last sample at which a surface the maneuver drove stands more than a tenth of
    its largest excursion from its start; None when that window covers at least
    :data:`WINDOW_SHARE` of the record (the maneuver fills it) or no surface was driven."""
    moved = np.zeros(p.n, dtype=bool)
    for s in SURFACES:
        if s in p.driven and s in p.smooth:
            excursion = np.abs(p.smooth[s] - p.start[s])
            moved |= excursion > 0.1 * float(np.max(excursion))
    if not moved.any():
        return None
    first, last = np.nonzero(moved)[0][[0, -1]]
    lo = max(0, int(first - WINDOW_BEFORE_S / p.dt))
    hi = min(p.n, int(last + WINDOW_AFTER_S / p.dt) + 1)
    return None if hi - lo >= WINDOW_SHARE * p.n else slice(lo, hi)


# The maneuver's window (maneuver_window): a second before its inputs, eight seconds after
# them (an airliner's short period and the first of its Dutch roll die out in that); a window
# of 70 % of the record or more is the record.
WINDOW_BEFORE_S, WINDOW_AFTER_S, WINDOW_SHARE = 1.0, 8.0, 0.7


def kinematic_bias_of(kin: KinematicResult, channel: str, applied: set[str]) -> tuple[float, float]:
    """The kinematic estimate of a vane bias and its standard error (0 ± s.e. once the
    channels were corrected for it); an infinite s.e. when the check had no such bias."""
    name = f"bias_{channel}"
    if name not in kin.selection.params:
        return 0.0, np.inf
    se = kin.selection.std_errors.get(name, np.inf)
    return (0.0 if name in applied else kin.selection.params[name]), (se if se > 0 else np.inf)


def withhold_shift_a_vane_bias_makes(cands: list[Candidate], step: StepwiseFits, p: Prepared, kin: KinematicResult,
                                     applied: set[str], slope_of, mismatch: dict[str, np.ndarray],
                                     measured: dict[str, np.ndarray], trim: TrimPoint, V0: float) -> None:
    """Deselect a moment-reference shift whose C_m mistrim, less what the thrust's own moment
    can make (:func:`stepwise_axes.thrust_mistrim_bound`), an α-vane bias would make: the model
    evaluated along an α reading b high is off by −b times its C_m slope (``slope_of``), so the
    mistrim's rest R takes b = −R over the slope's mean. Withheld when that b is plausible
    (:func:`kinematics.is_plausible`), within :data:`rivals.KINEMATIC_Z` standard errors of
    the kinematic estimate of the bias (:func:`kinematic_bias_of`) and of what C_Z's constant
    says of it (the bias puts −b times C_Z's slope there, a shift nothing): the mean of C_m,
    which alone tells a shift from a C_m,α change, then says nothing a bias could not. A
    probe's A-4 (7,450 ft / 516 ft/s, pitch doublets at 25 Hz, 1.8 times the noise, thrust
    recorded without its line) with C_m,α −0.13 had a 0.17 ft shift named from C_m's constant
    −0.0035: the thrust's moment makes −0.0030 (the noise-free null's constant), and the rest
    an α reading 0.07° low makes, where the kinematics put the bias at −0.06° ± 0.04° and C_Z's
    constant, −0.0028 ± 0.0011, is the −0.005 it would make within two standard errors. On a
    c172x, whose C_m slope is steep, the mistrim of a 0.31 ft shift is an α bias of −0.80°, and
    the kinematics without h allow it (+0.14° ± 0.62°), but C_Z's constant, −0.0015 ± 0.0022,
    is not the −0.063 it would make."""
    shifts = [c for c in cands if c.selected and c.parameter == "dx_moment_reference" and c.channel == "Cm"]
    if not shifts or "Cm" not in step.selections:
        return
    inner = interior(p)
    slope = float(np.mean(slope_of("alpha")["Cm"][inner]))
    cbar, cz = p.meta["geometry"]["cbar_ft"], float(np.mean(measured["CZ"][inner]))
    bound = 0.0 if "thrust" in p.raw and "thrust_offset_ft" in p.meta else thrust_mistrim_bound(p, trim)
    estimate, se = kinematic_bias_of(kin, "alpha", applied)
    for c in shifts:
        test = shift_mistrim_test(p, c.estimate, "Cm", step.selections, step.nuisances, mismatch, measured)
        if test is None or slope == 0.0:
            continue
        mistrim = test.dx_ft * cz / cbar
        rest = np.sign(mistrim) * max(abs(mistrim) - bound, 0.0)
        bias = -rest / slope
        if not is_plausible("bias_alpha", bias, V0) or abs(bias - estimate) > rivals.KINEMATIC_Z * se:
            continue
        lift, lift_se = constant_beside_terms(p, "CZ", step.selections, step.nuisances, mismatch)
        lift_made = -float(np.mean(slope_of("alpha")["CZ"][inner])) * bias
        if abs(lift - lift_made) > rivals.KINEMATIC_Z * lift_se:
            continue
        c.selected = False
        c.details["bias_alternative"] = {"bias_alpha_rad": bias, "kinematic": estimate, "kinematic_std": se,
                                         "mistrim": mistrim, "thrust_mistrim_bound": bound,
                                         "cz_constant": lift, "cz_constant_std": lift_se, "cz_constant_made": lift_made}
        c.reason = (f"not named: C_m's mistrim ({mistrim:+.2g}), less the {bound:.2g} the thrust's moment can make, is "
                    f"what an α vane reading {np.degrees(bias):+.2f}° off makes through the model's C_m slope, and "
                    f"neither the kinematics ({np.degrees(estimate):+.2f}° ± {np.degrees(se):.2f}°) nor C_Z's "
                    f"constant ({lift:+.2g} ± {lift_se:.1g}, the bias would make {lift_made:+.2g}) rule that bias "
                    "out: the mean of C_m cannot tell the shift from the C_m,α change its C_Z column imitates")


def withhold_rivals(cands: list[Candidate], selections: dict, nuisances: dict, mismatch: dict[str, np.ndarray],
                    p: Prepared, slope_of, kin: KinematicResult, applied: set[str], V0: float,
                    measured: dict[str, np.ndarray]) -> None:
    """Deselect the aerodynamic terms the data cannot tell from a rival (:mod:`rivals`): a
    collinear candidate of the same axis, or a vane bias the kinematics cannot rule out. A
    term that survives keeps its strongest collinear rival in ``details['rival']`` for the
    validation maneuver to judge. A moment-reference shift is no rival when the size it
    would need is refuted by the mean of C_m (:func:`_refuted_shift`)."""
    inner = interior(p)
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

        def ask(gate: float):
            """The strongest rival from ``gate``, a shift C_m's mean refutes set aside (and returned)."""
            first = rivals.strongest_rival(z, columns, key, others, pool, min_correlation=gate)
            refuted = _refuted_shift(first, by_key, c.channel, p, selections, nuisances, mismatch, measured)
            if not refuted:
                return first, None
            rest = [k for k in pool if k != first.key]
            return rivals.strongest_rival(z, columns, key, others, rest, min_correlation=gate), (first, refuted)
        rival, refuted = ask(rivals.TERM_RIVAL_CORRELATION)
        set_apart = False
        if rival is not None and abs(rival.correlation) < rivals.RIVAL_CORRELATION and abs(rival.t_term) >= cand.T_IN:
            # below the collinearity limit a rival is asked only whether the identification can
            # tell the term from it; where it can, the collinear rivals are judged as before, and
            # without one this rival is kept only for the validation maneuver's own fit to judge
            # (validation.rival_entered_instead), not its RMS
            looser = (rival, refuted)
            rival, refuted = ask(rivals.RIVAL_CORRELATION)
            if rival is None:
                rival, refuted = looser
                set_apart = True
        if refuted and abs(refuted[0].correlation) >= rivals.RIVAL_CORRELATION:
            # the term then rests on its own t (validation.unreplicated) only where the two
            # columns are collinear (the seed's limit); below it its estimate stands apart and the
            # shift is simply ruled out (the outside sweep's F-16 C_n,β +0.03, lateral at 330 ft/s:
            # r −0.78, t 3.2 beside the shift, the validation's own t 3.9)
            c.details["refuted_rival"] = {"parameter": "dx_moment_reference", "effect": "cg_offset",
                                          "correlation": refuted[0].correlation, "t_term": refuted[0].t_term,
                                          "reason": refuted[1]}
        if rival is not None:
            rt = by_key[rival.key]
            c.details["rival"] = {"parameter": rt.parameter, "effect": rt.effect, "axis": c.channel,
                                  "correlation": rival.correlation, "t_term": rival.t_term,
                                  "t_rival": rival.t_rival, "coefficient": rival.swapped,
                                  "under_collinearity": set_apart}
            apart = _shift_set_apart(c, p, selections, nuisances, mismatch, measured)
            if apart:
                c.details["rival"]["set_apart"] = apart
            elif abs(rival.t_term) < cand.T_IN:
                # the identification maneuver cannot tell them apart: a finding only if the
                # validation maneuver prefers it (validation.validation_check), never without one
                c.details["rival"]["indistinct"] = (
                    f"the identification maneuver cannot tell it from {rt.parameter} (columns correlated "
                    f"{rival.correlation:+.2f}; beside it, t = {rival.t_term:.1f})")
        for x in rivals.BIAS_SOURCES:
            if x not in by_key[key].sources:
                continue
            b = rivals.bias_rival(z, columns[key], [columns[n] for n in others], slope_of(x)[c.channel][inner], x,
                                  kinematic_bias_of(kin, x, applied))
            if (b is not None and abs(b.t_term) < cand.T_IN and not b.ruled_out
                    and is_plausible(f"bias_{x}", b.bias_rad, V0)):
                _not_named_for(c, f"bias_{x}", (
                    f"entered, but not named: a {x} vane bias of {np.degrees(b.bias_rad):.2f} deg would imitate it "
                    f"through the model's nonlinearity (beside it, t = {b.t_term:.1f}), and the kinematics cannot rule "
                    f"that bias out ({_bias_text(b)})"))
                break
        if c.selected:
            withhold_for_an_unchecked_scale(c, by_key[key].sources, kin, z, columns[key], [columns[n] for n in others],
                                            slope_of, p, inner)


def withhold_beside_an_unoffered_term(cands: list[Candidate], step: StepwiseFits, mismatch: dict[str, np.ndarray],
                                      p: Prepared) -> None:
    """Deselect a term that a term not offered on its axis (its source never moved above its
    noise, :func:`candidates.offered`; the kinds :data:`stepwise_axes.UNOFFERED_RIVALS`) would
    replace: beside the unoffered term's column the term falls under the entry t
    (:data:`candidates.T_IN`), the two columns correlated by at least
    :data:`rivals.TERM_RIVAL_CORRELATION` or the unoffered term standing at the entry t beside
    it. The unoffered term could not be named there, but neither can what it imitates.

    A probe's c182 (7,000 ft / 165 ft/s, pitch doublets, 1.8 times the noise) with C_m,α̇ −11.7
    had C_m,δe −0.55 named (t 22.6, the model −0.82): beside the kinematic α̇ column (r −0.92)
    its t fell to 0.9, α̇'s stood at −13.6; a J-3 Cub's C_m,α̇ −8.2 the same way (probe seeds
    4264, 4316; offering C_m's α̇ there on q named both, but also, on a c172x null, the model's
    own C_m,α̇, which the model along the inertial α leaves out: tried and dropped). A T-37
    (16,900 ft / 363 ft/s, a 0.18-1.5 Hz pitch sweep, 0.31 times the noise) with C_m ΔV/V
    +1.19 had a C_m,q̂ change of +2.9 named (t 9.0): the airspeed moved 0.2 %, 2.3 times its
    noise, so no ΔV/V term was offered, yet beside its
    column (r 0.56) C_m,q̂ fell to t 1.7 and ΔV/V stood at 11.1 — in a sweep's pitching motion
    the airspeed follows q (ΔV ≈ (g/ω²)·q at each frequency; probe seed 4639)."""
    inner = interior(p)
    for c in cands:
        rivals_here = [t for t in step.unoffered.get(c.channel, ()) if t.parameter != c.parameter]
        if not (c.selected and rivals_here and c.channel in step.selections):
            continue
        sel, by_key = step.selections[c.channel]
        key = next((k for k, t in by_key.items() if t.parameter == c.parameter and k in sel.names), None)
        if key is None or np.ptp(by_key[key].column[inner]) <= 0:
            continue
        column = by_key[key].column[inner]
        nuisance = [col[inner] for col in step.nuisances.get(c.channel, {}).values() if np.ptp(col[inner]) > 0]
        others = [by_key[n].column[inner] for n in sel.names if n != key and n in by_key] + nuisance
        for rival in rivals_here:
            rc = rival.column[inner]
            if np.ptp(rc) <= 0:
                continue
            r = float(np.corrcoef(column, rc)[0, 1])
            try:
                t_term, t_rival = rivals.t_pair(mismatch[c.channel][inner], others, column, rc)
            except (SingularRegressorsError, np.linalg.LinAlgError):
                t_term, t_rival = 0.0, 0.0  # the columns cannot be told apart: withheld if correlated
            if abs(t_term) >= cand.T_IN or (abs(r) < rivals.TERM_RIVAL_CORRELATION and abs(t_rival) < cand.T_IN):
                continue
            c.selected = False
            c.details["unoffered_rival"] = {"parameter": rival.parameter, "effect": rival.effect, "correlation": r,
                                            "t_term": t_term, "t_rival": t_rival}
            c.reason = (f"entered, but not named: a {rival.parameter} term, not offered because "
                        f"{_unoffered_why(rival, p)}, would explain it as well (columns correlated {r:+.2f}; beside "
                        f"it, t = {t_term:.1f}, the {rival.parameter} term's t = {t_rival:.1f})")
            break


def _unoffered_why(term, p: Prepared) -> str:
    """Why an unoffered rival (:func:`withhold_beside_an_unoffered_term`) was not offered: its
    sources the maneuver did not drive (:attr:`Prepared.driven`)."""
    what = {"alpha": "α", "V": "the airspeed", "beta": "β"}
    undriven = [s for s in term.sources if s not in p.driven] or list(term.sources)
    return " and ".join(f"{what.get(s, s)} never moved above its noise" for s in undriven)


def withhold_for_an_unchecked_scale(c: Candidate, sources: tuple[str, ...], kin: KinematicResult, z: np.ndarray,
                                    column: np.ndarray, others: list[np.ndarray], slope_of, p: Prepared,
                                    inner: slice) -> None:
    """Deselect a term built on a vane's angle (α or β, :data:`rivals.BIAS_SOURCES`) that a
    scale factor of that vane would imitate where the kinematics could not check one (the
    angle hardly moves about its mean: ``kin.dropped``). A scale k leaves −k·(∂C/∂x)·x in the
    mismatch of a model evaluated along the vane, x the angle: collinear with the term's
    column (|r| >= :data:`rivals.RIVAL_CORRELATION`), the scale it takes plausible
    (:func:`kinematics.is_plausible`) and the term under the entry t beside it, the two are
    one. (The outside sweep's F-16 C_m,α change of −0.1 at 550 ft/s, α moving 2.8 times its
    noise, would take a scale of −1.6 through C_m's slope of −0.035.) An independent script's
    c182 in a 45° bank (4,600 ft / 186 ft/s, three-axis multisine at 100 Hz, twice the noise,
    no altitude channel) with its α vane reading 10 % high, α moving 2.7 times its noise, had
    C_Z,α +1.32 named (t 5.6): beside the scale's column (r 1.000) it stood at t −2.3."""
    for x in rivals.BIAS_SOURCES:
        why = kin.dropped.get(f"scale_{x}")
        if x not in sources or why is None or x not in p.smooth:
            continue
        scale = (-slope_of(x)[c.channel] * p.smooth[x])[inner]
        if np.ptp(scale) <= 0 or np.ptp(column) <= 0:
            continue
        r = float(np.corrcoef(scale, column)[0, 1])
        if abs(r) < rivals.RIVAL_CORRELATION:
            continue
        k = rivals.coefficient_beside(z, others, scale)
        if not is_plausible(f"scale_{x}", k, 0.0):
            continue
        try:
            t_term = rivals.t_pair(z, others, column, scale)[0]
        except (SingularRegressorsError, np.linalg.LinAlgError):
            t_term = 0.0  # one column: the term cannot be told from the scale
        if abs(t_term) >= cand.T_IN:
            continue
        _not_named_for(c, f"scale_{x}", (
            f"entered, but not named: a scale factor of the {x} vane of {k:+.3f} would imitate it through the model's "
            f"slope (columns correlated {r:+.3f}; beside it, t = {t_term:.1f}), and the kinematics could not check one "
            f"({why})"))
        return


def _not_named_for(c: Candidate, sensor: str, reason: str) -> None:
    """Deselect ``c`` for the sensor error ``sensor`` that would imitate it, saying why."""
    c.selected = False
    c.details["sensor_rival"] = sensor
    c.reason = reason


def note_untested_coupling(cands: list[Candidate], p: Prepared) -> None:
    """Say, on a named β derivative, that an α·β coupling would read as it when the coupling
    could not be tested because α and β, both driven, never moved together (the test of
    :func:`candidates.offered`: :func:`candidates.joint_excitation` under
    :data:`candidates.JOINT_SNR`). Then (α − α₀)β is β
    times the α the sideslip was flown at, and a coupling k reads as a β-derivative change of
    k·Δα, Δα the β²-weighted mean of α − α₀ over the interior: the caveat gives that Δα and
    the k the change would take (probe 15: a C_l α·β coupling of −2 read as C_l,β +0.014 at
    Δα −0.58°). Only a maneuver moving α and β together tells them apart."""
    if not {"alpha", "beta"} <= set(p.driven) or cand.joint_excitation(p) >= cand.JOINT_SNR:
        return
    inner = interior(p)
    reg = cand.regressors(p)
    a, b = reg["alpha"][inner], reg["beta"][inner]
    weight = float(np.sum(b ** 2))
    if weight <= 0.0:
        return
    offset = float(np.sum(b ** 2 * a)) / weight
    for c in cands:
        if not (c.selected and c.effect == "coefficient_error" and c.parameter == f"{c.channel}_beta"):
            continue
        change = c.details.get("change", 0.0)
        if offset == 0.0 or not change:
            continue
        c.details["coupling_alternative"] = {"alpha_offset_rad": offset, "coupling": change / offset}
        caveat = (f"α and β never moved together here, so a {c.channel} α·β coupling of {change / offset:.3g} per "
                  f"rad² would read as this change (the sideslip was flown {np.degrees(offset):+.2f}° of α from "
                  "the start); only a maneuver moving α and β together tells the two apart")
        prior = c.details.get("not_ruled_out")
        c.details["not_ruled_out"] = f"{prior}; {caveat}" if prior else caveat


def note_surface_scale(cands: list[Candidate]) -> None:
    """Say, on a named control derivative (``Cm_de``, ``Cl_da`` ...), that a scale error of
    that surface's position sensor would read as it, unless the recording rules that out.

    The recorded deflection δ_r = (1 + k)·δ makes every term in δ look 1/(1 + k) times its
    size, on every axis at once: a change f = ΔC_δ/C_δ of one derivative is a scale
    k = −f/(1 + f) when the surface's other derivatives moved by the same fraction. Each other
    derivative of the surface the stepwise fitted (selected or not) tests that: one whose change
    lies more than :data:`SURFACE_SCALE_Z` standard errors from f times its model value rules
    the scale out (the evidence says which); otherwise the caveat gives the k that would take
    and how well the others were measured. Probe 65: a 10 % stabilator position scale on F-16,
    737 and c172x multisines was named C_m,δe −9 % (t 8-18) with C_Z,δe measured to ±0.05-0.09,
    no test of a 9 % change of −0.4."""
    fitted = {c.parameter: c for c in cands
              if c.effect == "coefficient_error" and c.details.get("model_over_maneuver") and c.std_error > 0}
    for c in cands:
        surface = c.parameter.rpartition("_")[2]
        if not (c.selected and c.parameter in fitted and surface in SURFACES):
            continue
        f = c.details["change"] / c.details["model_over_maneuver"]
        if f <= -1.0:
            continue
        k = -f / (1.0 + f)
        others = [(o.parameter, o.details["change"], o.std_error, f * o.details["model_over_maneuver"])
                  for o in fitted.values() if o is not c and o.parameter.endswith(f"_{surface}")]
        refuting = [x for x in others if abs(x[1] - x[3]) > SURFACE_SCALE_Z * x[2]]
        c.details["surface_scale"] = {"scale": k, "fraction": f,
                                      "tested_by": {n: {"change": d, "std_error": se, "scale_predicts": e}
                                                    for n, d, se, e in others},
                                      "ruled_out": bool(refuting)}
        if refuting:
            continue
        seen = "; ".join(f"{n} changed {d:+.3g} ± {se:.2g} where the scale predicts {e:+.3g}" for n, d, se, e in others)
        caveat = (f"a {surface} position-sensor scale error of {k:+.3g} (recorded = (1 + k) × true) would read as this "
                  f"change, with the surface's other derivatives moved by the same fraction ({100 * f:+.1f} %)"
                  + (f", which this recording cannot rule out ({seen})" if seen else
                     ", which this recording does not test (no other derivative of it fitted)")
                  + "; a calibration of the surface position tells them apart")
        prior = c.details.get("not_ruled_out")
        c.details["not_ruled_out"] = f"{prior}; {caveat}" if prior else caveat


# A control derivative's change rules a position-sensor scale out when another derivative of
# the same surface lies this many standard errors from the same fractional change.
SURFACE_SCALE_Z = 3.0


def _refuted_shift(rival: rivals.Rival | None, by_key: dict, axis: str, p: Prepared, selections: dict,
                   nuisances: dict, mismatch: dict[str, np.ndarray], measured: dict[str, np.ndarray]) -> str:
    """Why a moment-reference shift cannot be the rival it looks like, '' when it can (or the
    rival is something else). A shift Δx is one parameter on two axes: the C_n it would
    explain through C_Y (the C_Y column follows β, as C_n,β's does, on a lateral maneuver)
    comes with a C_m of Δx·C_Z/c̄, whose mean a lateral maneuver still records. When that
    mean falls short of what the shift needs (:func:`stepwise_axes.shift_mistrim_test`, the
    test the stepwise's own shift must pass), the shift is refuted, not a rival."""
    if rival is None or by_key[rival.key].effect != "cg_offset":
        return ""
    dx = rival.swapped * by_key[rival.key].scale
    test = shift_mistrim_test(p, dx, axis, selections, nuisances, mismatch, measured)
    if test is None or not test.refuted:
        return ""
    return test.reason


def _shift_set_apart(c: Candidate, p: Prepared, selections: dict, nuisances: dict, mismatch: dict[str, np.ndarray],
                     measured: dict[str, np.ndarray]) -> str:
    """Why a moment-reference shift read off C_n is set apart from its collinear rival (a C_n,β
    change, whose column the shift's C_Y column follows on a lateral maneuver), '' when it
    is not: the shift is one parameter on two axes, and C_m's mean carries the mistrim
    Δx·mean(C_Z)/c̄ it predicts (:func:`stepwise_axes.shift_mistrim_test` does not refute it),
    itself a shift of the same sign at least :data:`stepwise_axes.CG_MEAN_Z` standard errors
    from zero and at least :data:`candidates.PRACTICAL_SHARE` of C_m's excursion. A C_n term
    explains nothing of C_m's constant; a C_n,β error and a C_m₀ error of just the matching
    size would have to coincide."""
    if c.effect != "cg_offset" or c.channel != "Cn":
        return ""
    test = shift_mistrim_test(p, c.estimate, c.channel, selections, nuisances, mismatch, measured)
    if (test is None or test.refuted or np.sign(test.dx_ft) != np.sign(c.estimate)
            or abs(test.dx_ft) < CG_MEAN_Z * test.std_error_ft or test.share < cand.PRACTICAL_SHARE):
        return ""
    return (f"C_m's mean carries the mistrim the shift predicts: a shift of {test.dx_ft:.3g} ± "
            f"{test.std_error_ft:.2g} ft, against {c.estimate:.3g} ft from the {c.channel} mismatch")


def _bias_text(b: rivals.BiasRival) -> str:
    if not np.isfinite(b.kinematic_std):
        return f"they do not test a {b.channel} bias"
    return f"bias_{b.channel} = {np.degrees(b.kinematic):.2f} ± {np.degrees(b.kinematic_std):.2f} deg"


AMBIGUOUS_KINDS = ("scale", "skew", "vane")
# The instrument each coefficient is measured with (seed Eqs. 1, 3-5): a skew of it imitates
# an α̇ or rate term of that coefficient (ΔC ≈ −τ dC/dt follows the rates), a scale every term.
DEPENDENT_SENSOR = {"CX": "ax", "CY": "ay", "CZ": "az", "Cl": "p", "Cm": "q", "Cn": "r"}


# The rate each surface mainly drives: a time skew of that rate's channel makes the surface
# look late by the same amount.
SURFACE_RATE = {"de": "q", "da": "p", "dr": "r"}
# The attitude each rate integrates to (φ̇ = p, θ̇ = q at small angles): a lagging rate and an
# attitude leading it by the same time are one relative skew to the kinematics, which may give
# it to either. A probe's F-4N (583 ft/s, lateral 2-1-1s at 40 Hz) with p 62 ms late had a φ
# skew of −60 ms (t −11.7) fitted, p's own at 29 ± 16 ms, and an aileron delay of 64 ms named
# (probe seed 4167).
RATE_ATTITUDE = {"p": "phi", "q": "theta"}


def _withhold_skewed_delay(c: Candidate, kin: KinematicResult) -> None:
    """Deselect a control delay the kinematics cannot tell from a time skew of the rate its
    surface drives: a gyro that lags imitates an actuator that lags (the coefficient measured
    from the lagging rate's derivative, less the model along the lagging rate, leaves the
    surface's term late by the same time). Withheld when the kinematic skew lies within two
    standard errors of the delay (both estimates' errors combined: they do not rule a skew of
    that size out), or shows (|t| >= :data:`AMBIGUOUS_T`, same sign) within 30 % of it. A
    skew the kinematics could not test (the rate hardly moves) leaves the delay named, with
    the caveat in ``details['not_ruled_out']``. The attitude the rate integrates to
    (:data:`RATE_ATTITUDE`) leading by the delay is the same relative skew and is asked too."""
    rate = SURFACE_RATE.get(c.channel, "")
    name = f"skew_{rate}"
    found = kinematic_estimate(kin, name)
    if found is None:
        c.details["not_ruled_out"] = (f"a {rate}-gyro lag of the same size would look alike; the kinematic check did "
                                      f"not test one ({name} not offered)")
        return
    asked = [(name, 1.0)] + ([(f"skew_{RATE_ATTITUDE[rate]}", -1.0)] if rate in RATE_ATTITUDE else [])
    for skew_name, sign in asked:
        found = kinematic_estimate(kin, skew_name)
        if found is None:
            continue
        skew, t = sign * found[0], found[1]
        se_skew = kinematic_std_error(kin, skew_name)
        gap = abs(skew - c.estimate)
        shows = t >= AMBIGUOUS_T and np.sign(skew) == np.sign(c.estimate) and gap <= 0.3 * abs(c.estimate)
        if gap <= 2.0 * float(np.hypot(c.std_error, se_skew)) or shows:
            c.selected = False
            c.details["sensor_rival"] = skew_name
            lag = (f"the {rate} channel lagging by {skew:.3f} ± {se_skew:.3f} s ({skew_name}, t = {t:.1f})"
                   if sign > 0 else f"{RATE_ATTITUDE[rate]} leading {rate} by {skew:.3f} ± {se_skew:.3f} s "
                   f"({skew_name}, t = {t:.1f}: to the kinematics the same as {rate} lagging)")
            c.reason = (f"entered, but not named: the kinematics show {lag}, which "
                        + ("looks like this delay" if t >= AMBIGUOUS_T else "does not rule out a lag of this size"))
            return


# A suspected sensor error withholds a term only if, anywhere within IMITATION_Z standard
# errors of its kinematic estimate, it would imitate at least IMITATION_SHARE of the term's
# change (in the change's direction).
IMITATION_Z = 3.0
IMITATION_SHARE = 0.5

# The rival a simulation's integration step makes (:func:`euler_lag_estimate`).
EULER_LAG = "euler_lag"
MOMENT_AXES = ("Cl", "Cm", "Cn")


@dataclass(frozen=True)
class EulerLag:
    """What the kinematics say of the lag a simulation's rectangular-Euler step leaves
    between the rates' derivatives and the moments (:func:`euler_lag_estimate`): the gyros'
    lead they read (s; negative: lagging), its |t| and standard error, and the lags they
    allow, ``low`` to ``high`` (s, within the physical range 0 to half the sample interval; to
    a whole one after a gyro skew was applied, ``after_skew``)."""

    tau: float
    t: float
    std_error: float
    low: float
    high: float
    after_skew: str = ""   # the gyro skew applied to the channels, which took in the step's lead
    lead_high: float = np.nan  # the largest gyro lead the step itself explains (:func:`euler_lead`)

    @property
    def shown(self) -> bool:
        """The kinematics see the lead itself (|t| >= :data:`AMBIGUOUS_T`), not only allow it."""
        return self.tau > 0 and self.t >= AMBIGUOUS_T


def _gyro_lead(kin: KinematicResult) -> tuple[float, float, float] | None:
    """(lead, |t|, standard error) of the rate gyros against the attitude: minus their common
    skew (:data:`GYRO_UNIT`) or, where only one gyro's skew was estimated (a single-axis
    maneuver), minus that gyro's."""
    unit = suspected_estimate(kin, GYRO_UNIT)
    if unit is None:
        found = [e for g in GYROS for e in [suspected_estimate(kin, f"skew_{g}")] if e is not None and e[2] > 0]
        unit = min(found, key=lambda e: e[2], default=None)
    if unit is None or not np.isfinite(unit[2]) or unit[2] <= 0:
        return None
    return -unit[0], unit[1], unit[2]


def euler_lag_estimate(p: Prepared, kin: KinematicResult, applied: dict[str, float] | None = None) -> EulerLag | None:
    """The lag of the rates' derivatives behind the moments that a simulation integrating
    rates and attitude by rectangular Euler leaves in its recording, as far as the kinematics
    allow it; None when they rule it out.

    With x[k+1] = x[k] + h·ẋ[k] (JSBSim's default for the rotational rates and the attitude),
    the central difference of the attitude at k lags the gyros by h/2, so the kinematics read
    the rate gyros as *leading* by h/2 (a negative common skew, :data:`GYRO_UNIT`), and the
    central difference of the rates, from which ṗ, q̇, ṙ and the moment coefficients are
    built, lags the moments by the same h/2. The lag is physically between 0 and half the
    sample interval (a simulation step no longer than the recording's); the lags allowed are
    those within :data:`IMITATION_Z` standard errors of the lead the kinematics read. It is
    asked whatever the lead's t, as an unresolved gyro skew is where the α vane's error column
    carries it: at 50 Hz a script's 5 ms lag is under the kinematics' resolution (gyros'
    lead t 1.4–3.4 on an independent script's c172x three-axis nulls), where it gave
    C_m,α̇ +1.7 to +2.1 (t 6–8; +1.5 noise-free, where the lead is seen at t 164). A gyro
    skew cannot stand for it: shifting the rates moves their derivatives the other way (an
    independent c172x script at 100 Hz, noise-free: the common skew −5 ms, t 360, whose own
    correction imitated −1.0 of a C_m,α̇ change of +1.66).

    Where a rate gyro's skew was applied to the channels (``applied``, the sensor corrections;
    :func:`applied_gyro_skew`), the kinematics read the sensor's lag less the step's lead, and
    the correction took the lead in: the corrected rates lag by what it left, up to half a
    step, and their derivatives the moments by up to a whole step, which the kinematics no
    longer see. The lags allowed are then 0 to a sample interval and three standard errors of
    the applied skew (``after_skew`` names it). An independent script's A-4 whose q gyro was
    40 ms late (9,100 ft / 529 ft/s, pitch 3-2-1-1 in a 33° turn at 100 Hz) had it named at
    35.0 ± 0.9 ms and beside it a C_m,δe change of −0.021 (4.3 % of C_m's excursion) that the
    derivatives advanced by half a step take to 3.0 %, and by a whole step out."""
    skewed = applied_gyro_skew(applied or {})
    if skewed:
        se = kinematic_std_error(kin, skewed)
        se = se if np.isfinite(se) else 0.0
        return EulerLag(p.dt / 2, 0.0, se, 0.0, p.dt + IMITATION_Z * se, skewed, p.dt / 2 + IMITATION_Z * se)
    lead = _gyro_lead(kin)
    if lead is None:
        return None
    tau, t, se = lead
    low, high = max(0.0, tau - IMITATION_Z * se), min(p.dt / 2, tau + IMITATION_Z * se)
    if high <= 0.0 or low > high:
        return None
    return EulerLag(tau, t, se, low, high, lead_high=high)


def applied_gyro_skew(applied: dict[str, float]) -> str:
    """The rate gyros' skew (their common one, else one gyro's) among the sensor corrections
    ``applied`` to the channels, '' when none was."""
    for name in (GYRO_UNIT,) + tuple(f"skew_{g}" for g in GYROS):
        if applied.get(name):
            return name
    return ""


def imitation(p: Prepared, kin: KinematicResult, aircraft: Aircraft, ic: InitialCondition,
              mismatch: dict[str, np.ndarray], step: StepwiseFits, slope_of=None, V0: float | None = None,
              applied: dict[str, float] | None = None):
    """``imitated(c, name)``: the largest change of term ``c``'s parameter, in the direction of
    its own change, that sensor error ``name`` imitates anywhere within :data:`IMITATION_Z`
    standard errors of its kinematic estimate; None when it cannot be computed.

    The imitation is computed, not assumed: the channels are corrected by the kinematic
    estimate v, the measured and the model's coefficients evaluated again, and the axis's fit
    (the term, the axis's other selected terms, its nuisance columns and a constant; ordinary
    least squares) made on both: δ per v, linear in the error's size. (A 2.3 % q-scale
    suspicion, kinematic t = 2.6, withheld a C_m,q̂ change of −5.9 on the model's −0.95 at
    380 ft/s: such a scale imitates 0.4 at most.)

    The α vane's error column (:func:`stepwise_axes.vane_noise_columns`), where it is in the
    fit, is built again from the corrected channels (``slope_of`` and ``V0`` as it was built;
    without them it is kept as it was): it is the vane's angle less the one the gyros and
    accelerometers integrate to, so a gyro's time skew is in it, and through it in the fit,
    though the mismatch itself hardly carries the skew. JSBSim's rotational rates, integrated
    by rectangular Euler from the moments of the step before, lag those moments by half a
    step (5 ms at 100 Hz); an independent c172x script's nulls then gave a C_m,α̇ of +1.1 to
    +1.4 (t 5.4–9.7) that the kinematics' q skew (−5 to −7 ms, t 4.3–5.2) explained through
    this column alone (probe 22, 5 Dec 2026)."""
    inner = interior(p)
    vane_key = "vane_alpha_noise"
    follows_inertial_alpha = "alpha" in undriven_inertial(p)

    def refit(z: np.ndarray, cols: list[np.ndarray]) -> float:
        A = np.column_stack(cols + [np.ones(z.size)])
        return float(np.linalg.lstsq(A, z, rcond=None)[0][0])

    def part(c: Candidate, name: str, at: tuple[float, float] | None = None,
             removed: bool = False) -> tuple[float, float] | None:
        """(centre, half-width) of what error ``name`` imitates of ``c``'s change, in its
        direction: per_v·v and IMITATION_Z·|per_v|·σ; v ± σ the kinematic estimate, or ``at``
        (an error named on two tests, at its combined size). ``removed``: the channels already
        carry the correction v, and per_v is measured by taking it out again (the term's
        estimate with the correction less the one without), not by doubling it."""
        if name == EULER_LAG:  # probed at the largest lag allowed; the interval's ends below
            lag = euler_lag_estimate(p, kin, applied)
            found = None if lag is None else (lag.high, 1.0, 0.0)
        elif at is not None:
            lag, found = None, (at[0], abs(at[0]) / at[1] if at[1] > 0 else np.inf, at[1])
        else:
            lag, found = None, suspected_estimate(kin, name)
        sel, by_key = step.selections.get(c.channel, (None, {}))
        key = next((k for k, t in by_key.items() if t.parameter == c.parameter), None)
        change = term_change(c)
        if found is None or key is None or not found[0] or not change:
            return None
        v, t, _ = found
        if name == EULER_LAG:
            corrected = rate_derivatives_advanced(p, v)
        else:
            corrected = corrected_recording(p, kin, {m: -v if removed else v for m in unit_members(kin, name)})
        # an inertial α the model follows is rebuilt from the corrected channels: the error's
        # own path into the model's states (inertial_alpha_sensors)
        changed = model_along(corrected, aircraft, ic, inertial_from=None if follows_inertial_alpha else p).mismatch()
        cols = [by_key[key].column[inner]] + [by_key[k].column[inner] for k in sel.names if k != key and k in by_key]
        nuisances = step.nuisances.get(c.channel, {})
        fixed = [x[inner] for n, x in nuisances.items() if n != vane_key and np.ptp(x[inner]) > 0]
        if vane_key in nuisances:
            rebuilt = nuisances[vane_key]
            if slope_of is not None and V0 is not None:
                rebuilt = vane_error_column(slope_of, turbulence_test(corrected)[0], V0, c.channel)
            before = refit(mismatch[c.channel][inner], cols + fixed + [nuisances[vane_key][inner]])
            after = refit(changed[c.channel][inner], cols + fixed + [rebuilt[inner]])
        else:
            before = refit(mismatch[c.channel][inner], cols + fixed)
            after = refit(changed[c.channel][inner], cols + fixed)
        # what an error of size v adds to the term's estimate (removed: what its correction added)
        per_v = (before - after) / v
        if lag is not None:  # the most any lag allowed imitates: the interval's ends, as (centre, half-width)
            ends = [per_v * x * np.sign(change) for x in (lag.low, lag.high)]
            return 0.5 * (ends[0] + ends[1]), 0.5 * abs(ends[0] - ends[1])
        sigma = abs(v) / t if t > 0 else np.inf
        return per_v * v * np.sign(change), IMITATION_Z * abs(per_v) * sigma

    def imitated(c: Candidate, name: str | tuple[str, ...], at: tuple[float, float] | None = None,
                 applied: bool = False, whole: bool = False) -> float | None:
        """The most ``name`` imitates within IMITATION_Z standard errors (of ``at``, estimate
        and standard error, when given); for several errors at once (a tuple), within that
        many of their joint estimate (independent: the centres add, the half-widths in
        quadrature). ``applied``: the error is already corrected for at its estimate, and
        what counts is how much of the change moving that correction within IMITATION_Z
        standard errors can take away (the half-width alone); ``whole`` as well: or removing
        the correction altogether (the centre)."""
        names = (name,) if isinstance(name, str) else name
        parts = [part(c, n, at, removed=applied) for n in names]
        if any(x is None for x in parts):
            return None
        spread = float(np.sqrt(sum(x[1] ** 2 for x in parts)))
        centre = sum(x[0] for x in parts)
        if applied:
            return max(spread, centre) if whole else spread
        return centre + spread
    return imitated


def withhold_resting_on_an_uncertain_correction(cands: list[Candidate], kin: KinematicResult,
                                                applied: dict[str, float], imitated) -> None:
    """Deselect coefficient terms that rest on a sensor correction the kinematics applied
    without being sure of it: a value applied from |t| :data:`sensor_rules.APPLY_T` on but
    below the kinematic entry t (:data:`kinematics.T_IN`), which moved within
    :data:`IMITATION_Z` of its standard errors would take at least
    :data:`IMITATION_SHARE` of the term's change away, or would without the correction at all
    (``imitated(..., applied=True, whole=True)``, :func:`imitation`): a correction under the
    entry t is not established, and a term that rests on it is not either. An independent
    script's c182 (168 ft/s, doublets, 25 Hz) with p 40 ms late had an α bias of 0.52°
    applied at kinematic t 3.1 (the skew's doing, the skew itself under its practical size);
    along the α so corrected the model's C_n,p̂, which follows α, left a C_n,p̂ change of
    −0.018 (t −8.4), −0.003 without the correction. Another c182, a null (5,100 ft, 3-2-1-1 on
    each axis at 50 Hz, half the noise, no h), had an α bias of 0.45° ± 0.12° applied (t 3.8):
    moved by three of its errors it took under half of a C_n,p̂ change of −0.015 (t −15) away,
    removed, 0.012 of it (with the correction not applied C_n,p̂ did not enter, t −2.0)."""
    unsure = {n: v for n, v in applied.items() if kinematic_t(kin, n) < KIN_T_IN}
    if imitated is None or not unsure:
        return
    for c in cands:
        if not (c.selected and c.effect in ("coefficient_error", "unsteady_alphadot", "nonlinear_alpha",
                                            "cross_coupling") and c.test.startswith("stepwise")):
            continue
        change = abs(term_change(c))
        for name, v in unsure.items():
            se = kinematic_std_error(kin, name)
            size = imitated(c, name, (v, se), applied=True, whole=True) if np.isfinite(se) and se > 0 else None
            if size is None or size < IMITATION_SHARE * change:
                continue
            c.selected = False
            c.details["sensor_rival"] = name
            c.details["uncertain_correction"] = {"parameter": name, "applied": v, "std_error": se,
                                                 "imitates_at_most": size, "change": change}
            c.reason = (f"entered, but not named: it rests on the correction for {_named(name)} = {v:.3g} ± {se:.2g} "
                        f"(kinematic t = {abs(v) / se:.1f}, applied though below the entry t); moved within "
                        f"{IMITATION_Z:g} of its standard errors, or removed, that correction takes {size:.2g} of this "
                        f"change of {change:.3g} away")
            break


# The channels the α vane's error column is integrated from, beyond the gyros and the vane:
# a skew or scale of theirs is in the column, and through it in the axis's fit.
VANE_COLUMN_SENSORS = ("az",)
# The channels the inertial α is integrated from (the w equation: q and a_z), where the model
# follows it (:func:`along.undriven_inertial`), beyond the vane: a skew of theirs moves the
# model's α itself, on every axis that reads α (INERTIAL_ALPHA_AXES).
INERTIAL_ALPHA_SENSORS = ("q", "az")
INERTIAL_ALPHA_AXES = ("CX", "CZ", "Cm")


def inertial_alpha_sensors(p: Prepared) -> dict[str, tuple[str, ...]]:
    """Per axis, the sensors the model's α is built from where it follows the inertial α
    (:data:`INERTIAL_ALPHA_SENSORS`; empty otherwise), for :func:`withhold_ambiguous`'s
    ``column_sensors``: a q gyro 40 ms late on an independent script's 787-8 (pitch sweep at
    791 ft/s, 40 Hz, twice the vanes' noise; α under the vane's noise, so the model follows
    the inertial α) put α −τ·q into the model, read as a C_Z,q̂ change of −8.9 (t −7.5) while
    the kinematics put the skew at 26 ± 26 ms."""
    return {a: INERTIAL_ALPHA_SENSORS for a in INERTIAL_ALPHA_AXES} if "alpha" in undriven_inertial(p) else {}


def _lag_shaped(c: Candidate) -> bool:
    """Whether term ``c`` follows its coefficient's rate of change (C_m,α̇ or a rate
    derivative), the shape a lag imitates, rather than its level."""
    rate_term = c.effect == "coefficient_error" and c.parameter.split("_", 1)[1] in ("qhat", "phat", "rhat")
    return c.effect == "unsteady_alphadot" or rate_term


def left_impractical(c: Candidate, size: float, change: float) -> bool:
    """Whether term ``c``'s change less the part ``size`` of it that a simulation's own
    integration lag imitates (:data:`EULER_LAG`, :func:`imitation`) would explain under
    :data:`candidates.PRACTICAL_SHARE` of its coefficient's excursion (the term's
    ``excursion_share`` scaled by what is left): what is left would not have been named. The
    lag is no error of the aircraft's to name, so unlike a sensor rival it need not imitate
    :data:`IMITATION_SHARE` of the change to withhold it. An independent script's noise-free
    c172x null (4,700 ft / 196 ft/s, three-axis doublets at 100 Hz, integrated at 100 Hz)
    drew C_m,α̇ +1.51 (t 35, 5.5 % of C_m's excursion) on a model without α̇ terms, the gyros
    read as leading the attitude by 5.0 ms (t 266): the rates' derivatives advanced by that
    lag imitate 0.75 of it, and the rest, 0.64 refitted so, explains 2.3 %."""
    share = c.details.get("excursion_share")
    if share is None or change <= 0.0 or size <= 0.0:
        return False
    return share * (change - size) / change < cand.PRACTICAL_SHARE


def term_change(c: Candidate) -> float:
    """What term ``c`` changes in the model: a coefficient error's change from the model's
    value, any other term's whole estimate (the model has none)."""
    return c.details.get("change", c.estimate) if c.effect == "coefficient_error" else c.estimate


def regressor_channel(c: Candidate) -> str | None:
    """The measured channel term ``c``'s regressor is built on: a derivative's own (C_m,q̂ on
    q), and α for an α̇ term. The model is evaluated along the α vane, so an error of the vane
    (a lag: −τα̇ times the model's slope; a vane ahead: −x·q/V) reaches the mismatch as a
    term in α̇: a c172x recording whose α was 80 ms late named a C_Z,α̇ of −55 that the α
    vane's suspected error imitates. Likewise α's powers: the model's nonlinear slope along a
    scaled vane puts α·Δα into the mismatch (a c172x pitch maneuver with a 10 % α scale named
    a C_X α² of −0.73)."""
    if c.effect in ("unsteady_alphadot", "nonlinear_alpha"):
        return "alpha"
    return cand.REGRESSOR_SOURCE.get(c.parameter.split("_", 1)[1])


def regressor_channels(c: Candidate) -> tuple[str | None, ...]:
    """The measured channels term ``c``'s regressor is built on (:func:`regressor_channel`),
    and for an α̇ term on a moment axis also a_z: its α̇ is the kinematic one
    (:func:`candidates.alpha_rate`), q less the normal acceleration over V, so an a_z lag moves
    it by (g/V)·τ·ȧ_z, which follows α̇ itself (the q gyro is the axis's own sensor, asked as
    C_m's). An independent script's J3 Cub (2,400 ft / 118 ft/s, pitch multisine at 100 Hz,
    half the noise) with a_z 40 ms late had C_m,α̇ +1.16 named (t 10): the kinematics suspected
    the skew (46 ms, t 7.0) but could not tell it from an α-vane scale, and only the vane's
    errors had been asked."""
    own = regressor_channel(c)
    if c.effect == "unsteady_alphadot" and c.channel not in cand.VANE_ALPHA_RATE_AXES:
        return own, "az"
    return (own,)


def euler_lead(kin: KinematicResult, name: str, euler_lag: EulerLag | None) -> bool:
    """Whether gyro-skew suspicion ``name`` (the unit's or one gyro's) reads the gyros *leading*
    by no more than a simulation's rectangular-Euler step allows (:func:`euler_lag_estimate`:
    within :data:`IMITATION_Z` standard errors of ``euler_lag.high``). Such a lead is the
    attitude lagging the rates, not the rates shifted: shifting them would move their
    derivatives the wrong way, and the lag is asked as its own rival instead. F-16 XML copies
    flown by the independent script at 5,000 ft / 330 ft/s (three-axis multisine, 50 Hz)
    withheld a true C_n,r̂ −0.3, C_l,p̂ −0.1 and C_m,α̇ −3 for the rate gyros' common skew
    (−5 ms leads, t 3.2–3.3), the half step of JSBSim's 100 Hz integration."""
    if euler_lag is None or not (name == GYRO_UNIT or name in {f"skew_{g}" for g in GYROS}):
        return False
    found = suspected_estimate(kin, name)
    if found is None:
        return False
    v, _, se = found
    return v < 0 and -v - IMITATION_Z * se <= euler_lag.lead_high


def _named(rival: str | tuple[str, ...]) -> str:
    """A suspicion as the reasons name it (several errors at once: each, together)."""
    if not isinstance(rival, str):
        return " and ".join(_named(r) for r in rival) + " together"
    if rival == EULER_LAG:
        return "the rates' derivatives lagging the moments (a simulation's rectangular-Euler step)"
    return f"{rival}, the rate gyros' common time skew" if rival == GYRO_UNIT else rival


def withhold_ambiguous(cands: list[Candidate], kin: KinematicResult, imitated=None,
                       column_sensors: dict[str, tuple[str, ...]] | None = None,
                       euler_lag: EulerLag | None = None, contested: dict | None = None) -> None:
    """Deselect coefficient errors the kinematics cannot tell from a sensor error on the
    channel they are built on (:data:`AMBIGUOUS_T`) and that the sensor error, at a size the
    kinematics allow, would imitate (``imitated``, :func:`imitation`; half the change); the
    reason names the rival, and ``details['suspicion']`` keeps it for the validation maneuver
    (:func:`replication.lift_unreplicated_suspicions`).

    The sensors an axis is measured with are its own (:data:`DEPENDENT_SENSOR`) and, per axis
    in ``column_sensors``, those its nuisance columns are built from: the α vane's error
    column (:func:`stepwise_axes.vane_noise_columns`) integrates a_z (:data:`VANE_COLUMN_SENSORS`).
    On an axis with that column in its fit the gyros' skew reaches every term through it, and
    a skew need not be suspected: each sensor's (and the gyros' common one) is asked whatever
    its t, within :data:`IMITATION_Z` standard errors of its kinematic estimate, for every
    term (the imitation is computed: a skewed q̇ carries C_m,δe·δ̇e too), and, when none alone
    imitates half the change, the q gyro's and a_z's together (the centres added, the
    half-widths in quadrature: :func:`imitation`). A pitch maneuver hardly lets the kinematics
    resolve the 5 ms skew of a script's JSBSim gyros (q −2 to −6 ms, t 1–3): the test
    script's twenty c172x pitch nulls at 100 Hz named 9 false findings at the sixteenth
    session's start, 3 with suspected skews alone, 1 so. Asked on every axis, not only where
    the column is, it withheld six true F-16 and DHC-6 findings of the outside sweep (C_m,α̇
    −3, C_m,q̂ −6, C_n,r̂ −0.3, C_l,p̂ −0.1), whose skews the kinematics bound loosely. A force
    axis's own accelerometer skew is asked so too, whatever its t, of that axis's rate terms
    (a skew τ adds τ·Ċ, which follows α̇ or the rate): a probe's F-4N with a_z 40 ms late was
    named C_Z,q̂ +12.2 (t 7.8), the skew read at 24 ± 16 ms (t 1.5).

    ``euler_lag`` (:func:`euler_lag_estimate`), unless the kinematics rule it out, is asked of
    every rate-shaped moment term (C_m,α̇ and the rate derivatives of C_l, C_m, C_n) the same
    way: withheld when the rates' derivatives lagging the moments by any lag it allows
    imitate half its change, or so much of it that the rest is no practical finding
    (:func:`left_impractical`).

    A suspect the kinematics cannot tell from a rival (``contested``,
    :func:`sensor_rules.contested_parameters`) brings the rival in as a suspect of its own
    channel, at the rival's own estimate (an α vane 15 ft ahead of the c.g. and an 80 ms α
    lag both follow q on a pitch maneuver: a pa28 recording whose α was 80 ms late named a
    C_Z,α change of +0.69 that only the vane offset, imitating −0.16 of it, had been asked
    about)."""

    asked: set[tuple[int, str]] = set()  # (term, rival) found not to explain it
    contest_at: dict[str, tuple[float, float]] = {}  # a contested suspect's rival: its own (estimate, s.e.)

    def explains(c: Candidate, rival: str, t: float) -> bool:
        if (id(c), rival) in asked:
            return False  # asked already (the regressor's sensor and the coefficient's)
        at = contest_at.get(rival) if isinstance(rival, str) else None
        size = None if imitated is None else imitated(c, rival, at) if at else imitated(c, rival)
        change = abs(term_change(c))
        if size is None or size >= IMITATION_SHARE * change or (rival == EULER_LAG
                                                                  and left_impractical(c, size, change)):
            return True
        asked.add((id(c), rival))
        kept = c.details.get("sensor_suspect")
        if kept is None or size > kept["imitates_at_most"]:  # the suspect that reaches furthest
            c.details["sensor_suspect"] = {"parameter": rival, "imitates_at_most": size, "change": change}
        asks = "suspect" if t >= AMBIGUOUS_T else "do not rule out"
        c.reason += (f"; the kinematics {asks} {_named(rival)} (t = {t:.1f}), which would imitate at most "
                     f"{size:.2g} of this change of {change:.3g}")
        return False
    suspects: dict[str, list[tuple[str, float]]] = {}  # each channel's suspected errors, largest t first
    for name, sp in kin.parameters.items():
        found = kinematic_estimate(kin, name)
        if found is not None and name.split("_", 1)[0] in AMBIGUOUS_KINDS and found[1] >= AMBIGUOUS_T:
            suspects.setdefault(sp.channel, []).append((name, found[1]))
    for name, contest in (contested or {}).items():
        own, other = kin.parameters.get(name), kin.parameters.get(contest.rival)
        solo = contest.rival_estimate or kinematic_estimate(kin, contest.rival)
        if (own is None or other is None or solo is None or not solo[0] or solo[1] < AMBIGUOUS_T
                or contest.rival.split("_", 1)[0] not in AMBIGUOUS_KINDS
                or name not in [n for n, _ in suspects.get(own.channel, [])]):
            continue
        if contest.rival not in [n for n, _ in suspects.get(other.channel, [])]:
            suspects.setdefault(other.channel, []).append((contest.rival, solo[1]))
            contest_at[contest.rival] = (solo[0], abs(solo[0]) / solo[1])
    for found in suspects.values():
        found.sort(key=lambda r: -r[1])
    unit = suspected_estimate(kin, GYRO_UNIT)  # the rate gyros' common skew, beside each one's own
    units = {g: (GYRO_UNIT, unit[1]) for g in GYROS
             if unit is not None and unit[1] >= AMBIGUOUS_T and f"skew_{g}" in unit_members(kin, GYRO_UNIT)}

    def rivals_of(channel: str | None) -> list[tuple[str, float]]:
        """Every suspected error of the channel (a vane ahead of the c.g. and the vane's lag,
        which the kinematics may not tell apart: each is asked), then the gyros' common skew."""
        return [r for r in suspects.get(channel or "", []) + [units.get(channel or "")]
                if r is not None and not euler_lead(kin, r[0], euler_lag)]

    def unruled_skews(channel: str | None) -> list[tuple[str, float]]:
        """The channel's own skew and, for a gyro, the gyros' common one, whatever their t."""
        names = [f"skew_{channel}"] + ([GYRO_UNIT] if channel in GYROS else [])
        found = [(n, suspected_estimate(kin, n)) for n in names]
        return [(n, e[1]) for n, e in found if e is not None and e[0]]

    for c in cands:
        if c.selected and c.effect == "control_delay":
            _withhold_skewed_delay(c, kin)
        if not (c.selected and c.effect in ("coefficient_error", "unsteady_alphadot", "nonlinear_alpha")):
            continue
        found = next(((r, ch) for ch in regressor_channels(c) for r in rivals_of(ch) if explains(c, *r)), None)
        if found is not None:
            (rival, t), channel = found
            c.selected = False
            c.details["sensor_rival"] = rival
            c.details["suspicion"] = _suspicion(rival, t, contest_at)
            c.reason = (f"entered, but not named: the {channel} sensor itself may be in error ({_named(rival)}, "
                        f"kinematic t = {t:.1f}), an error that would imitate this term")
    for c in cands:  # the sensors the coefficient itself is measured with
        sensors = (DEPENDENT_SENSOR.get(c.channel or ""),) + (column_sensors or {}).get(c.channel or "", ())
        # a lag imitates terms that follow the coefficient's rate of change, not its level
        lag_shaped = _lag_shaped(c)
        rivals = [(r, sensor) for sensor in sensors for r in rivals_of(sensor)]
        # where the α vane's error column is in the fit, the gyros' skew reaches every term
        # through it, and a skew need not be suspected: one not ruled out is asked too
        through_column = c.channel in (column_sensors or {})
        # an accelerometer's skew moves its own force's rate terms: asked whatever its t too
        unruled = sensors if through_column else sensors[:1] if lag_shaped and c.channel in cand.FORCE_AXES else ()
        rivals += [(r, sensor) for sensor in unruled for r in unruled_skews(sensor)
                   if (r[0], sensor) not in [(x[0], y) for x, y in rivals]]
        if not (c.selected and rivals and c.test.startswith("stepwise")):
            continue
        found = next(((r, sensor) for r, sensor in rivals
                      if (lag_shaped or through_column or not r[0].startswith("skew")) and explains(c, *r)), None)
        skews = tuple(dict.fromkeys(r[0] for r, _ in rivals if r[0].startswith("skew_") and r[0] != GYRO_UNIT))
        if found is None and through_column and len(skews) > 1:  # the instruments' timing together
            t_joint = min(t for (n, t), _ in rivals if n in skews)
            found = ((skews, t_joint), " and ".join(dict.fromkeys(sensor for (n, _), sensor in rivals
                                                                  if n in skews)))
            if not explains(c, *found[0]):
                found = None
        if found is None:
            continue
        (rival, t), sensor = found
        c.selected = False
        c.details["sensor_rival"] = rival if isinstance(rival, str) else rival[0]
        c.details["suspicion"] = _suspicion(c.details["sensor_rival"], t, contest_at)
        if not isinstance(rival, str):
            c.details["sensor_rivals"] = list(rival)
        why = _measured_with(kin, rival, t, sensor)
        c.reason = f"entered, but not named: {c.channel} is measured with {sensor}, {why}"
    if euler_lag is None:
        return
    for c in cands:  # a simulation's integration step: the moments lead the rates' derivatives
        suspected = not c.selected and "suspicion" in c.details  # withheld above: asked too, for the lift
        if not ((c.selected or suspected) and c.channel in MOMENT_AXES and c.test.startswith("stepwise")
                and (_lag_shaped(c) or _after_skew_reaches(euler_lag, c))):
            continue
        lag = euler_lag
        if suspected:
            if explains(c, EULER_LAG, lag.t if lag.shown else 0.0):
                c.details["also_imitated_by"] = EULER_LAG
                c.details["euler_lag_s"] = [lag.tau, lag.std_error, lag.low, lag.high]
                c.reason += ("; the rates' derivatives lagging the moments by a simulation's rectangular-Euler "
                             "step would imitate it too")
            continue
        if explains(c, EULER_LAG, lag.t if lag.shown else 0.0):
            c.selected = False
            c.details["sensor_rival"] = EULER_LAG
            c.details["euler_lag_s"] = [lag.tau, lag.std_error, lag.low, lag.high]
            if lag.after_skew:
                c.reason = (f"entered, but not named: the {lag.after_skew} applied to the channels took in the lead "
                            "a simulation integrating by rectangular Euler gives the rates; their derivatives, from "
                            f"which {c.channel} is built, may then lag the moments by up to {1000 * lag.high:.1f} ms, "
                            "which imitates this term")
                continue
            read = (f"read the rate gyros as leading the attitude by {1000 * lag.tau:.1f} ± "
                    f"{1000 * lag.std_error:.1f} ms (t = {lag.t:.1f})" if lag.shown else
                    f"do not rule out the rate gyros leading the attitude by up to {1000 * lag.high:.1f} ms "
                    f"(they read {1000 * lag.tau:.1f} ± {1000 * lag.std_error:.1f} ms)")
            c.reason = (f"entered, but not named: the kinematics {read}, as a simulation integrating by "
                        f"rectangular Euler records them; the rates' derivatives, from which {c.channel} is built, "
                        "then lag the moments by as much, which imitates this term")


# The moment axes each rate gyro's skew reaches through its derivative.
GYRO_AXES = {"skew_p": ("Cl", "Cn"), "skew_q": ("Cm",), "skew_r": ("Cl", "Cn"), GYRO_UNIT: MOMENT_AXES}


def _after_skew_reaches(lag: EulerLag, c: Candidate) -> bool:
    """Whether the lag a gyro skew's correction leaves (:func:`euler_lag_estimate`) is asked of
    term ``c`` whatever its shape: every term of the moment axes that gyro's derivative builds
    (a whole step's lag of q̇ reaches C_m,δe beside the δe delay column it also enters)."""
    return bool(lag.after_skew) and c.channel in GYRO_AXES.get(lag.after_skew, ())


def _suspicion(rival: str, t: float, contest_at: dict[str, tuple[float, float]]) -> dict:
    """The suspicion that withheld a term: the suspect and its t, and, for a contested
    suspect's rival brought in at its own estimate (:func:`withhold_ambiguous`), that estimate
    and standard error (``at``), the size the suspicion was made at, which the kinematic fit
    beside the contested suspect does not carry."""
    out = {"parameter": rival, "t": t}
    if rival in contest_at:
        out["at"] = list(contest_at[rival])
    return out


def _measured_with(kin: KinematicResult, rival: str | tuple[str, ...], t: float, sensor: str) -> str:
    """Why a term is withheld for an error of a sensor its axis is measured with
    (:func:`withhold_ambiguous`): a suspected one, one not ruled out, or several together."""
    if not isinstance(rival, str):
        each = "; ".join(f"{n} {1000 * e[0]:.1f} ± {1000 * e[2]:.1f} ms" for n in rival
                         for e in [suspected_estimate(kin, n)])
        return (f"whose time skews together ({each}) the kinematics do not rule out, and skews within "
                f"{IMITATION_Z:g} standard errors of them imitate this term")
    if t >= AMBIGUOUS_T:
        return (f"which may itself be in error ({_named(rival)}, kinematic t = {t:.1f}): a lagging or scaled "
                f"{sensor} imitates this term")
    v, _, se = suspected_estimate(kin, rival)
    return (f"whose time skew the kinematics do not rule out ({_named(rival)}: {1000 * v:.1f} ± {1000 * se:.1f} ms, "
            f"t = {t:.1f}), and a skew within {IMITATION_Z:g} standard errors of that imitates this term")
