"""A late control surface read as a set of aerodynamic terms: the rule that asks the stepwise
again with the surface's delay column in the fit."""
from __future__ import annotations

import numpy as np

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from harness.diagnosis import candidates as cand
from harness.diagnosis.along import interior
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.prepare import Prepared
from harness.diagnosis.stepwise_axes import StepwiseFits, practical_delay


def delay_column_t(z: np.ndarray, column: np.ndarray, nuisance: list[np.ndarray]) -> tuple[float, float]:
    """The delay column's coefficient (the delay τ, s: the column is the model's change per
    second of delay, :func:`candidates.delay_scan`) and its colored t, fitted on ``z``
    beside the axis's nuisance columns and a constant (Eq. 5, Eq. 40's standard error); zeros
    when the columns are dependent."""
    try:
        theta, se, _ = colored_fit(z, [column] + nuisance, ["delay"] + [f"n{i}" for i in range(len(nuisance))])
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return 0.0, 0.0
    return float(theta[0]), (float(theta[0] / se[0]) if se[0] > 0 else 0.0)


def name_the_delay_the_terms_imitate(cands: list[Candidate], step: StepwiseFits, delays: dict, p: Prepared,
                                     mismatch: dict[str, np.ndarray]) -> None:
    """Name a surface's delay, in place of the terms an axis it drives entered, when the
    stepwise asked again with the delay's column in the fit enters none of them.

    The forward selection enters by the white sum of squares (Eq. 5) and tests by the
    colored t (Eq. 40). On a slow aircraft the coefficient mismatch's own noise is slow and
    large, and a few derivative columns together (α, the surface, α̇) fit it and the late
    surface's −C_δ·δ̇·τ better than the delay's one column does, though by the colored t the
    delay alone is far the stronger. A probe's Cessna 182 at 4,800 ft and 188 ft/s (three-
    axis 3-2-1-1, twice the usual noise) with the elevator 60 ms late was named C_m,α +0.55,
    C_m,δe −0.27 and C_m,α̇ +10.5 (t 14, 9.8, 7.6): the delay column alone, τ 0.062 at t 11.7;
    beside it C_m,α stood at t 2.9 and nothing entered; the recording's change from its own
    null is the delay column at τ 0.060 to 0.3 % of its variance. Asked only where the scan's
    delay is positive, inside its grid and practical, and the delay column alone reaches the
    entry t with a positive τ on every axis whose terms are set aside."""
    inner = interior(p)
    for surface, scan in delays.items():
        delay = next((c for c in cands if c.parameter == f"tau_{surface}"), None)
        if delay is None or delay.selected or not practical_delay(p.dt) <= scan.tau_s <= cand.DELAY_GRID_S[-1]:
            continue
        replaced, t_best = [], 0.0
        for axis, column in scan.columns.items():
            sel, by_key = step.selections.get(axis, (None, {}))
            entered = [c for c in cands if c.selected and c.channel == axis and c.test.startswith("stepwise")]
            if sel is None or not entered:
                continue
            nuisance = dict(step.nuisances.get(axis, {}))
            tau, t = delay_column_t(mismatch[axis][inner], column[inner],
                                    [v[inner] for v in nuisance.values() if np.ptp(v[inner]) > 0])
            if tau <= 0.0 or t < cand.T_IN or _enters_beside(p, axis, mismatch[axis], by_key, nuisance,
                                                             {f"delay_{surface}": column}):
                replaced = []
                break
            replaced += entered
            t_best = max(t_best, t)
        if not replaced:
            continue
        names = ", ".join(c.parameter for c in replaced)
        for c in replaced:
            c.selected = False
            c.reason = (f"entered, but with {surface}'s delay column in the fit ({1e3 * scan.tau_s:.0f} ms, the "
                        "delay scan's) the stepwise enters no term: a late surface imitates it")
        delay.selected, delay.t = True, t_best
        delay.details["replaced"] = [c.parameter for c in replaced]
        delay.reason = (f"the stepwise entered {names} instead; its delay column alone stands at t = {t_best:.1f}, "
                        "and beside it no term enters")


def _enters_beside(p: Prepared, axis: str, z: np.ndarray, by_key: dict, nuisance: dict, delay: dict) -> bool:
    """Whether ``axis``'s stepwise enters any of its terms with the delay column ``delay``
    forced into the fit beside the nuisances (True, so nothing is replaced, when the forced
    columns are dependent)."""
    try:
        return bool(cand.axis_selection(p, axis, z, list(by_key.values()), forced=nuisance | delay).names)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return True
