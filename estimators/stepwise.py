"""Stepwise regression over a library of named candidate regressors (Efroymson's procedure).

Model structure determination for the equation-error method (seed §II: "evaluating many
different candidate model structures ... using statistical modeling metrics to choose among
them"). Forward selection with backward elimination, fully non-interactive:

1. start from the bias alone (when ``bias``) plus the ``forced`` terms, which never leave;
2. **enter**: of the candidates not in the model, take the one with the largest partial F
   (Eq. 1 below); add it if F > ``f_in`` and, under ``rule='F+PSE'``, if it lowers the
   predicted square error PSE; otherwise stop;
3. **remove**: while some included (non-forced) term has partial F < ``f_out`` — or, under
   ``'F+PSE'``, would lower PSE by leaving — drop the one with the smallest F;
4. repeat from 2.

Partial F of term j with respect to a model whose other terms are S (p parameters in S,
bias included; N data points)::

    F_j = (SSE_S − SSE_{S+j}) / s²_{S+j},   s²_{S+j} = SSE_{S+j} / (N − p − 1)      (1)

which has an F(1, N − p − 1) distribution when θ_j = 0 and the equation error is white and
Gaussian. It equals t_j² = θ̂_j² / (s² [(XᵀX)⁻¹]_jj) of the model containing j (seed Eqs. 15-17).
PSE = SSE/N + σ²_max p/N, σ²_max the variance of z about its mean
(:attr:`estimators.result.ModelFit.pse`).

Entry and removal F values are computed from the orthogonal projection of each candidate
off the current regressors (one QR per step for all candidates); every model that is
adopted is then solved by :func:`estimators.least_squares.least_squares`, whose rank check
is the final arbiter of collinearity.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
import scipy.linalg

from estimators.least_squares import LeastSquares, SingularRegressorsError, least_squares, r_squared
from estimators.regressors import DataOptions, RegressionData
from estimators.result import ModelFit, collinearity

__all__ = ["RULES", "StepwiseSpec", "StepwiseStep", "CandidateF", "StepwiseResult", "Stepwise", "stepwise_regression"]

RULES = ("F", "F+PSE")
_SINGULAR = 1e-10  # a candidate whose part orthogonal to the model is this small (relative) is dependent
_EXACT_FIT = 1e-24  # s² below this fraction of σ²_max: the model fits z to rounding error


@dataclass(frozen=True)
class StepwiseSpec:
    """Settings of one stepwise run.

    Attributes
    ----------
    forced : names entered first, in this order, and never removed.
    bias : include a constant term (always in the model, never a candidate).
    f_in, f_out : partial-F thresholds to enter and to stay (Eq. 1 of the module docstring);
        ``f_out <= f_in`` is required, otherwise a term could enter and leave forever.
    max_terms : largest number of selected terms (forced included, bias excluded).
    rule : ``'F'`` — enter while the best partial F exceeds ``f_in``; ``'F+PSE'`` — also
        require the entry to lower PSE, and remove a term whose removal lowers PSE.
    """

    forced: tuple[str, ...] = ()
    bias: bool = True
    f_in: float = 4.0
    f_out: float = 4.0
    max_terms: int | None = None
    rule: str = "F+PSE"

    def __post_init__(self) -> None:
        if self.rule not in RULES:
            raise ValueError(f"rule must be one of {RULES}, not {self.rule!r}")
        if not (np.isfinite(self.f_in) and self.f_in >= 0 and np.isfinite(self.f_out) and self.f_out >= 0):
            raise ValueError(f"f_in and f_out must be finite and non-negative, got {self.f_in}, {self.f_out}")
        if self.f_out > self.f_in:
            raise ValueError(f"f_out = {self.f_out} exceeds f_in = {self.f_in}: a term could enter and leave "
                             "endlessly; use f_out <= f_in")
        if self.max_terms is not None and self.max_terms < len(self.forced):
            raise ValueError(f"max_terms = {self.max_terms} is below the {len(self.forced)} forced terms")
        if len(set(self.forced)) != len(self.forced):
            raise ValueError(f"forced terms repeat: {self.forced}")


@dataclass(frozen=True)
class StepwiseStep:
    """One entry of the history.

    ``action`` is ``'start'``, ``'force'``, ``'add'``, ``'remove'``, ``'skip'`` (a candidate
    dependent on the model, not considered) or ``'stop'``. ``partial_f`` is the F of the term
    entering or leaving (nan otherwise); ``r2``, ``pse``, ``s2`` and ``selected`` describe the
    model after the action.
    """

    action: str
    name: str | None
    partial_f: float
    r2: float
    pse: float
    s2: float
    selected: tuple[str, ...]
    note: str = ""


@dataclass(frozen=True)
class CandidateF:
    """A candidate's partial F at the final model: F-to-remove when included, F-to-enter
    otherwise (nan when it is linearly dependent on the selected terms)."""

    name: str
    included: bool
    forced: bool
    partial_f: float
    note: str = ""


@dataclass(frozen=True)
class StepwiseResult:
    """Outcome of :func:`stepwise_regression`.

    Attributes
    ----------
    selected : the chosen terms in order of entry (forced first).
    history : every action taken, with the statistics of the model after it.
    fit : the final model, ``method='stepwise'``, names ``selected + ('bias',)`` when bias.
    candidates : partial F of every candidate at the final model.
    spec : the settings used.
    stop_reason : why the procedure stopped.
    """

    selected: tuple[str, ...]
    history: tuple[StepwiseStep, ...]
    fit: ModelFit
    candidates: tuple[CandidateF, ...]
    spec: StepwiseSpec
    stop_reason: str

    @property
    def partial_f(self) -> dict[str, float]:
        """Name → final partial F (to remove if included, to enter if not)."""
        return {c.name: c.partial_f for c in self.candidates}

    def summary(self) -> str:
        """The history and the final table of candidates, as text."""
        lines = [f"stepwise regression ({self.spec.rule}, F_in = {self.spec.f_in:g}, "
                 f"F_out = {self.spec.f_out:g}): {', '.join(self.selected) or '(no terms)'}",
                 f"{'action':<8}{'term':<16}{'F':>10}{'R2':>10}{'PSE':>12}{'s2':>12}  note"]
        for h in self.history:
            lines.append(f"{h.action:<8}{h.name or '':<16}{h.partial_f:>10.4g}{h.r2:>10.5f}"
                         f"{h.pse:>12.4g}{h.s2:>12.4g}  {h.note}")
        lines.append(f"{'candidate':<16}{'in':<4}{'partial F':>12}")
        for c in self.candidates:
            flag = "yes" if c.included else "no"
            lines.append(f"{c.name:<16}{flag:<4}{c.partial_f:>12.4g}  {c.note}")
        return "\n".join(lines)


# -- the problem and its models -----------------------------------------------------------------
@dataclass(frozen=True)
class _Problem:
    z: np.ndarray
    C: np.ndarray
    names: tuple[str, ...]
    bias: bool
    dependent: str
    aliases: Mapping[str, str]

    @property
    def n(self) -> int:
        return len(self.z)

    @property
    def sigma2_max(self) -> float:
        return float(np.mean((self.z - self.z.mean()) ** 2))

    def index(self, name: str) -> int:
        name = self.aliases.get(name, name)
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"{name!r} is not a candidate; candidates are {list(self.names)}") from None

    def design(self, terms: Sequence[int]) -> np.ndarray:
        cols = [self.C[:, j] for j in terms] + ([np.ones(self.n)] if self.bias else [])
        return np.column_stack(cols) if cols else np.empty((self.n, 0))

    def labels(self, terms: Sequence[int]) -> tuple[str, ...]:
        return tuple(self.names[j] for j in terms) + (("bias",) if self.bias else ())


@dataclass(frozen=True)
class _Model:
    terms: tuple[int, ...]
    fit: ModelFit
    ls: LeastSquares | None

    @property
    def sse(self) -> float:
        return float(self.fit.residuals @ self.fit.residuals)


def _as_problem(z: npt.ArrayLike | None, candidates: Mapping[str, npt.ArrayLike] | RegressionData,
                bias: bool | None, dependent: str | None) -> _Problem:
    aliases: dict[str, str] = {}
    if isinstance(candidates, RegressionData):
        data = candidates
        if z is not None and not np.array_equal(np.asarray(z, dtype=float), data.z):
            raise ValueError("z differs from the RegressionData's own dependent variable; pass z=None")
        z = data.z
        names = tuple(n for n in data.names if n != "bias")
        aliases = dict(zip(data.equation.regressors, names))
        columns = [data.X[:, j] for j in range(data.X.shape[1])]
        bias = data.equation.bias if bias is None else bias
        dependent = data.equation.dependent if dependent is None else dependent
    else:
        names = tuple(candidates)
        columns = [candidates[k] for k in names]
    if z is None:
        raise ValueError("z is required unless candidates is RegressionData")
    z = np.asarray(z)
    if np.iscomplexobj(z) or z.ndim != 1 or not np.all(np.isfinite(z)):
        raise ValueError("z must be a real, finite 1-D array")
    z = z.astype(float)
    bias = True if bias is None else bool(bias)
    if not all(isinstance(k, str) for k in names):
        raise TypeError("candidate names must be strings")
    if bias and "bias" in names:
        raise ValueError("'bias' is reserved for the constant term; rename the candidate")
    cols = []
    for name, col in zip(names, columns):
        a = np.asarray(col)
        if np.iscomplexobj(a) or a.shape != z.shape or not np.all(np.isfinite(a)):
            raise ValueError(f"candidate {name!r} must be a real, finite array of shape {z.shape}")
        cols.append(a.astype(float))
    C = np.column_stack(cols) if cols else np.empty((len(z), 0))
    return _Problem(z, C, names, bias, dependent or "z", aliases)


def _fit(prob: _Problem, terms: tuple[int, ...]) -> _Model:
    """Least squares of z on the terms (+ bias); raises SingularRegressorsError."""
    A, names = prob.design(terms), prob.labels(terms)
    if A.shape[1] == 0:
        ls, params, cov = None, np.empty(0), np.empty((0, 0))
        fitted = np.zeros(prob.n)
        s2 = float(prob.z @ prob.z) / prob.n
    else:
        ls = least_squares(A, prob.z, names)
        params, fitted, s2 = ls.theta, ls.fitted, ls.s2
        cov = s2 * ls.xtx_inv
    resid = prob.z - fitted
    fit = ModelFit(method="stepwise", domain="time", dependent=prob.dependent, names=names, params=params,
                   cov=cov, residuals=resid, fitted=fitted, n=prob.n, s2=s2, r2=r_squared(prob.z, resid))
    return _Model(terms, fit, ls)


def _f_added(old: _Model, new: _Model) -> float:
    """Eq. 1 from the two solved models."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.float64(old.sse - new.sse) / new.fit.s2)


def _entry_f(prob: _Problem, model: _Model, pool: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Partial F to enter (Eq. 1) for every candidate in ``pool``, and which are dependent.

    With Q an orthonormal basis of the current regressors, c̃ = c − QQᵀc and residual v,
    SSE_S − SSE_{S+j} = (c̃ᵀv)² / c̃ᵀc̃ (Frisch-Waugh-Lovell)."""
    C = prob.C[:, pool]
    A = prob.design(model.terms)
    if A.shape[1]:
        q = scipy.linalg.qr(A, mode="economic")[0]
        Ct = C - q @ (q.T @ C)
    else:
        Ct = C.copy()
    norm_c, norm_t = np.linalg.norm(C, axis=0), np.linalg.norm(Ct, axis=0)
    singular = norm_t <= _SINGULAR * norm_c
    safe = np.where(singular, 1.0, norm_t)
    gain = np.where(singular, 0.0, (Ct.T @ model.fit.residuals / safe) ** 2)
    dof = prob.n - len(model.fit.names) - 1
    sse_with = np.maximum(model.sse - gain, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(sse_with > 0, gain * dof / np.where(sse_with > 0, sse_with, 1.0), np.inf)
    return np.where(singular, np.nan, f), singular


def _removal_f(model: _Model) -> np.ndarray:
    """Partial F to remove each included term: t² of seed Eqs. 15-17 (Eq. 1 with S = others)."""
    ls = model.ls
    k = len(model.terms)
    with np.errstate(divide="ignore", invalid="ignore"):
        return ls.theta[:k] ** 2 / (ls.s2 * np.diag(ls.xtx_inv)[:k])


def _record(action: str, name: str | None, f: float, model: _Model, prob: _Problem, note: str = "") -> StepwiseStep:
    return StepwiseStep(action, name, float(f), float(model.fit.r2), float(model.fit.pse), float(model.fit.s2),
                        tuple(prob.names[j] for j in model.terms), note)


# -- the procedure ------------------------------------------------------------------------------
def _forward(prob: _Problem, spec: StepwiseSpec, model: _Model,
             skips: list[tuple[str, str]]) -> tuple[_Model | None, float, str]:
    """One entry step: (new model, its partial F, '') or (None, nan, why the procedure stops)."""
    if spec.max_terms is not None and len(model.terms) >= spec.max_terms:
        return None, np.nan, f"max_terms = {spec.max_terms} reached"
    pool = [j for j in range(len(prob.names)) if j not in model.terms]
    if not pool:
        return None, np.nan, "every candidate is in the model"
    if prob.n - len(model.fit.names) - 1 <= 0:
        return None, np.nan, "no degrees of freedom left for another term"
    if model.fit.s2 <= _EXACT_FIT * prob.sigma2_max:
        return None, np.nan, "the model fits z to rounding error: no term can improve it"
    f, singular = _entry_f(prob, model, pool)
    for j, dep in zip(pool, singular):
        if dep:
            skips.append((prob.names[j], "linearly dependent on the terms in the model (design would be "
                                         "singular); not considered"))
    order = [pool[i] for i in np.argsort(-np.nan_to_num(f, nan=-np.inf), kind="stable") if not singular[i]]
    for j in order:
        f_j = f[pool.index(j)]
        if not f_j > spec.f_in:
            return None, np.nan, (f"no candidate has partial F > F_in = {spec.f_in:g} "
                                  f"(best: {prob.names[j]}, F = {f_j:.4g})")
        try:
            new = _fit(prob, model.terms + (j,))
        except SingularRegressorsError as exc:
            skips.append((prob.names[j], f"skipped: {exc}"))
            continue
        f_exact = _f_added(model, new)
        if not f_exact > spec.f_in:
            return None, np.nan, (f"no candidate has partial F > F_in = {spec.f_in:g} "
                                  f"(best: {prob.names[j]}, F = {f_exact:.4g})")
        if spec.rule == "F+PSE" and not new.fit.pse < model.fit.pse:
            return None, np.nan, (f"adding the best candidate {prob.names[j]} (F = {f_exact:.4g}) would not "
                                  f"lower PSE ({model.fit.pse:.6g} -> {new.fit.pse:.6g})")
        return new, f_exact, ""
    return None, np.nan, "no candidate can enter without making the design singular"


def _backward(prob: _Problem, spec: StepwiseSpec, model: _Model, forced: set[int],
              history: list[StepwiseStep]) -> _Model:
    """Drop terms that no longer pay, one at a time, weakest first."""
    while True:
        removable = [k for k, j in enumerate(model.terms) if j not in forced]
        if not removable:
            return model
        f = _removal_f(model)
        k = min(removable, key=lambda i: f[i])
        without = _fit(prob, model.terms[:k] + model.terms[k + 1:])
        if f[k] < spec.f_out:
            note = f"partial F {f[k]:.4g} < F_out = {spec.f_out:g}"
        elif without.fit.s2 <= _EXACT_FIT * prob.sigma2_max:
            note = "the model fits z to rounding error without it (its partial F is rounding noise)"
        elif spec.rule == "F+PSE" and without.fit.pse < model.fit.pse:
            note = f"removing it lowers PSE ({model.fit.pse:.6g} -> {without.fit.pse:.6g})"
        else:
            return model
        history.append(_record("remove", prob.names[model.terms[k]], f[k], without, prob, note))
        model = without


def _candidate_table(prob: _Problem, model: _Model, forced: set[int]) -> tuple[CandidateF, ...]:
    pool = [j for j in range(len(prob.names)) if j not in model.terms]
    if pool and prob.n - len(model.fit.names) - 1 > 0:
        f_in, singular = _entry_f(prob, model, pool)
    else:
        f_in, singular = np.full(len(pool), np.nan), np.zeros(len(pool), dtype=bool)
    f_out = _removal_f(model) if model.terms else np.empty(0)
    out = []
    for j, name in enumerate(prob.names):
        if j in model.terms:
            out.append(CandidateF(name, True, j in forced, float(f_out[model.terms.index(j)]), "F to remove"))
        else:
            i = pool.index(j)
            note = "linearly dependent on the selected terms" if singular[i] else "F to enter"
            out.append(CandidateF(name, False, False, float(f_in[i]), note))
    return tuple(out)


def stepwise_regression(z: npt.ArrayLike | None, candidates: Mapping[str, npt.ArrayLike] | RegressionData, *,
                        forced: Sequence[str] = (), bias: bool | None = None, f_in: float = 4.0,
                        f_out: float = 4.0, max_terms: int | None = None, dt: float | None = None,
                        dependent: str | None = None, rule: str = "F+PSE") -> StepwiseResult:
    """Choose regressors for ``z`` from named candidates by stepwise regression (Efroymson).

    Parameters
    ----------
    z : array_like, shape (N,), or None
        The dependent variable (e.g. Cm from seed Eq. 4). None when ``candidates`` is a
        RegressionData, whose own z is then used.
    candidates : mapping name -> array (N,), or RegressionData
        The library of candidate regressors. A RegressionData (e.g. from
        :func:`estimators.regressors.regression_data` with the candidates as regressors)
        contributes its regressors under their parameter names (``Cm_alpha``), and its bias
        flag, dependent name and ``dt`` become the defaults.
    forced : sequence of str
        Terms entered first and never removed (for a RegressionData the regressor term
        ``'alpha'`` or the parameter name ``'Cm_alpha'``).
    bias : bool, optional
        Include a constant term (default True; a RegressionData's own setting).
    f_in, f_out : float
        Partial-F thresholds to enter and to stay (module docstring, Eq. 1). F = 4 is about
        the 5 % point of F(1, ν) for large ν, i.e. a t-ratio of 2 (seed: ±2 standard errors).
    max_terms : int, optional
        Most terms to select (forced included, bias excluded).
    dt : float, optional
        Sampling interval, recorded in ``fit.info``.
    dependent : str, optional
        Name of z for the fit (default ``'z'`` or the RegressionData's).
    rule : {'F+PSE', 'F'}
        Stopping rule. ``'F'``: stop when no candidate has partial F > ``f_in``.
        ``'F+PSE'`` (default): also stop when adding the best candidate would not lower the
        predicted square error PSE = SSE/N + σ²_max p/N, and remove an included term whose
        removal lowers PSE. Entering lowers PSE exactly when SSE falls by more than σ²_max,
        i.e. when F > σ²_max/s²: for well-fitted data (R² near 1) that is far stricter than
        F > 4, which keeps spurious terms out; for poorly fitted data F > ``f_in`` governs.

    Returns
    -------
    StepwiseResult
        ``selected`` (order of entry), ``history``, ``fit`` (ModelFit, ``method='stepwise'``,
        with collinearity diagnostics), ``candidates`` (final partial F of every candidate)
        and ``stop_reason``.

    Raises
    ------
    KeyError
        A forced name that is not a candidate.
    SingularRegressorsError
        The forced terms (with the bias) are linearly dependent.
    ValueError
        Bad thresholds, rule, shapes or non-finite data.

    Notes
    -----
    A candidate that is (numerically) a linear combination of the terms in the model is
    never entered; the history records a ``'skip'`` for it (once per model state). The
    procedure never asks for input. It stops also when the model fits z to rounding error,
    when no degrees of freedom remain, or if it would revisit a model (a cycle).
    """
    prob = _as_problem(z, candidates, bias, dependent)
    spec = StepwiseSpec(forced=tuple(prob.aliases.get(n, n) for n in forced), bias=prob.bias,
                        f_in=float(f_in), f_out=float(f_out), max_terms=max_terms, rule=rule)
    forced_idx = {prob.index(n) for n in spec.forced}
    model = _fit(prob, ())
    history = [_record("start", None, np.nan, model, prob, "bias only" if prob.bias else "empty model")]
    for name in spec.forced:
        try:
            new = _fit(prob, model.terms + (prob.index(name),))
        except SingularRegressorsError as exc:
            raise SingularRegressorsError(f"forced term {name!r}: {exc}") from None
        history.append(_record("force", name, _f_added(model, new), new, prob, "forced"))
        model = new
    visited = {frozenset(model.terms)}
    noted: set[tuple[str, frozenset]] = set()
    stop_reason = "iteration limit reached"
    for _ in range(4 * len(prob.names) + 4):
        skips: list[tuple[str, str]] = []
        new, f_new, why = _forward(prob, spec, model, skips)
        for name, note in skips:
            if (name, frozenset(model.terms)) not in noted:
                noted.add((name, frozenset(model.terms)))
                history.append(_record("skip", name, np.nan, model, prob, note))
        if new is None:
            stop_reason = why
            break
        history.append(_record("add", prob.names[new.terms[-1]], f_new, new, prob))
        model = _backward(prob, spec, new, forced_idx, history)
        if frozenset(model.terms) in visited:
            stop_reason = "the procedure returned to a model it had already left (cycle)"
            break
        visited.add(frozenset(model.terms))
    history.append(_record("stop", None, np.nan, model, prob, stop_reason))

    A, names = prob.design(model.terms), prob.labels(model.terms)
    coll = collinearity(A, names, model.fit.cov) if len(names) else None
    warnings = () if coll is None else coll.warnings()
    info = {"rule": spec.rule, "f_in": spec.f_in, "f_out": spec.f_out, "stop_reason": stop_reason,
            "steps": len(history)}
    if dt is None and isinstance(candidates, RegressionData):
        dt = candidates.dt
    if dt is not None:
        info["dt"] = float(dt)
    final = ModelFit(method="stepwise", domain="time", dependent=prob.dependent, names=names,
                     params=model.fit.params, cov=model.fit.cov, residuals=model.fit.residuals,
                     fitted=model.fit.fitted, n=prob.n, s2=model.fit.s2, r2=model.fit.r2, collinearity=coll,
                     warnings=warnings, info=info)
    return StepwiseResult(selected=tuple(prob.names[j] for j in model.terms), history=tuple(history), fit=final,
                          candidates=_candidate_table(prob, model, forced_idx), spec=spec, stop_reason=stop_reason)


@dataclass(frozen=True)
class Stepwise:
    """Stepwise regression behind the estimators' one ``fit`` (registry name ``stepwise``): the
    equation's regressors are the candidates, and the fit is the final model's (its names a
    subset of them). The full history is :func:`stepwise_regression`'s."""

    data: DataOptions = field(default_factory=DataOptions)
    f_in: float = 4.0
    f_out: float = 4.0
    rule: str = "F+PSE"
    method = "stepwise"

    def fit(self, source, equation=None) -> ModelFit:
        from estimators.equation_error import _as_data
        d = _as_data(source, equation, self.data)
        return stepwise_regression(None, d, f_in=self.f_in, f_out=self.f_out, rule=self.rule).fit
