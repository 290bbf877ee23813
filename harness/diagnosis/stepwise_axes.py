"""The per-axis stepwise fits on the coefficient mismatch: the accelerometer position, the
delay scans, the nuisance columns (thrust, vane noise), the moment-reference mean test,
and the candidates the selections give, with their practical sizes."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from harness.diagnosis import candidates as cand
from harness.diagnosis.along import ModelAlong, interior
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.gust_rules import turbulence_test
from harness.diagnosis.kinematics import PRACTICAL
from harness.diagnosis.prepare import COEFFICIENTS, Prepared, throttle_travel
from models.constants import SURFACES
from models.replay import AeroAlong
from models.trim import TrimPoint


def offset_candidate(p: Prepared, mismatch: dict[str, np.ndarray], noise: dict[str, float],
                     measured: dict[str, np.ndarray]) -> tuple[cand.OffsetTest, Candidate]:
    """The accelerometer position from the force mismatches: named when significant, at
    least 1.5 ft and at least 4 % of the force coefficients' excursion; when named, its
    columns are removed from ``mismatch`` (in place)."""
    off = cand.accelerometer_offset(p, mismatch, noise)
    x, sx = off.position_ft[0], off.std_error_ft[0]
    cols = cand.accelerometer_columns(p)
    inner = interior(p)
    share = max(cand.contribution_share(sum(off.position_ft[i] * cols[a][c] for i, a in enumerate("xyz"))[inner],
                                        1.0, measured[c][inner]) for c in ("CX", "CY", "CZ"))
    sel = (max(abs(v) for v in off.t) >= cand.T_IN and abs(x) >= PRACTICAL["offset_ft"]
           and off.gain >= cand.MIN_GAIN / 2 and share >= cand.PRACTICAL_SHARE)
    reason = "significant and practical" if sel else \
        "not significant, under 1.5 ft, or under 4 % of the force coefficients' excursion"
    band = _offset_by_band(p, mismatch, noise, off) if sel and p.meta.get("accelerometer_at_cg") else ""
    if band:
        sel, reason = False, band
    rival = cand.offset_rival(p, mismatch, noise, off) if sel else None
    if rival is not None:  # the mismatch is left whole for the stepwise fits to judge
        sel = False
        reason = (f"not named: the force mismatch cannot tell it from {rival.parameter} on {rival.built_on} "
                  f"(r = {rival.correlation:+.2f}): "
                  f"beside it the position stands at t = {rival.t_offset:.1f}, and {rival.parameter} at t = "
                  f"{rival.t_rival:.1f} beside the position; the mismatch is left to the stepwise fits")
    if sel:
        for i, a in enumerate("xyz"):
            for c in ("CX", "CY", "CZ"):
                mismatch[c] = mismatch[c] - off.position_ft[i] * cols[a][c]
    return off, Candidate("sensor_offset", "lon", "accelerometer", "x_accelerometer", x, sx,
                          x / sx if sx > 0 else 0.0, off.gain, "ft", "force mismatch on ω̇×r + ω×(ω×r)", sel, reason,
                          {"position_ft": list(off.position_ft), "std_error_ft": list(off.std_error_ft),
                           "t_xyz": list(off.t)}
                          | ({"offset_rival": rival.parameter, "offset_rival_t": rival.t_rival,
                              "offset_t_beside": rival.t_offset} if rival else {}))


# A rigid accelerometer offset reads the same in every band: the position read off the force
# mismatches low-passed at OFFSET_BAND_SHARE of the common filter's cut-off may lie at most
# OFFSET_BAND_Z standard errors (the two fits' in quadrature) from the whole band's.
OFFSET_BAND_SHARE = 0.5
OFFSET_BAND_Z = 4.0


def _offset_by_band(p: Prepared, mismatch: dict[str, np.ndarray], noise: dict[str, float],
                    off: cand.OffsetTest) -> str:
    """Why the accelerometer position the force mismatches read, on a recording whose
    accelerometer was carried to the c.g. from the metadata's position, is not a rigid offset,
    '' when it may be: its best-determined component low-passed at :data:`OFFSET_BAND_SHARE`
    of the common cut-off lies :data:`OFFSET_BAND_Z` standard errors or more from the whole
    band's (:func:`candidates.accelerometer_offset`). The rotational terms of a sensor at r are
    a linear function of the rates, which filtering both sides keeps; motion the gyros carry
    and the accelerometer does not feel — a structural mode inside the band, which the carry
    puts into a_z times the arm — grows with frequency. (Asked only after a carry: without one
    a true position read off a propeller aircraft's force mismatch, beside its unrecorded
    thrust's own mismatch, drifts by band too — two probe c172p's, 6.6 and 5.6 ft ahead, read
    2.2 and 2.9 ft, which the test would have withheld.) A probe's T-37 (25 Hz, a 4.5 Hz mode in q
    and a_z inside the 6.1 Hz cut-off, the accelerometer 5.3 ft aft and 1.7 ft below the c.g.
    in the metadata) read the position 4.79 ± 0.13 ft from it in the whole band, 2.05 ± 0.27
    below 3 Hz and −0.18 ± 0.56 below 1 Hz."""
    i = int(np.argmax(np.abs(off.t)))
    try:
        low = cand.accelerometer_offset(p, mismatch, noise, OFFSET_BAND_SHARE * p.common_cutoff_hz)
    except (SingularRegressorsError, np.linalg.LinAlgError, ValueError):
        return ""
    spread = float(np.hypot(low.std_error_ft[i], off.std_error_ft[i]))
    if not (np.isfinite(spread) and spread > 0):
        return ""
    z = abs(low.position_ft[i] - off.position_ft[i]) / spread
    if z < OFFSET_BAND_Z:
        return ""
    axis = "xyz"[i]
    return (f"not named: not a rigid offset: its {axis} reads {off.position_ft[i]:.3g} ± {off.std_error_ft[i]:.2g} "
            f"ft in the whole band and {low.position_ft[i]:.3g} ± {low.std_error_ft[i]:.2g} ft below "
            f"{OFFSET_BAND_SHARE * p.common_cutoff_hz:.2g} Hz ({z:.1f} standard errors apart); motion the gyros "
            "carry and the accelerometer does not feel (a structural mode) grows with frequency so")


def delay_scans(p: Prepared, mismatch: dict[str, np.ndarray], aero: AeroAlong,
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
class StepwiseFits:
    selections: dict        # axis -> (ColoredSelection, {key: Term})
    nuisances: dict         # axis -> {name: column} always in the fit
    not_offered: dict       # axis -> terms not offered, with the reason
    shares: dict            # (axis, key) -> share of the coefficient's excursion
    pinned: CgMeanTest | None = None  # a moment-reference shift sized by C_m's mistrim
    ar_t: dict = field(default_factory=dict)  # (axis, key) -> t with the AR autocorrelation (candidates.AR_ENTRY_T)
    unoffered: dict = field(default_factory=dict)  # axis -> [Term] not offered, source undriven (UNOFFERED_RIVALS)


# The terms kept, where they were not offered because their source was not driven
# (candidates.offered), as rivals of what is named in their place
# (term_rules.withhold_beside_an_unoffered_term).
UNOFFERED_RIVALS = ("alphadot", "dV")


# The α vane's noise column enters C_m's fit where it is a material part of the mismatch:
# fitted alone (with a constant) it takes at least this share off C_m's mismatch RMS.
VANE_NOISE_SHARE = 0.15


def vane_error_column(slope_of, gust, V0: float, axis: str) -> np.ndarray:
    """−∂C/∂α·e for coefficient ``axis``: what the α vane's error e passes into the mismatch of
    a model evaluated along the vane (errors in variables), e the vane's angle less the one the
    inertial channels integrate to, −w/V with w the kinematic residual's vertical "gust"
    (``gust.w_fps``) and V the airspeed ``V0``; ``slope_of`` the model's slopes
    (:func:`along.slope_function`)."""
    return slope_of("alpha")[axis] * np.asarray(gust.w_fps, dtype=float) / V0


def vane_noise_columns(p: Prepared, along: ModelAlong, slope_of, V0: float, mismatch: dict[str, np.ndarray],
                       gust=None) -> dict[str, np.ndarray]:
    """The columns −∂C/∂α·e that the α vane's own error passes into the mismatch of C_m and
    C_X, e the vane's angle less the one the inertial channels integrate to (the kinematic
    residual's vertical "gust" over the airspeed, high-passed at :data:`spectra.GUST_HIGHPASS_HZ`);
    empty when the model is not evaluated along the vane (α held at its start); C_m's only when
    it takes :data:`VANE_NOISE_SHARE` or more off C_m's mismatch RMS, C_X's always. ``gust`` is
    the gust estimate already made from these channels; None makes it again (after sensor
    corrections).

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
    :func:`spectra.air_share`, is this fit on C_Z).

    C_X's column is in its fit whatever its share: a drag polar's slope grows with α, so the
    wander e reaches C_X's mismatch as −(C_X,α + C_X''·Δα)·e, and its part Δα·e is what the
    vane's Δα², which carries e too, fits (errors in variables). An independent script's
    c172x null (173 ft/s, pitch 3-2-1-1 at 40 Hz) drew C_X α² −0.75 at t −8.2, the same
    flight's noise-free copy −0.16 at t −4.8 (the propeller's thrust, which the constant-thrust
    stand-in leaves in C_X); with the column, −0.55 at t −3.9, though it took 0.2 % of C_X's
    mismatch RMS. Both sweeps kept every score with it."""
    if "alpha" not in along.states or np.ptp(along.states["alpha"]) == 0.0:
        return {}
    if gust is None:
        gust, _ = turbulence_test(p)
    if gust.w_fps is None:
        return {}
    column = vane_error_column(slope_of, gust, V0, "Cm")
    inner = interior(p)
    z = mismatch["Cm"][inner]
    A = np.column_stack([column[inner], np.ones(z.size)])
    left = z - A @ np.linalg.lstsq(A, z, rcond=None)[0]
    share = 1.0 - float(np.std(left)) / max(float(np.std(z)), 1e-300)
    return ({"Cm": column} if share >= VANE_NOISE_SHARE else {}) | {"CX": vane_error_column(slope_of, gust, V0, "CX")}


def stepwise_fits(p: Prepared, propeller: bool, aero: AeroAlong, measured: dict[str, np.ndarray],
                  mismatch: dict[str, np.ndarray], delays: dict,
                  vane: dict[str, np.ndarray] | None = None) -> StepwiseFits:
    """Per-axis colored forward selection over the offered candidate terms (and the delay
    columns), with the thrust nuisance where thrust was not recorded and the α vane's noise
    column (:func:`vane_noise_columns`) where the model follows the vane; drift terms that
    thrust or a propeller would imitate are not offered."""
    selections, nuisances, not_offered, shares, pools, ar_t, unoffered = {}, {}, {}, {}, {}, {}, {}
    for axis in COEFFICIENTS:
        terms, skipped = cand.offered(p, cand.library(p, axis, aero.derivatives, measured, aero.coefficients))
        unoffered[axis] = [t for t in skipped if t.key in UNOFFERED_RIVALS]
        not_offered[axis] = [{"effect": t.effect, "parameter": t.parameter, "sources": list(t.sources)}
                             | ({"reason": t.details["not_offered"]} if "not_offered" in t.details else {})
                             for t in skipped]
        nuisance = _thrust_nuisance(p, axis, terms, propeller)
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
        selections[axis] = _select(p, axis, mismatch, terms, extra, nuisance, measured, shares, ar_t)
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
            selections[a] = _select(p, a, mismatch, terms, extra, nuisances[a], measured, shares, ar_t)
            pools[a] = (terms, extra)
        not_offered[axis].append({"effect": "cg_offset", "parameter": "dx_moment_reference", "sources": ["alpha"],
                                  "reason": test.reason})
    return StepwiseFits(selections, nuisances, not_offered, shares, pinned, ar_t, unoffered)


def pinned_shift(test: CgMeanTest, p: Prepared | None = None, trim: TrimPoint | None = None) -> Candidate:
    """The moment-reference shift C_m's mistrim says (:func:`_cg_mean_test`), a candidate
    named when significant (the entry t), practical (the mistrim at least
    :data:`candidates.PRACTICAL_SHARE` of C_m's excursion) and, given the recording ``p`` and
    the model's ``trim``, beyond the mistrim the thrust's own moment can make
    (:func:`thrust_mistrim_bound`) by two standard errors."""
    t = test.dx_ft / test.std_error_ft if test.std_error_ft > 0 else 0.0
    sel = abs(t) >= cand.T_IN and _practical(test.share)
    reason = "entered" if sel else ("not entered" if abs(t) < cand.T_IN else _impractical_reason(test.share))
    details = {"mistrim_share": test.share}
    if sel and p is not None and trim is not None:
        cbar, cz = p.meta["geometry"]["cbar_ft"], float(np.mean(p.measured["CZ"][interior(p)]))
        mistrim, se = abs(test.dx_ft * cz / cbar), abs(test.std_error_ft * cz / cbar)
        bound = thrust_mistrim_bound(p, trim)
        details["thrust_mistrim_bound"] = bound
        if mistrim - 2.0 * se < bound:
            sel = False
            reason = (f"not named: C_m's mistrim ({mistrim:.2g} ± {se:.1g}) is within what the thrust's moment "
                      f"through a thrust line {thrust_line_offset(p, trim):.2f} ft from the c.g. can make "
                      f"({bound:.2g}): thrust and its line were not recorded")
    return Candidate("cg_offset", cand.AXIS_NAME["Cm"], "Cm", "dx_moment_reference", test.dx_ft, test.std_error_ft,
                     t, test.explained, "ft", "the mistrim of C_m (its constant over the mean of C_Z)", sel, reason,
                     details)


def withhold_shift_within_thrust(cands: list[Candidate], step: StepwiseFits, p: Prepared, trim: TrimPoint,
                                 mismatch: dict[str, np.ndarray], measured: dict[str, np.ndarray]) -> None:
    """A moment-reference shift C_m's stepwise entered is named only when C_m's mistrim beside
    its other terms (the constant :func:`shift_mistrim_test` reads) stands two standard errors
    beyond what the thrust's own moment can make (:func:`thrust_mistrim_bound`), as a shift
    sized by the mistrim must (:func:`pinned_shift`). Its C_Z column follows α (C_Z is α as the
    accelerometer measures it, with less noise than the vane, so the stepwise may prefer it to
    a C_m,α change's α), and only the mistrim tells the two apart; a constant the thrust's
    moment can make does not. An independent script's T-37 (6,900 ft / 382 ft/s, pitch 3-2-1-1
    at 100 Hz, metric units) with C_m,α −0.15 had a 0.186 ft shift named (t 20; C_m,α at t 2.9
    beside it), its C_m constant −0.0042, the thrust's moment through the model's thrust line
    0.73 ft from the c.g. up to 0.0045."""
    if "thrust" in p.raw and "thrust_offset_ft" in p.meta:
        return
    bound = thrust_mistrim_bound(p, trim)
    cbar, cz = p.meta["geometry"]["cbar_ft"], float(np.mean(measured["CZ"][interior(p)]))
    for c in cands:
        if not (c.selected and c.parameter == "dx_moment_reference" and c.channel == "Cm"
                and c.test.startswith("stepwise")):
            continue
        test = shift_mistrim_test(p, c.estimate, "Cm", step.selections, step.nuisances, mismatch, measured)
        if test is None:
            continue
        mistrim, se = abs(test.dx_ft * cz / cbar), abs(test.std_error_ft * cz / cbar)
        c.details["thrust_mistrim_bound"] = bound
        if mistrim - 2.0 * se < bound:
            c.selected = False
            c.reason = (f"not named: C_m's mistrim beside its other terms ({mistrim:.2g} ± {se:.1g}) is within what "
                        f"the thrust's moment through a thrust line {thrust_line_offset(p, trim):.2f} ft from the c.g. "
                        f"can make ({bound:.2g}; thrust and its line were not recorded): the mean of C_m cannot tell "
                        "the shift from the C_m,α change its C_Z column imitates")


def withhold_stiffness_a_shift_makes(cands: list[Candidate], step: StepwiseFits, p: Prepared,
                                     mismatch: dict[str, np.ndarray], measured: dict[str, np.ndarray],
                                     trim: TrimPoint | None = None) -> None:
    """A C_m,α change is not named when a moment-reference shift reads as it and C_m's mean
    carries the mistrim that shift predicts: the shift Δx whose Δx·C_Z/c̄ is nearest the
    change's own contribution (least squares on the measured C_Z), tested by
    :func:`shift_mistrim_test` beside C_m's other terms, not refuted, its mistrim's own shift
    of the same sign :data:`CG_MEAN_Z` standard errors from zero, within a factor
    :data:`SHIFT_MEAN_FACTOR` of Δx and at least :data:`candidates.PRACTICAL_SHARE` of C_m's
    excursion. The pitch maneuver's C_Z follows α, and the stepwise can give the change to
    either column; a C_m,α change about trim explains nothing of C_m's constant. A probe's
    c172x (7,150 ft / 160 ft/s, pitch sweep, thrust not recorded) with its reference point
    0.16 ft from the model's had the stepwise's shift refuted by its wrong sign (its C_Z column
    shared with the α one), and the C_m,α change of +0.32 (a 0.15 ft shift) named in its place
    while C_m's constant said 0.24 ft. The shift the mistrim says is then the candidate in the
    change's place (:func:`pinned_shift`, with the model's ``trim`` for the thrust's bound): a
    probe's 787-8 (26,100 ft / 698 ft/s, three-axis, 1.7 times the noise, thrust not recorded)
    with its reference point 3.07 ft aft had C_m,α −1.12 entered (t 8.1) for it and withheld,
    C_m's constant saying −3.18 ± 0.04 ft, and nothing was named; likewise an F-16, an F-4N and
    a Cessna 172R with shifts of 0.16-0.67 ft (pitch maneuvers)."""
    _, by_key = step.selections.get("Cm", (None, {}))
    inner = interior(p)
    cbar = p.meta["geometry"]["cbar_ft"]
    cz = measured["CZ"][inner] - np.mean(measured["CZ"][inner])
    for c in cands:
        if not (c.selected and c.effect == "coefficient_error" and c.parameter == "Cm_alpha"
                and c.test.startswith("stepwise")):
            continue
        key = next((k for k, t in by_key.items() if t.parameter == c.parameter), None)
        change = c.details.get("change")
        if key is None or not change or float(cz @ cz) <= 0.0:
            continue
        contribution = change / by_key[key].scale * by_key[key].column[inner]
        dx = cbar * float(cz @ (contribution - np.mean(contribution))) / float(cz @ cz)
        test = shift_mistrim_test(p, dx, "Cm", step.selections, step.nuisances, mismatch, measured)
        if (test is None or test.refuted or np.sign(test.dx_ft) != np.sign(dx)
                or abs(test.dx_ft) < CG_MEAN_Z * test.std_error_ft or test.share < cand.PRACTICAL_SHARE
                or not 1.0 / SHIFT_MEAN_FACTOR <= test.dx_ft / dx <= SHIFT_MEAN_FACTOR):
            continue
        c.selected = False
        c.details["shift_alternative"] = {"dx_ft": dx, "mistrim_dx_ft": test.dx_ft,
                                          "mistrim_std_error_ft": test.std_error_ft}
        c.reason = (f"not named: a moment-reference shift of {dx:.3g} ft reads as this change on a maneuver whose C_Z "
                    f"follows α, and C_m's constant carries the mistrim of a {test.dx_ft:.3g} ± "
                    f"{test.std_error_ft:.2g} ft shift, which a C_m,α change about trim does not make: the shift is "
                    f"the candidate in its place (it had been: {c.reason})")
        if not any(o.selected and o.parameter == "dx_moment_reference" for o in cands):
            shift = pinned_shift(test, p, trim)
            shift.details["in_place_of"] = {"parameter": c.parameter, "change": change, "dx_ft": dx}
            cands.append(shift)


# How far (a factor either way) the shift C_m's mistrim says may lie from the one a C_m,α
# change reads as, for the two to be taken as one (withhold_stiffness_a_shift_makes).
SHIFT_MEAN_FACTOR = 2.0


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
            nuisance: dict, measured: dict[str, np.ndarray], shares: dict, ar_t: dict) -> tuple:
    """One axis's stepwise (:func:`candidates.axis_selection`), each term's share of the
    coefficient's excursion put in ``shares`` and each selected term's t with the AR residual
    autocorrelation in ``ar_t`` (:func:`candidates.autoregressive_t`); returns
    ``(selection, {key: Term})``."""
    inner = interior(p)
    sel = cand.axis_selection(p, axis, mismatch[axis], terms, extra, forced=nuisance)
    by_key = {t.key: t for t in terms}
    columns = {t.name: by_key[t.name].column if t.name in by_key else extra[t.name] for t in sel.terms}
    for t in sel.terms:
        shares[(axis, t.name)] = cand.contribution_share(columns[t.name][inner], t.estimate, measured[axis][inner])
    for k in [k for k in ar_t if k[0] == axis]:
        del ar_t[k]
    ar_t.update({(axis, n): t for n, t in cand.autoregressive_t(mismatch[axis], sel, columns, nuisance, inner).items()})
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
    shared the C_Z column with terms that follow α (C_Z does), oversizing it. Only for a shift
    C_m's stepwise entered: one read off C_n's C_Y column and refuted there stood in for a
    C_n term, and C_m's constant beside it is the model's own mistrim as much as any shift
    (an independent script's T-6 in a 20° turn, lateral multisine, C_n,β +0.03: C_n entered a
    shift for it, and the 0.03 ft C_m's constant said was named beside the C_n,β change; the
    same constant stands on the null, where C_n enters nothing)."""
    sel, by_key = selections[axis]
    if "cg" not in sel.names:
        return None
    test = shift_mistrim_test(p, sel.params["cg"] * by_key["cg"].scale, axis, selections, nuisances, mismatch,
                              measured)
    if test is not None and test.pinned and axis != "Cm":
        test = test._replace(pinned=False)
    if test is not None and test.pinned:
        test = test._replace(reason=test.reason + f", the mistrim of a {test.dx_ft:.3g} ± {test.std_error_ft:.2g} ft "
                                                  "shift, named instead")
    return test


def constant_beside_terms(p: Prepared, axis: str, selections: dict, nuisances: dict,
                          mismatch: dict[str, np.ndarray]) -> tuple[float, float]:
    """The constant of ``axis``'s mismatch over the interior beside the axis's entered terms
    (a moment-reference shift's excepted) and nuisance columns, and its standard error (a
    colored-residual fit, Eq. 5's standard errors)."""
    inner = interior(p)
    sel, terms = selections[axis]
    cols = [terms[k].column[inner] for k in sel.names if k in terms and k != "cg"]
    cols += [c[inner] for c in nuisances.get(axis, {}).values() if np.ptp(c[inner]) > 0]
    theta, se, _ = colored_fit(mismatch[axis][inner], cols, [f"x{i}" for i in range(len(cols))])
    return float(theta[-1]), float(se[-1])


def shift_mistrim_test(p: Prepared, dx: float, axis: str, selections: dict, nuisances: dict,
                       mismatch: dict[str, np.ndarray], measured: dict[str, np.ndarray]) -> CgMeanTest | None:
    """A moment-reference shift of ``dx`` ft, read off ``axis``'s mismatch, against the mean
    of C_m's mismatch beside C_m's entered terms (:func:`_cg_mean_test`, which applies it to
    the shift the stepwise entered; :func:`harness.diagnosis.term_rules.withhold_rivals` to
    a shift that would imitate another term). None when the mean of C_Z is zero."""
    inner = interior(p)
    cbar = p.meta["geometry"]["cbar_ft"]
    cz = float(np.mean(measured["CZ"][inner]))
    if cz == 0.0:
        return None  # no lift on average (a zero-g arc): the mean says nothing of a shift
    predicted = dx * cz / cbar
    mean, mean_se = constant_beside_terms(p, "Cm", selections, nuisances, mismatch)
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
    return CgMeanTest(True, reason, dx_mean, se_mean, bool(pinned), share, explained)


def _thrust_nuisance(p: Prepared, axis: str, terms: list, propeller: bool) -> dict[str, np.ndarray]:
    """Columns always in the fit of ``axis`` for what the thrust does outside the model's
    aerodynamics. Without a thrust channel (thrust held at trim), CX gets the airspeed
    change: a jet's thrust changes with airspeed at a fixed throttle, and no other term may
    stand in for it. C_m gets it on a propeller aircraft (the slipstream over the tail changes
    with the thrust); on a jet the thrust's moment is bounded instead
    (:func:`thrust_moment_bound`, :func:`withhold_thrust_drift`), and a C_m drift well
    beyond that bound is named. (With a thrust channel, Eqs. 1 and 4 use it, with the
    metadata's ``thrust_offset_ft``.)"""
    if axis not in ("CX", "Cm") or "thrust" in p.raw or (axis == "Cm" and not propeller):
        return {}
    return {"thrust_dV": t.column for t in terms if t.key == "dV"}


def thrust_line_offset(p: Prepared, trim: TrimPoint) -> float:
    """The thrust line's distance from the c.g. (ft): the larger of the metadata's
    ``thrust_offset_ft`` and the model's own at its trim."""
    return max(abs(float(p.meta.get("thrust_offset_ft", 0.0))), abs(trim.thrust_offset_ft))


def thrust_mistrim_bound(p: Prepared, trim: TrimPoint) -> float:
    """The C_m mistrim the thrust's own moment can make when thrust is not recorded: the mean
    over the maneuver's interior of ``T · |z_T| / (q̄ S c̄)``, T the model's trim thrust raised
    as far as the lapse :data:`THRUST_LAPSE_MAX` allows where the airspeed fell below its start,
    ``(V_0/V)^lapse``, q̄ the recorded dynamic pressure, z_T from :func:`thrust_line_offset`
    (zero with a thrust channel and the metadata's ``thrust_offset_ft``: Eqs. 1 and 4 then take
    the moment out). An independent script's A-4 (thrust line 1.04 ft above its c.g.) in a
    20° banked turn at 550 ft/s had a C_m constant of −0.0027 on its null, −0.0026 with C_m,α
    −0.25, where the stepwise entered a shift for the C_m,α change and the shift the mistrim
    says, 0.114 ft aft, was named. At the trim's q̄ alone the bound missed the slowing: an
    OV-10 (thrust line 0.94 ft from its c.g.) in a 33° banked turn at 348 ft/s, slowing to
    319 ft/s over a three-axis 3-2-1-1, with C_m,α −0.15, had a constant of 0.0072 ± 0.0004
    noise-free against a trim bound of 0.0073, and with twice the noise the 0.105 ft shift it
    says was named."""
    if "thrust" in p.raw and "thrust_offset_ft" in p.meta:
        return 0.0
    geo = p.meta["geometry"]
    inner = interior(p)
    qbar, V = p.smooth["qbar"][inner], p.smooth["V"][inner]
    lapse = np.maximum(1.0, (p.start["V"] / V) ** THRUST_LAPSE_MAX)
    return (abs(trim.thrust_lbf) * thrust_line_offset(p, trim) / (geo["S_ft2"] * geo["cbar_ft"])
            * float(np.mean(lapse / qbar)))


def thrust_moment_bound(p: Prepared, trim: TrimPoint) -> float:
    """The largest C_m change per unit ΔV/V that the thrust's moment can put into the
    mismatch when thrust is not recorded (held at trim): ``k · T · |z_T| / (q̄ S c̄)``, with T
    and q̄ at the model's trim and z_T from :func:`thrust_line_offset`.

    Seed Eq. 4 takes ``T · z_T`` out of the measured C_m with the metadata's
    ``thrust_offset_ft``; the model's C_m holds no thrust-line moment. With the offset given,
    the mismatch keeps the thrust's change, ``ΔT · z_T / (q̄ S c̄)``: k is the lapse
    :data:`THRUST_LAPSE_MAX`. Without it the whole moment stays, and its coefficient moves with
    the dynamic pressure that divides it as well, −2 per unit ΔV/V: k is
    ``THRUST_LAPSE_MAX`` + :data:`QBAR_PER_DV`. A noise-free F-15 flight of the model itself
    (13,400 ft / 742 ft/s, three-axis 3-2-1-1, slowing 17 %) drew C_m,ΔV −0.0026 (t −9),
    which its propulsive moment coefficient along the flight shows, −0.0025 (C_m,T 0.0009,
    thrust lapse −0.65); a C_l,δa change there named a C_m,ΔV −0.0036 ± 0.0007 beside it,
    past the lapse-only bound of 0.0015."""
    geo = p.meta["geometry"]
    k = THRUST_LAPSE_MAX + (0.0 if "thrust_offset_ft" in p.meta else QBAR_PER_DV)
    return k * abs(trim.thrust_lbf) * thrust_line_offset(p, trim) / (trim.qbar_psf * geo["S_ft2"] * geo["cbar_ft"])


def withhold_thrust_drift(cands: list[Candidate], p: Prepared, trim: TrimPoint) -> None:
    """Without a thrust channel, a C_m drift (ΔV/V term) on a jet is named only when it stands
    two standard errors beyond what the thrust's change could imitate
    (:func:`thrust_moment_bound`); the bound goes into its evidence and its reason either way
    (the finding rests on the thrust line the model and metadata give)."""
    if "thrust" in p.raw:
        return
    bound = thrust_moment_bound(p, trim)
    left = "" if "thrust_offset_ft" in p.meta else " and the dynamic pressure dividing its moment"
    why = (f"thrust was not recorded, and its change with airspeed{left}, through a thrust line "
           f"{thrust_line_offset(p, trim):.2f} ft from the c.g., could imitate a C_m drift of up to {bound:.2g} "
           "per unit ΔV/V")
    for c in cands:
        if c.parameter != "Cm_dV" or not c.test.startswith("stepwise"):
            continue
        c.details["thrust_bound"] = bound
        if c.selected and abs(c.estimate) - 2.0 * c.std_error < bound:
            c.selected, c.reason = False, f"not named: {why}"
        elif c.selected:
            c.reason += f"; {why}, under this one by more than two standard errors"


def withhold_on_moving_throttle(cands: list[Candidate], p: Prepared, propeller: bool) -> None:
    """When the recorded throttle moved and thrust was not recorded (:func:`throttle_travel`),
    deselect every candidate fitted to the mismatch of an axis the thrust's change enters (its
    terms, a moment-reference shift, the delay of its surface): C_X (its force) and C_m (its
    moment through the thrust line), and behind a propeller C_l and C_n as well (torque,
    P-factor, slipstream over the tail). The model holds thrust at trim, so the mismatch there
    carries the change, in the shape of whatever followed the throttle."""
    if p.recording is None or throttle_travel(p.recording) is None:
        return
    channels = THROTTLE_CHANNELS + (PROPELLER_THROTTLE_CHANNELS if propeller else ())
    for c in cands:
        if c.selected and c.channel in channels:
            c.selected, c.reason = False, NOT_WITH_THROTTLE


# The mismatch axes a thrust change enters, and the surfaces whose delays are fitted to them.
THROTTLE_CHANNELS = ("CX", "Cm", "de")
PROPELLER_THROTTLE_CHANNELS = ("Cl", "Cn", "da", "dr")
NOT_WITH_THROTTLE = ("not named: the throttle moved and thrust was not recorded; the model held thrust at trim, so "
                     "this axis's mismatch carries the thrust's change (record thrust_lbf)")


# How fast a jet's thrust may change with airspeed at a fixed throttle, |d ln T / d ln V|, for
# the bound on its moment (thrust_moment_bound): twice the -1 of constant power (T = P/V, the
# fastest a propeller's falls); a jet's net thrust, m_dot (V_jet - V) with m_dot rising with
# the ram pressure, falls more slowly than that.
THRUST_LAPSE_MAX = 2.0
# d ln q̄ / d ln V at a steady altitude: a thrust moment left in the measured C_m
# (no thrust_offset_ft) changes its coefficient by this much per unit ΔV/V (thrust_moment_bound).
QBAR_PER_DV = 2.0


PROPELLER_DRIFT = ("the propeller's torque, P-factor and slipstream change with airspeed at a fixed throttle, "
                   "outside the model's aerodynamic coefficients: a lateral drift term would fit them")
NO_THRUST_DRIFT = ("thrust was not recorded (held constant at trim): a drift in CX (or, behind a propeller, in Cm) "
                   "cannot be told from the thrust's own change with airspeed (its force; its moment and slipstream)")


def practical_size(name: str, dt: float) -> float:
    kind, _, channel = name.partition("_")
    if kind == "bias":
        return PRACTICAL["bias"].get(channel, 1.0)
    if kind == "scale":
        return PRACTICAL["scale"]
    if kind == "skew":
        return PRACTICAL["skew_samples"] * dt
    return PRACTICAL["offset_ft"]


# The smallest transport delay worth naming: PRACTICAL_DELAY_S, and at least
# PRACTICAL_DELAY_SAMPLES samples (practical_delay). Below it a delay cannot be told from the
# timing of the flown recordings themselves: the noise-free self-checks of the outside sweep
# show up to 13.1 ms at 50 Hz (0.65 sample: the 737's rudder and aileron, the DHC-6's
# aileron), 4.9 ms at 200 Hz (1 sample), none at 20 Hz; noisy nulls up to 12.9 ms at 20 Hz.
# Two samples, the rule until 4 Dec 2026, was the same 40 ms at 50 Hz but 100 ms at 20 Hz,
# where an 80 ms stabilator delay on the c172x (estimated 85 ms, t 35) went unnamed, and 10 ms
# at 200 Hz, twice a self-check's.
PRACTICAL_DELAY_S = 0.04
PRACTICAL_DELAY_SAMPLES = 1.5


def practical_delay(dt: float) -> float:
    """The smallest transport delay named (s) at sample interval ``dt``: three times the
    largest a noise-free self-check shows, and no less than :data:`PRACTICAL_DELAY_SAMPLES`
    samples (the self-checks reach one sample at 200 Hz)."""
    return max(PRACTICAL_DELAY_S, PRACTICAL_DELAY_SAMPLES * dt)


def _practical(share: float) -> bool:
    return share >= cand.PRACTICAL_SHARE


def _impractical_reason(share: float) -> str:
    return f"entered, but too small to matter: it explains {cand.share_below_practical(share)}"


def _stands_ar(ar_t: dict, axis: str, t) -> bool:
    v = ar_t.get((axis, t.name))
    return v is None or abs(v) >= cand.AR_ENTRY_T


def not_entered_reason(share: float, t_ar: float | None) -> str:
    """Why a term the stepwise entered is not a candidate finding: too small to matter, or
    not standing with the AR residual autocorrelation (:data:`candidates.AR_ENTRY_T`)."""
    if not _practical(share):
        return _impractical_reason(share)
    return (f"entered, but with the residual's autocorrelation from an autoregressive model of it t = {t_ar:.1f}, "
            f"under the entry t of {cand.AR_ENTRY_T:g}: the sample autocorrelation (seed Eq. 39) reads the error of "
            "a column whose power lies in a few frequencies too small there")


def aero_candidates(selections: dict, delays: dict, dt: float,
                    shares: dict[tuple[str, str], float] | None = None,
                    ar_t: dict[tuple[str, str], float] | None = None) -> list[Candidate]:
    """The stepwise fits' terms as candidates: a term is selected when it entered, matters
    (its share of the coefficient's excursion) and stands with the AR residual
    autocorrelation too (``ar_t``, :data:`candidates.AR_ENTRY_T`)."""
    shares = shares or {}
    ar_t = ar_t or {}

    def _practical_here(axis: str, t) -> bool:
        return _practical(shares.get((axis, t.name), 0.0)) and _stands_ar(ar_t, axis, t)
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
            sel = t.selected and _practical_here(axis, t)
            reason = ("entered" if sel else not_entered_reason(share, ar_t.get((axis, t.name)))
                      if t.selected else "not entered")
            out.append(Candidate(term.effect, cand.AXIS_NAME[axis], axis, term.parameter, est, se, t.t, t.gain,
                                 term.units, f"stepwise on the {axis} mismatch", sel, reason,
                                 ({"change": t.estimate, "model_over_maneuver": term.details["model_value"],
                                   "model_at_trim": term.details["trim_value"]}
                                  if term.effect == "coefficient_error" else {}) | {"excursion_share": share}))
    for s, rows in delay_seen.items():
        scan = delays[s]
        # significance from the stepwise entry of the delay column (its coefficient is τ);
        # size and standard error from the scan's linearised fit
        best = max(rows, key=lambda r: abs(r[1].t))[1]
        entered = any(t.selected and _practical_here(a, t) for a, t in rows)
        inside = scan.tau_s <= cand.DELAY_GRID_S[-1]
        sel = entered and inside and scan.tau_s >= practical_delay(dt)
        gain = max(t.gain for _, t in rows)
        out.append(Candidate("control_delay", "pitch" if s == "de" else ("roll" if s == "da" else "yaw"), s, f"tau_{s}",
                             scan.tau_s, scan.std_error, best.t, gain, "s", f"delay scan of {s} + stepwise", sel,
                             "entered" if sel else ("not entered" if not entered else
                                                    "entered, but the delay lies beyond the scanned 0-0.3 s: not an "
                                                    "actuator delay" if not inside else
                                                    f"entered, but under {1e3 * practical_delay(dt):.0f} ms, "
                                                    "the smallest delay named"),
                             {"axes": [a for a, _ in rows], "scan_t": scan.t, "stepwise_t": best.t}))
    if cg_seen:
        axis, t, term = max(cg_seen, key=lambda r: abs(r[1].t))
        sel = any(r[1].selected and _practical_here(r[0], r[1]) for r in cg_seen)
        out.append(Candidate("cg_offset", cand.AXIS_NAME[axis], axis, term.parameter, t.estimate * term.scale,
                             abs(t.std_error * term.scale), t.t, t.gain, "ft", f"stepwise on the {axis} mismatch",
                             sel, "entered" if sel else (not_entered_reason(shares.get((axis, t.name), 0.0),
                                                                            ar_t.get((axis, t.name)))
                                                         if t.selected else "not entered")))
    return out
