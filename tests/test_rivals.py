"""The rival tests of the diagnosis (harness/diagnosis/rivals.py), on synthetic mismatches
whose answer is known."""
from __future__ import annotations

import numpy as np
import pytest

from harness.diagnosis import rivals


def _signals(n: int = 2000, seed: int = 3):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 20.0, n)
    a = np.sin(0.7 * t) + 0.3 * np.sin(2.1 * t)
    return rng, t, a


def test_a_collinear_rival_that_explains_the_data_as_well_is_found():
    rng, t, a = _signals()
    b = a + 0.05 * np.sin(5.3 * t)          # correlated with a at > 0.99
    z = 2.0 * a + 0.05 * rng.standard_normal(t.size)
    r = rivals.strongest_rival(z, {"a": a, "b": b, "c": np.cos(0.3 * t)}, "a", [], ["b", "c"])
    assert r is not None and r.key == "b"
    assert abs(r.correlation) > rivals.RIVAL_CORRELATION
    # in the fit with its rival, the true term stays significant (the data do tell them apart
    # here: the rival's extra sine is absent from z), and the rival alone takes about a's size
    assert abs(r.t_term) > 5.0
    assert r.swapped == pytest.approx(2.0, rel=0.05)


def test_an_indistinguishable_rival_leaves_the_term_insignificant():
    rng, t, a = _signals()
    b = a + 0.002 * rng.standard_normal(t.size)   # the same column up to noise
    z = 2.0 * a + 0.3 * rng.standard_normal(t.size)
    r = rivals.strongest_rival(z, {"a": a, "b": b}, "a", [], ["b"])
    assert r is not None and abs(r.t_term) < 5.0


def test_an_uncorrelated_candidate_is_no_rival():
    rng, t, a = _signals()
    z = 2.0 * a + 0.05 * rng.standard_normal(t.size)
    assert rivals.strongest_rival(z, {"a": a, "c": np.cos(3.3 * t)}, "a", [], ["c"]) is None


def test_a_vane_bias_seen_through_a_curved_model_is_recovered():
    # model C(x) = 2 x + 9 x^2: slope 2 + 18 x; a vane reading Δ high makes the mismatch
    # -slope·Δ, which a term in x imitates
    rng, t, a = _signals()
    x = 0.05 * a
    slope = 2.0 + 18.0 * x
    delta = np.radians(1.0)
    z = -slope * delta + 1e-4 * rng.standard_normal(t.size)
    b = rivals.bias_rival(z, x, [], slope, "alpha", (0.0, np.inf))
    assert b is not None
    assert b.bias_rad == pytest.approx(delta, rel=0.02)
    assert abs(b.t_term) < 5.0          # the x column adds nothing beside the slope column
    assert not b.ruled_out              # the kinematics did not test it
    tight = rivals.bias_rival(z, x, [], slope, "alpha", (0.0, np.radians(0.05)))
    assert tight.ruled_out              # 1 deg is 20 standard errors from a kinematic 0 ± 0.05 deg


def test_a_linear_model_gives_no_bias_rival():
    _, t, a = _signals()
    assert rivals.bias_rival(a, a, [], np.full(t.size, 2.0), "alpha", (0.0, 1.0)) is None
