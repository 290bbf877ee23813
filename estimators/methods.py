"""The estimation methods by name, so a method is swapped in one line (or one option).

Every method of the registry (:mod:`estimators.registry`: single-maneuver, multiple-maneuver or
stepwise, with its declared capabilities) is built by :func:`make_estimator` and fitted by its one
``fit``.
"""
from __future__ import annotations

from typing import Protocol

from estimators.equation_error import SIDPAC_FREQUENCY_OPTIONS, EquationErrorFrequency, EquationErrorTime
from estimators.registry import COMBINED_METHODS, METHODS, REGISTRY, MethodInfo, method_info
from estimators.regressors import DataOptions, Equation
from estimators.result import ModelFit
from models.errors import OptionError

__all__ = ["METHODS", "COMBINED_METHODS", "REGISTRY", "MethodInfo", "method_info", "SIDPAC_FREQUENCY_OPTIONS",
           "Estimator", "make_estimator", "parse_frequencies"]


class Estimator(Protocol):
    """What every estimator offers: a name and ``fit(source, equation) -> ModelFit``."""

    @property
    def method(self) -> str: ...

    def fit(self, source, equation: Equation | None = None) -> ModelFit: ...


def make_estimator(name: str, *, errors: str | None = None, max_lag: int | None = None,
                   autocorrelation: str = "sample", frequencies_hz: tuple[float, ...] | str | None = None,
                   detrend: str = "lstsq",
                   data: DataOptions = DataOptions(), model: str | None = None,
                   acceleration: str = "time", hold: tuple[str, ...] = ()) -> Estimator:
    """The estimator called ``name`` (one of :data:`REGISTRY`).

    ``errors`` applies to the time-domain equation-error methods; ``None`` is the method's
    default: colored residuals (Eq. 40) for ``ee-smooth``, conventional (Eq. 15) for
    ``ee-time``; ``autocorrelation`` the colored bounds' residual autocorrelation (``"sample"``,
    Eq. 39; ``"ar"``, its autoregressive model, which makes a bias term's bound honest). The
    frequency-domain method's bounds are conventional (Eqs. 20-22, accurate when the band
    holds the rigid-body dynamics, seed §III.E), and output error reports the Cramér-Rao bound.
    ``frequencies_hz`` and ``detrend`` shape ``ee-freq``: by default the seed's rule (2/T to
    1.2 Hz by 0.04 Hz) and a least-squares line; ``**SIDPAC_FREQUENCY_OPTIONS`` (``frequencies_hz='sidpac'``, ``detrend='endpoints'``)
    gives SIDPAC's Eq. 18 band and end-point line. ``model`` names the output-error family's
    built-in model (None: chosen from the equation fitted). ``acceleration`` and ``hold`` are
    ``ee-freq``'s options for moment equations whose angular accelerations are differentiated
    from the rates and whose inputs are steps on sample instants (see
    :class:`estimators.equation_error.EquationErrorFrequency`; not the defaults).
    """
    info = method_info(name)
    if errors == "colored" and not info.supports("colored"):
        raise OptionError(f"--errors colored applies to the time-domain equation-error methods, not {name}: "
                          "the frequency-domain residuals are treated as white over the band (seed §III.E) "
                          "and output error reports the Cramér-Rao bound")
    if autocorrelation != "sample" and not info.supports("colored"):
        raise OptionError(f"--autocorrelation {autocorrelation} applies to the colored errors (Eq. 40) of the "
                          f"time-domain equation-error methods, not to {name}")
    if name == "ee-time":
        return EquationErrorTime(errors=errors, max_lag=max_lag, autocorrelation=autocorrelation, data=data)
    if name == "ee-smooth":
        return EquationErrorTime(errors=errors, max_lag=max_lag, autocorrelation=autocorrelation,
                                 smooth_regressors=True, data=data)
    if name == "ee-freq":
        return EquationErrorFrequency(frequencies_hz=frequencies_hz, detrend=detrend, data=data,
                                      acceleration=acceleration, hold=tuple(hold))
    if name == "oe":
        from estimators.output_error import OutputError
        return OutputError(model=model, data=data)
    if name == "oe-freq":
        from estimators.frequency_output_error import FrequencyOutputError
        return FrequencyOutputError(model=model, data=data)
    if name == "fe":
        from estimators.filter_error import FilterError
        return FilterError(model=model, data=data)
    if name == "stepwise":
        from estimators.stepwise import Stepwise
        return Stepwise(data=data)
    from estimators.multiple import Combined
    return Combined(method=name, errors=errors or "conventional", max_lag=max_lag,
                    autocorrelation=autocorrelation, frequencies_hz=frequencies_hz, detrend=detrend)


def parse_frequencies(text: str) -> tuple[float, ...] | str:
    """``'F0:DF:F1'`` (inclusive of F1) or a comma list, in Hz; or a band by name: ``'auto'``
    (the seed's rule, 2/T to 1.2 Hz), ``'eq18'`` or ``'sidpac'`` (Eq. 18, 0.20:0.04:1.20)."""
    import numpy as np
    if text.strip() in ("auto", "eq18", "sidpac"):
        return text.strip()
    if ":" in text:
        try:
            f0, df, f1 = (float(x) for x in text.split(":"))
        except ValueError:
            raise OptionError(f"--frequencies must be auto, eq18, sidpac, F0:DF:F1 or a comma list, "
                              f"not {text!r}") from None
        if not (0 < f0 < f1 and df > 0):
            raise OptionError(f"--frequencies {text!r}: need 0 < F0 < F1 and DF > 0")
        n = int(round((f1 - f0) / df)) + 1
        return tuple(float(x) for x in f0 + df * np.arange(n))
    vals = tuple(float(x) for x in text.split(",") if x.strip())
    if not vals or min(vals) <= 0:
        raise OptionError(f"--frequencies {text!r}: give positive frequencies")
    return vals
