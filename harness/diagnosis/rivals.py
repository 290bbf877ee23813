"""Rivals: a term is named only when the data tell it from what would imitate it.

A stepwise regression enters the column that lowers the residual most, but a column nearly
collinear with it would have done almost as well, and when the two stand for different
physics (a C_m,α change and a moment-reference shift, whose column C_Z(t) follows α) the
choice is a coin toss the report must not present as a finding. Two kinds of rival:

* **A correlated candidate** on the same axis (correlation of the columns over the
  maneuver's interior at least :data:`TERM_RIVAL_CORRELATION`). The term is named only when it
  stays significant with the rival in the fit, |t| >= the entry t
  (:data:`harness.diagnosis.candidates.T_IN`). Its rival's size when fitted *in its place*
  is kept, so that the validation maneuver can say which of the two predicts better
  (``validation.validation_check``).
* **A bias of the α or β vane** that the kinematic check cannot rule out. The model is
  evaluated along the measured angle; a vane reading Δx high shifts the model's
  coefficients by its local slope times Δx, ``∂C/∂x(t)·Δx``. The constant part goes into
  the regression's intercept, but where the model is nonlinear in x the slope varies along
  the maneuver and the bias imitates an x-dependent term (a 1° α bias on the c172x looks
  like a C_X,α change through the curvature of its drag polar). The slope column is
  computed from the model itself (a second evaluation along the states, the angle shifted
  by :data:`SLOPE_STEP_RAD`); the term is withheld when it is not significant beside that
  column and the bias it would take lies within :data:`KINEMATIC_Z` standard errors of the
  kinematic estimate of the same bias (without an ``h`` channel, the kinematics hardly
  see an α bias).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from estimators.result import COLLINEARITY_LIMIT

# Columns correlated at least this much are rivals: the seed's collinearity limit (§III.G,
# pairwise |r| > 0.9 marks regressors whose estimates the data cannot separate).
RIVAL_CORRELATION = COLLINEARITY_LIMIT
# A same-axis candidate this correlated with a selected term is asked as its rival in the
# coefficient mismatch (:func:`harness.diagnosis.term_rules.withhold_rivals`): from here its
# column at least doubles the term's variance (1 / (1 − r²) ≥ 2), and whether the term then
# stands is its t beside it, not r. The seed's 0.9 is for white residuals and columns without
# noise; the mismatch's residual is colored, and a column built on a noisy channel correlates
# less with its rival than the clean signals do. An independent script's c172x (171.6 ft/s,
# three-axis multisine at 40 Hz) with C_m,q̂ −4 had C_m,δe +0.105 named (t 8.5): its column
# and q̂'s correlated −0.81 on that maneuver, and beside each other neither stood (t 2.8
# and −2.7); on the doublet validation maneuver they correlated −0.99. The kinematic check's
# gate is the same (:data:`harness.diagnosis.sensor_rules.KINEMATIC_RIVAL_CORRELATION`).
TERM_RIVAL_CORRELATION = 0.7
# A vane bias is ruled out by the kinematics only when it lies more than this many of their
# standard errors from their estimate.
KINEMATIC_Z = 3.0
# The angle step of the slope column's one-sided difference, rad (0.25 deg: small against
# the curvature of any table, large against the model's interpolation round-off).
SLOPE_STEP_RAD = 0.25 * np.pi / 180.0
BIAS_SOURCES = ("alpha", "beta")


@dataclass(frozen=True)
class Rival:
    """The strongest rival of a selected term: its name, how the term fares beside it, and
    the rival's coefficient when fitted in the term's place."""

    key: str
    correlation: float
    t_term: float        # the term's t with the rival in the fit
    t_rival: float       # the rival's t beside the term
    swapped: float       # the rival's coefficient fitted in the term's place


def t_pair(z: np.ndarray, others: list[np.ndarray], a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """The colored t of ``a`` and of ``b`` fitted together in ``z`` beside ``others`` and a constant."""
    theta, se, _ = colored_fit(z, others + [a, b], [f"o{i}" for i in range(len(others))] + ["a", "b"])
    j = len(others)
    return (float(theta[j] / se[j]) if se[j] > 0 else np.inf,
            float(theta[j + 1] / se[j + 1]) if se[j + 1] > 0 else np.inf)


def coefficient_beside(z: np.ndarray, others: list[np.ndarray], col: np.ndarray) -> float:
    """The least-squares coefficient of ``col`` in ``z`` beside ``others`` and a constant."""
    A = np.column_stack(others + [col, np.ones(z.size)])
    theta, *_ = np.linalg.lstsq(A, z, rcond=None)
    return float(theta[len(others)])


def strongest_rival(z: np.ndarray, columns: Mapping[str, np.ndarray], term: str, others: list[str],
                    pool: list[str], *, min_correlation: float = RIVAL_CORRELATION) -> Rival | None:
    """The rival in ``pool`` beside which ``term`` is least significant, among those whose
    column correlates with the term's by at least ``min_correlation``; None when there is
    none. ``others`` are the axis's other selected terms, kept in every fit."""
    a = columns[term]
    rest = [columns[n] for n in others]
    best: Rival | None = None
    for r in pool:
        b = columns[r]
        if np.ptp(b) <= 0 or np.ptp(a) <= 0:
            continue
        corr = float(np.corrcoef(a, b)[0, 1])
        if abs(corr) < min_correlation:
            continue
        try:
            t_term, t_rival = t_pair(z, rest, a, b)
        except (SingularRegressorsError, np.linalg.LinAlgError):
            t_term, t_rival = 0.0, 0.0
        if best is None or abs(t_term) < abs(best.t_term):
            best = Rival(r, corr, t_term, t_rival, coefficient_beside(z, rest, b))
    return best


# A slope that varies by less than this (per rad) along the maneuver is no slope: a bias of
# any plausible size moves the coefficient by less than 1e-9 with it. An independent script's
# A-4 (C_n does not depend on α in its model) had a C_n α·β coupling at t 52 withheld for an
# α-vane bias of −0.00° beside a C_n,α "slope" of 1e-13 per rad, the finite difference's rounding.
SLOPE_FLOOR = 1e-8


@dataclass(frozen=True)
class BiasRival:
    """A vane bias that would imitate a term: the bias it takes (rad), the term's t beside
    the model's slope column, and the kinematic estimate it is compared with."""

    channel: str
    bias_rad: float
    t_term: float
    kinematic: float
    kinematic_std: float

    @property
    def ruled_out(self) -> bool:
        return abs(self.bias_rad - self.kinematic) > KINEMATIC_Z * self.kinematic_std


def bias_rival(z: np.ndarray, term_column: np.ndarray, others: list[np.ndarray], slope: np.ndarray, channel: str,
               kinematic: tuple[float, float]) -> BiasRival | None:
    """Whether a bias of ``channel`` explains the mismatch ``z`` as well as the term does.

    ``slope`` is the model's ∂C/∂x along the states (per rad); the mismatch a bias Δx makes
    is ``−slope·Δx``, so the bias is minus the slope column's coefficient. ``kinematic`` is
    the kinematic check's (estimate, standard error) of the same bias. None when the slope
    does not vary along the maneuver (a constant: the intercept already absorbs it), or varies
    by less than :data:`SLOPE_FLOOR` (a coefficient that does not depend on the angle at all,
    its slope the finite difference's rounding)."""
    if np.ptp(slope) <= max(1e-9 * float(np.max(np.abs(slope))), SLOPE_FLOOR):
        return None
    try:
        t_term, _ = t_pair(z, others, term_column, slope)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        t_term = 0.0
    bias = -coefficient_beside(z, others, slope)
    return BiasRival(channel, bias, t_term, float(kinematic[0]), float(kinematic[1]))

