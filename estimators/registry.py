"""The one registry of estimators: every method by name with its capabilities, declared here with
the method (time or frequency domain, the error bounds it reports, whether it fits a bias, takes
several maneuvers or fits a whole output-error model), so that no other package keeps lists of
method names. Light to import (the command line builds its options from it); the estimators
themselves are built by :func:`estimators.methods.make_estimator`.
"""
from __future__ import annotations

from dataclasses import dataclass

from models.errors import OptionError

__all__ = ["MethodInfo", "REGISTRY", "METHODS", "COMBINED_METHODS", "method_info"]


@dataclass(frozen=True)
class MethodInfo:
    """A method's capabilities, declared with it.

    ``domain``: ``'time'`` or ``'frequency'``. ``errors``: the error bounds it reports, its
    default first (``conventional`` Eq. 15, ``colored`` Eq. 40, ``cramer-rao``). ``maneuvers``:
    ``'one'`` (a recording or one RegressionData) or ``'several'`` (``fit`` takes a sequence of
    RegressionData of the same equation, seed §III.F). ``whole_model``: fits its whole dynamic
    model once per flight, not one equation (output error). ``selects_terms``: chooses its own
    regressors from the candidates given (stepwise), so its estimates cover a subset of them.
    ``bias``: whether it fits a bias term (the frequency domain never does).
    """

    name: str
    domain: str
    errors: tuple[str, ...]
    maneuvers: str = "one"
    whole_model: bool = False
    selects_terms: bool = False
    bias: bool = True

    def supports(self, errors: str) -> bool:
        return errors in self.errors

    def error_types(self, wanted: tuple[str, ...]) -> tuple[str, ...]:
        """The error types of ``wanted`` this method reports, or its default when none."""
        return tuple(e for e in wanted if e in self.errors) or self.errors[:1]


REGISTRY: dict[str, MethodInfo] = {m.name: m for m in (
    MethodInfo("ee-time", "time", ("conventional", "colored")),
    MethodInfo("ee-smooth", "time", ("colored", "conventional")),
    MethodInfo("ee-freq", "frequency", ("conventional",), bias=False),
    MethodInfo("oe", "time", ("cramer-rao",), whole_model=True),
    MethodInfo("oe-freq", "frequency", ("cramer-rao",), whole_model=True),
    MethodInfo("fe", "time", ("cramer-rao",), whole_model=True),
    MethodInfo("stepwise", "time", ("conventional",), selects_terms=True),
    MethodInfo("ee-concat", "time", ("conventional", "colored"), maneuvers="several"),
    MethodInfo("ee-sequential", "time", ("conventional",), maneuvers="several"),
    MethodInfo("ee-sequential-unequal", "time", ("conventional",), maneuvers="several"),
    MethodInfo("ee-freq-combined", "frequency", ("conventional",), maneuvers="several", bias=False),
)}

METHODS: tuple[str, ...] = tuple(n for n, m in REGISTRY.items() if m.maneuvers == "one" and not m.selects_terms)
"""The methods that fit one recording's equation as given (``sidbench estimate --method``, a campaign's grid)."""

COMBINED_METHODS: tuple[str, ...] = tuple(n for n, m in REGISTRY.items() if m.maneuvers == "several")
"""The methods that fit several maneuvers together (a campaign's ``combine`` grid)."""


def method_info(name: str) -> MethodInfo:
    """What the registry declares of method ``name``."""
    try:
        return REGISTRY[name]
    except KeyError:
        raise OptionError(f"unknown method {name!r}; choose one of {METHODS}") from None
