"""A deliberately biased estimator, registered by the nightly test through a campaign's
``[method_factories]`` to plant a regression."""
from __future__ import annotations

import dataclasses

from estimators.methods import make_estimator


@dataclasses.dataclass(frozen=True)
class Biased:
    inner: object
    factor: float

    @property
    def method(self) -> str:
        return self.inner.method

    def fit(self, source, equation=None):
        fit = self.inner.fit(source, equation)
        return dataclasses.replace(fit, params=fit.params * self.factor)


def biased_frequency(method: str, **kwargs) -> Biased:
    """The frequency-domain estimator with every estimate 10 % too large."""
    return Biased(make_estimator("ee-freq", **kwargs), 1.10)
