"""Detection limits: what a verdict of ``none`` (or a short list) leaves possible.

Every tested parameter the diagnosis did not name has a size its estimate must reach before
its entry tests can name it: the test's entry t times the parameter's standard error
(significance), the share of the coefficient's excursion a term must explain (practical size,
:data:`candidates.PRACTICAL_SHARE`) and the share of the residual variance a stepwise term
must remove when it enters (:data:`candidates.MIN_GAIN`); for a sensor parameter, its entry t
and the smallest size worth naming (:data:`kinematics.PRACTICAL`); for a control delay, the
entry t and the smallest delay named. The limit is the largest of these (for a coefficient
error, on its change from the model's value).

It is a necessary condition only: an effect above it may still go unnamed (a rival imitates
it, the validation maneuver does not confirm it), so the limit says what the recording could
*not* have shown, not what it would have. And it bounds the *estimate*: an effect at the limit
is estimated above it about half the time, less often where the estimator shrinks it (a
C_m,q̂ change flown at 1.4 times the limit was estimated at 1.0 times it and not named, one at
twice the limit was named; tests/test_detection_limits.py).

Each standard error is the one the recording gave (the colored-residual bound of Eq. 5 with
Eqs. 38-40), so the limit moves with the noise, the maneuver's excitation and the record
length; it is stated on the identification maneuver only.
"""
from __future__ import annotations

import numpy as np

from harness.diagnosis import candidates as cand
from harness.diagnosis import kinematics
from harness.diagnosis.along import interior
from harness.diagnosis.evidence import Analysis, Candidate
from harness.diagnosis.prepare import COEFFICIENTS
from harness.diagnosis.stepwise_axes import practical_delay


def gain_floor(column: np.ndarray, fixed: list[np.ndarray], sse: float, min_gain: float = cand.MIN_GAIN) -> float:
    """The smallest estimate ``k`` of the coefficient of ``column`` whose entry removes
    ``min_gain`` of the residual variance (the stepwise's gain rule,
    :func:`colored_forward_selection`).

    With the term in the fit the residual sum of squares is ``sse``; without it the residual
    also carries ``k`` times the column's part orthogonal to the ``fixed`` columns and a
    constant, of sum of squares S⊥, so the gain is k²S⊥ / (sse + k²S⊥), and it reaches
    ``min_gain`` at k² = min_gain·sse / ((1 − min_gain)·S⊥). Infinite when the column lies in
    the span of the others."""
    A = np.column_stack(fixed + [np.ones(column.size)])
    rest = column - A @ np.linalg.lstsq(A, column, rcond=None)[0]
    s_perp = float(rest @ rest)
    if s_perp <= 1e-12 * max(float(column @ column), 1e-300):
        return np.inf
    return float(np.sqrt(min_gain * sse / ((1.0 - min_gain) * s_perp)))


def share_floor(column: np.ndarray, measured: np.ndarray, share: float = cand.PRACTICAL_SHARE) -> float:
    """The smallest coefficient whose term explains ``share`` of the measured coefficient's
    excursion (:func:`candidates.contribution_share` solved for the coefficient)."""
    spread = float(np.std(column))
    return share * float(np.std(measured)) / spread if spread > 0 else np.inf


def _stepwise_limit(a: Analysis, c: Candidate) -> dict | None:
    sel, by_key = a.selections.get(c.channel, (None, {}))
    key = next((k for k, t in by_key.items() if t.parameter == c.parameter), None)
    if sel is None or key is None:
        return None
    inner = interior(a.prepared)
    term = by_key[key]
    column = term.column[inner]
    fixed = [by_key[n].column[inner] for n in sel.names if n in by_key and n != key]
    fixed += [col[inner] for col in a.nuisances.get(c.channel, {}).values() if np.ptp(col[inner]) > 0]
    measured = (a.mismatch[c.channel] + a.aero.coefficients[c.channel])[inner]
    scale = abs(term.scale)
    # with the term in the fit: the final model's residual, or (a term not entered) that less its gain
    sse_with = sel.sse if key in sel.names else sel.sse * (1.0 - min(c.explained_fraction, 1.0))
    floors = {"significance": cand.T_IN * c.std_error,
              "gain": scale * gain_floor(column, fixed, sse_with),
              "practical size": scale * share_floor(column, measured)}
    out = _limit(c, floors)
    if c.effect == "coefficient_error":
        model = c.details.get("model_over_maneuver")
        if model is not None and np.isfinite(model):
            out["model_value"] = float(model)
            out["relative_to_model"] = out["limit"] / abs(model) if model else None
    return out


def _sensor_limit(a: Analysis, c: Candidate) -> dict:
    t_in = cand.T_IN if c.test.endswith("(bias always fitted)") else kinematics.T_IN
    return _limit(c, {"significance": t_in * c.std_error,
                      "practical size": kinematics.practical_floor(c.parameter, a.prepared.dt)})


def _delay_limit(a: Analysis, c: Candidate) -> dict:
    return _limit(c, {"significance": cand.T_IN * c.std_error, "practical size": practical_delay(a.prepared.dt)})


# Why an estimate above its limit stayed out when the stepwise never entered it: its floors
# are judged beside the final model, the stepwise's entry beside the terms entered before.
NOT_ENTERED = ("not entered: the stepwise stopped before it (it tries the column that removes the most first and "
               "stops at the first that fails the entry rules, at most 3 terms per axis)")


def estimated_size(c: Candidate) -> float:
    """The size a candidate's estimate gives the effect: a coefficient error's change from the
    model's value, any other parameter's estimate."""
    return abs(float(c.details.get("change", c.estimate))) if c.effect == "coefficient_error" else abs(c.estimate)


def _limit(c: Candidate, floors: dict[str, float]) -> dict:
    rule = max(floors, key=lambda k: floors[k])
    limit = float(floors[rule])
    out = {"effect": c.effect, "parameter": c.parameter, "units": c.units, "limit": limit,
           "estimate": estimated_size(c), "std_error": float(c.std_error), "rule": rule,
           "floors": {k: float(v) for k, v in floors.items()}}
    if out["estimate"] >= limit:  # the estimate cleared every floor: another rule withheld it
        out["withheld"] = NOT_ENTERED if c.reason == "not entered" else c.reason
    return out


def detection_limits(a: Analysis) -> list[dict]:
    """For each parameter the identification maneuver tested and the diagnosis did not name,
    the size its estimate must reach to be named (module docstring), as ``{'effect',
    'parameter', 'units', 'limit', 'estimate', 'std_error', 'rule', 'floors'}`` (``estimate`` is
    the estimated size, :func:`estimated_size`; a coefficient error also gives its model value
    and the limit relative to it; an estimate at or above its limit, withheld by another rule,
    gives that rule's words as ``withheld``); coefficient axes in :data:`prepare.COEFFICIENTS`
    order, then the delays, then the sensors. Parameters the maneuver did not test are in
    ``not_checked`` instead."""
    aero, delays, sensors = [], [], []
    for c in a.candidates:
        if c.selected or not np.isfinite(c.std_error) or c.std_error <= 0:
            continue
        if c.test.startswith("stepwise on the") and c.channel in COEFFICIENTS:
            row = _stepwise_limit(a, c)
            if row is not None:
                aero.append((COEFFICIENTS.index(c.channel), row))
        elif c.effect == "control_delay":
            delays.append((0, _delay_limit(a, c)))
        elif c.test.startswith("kinematic consistency"):
            sensors.append((0, _sensor_limit(a, c)))
    return [row for group in (aero, delays, sensors)
            for _, row in sorted(group, key=lambda r: (r[0], r[1]["parameter"]))]
