"""Two rules of the diagnosis that keep one error from being named as another: a force change
acting at a reference point away from the c.g. moves the moments too
(term_rules.withhold_explained_by_force_arm), and a kinematic rival is sized in the place of
the term it contests, not beside it (sensor_rules.kinematic_rival)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from harness.diagnosis.evidence import Candidate
from harness.diagnosis.sensor_rules import kinematic_rival
from harness.diagnosis.term_rules import (moment_of_force_change, reference_arm_ft,
                                          withhold_explained_by_force_arm)


def test_a_force_at_the_reference_point_moves_the_moments_by_r_cross_f():
    """r × F with r = (x, 0, z) and F = (C_X, C_Y, C_Z) q̄S: L = −z F_y, M = z F_x − x F_z,
    N = x F_y, over q̄Sb (q̄Sc̄ for M)."""
    r = np.array([1.5, 0.0, -4.0])
    F = np.array([0.02, -0.1, -0.3])
    L, M, N = np.cross(r, F)
    got = moment_of_force_change({"CX": F[0], "CY": F[1], "CZ": F[2]}, (r[0], r[2]), {"b_ft": 90.0, "cbar_ft": 12.0})
    assert got["Cl"] == pytest.approx(L / 90.0) and got["Cm"] == pytest.approx(M / 12.0)
    assert got["Cn"] == pytest.approx(N / 90.0)
    # the trim's structural positions (x aft, z up, in): the 737's AERORP 625/24, its c.g. 639/−40
    trim = SimpleNamespace(aero_rp_in=(625.0, 0.0, 24.0), cg_in=(639.0, 0.0, -40.0))
    assert reference_arm_ft(trim) == pytest.approx((14.0 / 12.0, -64.0 / 12.0))


def _stepwise(axis: str, key: str, parameter: str, column: np.ndarray, change: float):
    sel = SimpleNamespace(names=(key,), params={key: change})
    term = SimpleNamespace(column=column, parameter=parameter)
    cand = Candidate("coefficient_error", "lat", axis, parameter, change, abs(change) / 20, 20.0, 0.1, "1/rad",
                     f"stepwise on the {axis} mismatch", True, "entered")
    return (sel, {key: term}), cand


def _side_force_roll(dt: float, n: int, b_ft: float, cbar_ft: float, trim):
    """A recording stand-in with a two-sine β, and the roll a C_Y,β change of −0.25 acting at
    the trim's reference point makes about the c.g."""
    t = np.arange(n) * dt
    beta = 0.02 * np.sin(2 * np.pi * 0.3 * t) + 0.01 * np.sin(2 * np.pi * 0.9 * t)
    p = SimpleNamespace(n=n, dt=dt, smooth={"alpha": np.full(n, 0.05)},
                        meta={"geometry": {"b_ft": b_ft, "cbar_ft": cbar_ft}})
    return p, beta, -reference_arm_ft(trim)[1] * (-0.25 * beta) / b_ft


def test_a_roll_the_side_force_change_makes_about_the_cg_is_not_a_cl_change():
    """A C_Y,β change of −0.25 acting 5.3 ft above the c.g. (b 94.7 ft) rolls by +0.056 ΔC_Y:
    a C_l,β 'change' of −0.014 in the mismatch is its moment and is withheld; a C_l,β change of
    −0.03 on top of it stays."""
    rng = np.random.default_rng(1)
    trim = SimpleNamespace(aero_rp_in=(625.0, 0.0, 24.0), cg_in=(639.0, 0.0, -40.0))
    p, beta, roll = _side_force_roll(0.02, 1500, 94.7, 11.0, trim)
    n = p.n
    for extra, kept in ((0.0, False), (-0.03, True)):
        cy_sel, cy = _stepwise("CY", "beta", "CY_beta", beta, -0.25)
        cl_sel, cl = _stepwise("Cl", "beta", "Cl_beta", beta, -0.014 + extra)
        mismatch = {"CY": -0.25 * beta, "Cl": roll + extra * beta + rng.normal(scale=1e-5, size=n)}
        withhold_explained_by_force_arm([cy, cl], {"CY": cy_sel, "Cl": cl_sel}, mismatch, p, trim)
        assert cy.selected and cl.selected is kept
        if not kept:
            assert "reference point" in cl.reason


def test_a_force_change_left_unnamed_beside_the_accelerometer_still_explains_its_moment():
    """The T-37 of the docstring: its reference point 0.73 ft above the c.g. (b 33.83 ft), C_Y,β
    −0.25 withheld because the force mismatch cannot tell it from the accelerometer's position
    (``sensor_rival``): the C_l,β −0.0054 its arm makes is not named in its place. A force
    term withheld for another reason explains nothing."""
    rng = np.random.default_rng(5)
    trim = SimpleNamespace(aero_rp_in=(0.0, 0.0, 0.0), cg_in=(0.0, 0.0, -8.8))
    p, beta, roll = _side_force_roll(0.04, 750, 33.83, 5.47, trim)
    n = p.n
    for details, kept in (({"sensor_rival": "x_accelerometer"}, False), ({}, True)):
        cy_sel, cy = _stepwise("CY", "beta", "CY_beta", beta, -0.25)
        cy.selected, cy.details = False, dict(details)
        cl_sel, cl = _stepwise("Cl", "beta", "Cl_beta", beta, -0.0054)
        mismatch = {"CY": -0.25 * beta, "Cl": roll + rng.normal(scale=1e-6, size=n)}
        withhold_explained_by_force_arm([cy, cl], {"CY": cy_sel, "Cl": cl_sel}, mismatch, p, trim)
        assert cl.selected is kept
        if not kept:
            assert "unnamed beside the accelerometer's position" in cl.reason


def test_a_kinematic_rival_is_sized_in_the_place_of_the_term_it_contests():
    """Two nearly collinear kinematic columns (r ≈ 0.97): the record follows the rival's. Beside
    the selected term the rival's estimate is whatever the two share out; in its place it is
    the rival's own size, at a t the contest can use."""
    rng = np.random.default_rng(2)
    n = 3000
    rival = np.sin(np.linspace(0.0, 40.0, n))
    term = rival + 0.25 * np.sin(np.linspace(0.0, 23.0, n)) + 0.05 * rng.normal(size=n)
    start = 0.04 * rival + 0.003 * rng.normal(size=n)
    kin = SimpleNamespace(columns={"scale_alpha": term, "skew_az": rival}, forced=(),
                          selection=SimpleNamespace(names=("scale_alpha",)), start=start)
    name, r, t_own, t_rival, alone = kinematic_rival(kin, "scale_alpha")
    assert name == "skew_az" and abs(r) > 0.9
    assert alone[0] == pytest.approx(0.04, rel=0.05) and alone[1] > 10.0


def test_the_positions_rival_is_not_named_where_neither_stands_beside_the_other():
    """The force mismatch could not tell the accelerometer's position from a C_Y,β change (the
    position t 4.3 beside it): the change, left to the stepwise fit, is withheld when it too
    falls under the entry t beside the position (t 4.0), and kept where it stands (t 7.2, a true
    C_Y,β change read as an accelerometer aft)."""
    from harness.diagnosis.accelerometer_rules import withhold_the_positions_rival

    def cands(t_rival):
        off = Candidate("sensor_offset", "lon", "accelerometer", "x_accelerometer", 1.56, 0.15, 10.2, 0.1, "ft",
                        "force mismatch on ω̇×r + ω×(ω×r)", False, "not named",
                        {"offset_rival": "CY_beta", "offset_rival_t": t_rival, "offset_t_beside": 4.3})
        cy = Candidate("coefficient_error", "lat", "CY", "CY_beta", -0.905, 0.0013, 88.0, 0.3, "1/rad",
                       "stepwise on the CY mismatch", True, "entered")
        other = Candidate("coefficient_error", "lat", "CY", "CY_dr", -0.11, 0.005, -22.0, 0.1, "1/rad",
                          "stepwise on the CY mismatch", True, "entered")
        return [off, cy, other]

    ambiguous = cands(4.0)
    withhold_the_positions_rival(ambiguous)
    assert not ambiguous[1].selected and "cannot tell it from the accelerometer" in ambiguous[1].reason
    assert ambiguous[2].selected
    standing = cands(-7.2)
    withhold_the_positions_rival(standing)
    assert standing[1].selected


def test_two_sensor_errors_the_kinematics_cannot_tell_apart_are_not_both_named_on_corroboration():
    """Two corroborated suspects on nearly collinear kinematic columns (r ≈ 0.97), the record
    following their sum's share: each alone stands, together neither reaches AMBIGUOUS_T, and
    neither is named. Where the record follows one column's own part, that one stays."""
    from harness.diagnosis.sensor_naming import withhold_corroborated_rivals
    from harness.diagnosis.sensor_rules import AMBIGUOUS_T, kinematic_t_beside

    rng = np.random.default_rng(6)
    n = 2500
    a = np.sin(np.linspace(0.0, 40.0, n))
    b = a + 0.25 * np.sin(np.linspace(0.0, 23.0, n))
    noise = rng.normal(size=n)

    def named():
        return [Candidate("sensor_skew", None, "az", "skew_az", -0.06, 0.01, -6.0, 0.1, "s", "kinematic consistency",
                          True, "named on two independent tests"),
                Candidate("sensor_offset", None, "accelerometer", "offset_x", 3.5, 0.5, 7.0, 0.1, "ft",
                          "kinematic consistency", True, "named on two independent tests")]
    kin = SimpleNamespace(columns={"skew_az": a, "offset_x": b}, forced=(), selection=SimpleNamespace(names=()))
    kin.start = 0.01 * (a + b) + 0.08 * noise
    alone = [kinematic_t_beside(kin, x)[x] for x in ("skew_az", "offset_x")]
    together = kinematic_t_beside(kin, ("skew_az", "offset_x"))
    assert min(alone) >= AMBIGUOUS_T and max(together.values()) < AMBIGUOUS_T, (alone, together)
    cands = named()
    withhold_corroborated_rivals(cands, kin)
    assert not any(c.selected for c in cands)
    assert "cannot tell it from offset_x" in cands[0].reason
    kin.start = 0.05 * (b - a) + 0.08 * noise  # the offset's own part: it stands beside the skew
    cands = named()
    withhold_corroborated_rivals(cands, kin)
    assert cands[1].selected
    cands = named()[:1]  # one alone is left as it was
    withhold_corroborated_rivals(cands, kin)
    assert cands[0].selected


def test_an_accelerometer_position_from_the_force_mismatch_does_not_correct_the_channels():
    """The force mismatch's accelerometer position is named without a kinematic parameter: the
    delay-imitation test (which corrects the channels for a named sensor error and scans
    again) passes over it instead of failing, and the delay stays (a probe's F-15 with a 60 ms
    stabilator delay had both selected)."""
    from harness.diagnosis.sensor_naming import withhold_delays_imitated_by_named

    position = Candidate("sensor_offset", "lon", "accelerometer", "x_accelerometer", 3.6, 0.7, 5.3, 0.1, "ft",
                         "force mismatch on ω̇×r + ω×(ω×r)", True, "significant and practical")
    delay = Candidate("control_delay", "pitch", "de", "tau_de", 0.044, 0.001, 38.0, 0.2, "s",
                      "delay scan of de + stepwise", True, "entered")
    kin = SimpleNamespace(parameters={}, columns={}, forced=(), selection=SimpleNamespace(names=(), params={},
                                                                                          terms=()))
    withhold_delays_imitated_by_named([position, delay], kin, None, None, None, {}, {}, set())
    assert delay.selected and position.selected


def test_the_offset_rival_columns_on_the_inertial_alpha():
    """candidates.offset_rival_columns: with the inertial α among the regressors, C_Z,α on it
    alone and C_X,α with C_Z,α on it are tried too, both standing for the α derivative
    (rival_parameter); without it, only the measured states' columns."""
    from harness.diagnosis.candidates import INERTIAL_ALPHA, offset_rival_columns, rival_parameter
    n = 20
    moving = np.linspace(0.0, 1.0, n)
    reg = {"alpha": moving, "qhat": moving ** 2, "de": np.zeros(n)}
    plain = offset_rival_columns(reg, slice(0, n))
    assert not any(r == INERTIAL_ALPHA for pairs in plain for _, r in pairs)
    assert (("CX", "alpha"), ("CZ", "alpha")) in plain and (("CZ", "de"),) not in plain
    more = offset_rival_columns(reg | {INERTIAL_ALPHA: moving}, slice(0, n))
    assert set(more) - set(plain) == {(("CZ", INERTIAL_ALPHA),), (("CX", INERTIAL_ALPHA), ("CZ", INERTIAL_ALPHA))}
    assert rival_parameter("CZ", INERTIAL_ALPHA) == "CZ_alpha" and rival_parameter("CZ", "qhat") == "CZ_qhat"


def test_an_unnamed_position_counts_where_a_component_is_significant_and_practical():
    """accelerometer_rules._read_component: the components the force mismatches read at the
    entry t and of at least 1.5 ft; a significant 0.06 ft one (a noise-free record's) is not."""
    from harness.diagnosis.accelerometer_rules import _read_component
    details = {"position_ft": [-0.06, 6.12, 0.5], "std_error_ft": [0.008, 0.32, 0.4], "t_xyz": [-7.7, 19.4, 1.2]}
    off = Candidate("sensor_offset", "lon", "accelerometer", "x_accelerometer", -0.06, 0.008, -7.7, 0.1, "ft",
                    "force mismatch", False, "not significant, under 1.5 ft", details)
    assert _read_component(off) == "y = 6.12 ± 0.32 ft, t = 19.4"
    details["position_ft"][1] = 1.2
    assert _read_component(off) == "" and _read_component(None) == ""


def test_an_unoffered_rival_says_which_of_its_sources_was_not_driven():
    """term_rules._unoffered_why names only the sources the maneuver did not drive: a lateral
    axis's ΔV/V term (sources V and β) on a lateral maneuver lacks the airspeed alone."""
    from harness.diagnosis.term_rules import _unoffered_why
    lateral_dv = SimpleNamespace(sources=("V", "beta"))
    assert _unoffered_why(lateral_dv, SimpleNamespace(driven=("beta", "p", "r"))) == \
        "the airspeed never moved above its noise"
    assert _unoffered_why(lateral_dv, SimpleNamespace(driven=("q",))) == \
        "the airspeed never moved above its noise and β never moved above its noise"
