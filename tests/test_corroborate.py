"""Corroborated sensor errors (harness.diagnosis.corroborate): the ratio fit is exact on
noise-free data, and the verdict follows its three rules."""
import numpy as np
import pytest

from harness.diagnosis.corroborate import (AxisRatio, axis_ratio, corroborate, estimate_correlation,
                                          inverse_variance_mean, inverse_variance_mean_correlated)


def test_axis_ratio_recovers_the_multiple_of_the_signature_exactly():
    t = np.linspace(0.0, 10.0, 501)
    signature = np.sin(1.3 * t) + 0.2 * t
    other = np.cos(0.7 * t)
    z = 0.4 * other - 0.8 * signature + 0.05
    r = axis_ratio(z, [other], signature)
    assert r.ratio == pytest.approx(0.8, abs=1e-10)


def test_axis_ratio_is_none_for_a_flat_signature():
    assert axis_ratio(np.ones(50), [], np.zeros(50)) is None


def _r(a, s):
    return AxisRatio("", a, s)


def test_agreeing_axes_and_kinematics_name_the_sensor_with_the_pooled_size():
    v = corroborate("bias_alpha", 0.03, 0.01, {"CZ": _r(1.0, 0.1), "Cm": _r(0.9, 0.05)}, t_aero=5.0)
    assert v.named
    a_hat = (1.0 / 0.01 + 0.9 / 0.0025) / (1 / 0.01 + 1 / 0.0025)
    assert v.ratio == pytest.approx(a_hat)
    s_aero = 0.03 * np.sqrt(1.0 / (1 / 0.01 + 1 / 0.0025))
    w_k, w_a = 1 / 0.01 ** 2, 1 / s_aero ** 2
    assert v.estimate == pytest.approx((w_k * 0.03 + w_a * a_hat * 0.03) / (w_k + w_a))


def test_an_axis_that_disagrees_means_a_coefficient_error_not_an_instrument():
    v = corroborate("scale_alpha", 0.1, 0.02, {"CZ": _r(1.0, 0.05), "Cm": _r(0.0, 0.05)}, t_aero=5.0)
    assert not v.named and "disagree" in v.reason


def test_uninformative_axes_do_not_vote_and_weak_evidence_is_not_named():
    assert not corroborate("skew_q", 0.04, 0.01, {"Cm": _r(1.0, 3.0)}, t_aero=5.0).named
    v = corroborate("skew_q", 0.04, 0.01, {"Cm": _r(1.0, 0.4)}, t_aero=5.0)
    assert not v.named and "does not show it clearly" in v.reason


def test_a_size_far_from_the_kinematic_one_is_not_named():
    v = corroborate("skew_q", 0.04, 0.004, {"Cm": _r(2.0, 0.05)}, t_aero=5.0)
    assert not v.named and "times the kinematic size" in v.reason


def test_a_vane_scale_imitates_when_every_axis_that_can_tell_agrees():
    from harness.diagnosis.corroborate import imitates
    ag = imitates({"CZ": _r(3.0, 0.5), "Cm": _r(4.9, 1.6), "Cn": _r(-30.0, 40.0)}, t_aero=5.0)
    assert ag is not None and {a.axis for a in ag.axes} == {"CZ", "Cm"}
    # C_m says the vane scale is not there: a C_Z,α error, not the vane
    assert imitates({"CZ": _r(3.0, 0.5), "Cm": _r(0.0, 0.2)}, t_aero=5.0) is None
    # one axis alone cannot tell the two apart; nor can a weak signature
    assert imitates({"CZ": _r(3.0, 0.5), "Cm": _r(4.9, 40.0)}, t_aero=5.0) is None
    assert imitates({"CZ": _r(1.0, 0.5), "Cm": _r(1.0, 0.5)}, t_aero=5.0) is None


def test_inertial_angles_recover_alpha_without_the_vanes_wander():
    """A pitch-plane flight built from its kinematics (seed Eq. 1's w equation): the angle
    integrated from a_z, q and θ equals α to integration accuracy, and a slow wander added to
    the vane reading does not reach it beyond the constant and trend it is placed by."""
    from types import SimpleNamespace
    from harness.diagnosis.kinematics import inertial_angles
    from models.constants import G0_FPS2 as g
    dt, n = 0.01, 2001
    t = np.arange(n) * dt
    V = np.full(n, 500.0)
    alpha = 0.05 + 0.02 * np.sin(1.7 * t)
    theta = 0.05 + 0.03 * np.sin(0.9 * t)
    q = 0.03 * 0.9 * np.cos(0.9 * t)
    u, w = V * np.cos(alpha), V * np.sin(alpha)
    w_dot = V * np.cos(alpha) * 0.02 * 1.7 * np.cos(1.7 * t)
    az = (w_dot - q * u - g * np.cos(theta)) / g
    z = np.zeros(n)
    ch = {"V": V, "alpha": alpha, "beta": z, "p": z, "q": q, "r": z, "phi": z, "theta": theta, "ay": z, "az": az}
    p = SimpleNamespace(dt=dt)
    assert np.max(np.abs(inertial_angles(ch, p)["alpha"] - alpha)) < 1e-6
    wander = 0.0017 * np.sin(0.4 * t + 1.0)  # 0.1 deg, in the maneuver's band
    got = inertial_angles(ch | {"alpha": alpha + wander}, p)["alpha"]
    A = np.column_stack([np.ones(n), t])
    placed = wander - A @ np.linalg.lstsq(A, wander, rcond=None)[0]
    assert np.std(got - alpha) < 0.25 * np.std(placed)


def test_inverse_variance_mean_of_two_estimates():
    """(1/σ₁² x₁ + 1/σ₂² x₂)/(1/σ₁² + 1/σ₂²) and 1/√(1/σ₁² + 1/σ₂²): 0.10 ± 0.01 and
    0.13 ± 0.02 give 0.106 ± 0.01/√1.25; equal errors give the plain mean and σ/√2."""
    est, se = inverse_variance_mean([0.10, 0.13], [0.01, 0.02])
    assert est == pytest.approx((0.10 * 1e4 + 0.13 * 2.5e3) / 1.25e4) and se == pytest.approx(0.01 / np.sqrt(1.25))
    est, se = inverse_variance_mean([1.0, 3.0], [0.5, 0.5])
    assert est == pytest.approx(2.0) and se == pytest.approx(0.5 / np.sqrt(2.0))


def test_inverse_variance_mean_of_correlated_estimates():
    """The same weights, √(wᵀΣw) for the error: equal errors σ correlated ρ give the plain mean
    and σ√((1 + ρ)/2); fully correlated, the weighted mean of the σ's; uncorrelated, the
    independent mean's 1/√Σσ⁻²."""
    est, se = inverse_variance_mean_correlated([1.0, 3.0], [0.5, 0.5], np.array([[1.0, 0.9], [0.9, 1.0]]))
    assert est == pytest.approx(2.0) and se == pytest.approx(0.5 * np.sqrt(0.95))
    est, se = inverse_variance_mean_correlated([0.10, 0.13], [0.01, 0.02], np.ones((2, 2)))
    assert est == pytest.approx(inverse_variance_mean([0.10, 0.13], [0.01, 0.02])[0])
    assert se == pytest.approx(0.8 * 0.01 + 0.2 * 0.02)
    assert inverse_variance_mean_correlated([0.10, 0.13], [0.01, 0.02], np.eye(2)) == pytest.approx(
        inverse_variance_mean([0.10, 0.13], [0.01, 0.02]))


def _wander_and_signature(seed: int, n: int = 1500, dt: float = 0.02):
    from scipy.signal import lfilter
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    signature = np.sin(2 * np.pi * 0.3 * t) + 0.5 * np.sin(2 * np.pi * 0.77 * t)
    # a Gauss-Markov wander, τ = 1 s, unit variance
    wander = lfilter([np.sqrt(1 - 0.98 ** 2)], [1.0, -0.98], rng.normal(size=n))
    return rng, signature, wander


def test_estimates_sharing_one_residual_are_fully_correlated_and_independent_ones_are_not():
    """Two axes whose residuals are the same record (scaled) give estimates correlated 1;
    independent white residuals give about 0: over 40 seeds within 4/√N_eff of it, the
    Bartlett window's lags making N_eff ~ N/5 (30 s at 50 Hz), and mostly exactly 0, under
    twice the scatter of the same statistic on circularly shifted residuals (the chance of
    more than 8 of 40 there, each 5 %, is under 1e-3)."""
    rng, sig, _ = _wander_and_signature(0)
    e = rng.normal(size=sig.size)
    a, b = axis_ratio(0.1 * sig + e, [], sig), axis_ratio(0.1 * sig + 3 * e, [], 3 * sig)
    assert estimate_correlation(a, b) == pytest.approx(1.0, abs=1e-9)
    rhos = []
    for seed in range(40):
        rng, sig, _ = _wander_and_signature(seed)
        a = axis_ratio(rng.normal(size=sig.size), [], sig)
        b = axis_ratio(2 * rng.normal(size=sig.size), [], sig)
        rhos.append(estimate_correlation(a, b))
    assert abs(np.mean(rhos)) < 4 / np.sqrt(40 * sig.size / 5) and np.max(np.abs(rhos)) < 4 / np.sqrt(sig.size / 5)
    # under 2 of its own scatter (circular shifts) a correlation counts as none: ~95 % of these
    assert np.mean(np.array(rhos) == 0.0) >= 0.8


def test_axes_carrying_one_vane_wander_are_not_three_independent_tests():
    """C_Y, C_l and C_n each read a β-vane error through the model's slope, so the vane's own
    wander is in all three (here with a third of each residual white and independent). Each
    axis alone shows the signature at t ≈ 3.5; combined as independent they would show it at
    t ≈ 6 and name it; with their correlation the common t stays near the single axis's, under
    the aerodynamic entry t of 5."""
    rng, sig, wander = _wander_and_signature(3)
    ratios = {}
    for k, slope in (("CY", -1.0), ("Cl", 0.3), ("Cn", 0.5)):
        e = slope * (wander + 0.5 * rng.normal(size=sig.size))
        first = axis_ratio(e, [], slope * sig)
        ratios[k] = axis_ratio(e - 3.5 * first.std_error * slope * sig, [], slope * sig)
    single = [r.ratio / r.std_error for r in ratios.values()]
    assert all(2.0 < t < 6.0 for t in single), single
    independent = inverse_variance_mean([r.ratio for r in ratios.values()], [r.std_error for r in ratios.values()])
    verdict = corroborate("vane_beta_x", 1.0, 0.3, ratios, t_aero=5.0)
    assert not verdict.named and "does not show it clearly" in verdict.reason
    assert verdict.ratio / verdict.ratio_std < 0.7 * independent[0] / independent[1]


def test_a_scale_whose_mistrim_the_mismatch_lacks_is_refuted_by_the_mean():
    """corroborate.mistrim_test: a scale error acts on the whole reading, so the model along it
    is off at trim by the signature's mean (z = −a·Δ). A mismatch whose constant beside the
    other terms lacks that mistrim is a change of the aerodynamics that vanishes at trim (an
    independent script's lift change read as an α scale on C_X, C_Z and C_m); one that has
    it, or more than it, leaves the scale named, and a signature without a mean (a bias's,
    a skew's) is not tested."""
    def axis(mean, sig_mean=0.02):
        return AxisRatio("CZ", 1.0, 0.1, mean=mean, mean_se=0.002, signature_mean=sig_mean)

    kinematic = (-0.08, 0.02)
    lacking = corroborate("scale_alpha", *kinematic, {"CZ": axis(0.0)}, t_aero=5.0)
    assert not lacking.named and lacking.reason.startswith("refuted by the mean of CZ")
    assert corroborate("scale_alpha", *kinematic, {"CZ": axis(-0.02)}, t_aero=5.0).named
    assert corroborate("scale_alpha", *kinematic, {"CZ": axis(-0.04)}, t_aero=5.0).named
    assert corroborate("skew_q", *kinematic, {"CZ": axis(0.0, np.nan)}, t_aero=5.0).named
    from harness.diagnosis.corroborate import MISTRIM_SHARE, mistrim_test
    # short by less than the share of the prediction: not refuted
    assert mistrim_test((axis(-0.02 * (1 - 0.9 * MISTRIM_SHARE)),), 1.0, 0.01) == ""


def test_axis_ratio_reads_the_mismatch_constant_without_the_signature():
    """The mean the mistrim test weighs is the mismatch's own constant beside the other terms
    (the signature left out), and the signature's mean is kept beside the ratio."""
    t = np.linspace(0.0, 10.0, 501)
    signature = np.sin(1.3 * t) + 0.3
    other = np.cos(0.7 * t)
    z = 0.4 * other - 0.8 * (signature - 0.3)  # the perturbation without the mistrim
    r = axis_ratio(z, [other], signature)
    assert r.ratio == pytest.approx(0.8, abs=1e-10)
    assert r.signature_mean == pytest.approx(float(np.mean(signature)))
    expected = np.linalg.lstsq(np.column_stack([other, np.ones_like(t)]), z, rcond=None)[0][1]
    assert r.mean == pytest.approx(float(expected), abs=1e-12)


def test_a_gyro_skews_two_readings_may_differ_by_a_simulation_step():
    """A rectangular-Euler simulator puts its gyros h/2 ahead of the attitude's difference (the
    kinematics read a lead) and the rates' difference h/2 behind the moments (the moment
    mismatch reads a lag): a p skew of 40 ms at 100 Hz read 34 ± 3 ms and 45 ± 1 ms. They
    agree within one sample interval, which a rate gyro's skew is allowed; not another
    parameter."""
    from harness.diagnosis.corroborate import gyro_skew_tolerance
    ratios = {"Cl": _r(1.32, 0.03)}
    assert not corroborate("skew_p", 0.0343, 0.0026, ratios, t_aero=5.0).named
    named = corroborate("skew_p", 0.0343, 0.0026, ratios, t_aero=5.0, tolerance=gyro_skew_tolerance("skew_p", 0.01))
    assert named.named and 0.04 < named.estimate < 0.046
    assert gyro_skew_tolerance("skew_alpha", 0.01) == 0.0 and gyro_skew_tolerance("skew_r", 0.02) == 0.02


def test_the_offered_term_most_collinear_with_the_signature_beside_the_others():
    """axis_ratio keeps the axis's own candidate column most correlated with the signature once
    both are made orthogonal to the named terms and a constant (exact on constructed data),
    and the share the fitted signature makes of the coefficient's excursion."""
    t = np.linspace(0.0, 10.0, 501)
    other = np.cos(0.7 * t)
    rate = np.sin(1.3 * t)
    signature = 2.0 * rate + 0.5 * other + 0.1  # the named term and a constant explain the rest
    z = 0.4 * other - 0.8 * signature
    offered = {"Cl_phat": rate + 3.0 * other, "Cl_da": np.sin(2.9 * t) + 0.01 * rate}
    r = axis_ratio(z, [other], signature, offered=offered, excursion=float(np.std(z)) * 10)
    assert r.imitator == "Cl_phat" and r.imitator_r == pytest.approx(1.0, abs=1e-9)
    assert r.share == pytest.approx(0.8 * np.std(signature) / (10 * np.std(z)))
    assert axis_ratio(z, [other], signature).imitator == ""


def test_axes_their_own_terms_imitate_are_no_second_test():
    """corroborate.imitated_by_own_terms: the Global 5000 null's V scale (kinematic −0.059 ±
    0.017) shown by C_l alone (0.71 ± 0.13, collinear with C_l,p̂ at r 0.988, a share of
    0.026) is not named, nor one C_l and C_m show only as small rate-derivative changes; an
    axis making a practical share (an a_z skew's C_Z, 0.097) or a signature no term imitates
    tells it."""
    from harness.diagnosis.corroborate import IMITATOR_R, imitated_by_own_terms
    from harness.diagnosis.candidates import PRACTICAL_SHARE

    def ax(name, ratio, se, r, share):
        return AxisRatio(name, ratio, se, imitator="term", imitator_r=r, share=share)
    weak_cm = ax("Cm", 0.39, 0.41, 0.67, 0.007)
    v = corroborate("scale_V", -0.059, 0.0176, {"Cl": ax("Cl", 0.71, 0.126, 0.988, 0.026), "Cm": weak_cm},
                    t_aero=5.0)
    assert not v.named and "Cl as a change of term (r = 0.988" in v.reason
    assert imitated_by_own_terms((ax("CZ", 1.24, 0.17, 0.974, 0.097),)) == ""
    assert imitated_by_own_terms((ax("Cl", 0.71, 0.126, IMITATOR_R - 0.01, 0.026),)) == ""
    assert imitated_by_own_terms((ax("Cl", 0.71, 0.126, 0.99, PRACTICAL_SHARE),)) == ""
    # two axes, each as a small change of its own rate derivative (an F-16's V scale, kinematic t 3.2)
    assert imitated_by_own_terms((ax("Cl", 1.64, 0.41, 0.998, 0.025), ax("Cm", 1.46, 0.43, 0.99999, 0.012))) != ""
    assert imitated_by_own_terms((ax("Cl", 1.0, 0.2, 1.0, 0.09), ax("Cn", 1.0, 0.2, 1.0, 0.01))) == ""


def test_a_practical_share_on_imitated_axes_needs_the_kinematics_own_suspicion():
    """corroborate.imitated_by_own_terms: every showing axis a change of its own term, one of
    them of practical size, tells the sensor only where the kinematics stand at
    ONE_AXIS_KINEMATIC_T: the Global 5000 whose C_m,q̂ change of −4 named an α vane 18 ft ahead
    (kinematic 11 ± 4.4 ft, C_m 2.0 ± 0.2 times as C_m,q̂, r 0.999, share 0.040; C_X 1.25 ±
    0.53 as C_X,q̂, r 0.97) is refuted; the a_z skew's C_Z (share 0.097) at kinematic t 3.6
    is not."""
    from harness.diagnosis.corroborate import ONE_AXIS_KINEMATIC_T, imitated_by_own_terms

    def ax(name, ratio, se, r, share):
        return AxisRatio(name, ratio, se, imitator="term", imitator_r=r, share=share)
    axes = {"CX": ax("CX", 1.253, 0.53, 0.97, 0.036), "CZ": ax("CZ", 0.588, 0.523, 1.0, 0.017),
            "Cm": ax("Cm", 2.012, 0.197, 0.999, 0.0401)}
    why = imitated_by_own_terms(tuple(axes.values()), 11.05 / 4.40)
    assert "kinematics only at t = 2.5" in why and "a change of the term itself" in why
    v = corroborate("vane_alpha_x", 11.05, 4.40, axes, t_aero=5.0)
    assert not v.named and "kinematics only at t = 2.5" in v.reason
    assert imitated_by_own_terms(tuple(axes.values()), ONE_AXIS_KINEMATIC_T) == ""
    assert imitated_by_own_terms((ax("CZ", 1.24, 0.17, 0.974, 0.097),), 3.6) == ""


def test_a_share_under_the_practical_limit_never_prints_as_the_limit():
    """candidates.share_below_practical: 3.96 % reads "3.96 %", not "4.0 % (under 4 %)"."""
    from harness.diagnosis.candidates import share_below_practical
    assert share_below_practical(0.0396) == "3.96 % of the coefficient's excursion (under 4 %)"
    assert share_below_practical(0.032).startswith("3.2 % ")
    assert share_below_practical(0.03999).startswith("3.999 % ")


def test_one_axis_needs_the_kinematics_at_three_standard_errors():
    """corroborate.one_axis_and_a_weak_suspicion: a c182 in a banked turn whose C_m carried an
    α² change had a q scale named from C_m alone (0.90 ± 0.15) and the kinematics at t 2.5; at
    t 3 and beyond, or with a second axis showing it, the two tests may name it."""
    from harness.diagnosis.corroborate import ONE_AXIS_KINEMATIC_T, one_axis_and_a_weak_suspicion
    cm = AxisRatio("Cm", 0.90, 0.15, imitator="Cm_de", imitator_r=0.936, share=0.042)
    v = corroborate("scale_q", 0.0344, 0.0344 / 2.5, {"Cm": cm}, t_aero=5.0)
    assert not v.named and "only Cm shows it" in v.reason
    assert corroborate("scale_q", 0.0344, 0.0344 / ONE_AXIS_KINEMATIC_T, {"Cm": cm}, t_aero=5.0).named
    assert one_axis_and_a_weak_suspicion((cm, AxisRatio("CZ", 1.0, 0.3)), 2.5) == ""


def test_an_own_term_under_the_rival_correlation_is_still_fitted_beside_the_signature():
    """corroborate.axis_ratio fits the axis's most collinear own term beside the signature
    whatever their correlation: a probe's F-4N with C_Z,α 0.5 higher (pitch multisine,
    100 Hz) had its accelerometer named 5.1 ft aft on C_Z and C_m, C_Z's signature correlated
    with C_Z,α at r 0.697, under the 0.7 gate that fit once had, so C_Z counted as showing
    the error though beside C_Z,α it stood at t −0.2. Constructed: the mismatch is the term's
    change and noise, the signature shares r = 0.69 with the term."""
    from harness.diagnosis.corroborate import explained_by_own_term
    rng = np.random.default_rng(4)
    t = np.linspace(0.0, 30.0, 3001)
    term = np.sin(1.3 * t)
    other = np.sin(2.1 * t + 0.4)
    other -= term * np.dot(other, term) / np.dot(term, term)
    unit = lambda x: (x - x.mean()) / np.std(x)
    signature = 0.69 * unit(term) + np.sqrt(1.0 - 0.69 ** 2) * unit(other)
    z = 0.5 * term + 0.05 * rng.normal(size=t.size)
    r = axis_ratio(z, [], signature, offered={"CZ_alpha": term}, excursion=float(np.std(z)))
    assert r.imitator == "CZ_alpha" and r.imitator_r == pytest.approx(0.69, abs=0.01)
    assert abs(r.ratio) / r.std_error > 2.0                 # alone, the signature "shows" the error
    t_signature, t_term = r.beside_imitator
    assert abs(t_signature) < 2.0 and abs(t_term) > 10.0
    assert explained_by_own_term(r)
