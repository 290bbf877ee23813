"""Three rules that keep noise from being named: a time-skew rival that would have entered on
its own contests the term it stands beside (sensor_rules.rival_enters_alone), the nuisance biases
that lean on a contested term are not applied (sensor_rules.biases_of_contested), and a stepwise
term must also stand with the residual autocorrelation of an autoregressive model
(candidates.autoregressive_t)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from estimators.colored_stepwise import colored_fit
from harness.diagnosis import candidates as cand
from harness.diagnosis.kinematics import T_IN as KIN_T_IN
from harness.diagnosis.sensor_rules import (AMBIGUOUS_T, Contest, biases_of_contested, contested_parameters,
                                            kinematic_rival, rival_enters_alone, still_preferred)
from harness.diagnosis.stepwise_axes import aero_candidates


def test_a_rival_that_enters_alone_is_no_longer_outvoted_beside_the_term():
    """The T-37 of the docstring: beside the a_z skew the α scale keeps t 5.0 and the skew falls
    to 0.3, but the skew alone stands at 7.5: the pair is contested. A rival that alone stays
    under the entry t does not contest."""
    found = ("skew_az", -0.81, 5.0, 0.3, (0.036, 7.5))
    assert still_preferred(found) and rival_enters_alone(found)
    assert not rival_enters_alone(("skew_az", -0.81, 5.0, 0.3, (0.01, 2.0)))
    assert not rival_enters_alone(("skew_az", -0.81, 5.0, 0.3, None))
    # only a time skew's linearised column is so distrusted: the Twin Otter's accelerometer
    # position beside a β vane ahead of the c.g. stays with the t beside each other
    assert not rival_enters_alone(("vane_beta_x", -0.97, 4.0, 1.0, (5.3, 6.9)))
    assert not still_preferred(("skew_az", -0.81, 2.0, 0.3, None))  # the term itself too weak beside it
    assert not still_preferred(("skew_az", -0.81, 5.0, 3.0, None))  # the rival still stands beside it
    n = 3000
    rival = np.sin(np.linspace(0.0, 40.0, n))
    term = rival + 0.5 * np.sin(np.linspace(0.0, 23.0, n))  # r = 0.89
    kin = SimpleNamespace(columns={"scale_alpha": term, "skew_az": rival}, forced=(),
                          selection=SimpleNamespace(names=("scale_alpha",)))
    noise = np.random.default_rng(3).normal(size=n)
    kin.start = 0.05 * term + 0.02 * noise  # the term's own record: it stands beside the rival
    assert contested_parameters(kin) == {}
    kin.start = 0.01 * term + 0.04 * noise  # beside it the term keeps 2.5-6, the rival alone would enter
    found = kinematic_rival(kin, "scale_alpha")
    assert AMBIGUOUS_T <= found[2] < KIN_T_IN and found[3] < AMBIGUOUS_T and found[4][1] >= KIN_T_IN, found
    got = contested_parameters(kin)
    assert got["scale_alpha"].rival == "skew_az" and "alone in its place" in got["scale_alpha"].why


def test_a_bias_that_only_offsets_a_contested_scale_is_not_applied():
    """An α scale k on α = ᾱ + a(t) moves α's mean by k·ᾱ, which the α bias then takes back
    (−k·ᾱ). The record follows the rival (zero mean): with the rival in the scale's place the
    bias has nothing to do, so it is not applied while the scale is contested; a bias the
    record carries itself stays."""
    rng = np.random.default_rng(4)
    n = 3000
    tt = np.linspace(0.0, 30.0, n)
    wave = 0.02 * np.sin(1.3 * tt) + 0.004 * np.sin(3.1 * tt)
    alpha = 0.05 + wave
    rival = wave + 0.003 * np.sin(5.3 * tt)
    columns = {"bias_alpha": np.ones(n), "scale_alpha": alpha, "skew_az": rival}
    kin = SimpleNamespace(columns=columns, forced=("bias_alpha",), selection=SimpleNamespace(names=("scale_alpha",)))
    contested = {"scale_alpha": Contest("skew_az", 0.9, 4.0)}
    kin.start = 0.9 * rival + 0.002 * rng.normal(size=n)
    assert biases_of_contested(kin, contested) == {"bias_alpha"}
    kin.start = 0.9 * rival + 0.01 + 0.002 * rng.normal(size=n)  # a real bias of 0.01 as well
    assert biases_of_contested(kin, contested) == set()
    assert biases_of_contested(kin, {}) == set()


def _multisine_draws(n_draws: int):
    """Least-squares estimates of a three-line column's coefficient on white noise (truth 0),
    with Eq. 39's sample and the AR model's residual autocorrelation in Eq. 40."""
    n = 1000
    t = np.arange(n) / 25.0
    col = sum(np.sin(2 * np.pi * f * t + ph) for f, ph in ((0.3, 0.1), (0.7, 1.0), (1.1, 2.0)))
    est, se_sample, se_ar = [], [], []
    for seed in range(n_draws):
        e = np.random.default_rng(seed).normal(size=n)
        th, se, _ = colored_fit(e, [col], ["c"])
        _, se2, _ = colored_fit(e, [col], ["c"], autocorrelation="ar")
        est.append(th[0]), se_sample.append(se[0]), se_ar.append(se2[0])
    return np.array(est), np.array(se_sample), np.array(se_ar)


def test_a_multisine_columns_sample_error_scatters_and_the_ar_error_does_not():
    """A column with its power in three lines: the residual, orthogonal to it, keeps few degrees
    of freedom there, so Eq. 40 with Eq. 39's estimates scatters by about a fifth draw to draw
    (t heavy-tailed) while the AR model's, pooled over all frequencies, scatters a few per cent
    and matches the estimate's spread. 300 draws: a coefficient of variation is known to about
    1/√600 ≈ 4 % of itself, the spread over mean error to about ±0.04 (1σ)."""
    est, s, a = _multisine_draws(300)
    cv_sample, cv_ar = np.std(s) / np.mean(s), np.std(a) / np.mean(a)
    assert cv_sample > 0.15 and cv_ar < 0.08
    assert np.std(est) / np.mean(a) == pytest.approx(1.0, abs=0.15)
    # P(|t| > 3) is 0.27 % for a normal t: about 1 of 300 draws
    assert np.sum(np.abs(est / a) > 3.0) <= 4


def test_autoregressive_t_is_the_final_fits_t_with_the_ar_autocorrelation():
    rng = np.random.default_rng(1)
    n = 2000
    x = np.sin(np.linspace(0.0, 60.0, n))
    nuisance = np.cos(np.linspace(0.0, 17.0, n))
    z = 0.3 * x + 0.1 * nuisance + 0.05 * rng.normal(size=n)
    inner = slice(100, n - 100)
    sel = SimpleNamespace(names=("x",))
    got = cand.autoregressive_t(z, sel, {"x": x}, {"thrust": nuisance}, inner)
    th, se, _ = colored_fit(z[inner], [nuisance[inner], x[inner]], ["n", "x"], autocorrelation="ar")
    assert got == {"x": pytest.approx(th[1] / se[1])}
    assert cand.autoregressive_t(z, SimpleNamespace(names=()), {}, None, inner) == {}


def test_a_term_that_falls_under_the_entry_t_with_the_ar_errors_is_not_selected():
    term = SimpleNamespace(name="rhat", estimate=-0.094, std_error=0.0156, t=-6.05, gain=0.09, selected=True)
    column = SimpleNamespace(effect="coefficient_error", parameter="CY_rhat", scale=1.0, units="per rad",
                             details={"model_value": 0.22, "trim_value": 0.21})
    selections = {"CY": (SimpleNamespace(terms=(term,)), {"rhat": column})}
    shares = {("CY", "rhat"): 0.05}
    kept = aero_candidates(selections, {}, 0.04, shares, {("CY", "rhat"): -5.2})
    assert kept[0].selected and kept[0].reason == "entered"
    dropped = aero_candidates(selections, {}, 0.04, shares, {("CY", "rhat"): -4.2})
    assert not dropped[0].selected and "autoregressive" in dropped[0].reason and "t = -4.2" in dropped[0].reason
    # without the AR t (its fit failed) the sample-error verdict stands
    assert aero_candidates(selections, {}, 0.04, shares)[0].selected
