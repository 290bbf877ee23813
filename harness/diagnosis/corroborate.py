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
  which a single coefficient error cannot do: a wrong C_Z,α moves C_Z alone, a wrong α
  vane moves C_Z, C_m and C_X by the model's own slopes;
* the aerodynamic evidence is significant on its own (``â/σ_â`` at least the aerodynamic
  entry t);
* it agrees with the kinematic estimate (``|â - 1|`` within :data:`AGREE_Z` of the
  combined standard error).

The size named is the inverse-variance mean of the two estimates.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError

# An axis takes part when it determines the ratio to within ±100 % (one standard error).
INFORMATIVE_SE = 1.0
# Agreement: within this many standard errors ...
AGREE_Z = 3.0
# ... or this fraction of the common ratio (the model's slopes carry their own small errors).
AGREE_FRACTION = 0.3


@dataclass(frozen=True)
class AxisRatio:
    """One axis's estimate of the sensor error, as a multiple of the kinematic estimate."""

    axis: str
    ratio: float
    std_error: float


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
                "axes": {a.axis: {"ratio": a.ratio, "std_error": a.std_error} for a in self.axes},
                "named": self.named, "reason": self.reason}


def axis_ratio(z: np.ndarray, others: list[np.ndarray], signature: np.ndarray,
               constant: bool = True) -> AxisRatio | None:
    """``a ± σ`` of ``z ≈ others·θ - a·signature + c`` (colored-residual standard error);
    without ``c`` when not ``constant`` (a bias's signature is nearly a constant). None when
    the signature is flat (or, with the constant, dependent on the others)."""
    if np.ptp(signature) <= 0 if constant else not np.any(signature):
        return None
    try:
        theta, se, _ = colored_fit(z, others + [-signature], [f"o{i}" for i in range(len(others))] + ["a"],
                                   constant=constant)
    except (SingularRegressorsError, np.linalg.LinAlgError):
        return None
    j = len(others)
    return AxisRatio("", float(theta[j]), float(se[j]) if se[j] > 0 else np.inf)


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


def agreement(ratios: dict[str, AxisRatio]) -> Agreement | None:
    """The axes that can tell (σ at most :data:`INFORMATIVE_SE`), their inverse-variance
    common ratio, and those that depart from it by more than :data:`AGREE_Z` standard
    errors and :data:`AGREE_FRACTION`; None when no axis can tell."""
    axes = tuple(AxisRatio(k, r.ratio, r.std_error) for k, r in sorted(ratios.items())
                 if np.isfinite(r.std_error) and r.std_error <= INFORMATIVE_SE)
    if not axes:
        return None
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
    ag = agreement({k: AxisRatio(k, r.ratio / a0, r.std_error / abs(a0)) for k, r in ratios.items()})
    if ag is None or len(ag.axes) < 2 or ag.apart:
        return None
    axes = tuple(AxisRatio(a.axis, a.ratio * a0, a.std_error * abs(a0)) for a in ag.axes)
    return Agreement(axes, ag.ratio * a0, ag.std_error * abs(a0), ())


def corroborate(name: str, kinematic: float, kinematic_std: float, ratios: dict[str, AxisRatio], *,
                t_aero: float) -> Corroboration:
    """The verdict on a suspected sensor error (module docstring); ``ratios`` per axis from
    :func:`axis_ratio`, ``t_aero`` the aerodynamic entry t."""
    ag = agreement(ratios)
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
    if abs(a_hat - 1.0) > AGREE_Z * np.hypot(sa, rel_kin):
        return verdict(False, f"the coefficient mismatch asks for {a_hat:.2f} ± {sa:.2f} times the kinematic "
                       "size", a_hat, sa)
    v_aero, s_aero = a_hat * kinematic, abs(sa * kinematic)
    est, se = inverse_variance_mean([kinematic, v_aero], [kinematic_std, s_aero])
    return verdict(True, "named on two independent tests: the kinematics and the coefficient mismatch ("
                   + ", ".join(a.axis for a in axes) + ") agree on it", a_hat, sa, est, se)
