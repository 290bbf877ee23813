"""Corroborated sensor errors: one instrument error seen by two independent tests.

The kinematic check names a sensor error on its own only at |t| >= its entry t
(:data:`harness.diagnosis.kinematics.T_IN`, 6). Below that, a scale, lag or vane error it
merely *suspects* already keeps the coefficient terms it would imitate from being named
(``term_rules.withhold_ambiguous``, the vane-bias rival of :mod:`rivals`). The coefficient
mismatch is then a second, independent test of the same instrument error: the model's
aerodynamics are evaluated along the recorded states (seed Eqs. 1-5), so a sensor error
leaves a definite signature on *every* axis.

The signature is computed, not assumed: the channels are corrected by the kinematic
estimate ``v`` (the sensor's own correction), the model is evaluated again along them,
and the mismatch changes by ``Δ_C(t)`` on each axis ``C``. If the instrument is in error by
``a·v`` the mismatch carries ``-a·Δ_C(t)``, so a fit of each axis's mismatch on ``-Δ_C``
(beside the axis's other named terms, with a constant; colored-residual standard errors,
seed Eq. 39) gives ``a_C ± σ_C``. The error is named when

* the axes that can tell (``σ_C`` at most :data:`INFORMATIVE_SE`) agree with one ratio
  ``â`` (each within :data:`AGREE_Z` of its standard errors, or :data:`AGREE_FRACTION`),
  which a single coefficient error hardly does: a wrong C_Z,α moves C_Z alone, a wrong α
  vane moves C_Z, C_m and C_X by the model's own slopes (a change of lift moves C_X with C_Z
  nearly in the vane's proportion, and C_m through the reference point's arm: the mistrim
  below tells them apart);
* the aerodynamic evidence is significant on its own (``â/σ_â`` at least the aerodynamic
  entry t; σ_â allowing for the axes' estimates' correlation, :func:`estimate_correlation`:
  every axis carries the model's slope times the same vane wander);
* it agrees with the kinematic estimate (``|â - 1|`` within :data:`AGREE_Z` of the
  combined standard error, and for a rate gyro's skew one sample interval more:
  :func:`gyro_skew_tolerance`);
* the mismatch carries the mistrim a scale error makes at trim, which the ratios (fitted
  with a constant) leave out (:func:`mistrim_test`).

The size named is the inverse-variance mean of the two estimates.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.signal import correlate

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from harness.diagnosis.candidates import AMBIGUOUS_T, PRACTICAL_SHARE

# An axis takes part when it determines the ratio to within ±100 % (one standard error).
INFORMATIVE_SE = 1.0
# Agreement: within this many standard errors ...
AGREE_Z = 3.0
# ... or this fraction of the common ratio (the model's slopes carry their own small errors).
AGREE_FRACTION = 0.3
# The lag window of the axes' estimates' correlation, in correlation times of their residuals
# (:func:`_bartlett_lag`): a Gauss-Markov wander's correlation is recovered from 2 on.
LAG_WINDOW_TIMES = 2
# A correlation of the axes' estimates counts only when it stands this many times above its
# own scatter, read from this many circular shifts of one residual (:func:`estimate_correlation`).
SURROGATE_Z = 2.0
SURROGATES = 16


@dataclass(frozen=True)
class AxisRatio:
    """One axis's estimate of the sensor error, as a multiple of the kinematic estimate;
    ``influence`` (the estimate's row of the fit's pseudo-inverse) and ``residual`` let its
    correlation with another axis's estimate be computed (:func:`estimate_correlation`)."""

    axis: str
    ratio: float
    std_error: float
    influence: np.ndarray | None = field(default=None, repr=False, compare=False)
    residual: np.ndarray | None = field(default=None, repr=False, compare=False)
    mean: float = np.nan              # the mismatch's constant beside the other terms, without the signature,
    mean_se: float = np.nan           # and its standard error (:func:`mistrim_test`)
    signature_mean: float = np.nan    # the signature's mean over the maneuver (per unit ratio)
    imitator: str = ""                # the axis's own candidate term most collinear with the signature,
    imitator_r: float = 0.0           # and that correlation (:func:`imitated_by_own_terms`)
    share: float = np.nan             # the mismatch the fitted signature makes, over the coefficient's excursion
    beside_imitator: tuple[float, float] = (np.nan, np.nan)  # the signature's and the imitator's t fitted together

    def scaled(self, axis: str, factor: float) -> AxisRatio:
        """The same estimate in other units (ratio and standard error times ``factor``)."""
        return AxisRatio(axis, self.ratio * factor, self.std_error * abs(factor),
                         None if self.influence is None else self.influence * factor, self.residual,
                         self.mean, self.mean_se, self.signature_mean / factor if factor else np.nan,
                         self.imitator, self.imitator_r, self.share, self.beside_imitator)


@dataclass(frozen=True)
class Corroboration:
    """The aerodynamic test of a suspected sensor error, and its verdict."""

    name: str
    kinematic: float
    kinematic_std: float
    axes: tuple[AxisRatio, ...]
    ratio: float              # â, the informative axes' common ratio
    ratio_std: float
    named: bool
    reason: str
    estimate: float           # the combined size (the kinematic one when not named)
    std_error: float

    def as_dict(self) -> dict:
        return {"kinematic": self.kinematic, "kinematic_std": self.kinematic_std,
                "aerodynamic": self.ratio * self.kinematic, "aerodynamic_std": abs(self.ratio_std * self.kinematic),
                "axes": {a.axis: _axis_dict(a) for a in self.axes},
                "named": self.named, "reason": self.reason}


def _axis_dict(a: AxisRatio) -> dict:
    out = {"ratio": a.ratio, "std_error": a.std_error}
    if a.imitator:
        out |= {"imitator": a.imitator, "imitator_r": a.imitator_r, "share": a.share}
    if np.all(np.isfinite(a.beside_imitator)):
        out["beside_imitator"] = {"t_signature": a.beside_imitator[0], "t_term": a.beside_imitator[1]}
    if np.isfinite(a.mean):
        out |= {"mean": a.mean, "mean_std_error": a.mean_se, "signature_mean": a.signature_mean}
    return out


def axis_ratio(z: np.ndarray, others: list[np.ndarray], signature: np.ndarray,
               constant: bool = True, offered: dict[str, np.ndarray] | None = None,
               excursion: float = np.nan) -> AxisRatio | None:
    """``a ± σ`` of ``z ≈ others·θ - a·signature + c`` (colored-residual standard error);
    without ``c`` when not ``constant`` (a bias's signature is nearly a constant). None when
    the signature is flat (or, with the constant, dependent on the others). ``offered``: the
    axis's candidate columns by parameter, of which the one most collinear with the
    signature (beside the others) is kept (:func:`most_collinear`); ``excursion``: the measured
    coefficient's RMS about its mean, over which the fitted signature's RMS is its share."""
    if np.ptp(signature) <= 0 if constant else not np.any(signature):
        return None
    try:
        theta, se, residual = colored_fit(z, others + [-signature], [f"o{i}" for i in range(len(others))] + ["a"],
                                          constant=constant)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return None
    j = len(others)
    A = np.column_stack(others + [-signature] + ([np.ones(z.size)] if constant else []))
    influence = np.linalg.pinv(A)[j]
    mean, mean_se = np.nan, np.nan
    if constant:  # the mismatch's own constant beside the other terms (the signature's mean left out)
        theta0, se0, _ = colored_fit(z, others, [f"o{i}" for i in range(len(others))])
        mean, mean_se = float(theta0[-1]), float(se0[-1])
    imitator, r = most_collinear(signature, others, offered or {}, constant)
    share = abs(float(theta[j])) * float(np.std(signature)) / excursion if excursion > 0 else np.nan
    beside = _beside(z, others, signature, offered[imitator], constant) if imitator else (np.nan, np.nan)
    return AxisRatio("", float(theta[j]), float(se[j]) if se[j] > 0 else np.inf, influence, residual, mean, mean_se,
                     float(np.mean(signature)), imitator, r, share, beside)


def _beside(z: np.ndarray, others: list[np.ndarray], signature: np.ndarray, term: np.ndarray,
            constant: bool) -> tuple[float, float]:
    """The signature's and an own term's t fitted together beside ``others`` (NaN when they
    cannot be)."""
    try:
        theta, se, _ = colored_fit(z, others + [-signature, term], [f"o{i}" for i in range(len(others))] + ["a", "b"],
                                   constant=constant)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return np.nan, np.nan
    j = len(others)
    return tuple(float(theta[k] / se[k]) if se[k] > 0 else np.nan for k in (j, j + 1))


def most_collinear(signature: np.ndarray, others: list[np.ndarray], offered: dict[str, np.ndarray],
                   constant: bool = True) -> tuple[str, float]:
    """The offered column most correlated with ``signature`` once both are made orthogonal to
    ``others`` (and a constant), and that |correlation|; ('', 0) when none is offered."""
    cols = others + ([np.ones(signature.size)] if constant else [])
    def rest(x: np.ndarray) -> np.ndarray:
        if not cols:
            return x
        B = np.column_stack(cols)
        return x - B @ np.linalg.lstsq(B, x, rcond=None)[0]
    s = rest(signature)
    ns = float(np.linalg.norm(s))
    best, r_best = "", 0.0
    for name, col in offered.items():
        c = rest(col)
        nc = float(np.linalg.norm(c))
        if ns > 0 and nc > 0:
            r = abs(float(np.dot(s, c))) / (ns * nc)
            if r > r_best:
                best, r_best = name, r
    return best, r_best


def _bartlett_lag(residuals: list[np.ndarray]) -> int:
    """The lag window of :func:`estimate_correlation`: :data:`LAG_WINDOW_TIMES` the lag at
    which the residuals' mean normalised autocorrelation first falls under 1/e (their
    correlation time), at least 1 and at most a quarter of the record."""
    n = residuals[0].size
    acf = sum(correlate(v, v, method="fft")[n - 1:] / max(float(np.dot(v, v)), 1e-300) for v in residuals)
    below = np.flatnonzero(acf / len(residuals) < np.exp(-1.0))
    first = int(below[0]) if below.size else n
    return int(np.clip(LAG_WINDOW_TIMES * first, 1, n // 4))


def estimate_correlation(a: AxisRatio, b: AxisRatio) -> float:
    """The correlation of two axes' estimates of one sensor error, made from the same maneuver:
    seed Eq. 40 for two outputs, Cov(â, b̂) = Σ_τ w(τ) R_ab(τ) Σ_t g_a(t) g_b(t + τ), with g the
    estimates' rows of their fits' pseudo-inverses, R_ab(τ) = (1/N) Σ_u v_a(u) v_b(u + τ) the
    residuals' cross-correlation and w a Bartlett window over a few of their correlation
    times (:func:`_bartlett_lag`); each variance the same sum with a = b. With all lags, as
    the standard errors themselves are computed, the estimate scatters ±0.37 about zero for
    independent white residuals of a 30 s record at 50 Hz (±0.03 with the window), and the
    window still recovers a shared Gauss-Markov wander (τ 1 s, half the residuals' variance)
    as −0.89 ± 0.10 against the estimates' −0.95 (Monte Carlo). A correlation under
    :data:`SURROGATE_Z` times the scatter of the same statistic with one residual moved
    circularly past its correlation time (:data:`SURROGATES` shifts) is read as none. Zero
    when either axis lacks its influence or residual.

    The axes are not independent tests of a vane error: each carries the model's slope times
    the vane's own wander (the model is evaluated along the vane), so a wander that follows
    the error's signature by chance moves every axis's estimate alike."""
    if a.influence is None or b.influence is None or a.residual is None or b.residual is None:
        return 0.0
    n = a.residual.size
    lag = _bartlett_lag([a.residual, b.residual])
    k = np.arange(-(n - 1), n)
    window = np.clip(1.0 - np.abs(k) / (lag + 1.0), 0.0, 1.0)
    g_ab = correlate(b.influence, a.influence, method="fft")

    def cov(va: np.ndarray, vb: np.ndarray, g: np.ndarray) -> float:
        return float(np.dot(window * correlate(vb, va, method="fft"), g) / n)
    var_a = cov(a.residual, a.residual, correlate(a.influence, a.influence, method="fft"))
    var_b = cov(b.residual, b.residual, correlate(b.influence, b.influence, method="fft"))
    if var_a <= 0 or var_b <= 0:
        return 0.0
    rho = cov(a.residual, b.residual, g_ab) / np.sqrt(var_a * var_b)
    # the same statistic with b's residual moved circularly far past its correlation time
    # (independent of a's, with the spectra kept): its scatter is the estimate's own noise
    shifts = [(j * n) // (SURROGATES + 1) for j in range(1, SURROGATES + 1)]
    null = [cov(a.residual, np.roll(b.residual, m), g_ab) / np.sqrt(var_a * var_b) for m in shifts
            if lag < m < n - lag]
    noise = float(np.sqrt(np.mean(np.square(null)))) if null else 0.0
    if abs(rho) < SURROGATE_Z * noise:
        return 0.0
    return float(np.clip(rho, -1.0, 1.0))


def inverse_variance_mean_correlated(estimates, std_errors, correlation: np.ndarray) -> tuple[float, float]:
    """The inverse-variance mean of estimates of one quantity (:func:`inverse_variance_mean`)
    and its standard error when they are correlated: √(wᵀ Σ w), w the weights and
    Σ = D·ρ·D. The weights stay the independent ones, so the mean is the same; only its
    standard error allows for what the estimates share (with ρ = 1 throughout it is the
    weighted mean of the σ's, not 1/√Σσ⁻²)."""
    x = np.asarray(estimates, dtype=float)
    d = np.asarray(std_errors, dtype=float)
    w = 1.0 / d ** 2
    w /= w.sum()
    var = float(w @ (np.asarray(correlation, dtype=float) * np.outer(d, d)) @ w)
    return float(w @ x), float(np.sqrt(max(var, 0.0)))


@dataclass(frozen=True)
class Agreement:
    """The informative axes' common ratio ``â ± σ_â`` and the axes that depart from it."""

    axes: tuple[AxisRatio, ...]
    ratio: float
    std_error: float
    apart: tuple[AxisRatio, ...]

    @property
    def t(self) -> float:
        return self.ratio / self.std_error if self.std_error > 0 else 0.0

    def text(self) -> str:
        return ", ".join(f"{a.axis} {a.ratio:.2f} ± {a.std_error:.2f}" for a in self.axes)


def inverse_variance_mean(estimates, std_errors) -> tuple[float, float]:
    """The inverse-variance weighted mean of independent estimates and its standard error,
    1/√Σσ⁻² (the minimum-variance unbiased combination)."""
    w = 1.0 / np.square(np.asarray(std_errors, dtype=float))
    return float(np.dot(w, np.asarray(estimates, dtype=float)) / w.sum()), float(1.0 / np.sqrt(w.sum()))


def agreement(ratios: dict[str, AxisRatio], correlated: bool = False) -> Agreement | None:
    """The axes that can tell (σ at most :data:`INFORMATIVE_SE`), their inverse-variance
    common ratio (``correlated``: its standard error allowing for the axes' estimates'
    correlation, :func:`estimate_correlation`), and those that depart from it by more than
    :data:`AGREE_Z` standard errors and :data:`AGREE_FRACTION`; None when no axis can tell."""
    axes = tuple(r.scaled(k, 1.0) for k, r in sorted(ratios.items())
                 if np.isfinite(r.std_error) and r.std_error <= INFORMATIVE_SE)
    if not axes:
        return None
    if correlated and len(axes) > 1:
        rho = np.array([[1.0 if a is b else estimate_correlation(a, b) for b in axes] for a in axes])
        a_hat, se = inverse_variance_mean_correlated([a.ratio for a in axes], [a.std_error for a in axes], rho)
    else:
        a_hat, se = inverse_variance_mean([a.ratio for a in axes], [a.std_error for a in axes])
    apart = tuple(a for a in axes if abs(a.ratio - a_hat) > max(AGREE_Z * a.std_error, AGREE_FRACTION * abs(a_hat)))
    return Agreement(axes, a_hat, se, apart)


def imitates(ratios: dict[str, AxisRatio], *, t_aero: float) -> Agreement | None:
    """The agreement when a sensor error explains the mismatch on at least two axes alike,
    clearly (``t`` at least ``t_aero``): then a coefficient error on one of those axes
    cannot be told from it by the coefficients alone. None otherwise.

    The ratios are relative to a probe size; they are first put relative to the size all
    axes together ask for (so that an axis counts as informative, :data:`INFORMATIVE_SE`,
    when it can tell *that* size from zero), and the agreement is returned in probe units."""
    finite = [r for r in ratios.values() if np.isfinite(r.std_error) and r.std_error > 0]
    if not finite:
        return None
    a0, s0 = inverse_variance_mean([r.ratio for r in finite], [r.std_error for r in finite])
    if abs(a0) / s0 < t_aero:
        return None
    ag = agreement({k: r.scaled(k, 1.0 / a0) for k, r in ratios.items()})
    if ag is None or len(ag.axes) < 2 or ag.apart:
        return None
    axes = tuple(a.scaled(a.axis, a0) for a in ag.axes)
    return Agreement(axes, ag.ratio * a0, ag.std_error * abs(a0), ())


def gyro_skew_tolerance(name: str, dt: float) -> float:
    """How far the kinematics' and the coefficient mismatch's sizes of a rate gyro's time skew
    may lie apart for a simulated recording: one sample interval ``dt``. A simulator that
    integrates the rates and the attitude by rectangular Euler (JSBSim) leaves the attitude's
    difference h/2 behind the gyros, which the kinematics read as a gyro lead, and the rates'
    difference h/2 behind the moments, which the moment mismatch reads as a lag, h the step
    (no longer than the recording's). An independent script's 737 at 100 Hz with p 40 ms late:
    the kinematics 34 ± 3 ms, the C_l mismatch 45 ± 1 ms. Zero for any other parameter."""
    return dt if name in ("skew_p", "skew_q", "skew_r") else 0.0


def mistrim_test(axes: tuple[AxisRatio, ...], ratio: float, ratio_std: float) -> str:
    """Why the error's mean signature refutes it, '' when it does not. A scale error acts on
    the channel's whole value, trim included (x_r = (1 + k)·x): the model evaluated along
    it is off at trim too, by the signature's mean, which the ratios (fitted with a constant)
    do not use. A change of the aerodynamics that vanishes at trim (a derivative's, about
    the trim α) imitates the scale's perturbation on every axis it moves, but not its
    mistrim. On each axis where the mistrim ``ratio`` (``± ratio_std``) predicts stands
    :data:`MISTRIM_Z` standard errors from none, the mismatch's own constant beside its other
    terms is set against it; only a constant short of the prediction by :data:`MISTRIM_SHARE`
    of it and :data:`MISTRIM_Z` standard errors refutes (one beyond it may carry a trim error
    of the model's besides; an error whose signature has hardly a mean, a time skew's, is not
    tested: the model's own trim error would decide). An independent script's F-16 with lift
    +0.6 per rad about the trim α (8,000 ft / 400 ft/s, doublets, twice the noise) had an α
    scale of −0.078 named by the kinematics (t 4.3; −0.057 at t 3.6 on the same noise without
    the lift change) and C_X, C_Z, C_m: its C_Z mistrim of −0.028 was missing (+0.002 ± 0.002).
    A bias's signature is fitted without a constant, so there is no mean of its own to test."""
    for a in axes:
        if not (np.isfinite(a.mean) and np.isfinite(a.signature_mean)):
            continue
        predicted = -ratio * a.signature_mean
        sigma = float(np.hypot(a.mean_se, ratio_std * a.signature_mean))
        short = (predicted - a.mean) * np.sign(predicted)
        # a mistrim the axis can tell from none, and a constant short of it
        if abs(predicted) > MISTRIM_Z * sigma and short > max(MISTRIM_SHARE * abs(predicted), MISTRIM_Z * sigma):
            return (f"refuted by the mean of {a.axis}: the error would mistrim {a.axis} by {predicted:+.2g} "
                    f"± {ratio_std * abs(a.signature_mean):.1g}; its mismatch has a constant of {a.mean:+.2g} "
                    f"± {a.mean_se:.1g} (a change of the aerodynamics that vanishes at trim imitates it)")
    return ""


# A mean signature refutes an error when the mismatch's constant falls short of it by this share
# of it and this many standard errors (:func:`mistrim_test`).
MISTRIM_SHARE = 0.5
MISTRIM_Z = 3.0


def imitated_by_own_terms(axes: tuple[AxisRatio, ...], t_kinematic: float = np.inf) -> str:
    """Why the coefficient mismatch is no second test of the error, '' when it is one. Of the
    axes that show the error (their ratio at least :data:`SHOWING_T` standard errors from
    none), one at least must tell it from a change of one of its own terms: the signature no
    more collinear with any of them than :data:`IMITATOR_R`, or the mismatch it makes a
    practical share of the coefficient's excursion (:data:`candidates.PRACTICAL_SHARE`; a
    derivative off by less is within the model's own artefacts: noise-free recordings of the
    model show up to 0.017, and a simulation's timing artefacts move every rate derivative
    alike). An airspeed error meets a recorded q̄ only through the rate derivatives'
    normalisation (p̂ = pb/2V): on an independent script's Global 5000 null (25,000 ft /
    585 ft/s, three-axis multisine at 100 Hz, half the noise) the kinematics suspected a V
    scale of −0.059 (t 3.4) and C_l's mismatch followed its signature 0.71 ± 0.13 times, a
    C_l,p̂ change of 3 % (r = 0.988, a share of 0.026) that no other axis showed; on an F-16
    with a C_l,δa change (12,000 ft / 528 ft/s, doublets at 100 Hz) C_l and C_m followed a V
    scale of −0.019 (t 3.2) 1.6 and 1.5 times, as C_l,p̂ and C_m,q̂ changes of 2-3 % (r ≥ 0.998,
    shares 0.025 and 0.012). Each was named. An a_z skew of 80 ms on C_Z is collinear with
    C_Z,α̇ (r = 0.974) but makes a share of 0.097, a C_Z,α̇ of +25 per rad.

    A practical share says that something changed, not that it was the sensor: where every
    showing axis is imitated, the share tells only when the kinematics (``t_kinematic``) stand
    at :data:`ONE_AXIS_KINEMATIC_T` on their own. An independent script's Global 5000 with a
    C_m,q̂ change of −4 (33,000 ft / 723 ft/s, doublets in a 27° turn, 50 Hz) had an α vane
    named 18 ft ahead of the c.g.: the kinematics suspected 11 ± 4.4 ft (t 2.5), C_m followed
    the vane's signature 2.0 ± 0.2 times as a C_m,q̂ change (r 0.999, a share of 0.040), C_X
    and C_Z at 1.25 ± 0.53 and 0.59 ± 0.52 as their own q̂ terms (r 0.97, 1.0)."""
    showing = [a for a in axes if a.std_error > 0 and abs(a.ratio) / a.std_error >= SHOWING_T]
    suspected = abs(t_kinematic) >= ONE_AXIS_KINEMATIC_T
    if not showing or any(a.imitator_r < IMITATOR_R or (a.share >= PRACTICAL_SHARE and suspected) for a in showing):
        return ""
    each = "; ".join(f"{a.axis} as a change of {a.imitator} (r = {a.imitator_r:.3f}, {a.share:.3f} of its excursion)"
                     for a in showing)
    if any(a.share >= PRACTICAL_SHARE for a in showing):
        return (f"the coefficient mismatch shows it only as changes of the axes' own terms ({each}), and the "
                f"kinematics only at t = {abs(t_kinematic):.1f} (under {ONE_AXIS_KINEMATIC_T:g}): a change of the "
                f"term itself would show the same")
    return (f"the coefficient mismatch shows it only as changes of the axes' own terms, too small to tell from the "
            f"model's own artefacts: {each}")


def explained_by_own_term(a: AxisRatio) -> bool:
    """Whether axis ``a``'s showing of the error is its own candidate term most collinear with
    the signature, whatever their correlation: fitted together, the signature falls under
    :data:`SHOWING_T` while the term stays at :data:`candidates.AMBIGUOUS_T` (the data prefer
    the term, as in the accelerometer position's rival test, ``candidates.offset_rival``).
    Until 7 Dec 2026 the pair was fitted only at r >= 0.7 (the rival test's gate,
    :data:`rivals.TERM_RIVAL_CORRELATION`): a probe's F-4N with C_Z,α 0.5 higher (15,000 ft,
    pitch multisine at 100 Hz) had its accelerometer named 5.1 ft aft on C_Z and C_m, C_Z's
    signature at r 0.697 with C_Z,α and, beside it, at t −0.2. A correlation under the gate
    only makes the pair easier to tell apart."""
    return abs(a.beside_imitator[0]) < SHOWING_T and abs(a.beside_imitator[1]) >= AMBIGUOUS_T


def explained_by_own_terms(axes: tuple[AxisRatio, ...]) -> str:
    """Why the coefficient mismatch is no second test of the error, '' when it may be one:
    every axis that shows it (:data:`SHOWING_T`) is explained by a term of its own
    (:func:`explained_by_own_term`). An independent script's A-4 (8,100 ft / 543 ft/s, pitch
    multisine at 100 Hz) with C_Z,α 0.5 higher had an accelerometer named 3.8 ft aft: the
    kinematics put it at 3.1 ± 0.8 ft, and only C_Z followed its signature (1.74 ± 0.26
    times, C_Z,α at r 0.77); beside C_Z,α the signature stood at t −0.1, C_Z,α at −7.9."""
    showing = [a for a in axes if a.std_error > 0 and abs(a.ratio) / a.std_error >= SHOWING_T]
    explained = [a for a in showing if explained_by_own_term(a)]
    if not showing or len(explained) < len(showing):
        return ""
    each = "; ".join(f"{a.axis} by {a.imitator} (r = {a.imitator_r:.2f}; beside it the signature stands at t = "
                     f"{a.beside_imitator[0]:.1f}, the term at {a.beside_imitator[1]:.1f})" for a in explained)
    return f"each axis that shows it is fitted better by a term of its own: {each}"


def not_explained(axes: tuple[AxisRatio, ...]) -> tuple[AxisRatio, ...]:
    """The axes whose showing of the error is not one of their own terms
    (:func:`explained_by_own_term`): the axes the one-axis and imitation tests judge. An
    independent script's A-4 with a C_n α·β coupling of 2 (7,400 ft / 527 ft/s, three-axis
    multisine at 100 Hz, V in knots) had an airspeed scale of −0.039 named: the kinematics
    suspected −0.049 ± 0.018 (t 2.7; −0.054 on the same flight without the coupling), C_m
    followed its signature 2.4 ± 0.7 times but beside C_m,q̂ (r 0.72) stood at t −0.04, C_m,q̂
    at 3.7; C_l followed it 0.73 ± 0.12 times as a C_l,p̂ change (r 0.984, a share of 0.032)."""
    return tuple(a for a in axes if not explained_by_own_term(a))


def one_axis_and_a_weak_suspicion(axes: tuple[AxisRatio, ...], t_kinematic: float) -> str:
    """Why one axis and the kinematics together do not name the error, '' when they may. A
    single axis that shows the error (:data:`SHOWING_T`) may carry any unmodelled change of its
    own that follows the signature, not only one term; the kinematics must then stand at
    :data:`ONE_AXIS_KINEMATIC_T` at least, not at the bare suspicion level. An independent
    script's c182 in a 30° banked turn (5,000 ft / 187 ft/s, three-axis multisine at 40 Hz)
    with C_m α² +1.5 about the trim α had a q-gyro scale of 0.031 named: the kinematics
    suspected it at t 2.5 and C_m's mismatch, which carried the α² change, followed its
    signature 0.90 ± 0.15 times (collinear with C_m,δe at r 0.936, a share of 0.042). The
    sweeps' single-axis namings (p, q and a_z skews) stand at kinematic t 3.6–4.2."""
    showing = [a for a in axes if a.std_error > 0 and abs(a.ratio) / a.std_error >= SHOWING_T]
    if len(showing) != 1 or abs(t_kinematic) >= ONE_AXIS_KINEMATIC_T:
        return ""
    return (f"only {showing[0].axis} shows it, and the kinematics only at t = {abs(t_kinematic):.1f} (under "
            f"{ONE_AXIS_KINEMATIC_T:g}): one axis may carry an unmodelled change of its own that follows the signature")


# The kinematic |t| a sensor error needs when a single axis of the coefficient mismatch shows
# it (:func:`one_axis_and_a_weak_suspicion`): the conventional three standard errors.
ONE_AXIS_KINEMATIC_T = 3.0
# An axis shows an error when its ratio stands this many standard errors from none
# (:func:`imitated_by_own_terms`) ...
SHOWING_T = 2.0
# ... and tells it from a change of one of its own terms when the signature's correlation
# with each of them (beside the axis's named terms) stays under this.
IMITATOR_R = 0.95


def corroborate(name: str, kinematic: float, kinematic_std: float, ratios: dict[str, AxisRatio], *,
                t_aero: float, tolerance: float = 0.0) -> Corroboration:
    """The verdict on a suspected sensor error (module docstring); ``ratios`` per axis from
    :func:`axis_ratio`, ``t_aero`` the aerodynamic entry t. The axes' common ratio allows for
    their estimates' correlation (:func:`estimate_correlation`): on an independent script's
    F-16 null (8,000 ft / 450 ft/s, three-axis multisine at 50 Hz) the β vane's wander
    followed r/V by chance, and C_Y, C_l and C_n, each at t 2.8–4.0, combined as independent
    named a vane 18.7 ft ahead of the c.g. at t 6.8. ``tolerance``: a difference between the
    two sizes the tests may have without either being wrong (:func:`gyro_skew_tolerance`)."""
    ag = agreement(ratios, correlated=True)
    axes = ag.axes if ag is not None else ()

    def verdict(named: bool, reason: str, a=np.nan, sa=np.inf, est=kinematic, se=kinematic_std):
        return Corroboration(name, kinematic, kinematic_std, axes, float(a), float(sa), named, reason,
                             float(est), float(se))

    if ag is None:
        return verdict(False, "no axis of the coefficient mismatch can tell this sensor error")
    a_hat, sa = ag.ratio, ag.std_error
    if ag.apart:
        return verdict(False, f"the coefficient axes disagree on it ({ag.text()} of the kinematic size): a "
                       "coefficient error on one axis, not an instrument", a_hat, sa)
    if a_hat / sa < t_aero:
        return verdict(False, f"the coefficient mismatch does not show it clearly (t = {a_hat / sa:.1f})", a_hat, sa)
    rel_kin = abs(kinematic_std / kinematic) if kinematic != 0 else np.inf
    if abs(a_hat - 1.0) > AGREE_Z * np.hypot(sa, rel_kin) + abs(tolerance / kinematic):
        return verdict(False, f"the coefficient mismatch asks for {a_hat:.2f} ± {sa:.2f} times the kinematic "
                       "size", a_hat, sa)
    v_aero, s_aero = a_hat * kinematic, abs(sa * kinematic)
    est, se = inverse_variance_mean([kinematic, v_aero], [kinematic_std, s_aero])
    t_kin = kinematic / kinematic_std
    left = not_explained(axes)
    refuted = (explained_by_own_terms(axes) or imitated_by_own_terms(left, t_kin)
               or one_axis_and_a_weak_suspicion(left, t_kin)
               or mistrim_test(axes, est / kinematic, se / abs(kinematic)))
    if refuted:
        return verdict(False, refuted, a_hat, sa)
    return verdict(True, "named on two independent tests: the kinematics and the coefficient mismatch ("
                   + ", ".join(a.axis for a in axes) + ") agree on it", a_hat, sa, est, se)
