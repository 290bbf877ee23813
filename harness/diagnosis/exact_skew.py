"""Time skews judged by the exact shift, not by its first-order column.

The kinematic check (:mod:`harness.diagnosis.kinematics`) linearises every correction about
zero; a time skew's becomes x + τẋ. The term it leaves out, τ²ẍ/2, is τω/2 of the first
one: a quarter of it at 80 ms and 1 Hz, where an aircraft's short period lies. A linear
rival collinear with the skew's column (an α vane ahead of the c.g., x·q/V, against an α
skew, τ·α̇) can then fit the linearised equations better than the true skew does, and be
named in its place: a c172x recording at 5,000 ft / 190 ft/s with its α vane 80 ms late
named a vane 13.1 ft ahead at t 10.4, the skew at t 0.8 beside it, though the α record
shifted by exactly 80 ms leaves less kinematic residual than the vane at any offset.

So a selected sensor term is contested (the coefficient mismatch then decides,
:func:`harness.diagnosis.sensor_naming.kinematic_rivals`) when a collinear time skew,
applied as the exact shift x(t + τ) at its best τ, leaves less residual than the term itself
applied exactly at its best size near its estimate, with the other selected terms and the
forced biases fitted beside each.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError, partial_correlation, residual_after
from harness.diagnosis.kinematics import KinematicResult, kinematic_residuals
from harness.diagnosis.prepare import Prepared, interior_slice

# A skew is asked as a rival when its column's partial correlation with the selected term
# (the forced biases and other selected terms taken out) reaches this: below the 0.9 at which
# the linearised fit itself is left to the coefficient mismatch (rivals.RIVAL_CORRELATION),
# since the linearisation's own error makes the columns part where the exact shifts do not.
# The c172x's α skew against the α vane: 0.88.
SKEW_RIVAL_CORRELATION = 0.8


@dataclass(frozen=True)
class SkewRival:
    """A time skew that fits the kinematics better, applied exactly, than a selected term."""

    rival: str
    correlation: float
    tau: float            # the exact shift's best τ, s
    std_error: float      # the linearised column's standard error in the term's place, s
    rss_term: float       # residual sums of squares (weighted, stacked), the term applied exactly ...
    rss_skew: float       # ... and the skew at τ

    @property
    def t(self) -> float:
        return abs(self.tau) / self.std_error if self.std_error > 0 else 0.0


def fractional_shift(x: np.ndarray, tau: float, dt: float) -> np.ndarray:
    """x(t + τ) by the Fourier shift theorem on the record's even extension (no wrap-around
    step at the ends). Unlike linear interpolation it keeps the noise's power at every τ, so
    residuals at whole and fractional sample shifts compare fairly."""
    n = x.size
    ext = np.concatenate([x, x[::-1]])
    f = np.fft.rfftfreq(2 * n, dt)
    return np.fft.irfft(np.fft.rfft(ext) * np.exp(2j * np.pi * f * tau), 2 * n)[:n]


def stacked_residual(ch: dict[str, np.ndarray], p: Prepared, kin: KinematicResult) -> np.ndarray:
    """The weighted, stacked kinematic residual of channels ``ch``, as ``kin.start`` is made."""
    e = kinematic_residuals(ch, p)
    inner = interior_slice(p.n, p.dt)
    return np.concatenate([e[k][inner] * kin.weights[k] for k in kin.equations])


def _rss(z: np.ndarray, fixed: list[np.ndarray]) -> float:
    r = residual_after(z, fixed)
    return float(r @ r)


def skew_rival(kin: KinematicResult, p: Prepared, name: str) -> SkewRival | None:
    """The collinear time skew (:data:`SKEW_RIVAL_CORRELATION`) that, applied as the exact
    shift at its best τ, leaves less kinematic residual than selected term ``name`` applied
    exactly at its best size near its estimate (module docstring); None when there is none."""
    cols = kin.columns or {}
    if name not in cols or name.startswith("skew_"):
        return None
    others = [n for n in kin.forced + kin.selection.names if n != name and n in cols]
    fixed = [cols[n] for n in others]
    raw = dict(p.raw)
    sp = kin.parameters[name]
    own = _best_exact(lambda v: _rss(stacked_residual(sp.correct(raw, p, v), p, kin), fixed),
                      kin.selection.params[name], sp.step)
    best = None
    for rival, col in cols.items():
        if not rival.startswith("skew_") or rival in others or np.ptp(col) <= 0:
            continue
        r = partial_correlation(cols[name], col, fixed)
        if abs(r) < SKEW_RIVAL_CORRELATION:
            continue
        try:  # the linearised skew in the term's place: its start and standard error
            theta, se, _ = colored_fit(kin.start, fixed + [col], others + [rival], constant=False)
        except (SingularRegressorsError, np.linalg.LinAlgError):
            continue
        tau0, se0 = float(theta[-1]), float(se[-1])
        channel = kin.parameters[rival].channel

        def rss(tau: float) -> float:
            shifted = dict(raw)
            shifted[channel] = fractional_shift(raw[channel], tau, p.dt)
            return _rss(stacked_residual(shifted, p, kin), fixed)
        found = _best_exact(rss, tau0, 2.0 * p.dt, full=True)
        if found.fun < own and (best is None or found.fun < best.rss_skew):
            best = SkewRival(rival, r, float(found.x), se0, own, float(found.fun))
    return best


def _best_exact(rss, start: float, margin: float, full: bool = False):
    """The least of ``rss`` within twice ``start``'s size (plus ``margin``) either side of it:
    the exact correction's best size near the linearised one (its value; the optimiser's
    result when ``full``)."""
    span = 2.0 * abs(start) + margin
    found = minimize_scalar(rss, bounds=(start - span, start + span), method="bounded",
                            options={"xatol": span * 1e-3})
    return found if full else float(found.fun)


def scale_beside_exact_skew(kin: KinematicResult, p: Prepared, scale: str) -> float | None:
    """|t| of scale factor ``scale`` in the kinematic fit with its channel shifted exactly by
    the time skew the fit takes on it (:func:`term_beside_exact_skew`); None when the fit
    takes no skew on that channel.

    The first-order skew column leaves τ²ẍ/2 out (module docstring); on a channel moving at
    one frequency ω that is −τ²ω²/2 of the channel itself, which the linearised fit gives to
    a scale factor of +τ²ω²/2. An independent script's A-4 (539 ft/s, a 0.12-1.7 Hz sweep on
    aileron and rudder, 200 Hz) with r 71 ms late had the skew named (t 22) and beside it a
    scale of +0.054 on r (kinematic t 5.1), corroborated by C_n, which the same linearised
    correction reached."""
    return term_beside_exact_skew(kin, p, scale, f"skew_{kin.parameters[scale].channel}")


def term_beside_exact_skew(kin: KinematicResult, p: Prepared, term: str, skew: str) -> float | None:
    """|t| of selected kinematic term ``term`` with the channel of selected time skew ``skew``
    shifted exactly (the shift's best τ, :func:`fractional_shift`, with the skew's and the
    term's columns and the other selected terms fitted beside it); None when either is not
    in the fit. What the term fitted of the first-order skew column's leftover, τ²ẍ/2, is gone
    then; what it fits of its own error stays."""
    cols = kin.columns or {}
    if term not in cols or skew not in cols or skew not in kin.selection.names:
        return None
    channel = kin.parameters[skew].channel
    others = [n for n in kin.forced + kin.selection.names if n not in (term, skew) and n in cols]
    fixed = [cols[n] for n in others] + [cols[term]]
    raw = dict(p.raw)

    def shifted(tau: float) -> np.ndarray:
        return stacked_residual(raw | {channel: fractional_shift(raw[channel], tau, p.dt)}, p, kin)
    tau = _best_exact(lambda x: _rss(shifted(x), fixed), kin.selection.params[skew], 2.0 * p.dt, full=True).x
    try:
        theta, se, _ = colored_fit(shifted(float(tau)), fixed + [cols[skew]], others + [term, skew], constant=False)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return None
    return abs(float(theta[-2]) / float(se[-2])) if se[-2] > 0 else 0.0
