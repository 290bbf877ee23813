"""Drift terms a slow error of the model's own states imitates.

A flight-condition drift term (C ∝ ΔV/V, effects.md ``flight_condition_drift``) is the
slowest column a stepwise fit offers: its evidence lies at the record's lowest frequencies,
where the vanes' wander lives too (a Gauss-Markov wander is flat below 1/(2πτ)), and over a
30 s record such a wander may follow the airspeed's slow change by chance. The model
evaluated along an angle in error by Δβ(t) is off by ∂C/∂β·Δβ on every axis the angle
reaches, in the model's own proportions; a drift of the aerodynamics on one axis is not.
"""
from __future__ import annotations

import numpy as np

from harness.diagnosis import candidates as cand
from harness.diagnosis import corroborate
from harness.diagnosis.along import interior
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.prepare import Prepared
from harness.diagnosis.stepwise_axes import StepwiseFits


def withhold_lateral_drift_a_slow_sideslip_makes(cands: list[Candidate], step: StepwiseFits, p: Prepared,
                                                 mismatch: dict[str, np.ndarray], slope_of) -> None:
    """Deselect the lateral drift terms (C_Y, C_l, C_n ∝ ΔV/V) that a sideslip error following
    the drift column, Δβ = k·ΔV/V, explains on every lateral axis that can tell alike
    (:func:`corroborate.imitates`: each axis's mismatch fitted on −∂C/∂β·ΔV/V beside its other
    named terms and nuisances; ``slope_of`` the model's slopes along the states,
    :func:`along.slope_function`). A symmetric aircraft's lateral coefficients vanish at zero
    sideslip; three drifts in the proportions of C_Y,β, C_l,β and C_n,β are the sideslip the
    model followed drifting, not its aerodynamics. The inertial sideslip is placed on the vane
    by a constant, a trend and the integrals that gyro biases make (one of them ∫u dt, which
    follows the airspeed's change): an independent script's F-16 null (12,000 ft /
    528 ft/s, doublets at 3°, 100 Hz, the airspeed rising 40 ft/s) took the vane's slow
    wander (0.05° RMS below 0.2 Hz, correlated 0.82 with V) onto the inertial β (its error
    correlated 0.96 with V), and C_Y, C_l and C_n ΔV/V entered at t 12, 22 and −21 (7.7, 7.1
    and −7.4 along the vane itself)."""
    chosen = [c for c in cands if c.selected and c.effect == "flight_condition_drift" and c.channel in cand.LAT
              and c.channel in step.selections]
    if not chosen:
        return
    inner = interior(p)
    sel, by_key = step.selections[chosen[0].channel]
    drift = next(t.column for t in by_key.values() if t.parameter == chosen[0].parameter)
    slope = slope_of("beta")
    ratios = {}
    for axis in cand.LAT:
        if axis not in step.selections or axis not in mismatch:
            continue
        sel, by_key = step.selections[axis]
        others = [by_key[k].column[inner] for k in sel.names
                  if k in by_key and by_key[k].effect != "flight_condition_drift"]
        others += [v[inner] for v in step.nuisances.get(axis, {}).values() if np.ptp(v[inner]) > 0]
        r = corroborate.axis_ratio(mismatch[axis][inner], others, (slope[axis] * drift)[inner])
        if r is not None:
            ratios[axis] = r
    ag = corroborate.imitates(ratios, t_aero=cand.T_IN)
    if ag is None:
        return
    each = ", ".join(f"{a.axis} {np.degrees(a.ratio):.2f} ± {np.degrees(a.std_error):.2f}" for a in ag.axes)
    for c in chosen:
        c.selected = False
        c.reason = (f"entered, but a sideslip error following the drift column, Δβ = k·ΔV/V with k = "
                    f"{np.degrees(ag.ratio):.2f} ± {np.degrees(ag.std_error):.2f} deg, explains every lateral axis "
                    f"that can tell alike (k from {each}), in the model's own β slopes: the sideslip the model "
                    "followed drifted (the vane's slow wander), not its aerodynamics")
