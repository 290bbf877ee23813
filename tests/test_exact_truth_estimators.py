"""Issue 3 must-show 3: on the noise-free exact-truth F-16 recording every equation-error
method recovers the derivatives to 1e-4 relative (the frequency-domain method has no bias)."""
from __future__ import annotations

import pytest

from estimators.methods import make_estimator
from estimators.regressors import Equation

LON = ("alpha", "qhat", "de")
LAT = ("beta", "phat", "rhat", "da", "dr")
EQUATIONS = [("CX", LON), ("CZ", LON), ("Cm", LON), ("CY", LAT), ("Cl", LAT), ("Cn", LAT)]


@pytest.mark.parametrize("method,errors", [("ee-time", "conventional"), ("ee-time", "colored"),
                                           ("ee-smooth", "conventional"), ("ee-smooth", "colored"),
                                           ("ee-freq", "conventional")])
@pytest.mark.parametrize("coef,regs", EQUATIONS)
def test_equation_error_recovers_exact_truth(three_axis_exact, method, errors, coef, regs):
    truth = three_axis_exact.meta["truth"]["derivatives"]
    fit = make_estimator(method, errors=errors).fit(three_axis_exact, Equation(coef, regs))
    assert ("bias" in fit.names) == (method != "ee-freq")
    for r in regs:
        true = truth[f"{coef}_{r}"]["local"]
        assert fit.param(f"{coef}_{r}") == pytest.approx(true, rel=1e-4), (method, coef, r)
