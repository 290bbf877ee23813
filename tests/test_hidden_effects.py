"""Aircraft with hidden physics (the groundwork of the concealed-effect gallery), each pinned
to what the effect must do exactly."""
from __future__ import annotations

import numpy as np
import pytest

from maneuvers.fly import FlightSpec, fly_maneuver
from maneuvers.recording import G0_FPS2
from models.aircraft import Aircraft
from models.hidden import HiddenEffect


@pytest.fixture(scope="module")
def nominal():
    return fly_maneuver(FlightSpec())


TRIM_TOL = 1e-7  # rad: JSBSim's trim converges to ~2e-8 rad, differently for two XML copies


def _fly(effect: HiddenEffect):
    return fly_maneuver(FlightSpec(aircraft=Aircraft("f16", hidden=(effect,))))


def test_unsteady_alphadot_term_has_its_size(nominal):
    rec = _fly(HiddenEffect("unsteady_alphadot", -3.0))
    d = rec.meta["truth"]["derivatives"]
    assert d["Cm_alphadot"]["local"] == pytest.approx(-3.0, rel=1e-9)   # measured through the α̇ gate
    # Cm_q is not contaminated by the α̇ term (central differences agree to ~1e-8 across the two XML copies)
    assert d["Cm_qhat"]["local"] == pytest.approx(nominal.meta["truth"]["derivatives"]["Cm_qhat"]["local"], rel=1e-6)
    assert rec.meta["trim"]["alpha_rad"] == pytest.approx(nominal.meta["trim"]["alpha_rad"], abs=TRIM_TOL)
    assert rec.meta["simulation"]["hidden_effects"] == [{"effect": "unsteady_alphadot", "size": -3.0}]
    assert np.max(np.abs(rec.channel("alpha") - nominal.channel("alpha"))) > np.radians(0.2)


def test_nonlinear_alpha_term_vanishes_with_its_slope_at_trim(nominal):
    rec = _fly(HiddenEffect("nonlinear_alpha", -0.5))
    tn, th = nominal.meta["truth"]["derivatives"], rec.meta["truth"]["derivatives"]
    assert rec.meta["trim"]["alpha_rad"] == pytest.approx(nominal.meta["trim"]["alpha_rad"], abs=TRIM_TOL)
    assert th["Cm_alpha"]["local"] == pytest.approx(tn["Cm_alpha"]["local"], rel=1e-6)
    da = rec.channel("alpha") - rec.meta["trim"]["alpha_rad"]
    # at the first sample the aircraft is at trim: the added term is zero there
    assert rec.truth["Cm"].iloc[0] == pytest.approx(nominal.truth["Cm"].iloc[0], abs=1e-8)
    assert np.max(np.abs(da)) > np.radians(2)


def test_control_delay_shifts_the_whole_response(nominal):
    """Starting from trim with quiet time first, a 60 ms delay on the stabilator (9 frames at
    150 Hz, 3 samples at 50 Hz) makes the response the nominal one 3 samples later, while the
    recorded stabilator stays the commanded one. (Not to rounding error: a trim is steady to
    about 1e-8 rad, so the quiet second drifts; measured: the 3-sample shift leaves at most
    2.8e-5 of each response's range, shifts of 2 or 4 samples 0.5-2 %.)"""
    rec = _fly(HiddenEffect("control_delay", 0.06, surface="de"))
    assert np.array_equal(rec.channel("de"), nominal.channel("de"))
    for q in ("alpha", "q", "V", "az"):
        a, b = rec.channel(q), nominal.channel(q)
        span = np.ptp(b)
        miss = {k: np.max(np.abs(a[k:] - b[:-k])) / span for k in (2, 3, 4)}
        assert miss[3] < 1e-4 and miss[3] < 1e-2 * min(miss[2], miss[4]), (q, miss)


def test_sensor_offset_adds_the_rigid_body_terms(nominal):
    x = 5.0
    rec = _fly(HiddenEffect("sensor_offset", x, position_ft=(x, 0.0, 0.0)))
    p, q, r = (nominal.channel(c) for c in ("p", "q", "r"))
    pd, qd, rd = (nominal.channel(c) for c in ("pdot", "qdot", "rdot"))
    # ω̇ × r + ω × (ω × r) with r = (x, 0, 0)
    assert np.allclose(rec.channel("ax") - nominal.channel("ax"), -(q**2 + r**2) * x / G0_FPS2, atol=1e-15)
    assert np.allclose(rec.channel("ay") - nominal.channel("ay"), (rd + p * q) * x / G0_FPS2, atol=1e-15)
    assert np.allclose(rec.channel("az") - nominal.channel("az"), (-qd + p * r) * x / G0_FPS2, atol=1e-15)
    assert rec.meta["sensors"]["accelerometer_ft"] == [0.0, 0.0, 0.0]  # concealed


def test_bad_hidden_effects_are_refused():
    with pytest.raises(ValueError, match="unknown hidden effect"):
        HiddenEffect("gremlins", 1.0)
    with pytest.raises(ValueError, match="non-negative"):
        HiddenEffect("control_delay", -0.1)


def test_cross_coupling_in_abs_beta_is_even_in_sideslip():
    """C_l += k·|β|: the same increment at +β and −β, zero at β = 0 (the diagnosis's term for
    a model whose rolling moment is even in sideslip, as the package DHC6's is)."""
    from models.replay import InitialCondition, aero_along
    ic = InitialCondition(10_000.0, 500.0)
    n = 3
    states = {"V": np.full(n, 500.0), "alpha": np.full(n, 0.03), "beta": np.array([-0.05, 0.0, 0.05]),
              "p": np.zeros(n), "q": np.zeros(n), "r": np.zeros(n), "phi": np.zeros(n), "theta": np.full(n, 0.03)}
    surfaces = {"de": np.full(n, -0.02), "da": np.zeros(n), "dr": np.zeros(n)}
    effect = HiddenEffect("cross_coupling", 0.3, coefficient="Cl", regressor="beta_abs")
    assert effect.parameter == "Cl_beta_abs"
    base = aero_along(Aircraft("f16"), ic, states, surfaces).coefficients["Cl"]
    added = aero_along(Aircraft("f16", hidden=(effect,)), ic, states, surfaces).coefficients["Cl"]
    assert added - base == pytest.approx([0.3 * 0.05, 0.0, 0.3 * 0.05], abs=1e-9)
    with pytest.raises(ValueError, match="beta_abs"):
        HiddenEffect("cross_coupling", 0.3, coefficient="Cl", regressor="beta")


def test_aerodynamics_that_are_not_finite_along_a_recording_are_a_flight_error():
    """models.replay.aero_along: where the model's coefficients are not finite along the
    recorded states (a departure a script flew the F-16 into, 20,000 ft and 650 ft/s with its
    FCS off, ran α through ±180°) the error is a FlightError (a user error: exit status 2, no
    traceback), naming the first such sample and its state. Here the c172x's α̇ terms meet an
    α̇ that is not a number at the second sample."""
    from models.aircraft import library_xml
    from models.flight import FlightError
    from models.replay import InitialCondition, aero_along
    ic = InitialCondition(4_000.0, 180.0)
    n = 3
    states = {"V": np.full(n, 180.0), "alpha": np.full(n, 0.03), "beta": np.zeros(n), "p": np.zeros(n),
              "q": np.zeros(n), "r": np.zeros(n), "phi": np.zeros(n), "theta": np.full(n, 0.03)}
    surfaces = {"de": np.full(n, -0.02), "da": np.zeros(n), "dr": np.zeros(n)}
    with pytest.raises(FlightError, match=r"not finite along the recording \(.*Cm\) from sample 2 "
                                          r"\(α 1\.7°, β 0\.0°, V 180 ft/s, h 4000 ft\)"):
        aero_along(Aircraft(str(library_xml("c172x"))), ic, states, surfaces, alphadot=np.array([0.0, np.nan, 0.0]))
