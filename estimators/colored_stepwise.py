"""Forward selection of named candidate terms judged by colored-residual t statistics.

The partial F of classical stepwise regression (:mod:`estimators.stepwise`) assumes white
equation errors. Residuals of filtered flight data are anything but white, and the F values
then overstate significance by the ratio of the record length to its correlation time, so a
search over many candidates names terms on noise alone. Here every entry is judged by the
t statistic of the new term under the colored-residual covariance of seed Eq. 40
(:func:`estimators.colored.colored_residual_covariance`), and by how much of the remaining
residual variance it removes:

1. start from the constant term and the ``forced`` columns;
2. of the candidates not in the model, take the one that lowers the sum of squared residuals
   most (the largest partial correlation, as in Efroymson's procedure);
3. enter it when its colored |t| >= ``t_in`` and it removes at least ``min_gain`` of the
   residual variance; otherwise stop;
4. stop also at ``max_terms``.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from estimators.colored import colored_residual_covariance
from estimators.least_squares import SingularRegressorsError, least_squares

__all__ = ["ColoredTerm", "ColoredSelection", "colored_forward_selection", "colored_fit"]


@dataclass(frozen=True)
class ColoredTerm:
    """One candidate as judged against the final model.

    ``estimate``/``std_error``/``t`` are from the final model when the term is in it, else
    from the final model with this term added; ``gain`` is the fraction of the residual
    variance the term removed when it entered (or would remove now)."""

    name: str
    estimate: float
    std_error: float
    t: float
    gain: float
    selected: bool
    order: int  # 1-based entry order, 0 when not selected


@dataclass(frozen=True)
class ColoredSelection:
    names: tuple[str, ...]          # selected candidate names, in entry order
    params: dict[str, float]        # final estimates (constant term as 'bias', forced terms too)
    std_errors: dict[str, float]
    residuals: np.ndarray
    fitted: np.ndarray
    sse_start: float                # with the constant (and forced) terms only
    sse: float
    terms: tuple[ColoredTerm, ...]  # every candidate


def colored_fit(z: np.ndarray, columns: Sequence[np.ndarray], names: Sequence[str], max_lag: int | None = None,
                constant: bool = True, autocorrelation: str = "sample"):
    """Least squares (with a constant term unless ``constant=False``) and colored-residual
    covariance (Eq. 40; ``autocorrelation`` as in
    :func:`estimators.colored.colored_residual_covariance`). Returns ``(theta, std_errors,
    residuals)``, the constant last."""
    if not constant and not len(columns):
        return np.zeros(0), np.zeros(0), np.asarray(z, dtype=float).copy()
    A = np.column_stack(list(columns) + ([np.ones(z.size)] if constant else []))
    ls = least_squares(A, z, tuple(names) + (("bias",) if constant else ()), keep_factor=True)
    cov = colored_residual_covariance(A, ls.residuals, max_lag=max_lag, autocorrelation=autocorrelation,
                                      factor=ls.factor)
    return ls.theta, np.sqrt(np.maximum(np.diag(cov), 0.0)), ls.residuals


def _sse_of(z: np.ndarray, cols: Sequence[np.ndarray]) -> float:
    """The residual sum of squares of ``z`` fitted by ``cols`` in least squares (rank-deficient
    columns by the minimum-norm solution)."""
    if not cols:
        return float(z @ z)
    A = np.column_stack(cols)
    theta, *_ = np.linalg.lstsq(A, z, rcond=None)
    r = z - A @ theta
    return float(r @ r)


def _sse_with_each(z: np.ndarray, cols: Sequence[np.ndarray], candidates: Mapping[str, np.ndarray],
                   rtol: float = 1e-10) -> dict[str, float]:
    """:func:`_sse_of` ``(z, cols + [c])`` for each candidate ``c``, by projection: with ``Q`` an
    orthonormal basis of ``cols``, ``r`` the residual of ``z`` on it and ``c⊥`` the candidate's,
    the sum is ``r·r − (r·c⊥)² / (c⊥·c⊥)`` (the same least squares, one factorisation for all).
    A base or candidate dependent to ``rtol`` of its size is fitted directly instead."""
    if not candidates:
        return {}
    if not cols:
        Q, r = np.zeros((z.size, 0)), z
    else:
        Q, R = np.linalg.qr(np.column_stack(cols))
        d = np.abs(np.diag(R))
        if d.min() <= rtol * d.max():
            return {n: _sse_of(z, list(cols) + [c]) for n, c in candidates.items()}
        r = z - Q @ (Q.T @ z)
    rr = float(r @ r)
    C = np.column_stack(list(candidates.values()))
    C_perp = C - Q @ (Q.T @ C)
    size, left = np.einsum("ij,ij->j", C, C), np.einsum("ij,ij->j", C_perp, C_perp)
    along = r @ C_perp
    out = {}
    for j, (n, c) in enumerate(candidates.items()):
        if left[j] <= (rtol ** 2) * size[j]:
            out[n] = _sse_of(z, list(cols) + [c])
        else:
            out[n] = max(rr - along[j] ** 2 / left[j], 0.0)
    return out


def colored_forward_selection(z: npt.ArrayLike, candidates: Mapping[str, npt.ArrayLike], *,
                              forced: Mapping[str, npt.ArrayLike] | None = None, t_in: float = 5.0,
                              min_gain: float = 0.05, max_terms: int = 3,
                              max_lag: int | None = None, constant: bool = True) -> ColoredSelection:
    """Select candidate regressors for ``z`` by colored t statistics (module docstring).

    Parameters
    ----------
    z : the dependent record (e.g. a coefficient mismatch).
    candidates : name -> column, each as long as ``z``.
    forced : columns always in the model (not candidates).
    t_in, min_gain, max_terms : entry rules.
    max_lag : residual autocorrelation lags of Eq. 39 (all when None).
    constant : include a constant term (always in the model).
    """
    z = np.asarray(z, dtype=float)
    forced = {k: np.asarray(v, dtype=float) for k, v in (forced or {}).items()}
    pool = {k: np.asarray(v, dtype=float) for k, v in candidates.items()
            if np.ptp(np.asarray(v, dtype=float)) > 0}
    chosen: list[str] = []
    gains: dict[str, float] = {}

    def base(names: list[str]) -> list[np.ndarray]:
        return list(forced.values()) + [pool[n] for n in names] + ([np.ones(z.size)] if constant else [])

    sse_start = _sse_of(z, base([]))
    sse_now = sse_start
    while len(chosen) < max_terms:
        trial = _sse_with_each(z, base(chosen), {n: c for n, c in pool.items() if n not in chosen})
        if not trial:
            break
        best = min(trial, key=trial.get)
        gain = (sse_now - trial[best]) / sse_now if sse_now > 0 else 0.0
        names = list(forced) + chosen + [best]
        try:
            theta, se, _ = colored_fit(z, list(forced.values()) + [pool[n] for n in chosen + [best]], names, max_lag,
                                       constant)
        except (SingularRegressorsError, np.linalg.LinAlgError):
            pool.pop(best)
            continue
        t = theta[len(names) - 1] / se[len(names) - 1] if se[len(names) - 1] > 0 else np.inf
        if abs(t) < t_in or gain < min_gain:
            break
        chosen.append(best)
        gains[best] = gain
        sse_now = trial[best]

    names = list(forced) + chosen
    theta, se, resid = colored_fit(z, list(forced.values()) + [pool[n] for n in chosen], names, max_lag, constant)
    labels = names + (["bias"] if constant else [])
    params = dict(zip(labels, theta.tolist()))
    ses = dict(zip(labels, se.tolist()))
    terms = []
    for n in pool:
        if n in chosen:
            est, s = params[n], ses[n]
            terms.append(ColoredTerm(n, est, s, est / s if s > 0 else np.inf, gains[n], True, chosen.index(n) + 1))
            continue
        try:
            th, sn, r = colored_fit(z, list(forced.values()) + [pool[m] for m in chosen] + [pool[n]],
                                    names + [n], max_lag, constant)
        except (SingularRegressorsError, np.linalg.LinAlgError):
            continue
        g = (float(resid @ resid) - float(r @ r)) / float(resid @ resid) if resid @ resid > 0 else 0.0
        j = len(names)
        terms.append(ColoredTerm(n, float(th[j]), float(sn[j]), float(th[j] / sn[j]) if sn[j] > 0 else np.inf,
                                 g, False, 0))
    return ColoredSelection(names=tuple(chosen), params=params, std_errors=ses, residuals=resid,
                            fitted=z - resid, sse_start=sse_start, sse=float(resid @ resid), terms=tuple(terms))
