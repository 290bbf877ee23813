"""Terms a slow sideslip error or the thrust line imitates (harness.diagnosis.drift_rules,
stepwise_axes.pinned_shift), pinned to constructed mismatches whose source is known."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from harness.diagnosis.candidates import Term
from harness.diagnosis.drift_rules import withhold_lateral_drift_a_slow_sideslip_makes
from harness.diagnosis.evidence import Candidate

N, DT = 1500, 0.02
SLOPES = {"CY": -1.1, "Cl": -0.11, "Cn": 0.19}   # C_β per rad, an F-16's order
NOISE = {"CY": 0.002, "Cl": 0.0002, "Cn": 0.0003}


def _setup(sizes: dict[str, float], k_rad: float, seed: int = 3):
    """Lateral mismatches carrying −C_β·k·ΔV/V (a sideslip error following the drift column)
    plus an aerodynamic drift ``sizes[axis]``·ΔV/V, white noise, and each axis's stepwise
    fit with the drift term selected; returns the candidates, the step and the mismatches."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) * DT
    drift = 0.08 * (1.0 - np.exp(-t / 8.0))     # ΔV/V rising and levelling, as after a pitch doublet
    mismatch, selections, cands = {}, {}, []
    for axis, slope in SLOPES.items():
        mismatch[axis] = -slope * k_rad * drift + sizes.get(axis, 0.0) * drift + NOISE[axis] * rng.normal(size=N)
        term = Term("dV", "flight_condition_drift", f"{axis}_dV", "", drift)
        selections[axis] = (SimpleNamespace(names=("dV",), params={"dV": 1.0}), {"dV": term})
        cands.append(Candidate("flight_condition_drift", None, axis, f"{axis}_dV", 1.0, 0.1, 10.0, 0.1, "",
                               f"stepwise on the {axis} mismatch", selected=True, reason="entered"))
    step = SimpleNamespace(selections=selections, nuisances={})
    slopes = {axis: np.full(N, s) for axis, s in SLOPES.items()}
    return cands, step, SimpleNamespace(n=N, dt=DT), mismatch, lambda x: slopes


def test_drifts_in_the_model_s_beta_proportions_are_a_drifting_sideslip():
    """Δβ = 1.5°·ΔV/V (the F-16 null's k) on every lateral axis: the three drift terms
    are withheld, and the reason carries the common k."""
    cands, step, p, mismatch, slope_of = _setup({}, np.radians(1.5))
    withhold_lateral_drift_a_slow_sideslip_makes(cands, step, p, mismatch, slope_of)
    assert not any(c.selected for c in cands)
    import re
    k, se = map(float, re.search(r"k = ([-\d.]+) ± ([\d.]+) deg", cands[0].reason).groups())
    assert abs(k - 1.5) < 3 * se  # the common k within three of its standard errors


def test_a_drift_of_one_axis_s_aerodynamics_is_not_a_sideslip():
    """A C_n ΔV/V drift alone (C_Y and C_l flat) is not the β proportions: kept."""
    cands, step, p, mismatch, slope_of = _setup({"Cn": -0.006}, 0.0)
    for c in cands:
        c.selected = c.channel == "Cn"
    withhold_lateral_drift_a_slow_sideslip_makes(cands, step, p, mismatch, slope_of)
    assert [c.parameter for c in cands if c.selected] == ["Cn_dV"]


def test_a_mistrim_the_thrust_line_can_make_names_no_moment_reference_shift():
    """stepwise_axes.pinned_shift: the A-4's thrust line is 1.04 ft above its c.g.; 1,817 lbf
    of thrust at q̄ 265 psf (S 260 ft², c̄ 10.8 ft) mistrims C_m by 0.0025 when thrust is not
    recorded, so the 0.114 ft shift its C_m constant says (−0.0024 ± 0.0002 at a mean C_Z of
    −0.2) is not named; a shift mistrimming C_m five times that is; with thrust and its line
    recorded, the bound is zero. Where the airspeed falls the bound is the moment's mean
    coefficient along the recorded q̄, the thrust raised by the lapse: (V₀/V)^lapse."""
    from harness.diagnosis.stepwise_axes import THRUST_LAPSE_MAX, CgMeanTest, pinned_shift, thrust_mistrim_bound
    steady = {"qbar": np.full(N, 265.0), "V": np.full(N, 550.0)}
    p = SimpleNamespace(n=N, dt=DT, raw={}, meta={"geometry": {"S_ft2": 260.0, "b_ft": 27.5, "cbar_ft": 10.8}},
                        measured={"CZ": np.full(N, -0.2)}, smooth=steady, start={"V": 550.0})
    trim = SimpleNamespace(thrust_lbf=1817.0, thrust_offset_ft=-1.04, qbar_psf=265.0)
    bound = thrust_mistrim_bound(p, trim)
    assert bound == pytest.approx(1817.0 * 1.04 / (265.0 * 260.0 * 10.8), rel=1e-12)
    ratio = np.linspace(1.0, 0.9, N)  # slowing by 10 %
    slowing = SimpleNamespace(**{**vars(p), "smooth": {"qbar": 265.0 * ratio ** 2, "V": 550.0 * ratio}})
    from harness.diagnosis.prepare import interior_slice
    inner = interior_slice(N, DT)
    expected = bound * np.mean(ratio[inner] ** -(2.0 + THRUST_LAPSE_MAX))
    assert thrust_mistrim_bound(slowing, trim) == pytest.approx(expected, rel=1e-9)
    test = CgMeanTest(True, "", 0.114, 0.011, True, 0.12, 0.4)
    c = pinned_shift(test, p, trim)
    assert not c.selected and "thrust" in c.reason and c.details["thrust_mistrim_bound"] == bound
    assert pinned_shift(test._replace(dx_ft=0.6, std_error_ft=0.02), p, trim).selected
    recorded = SimpleNamespace(**{**vars(p), "raw": {"thrust": np.zeros(N)},
                                  "meta": {**p.meta, "thrust_offset_ft": 1.04}})
    assert thrust_mistrim_bound(recorded, trim) == 0.0 and pinned_shift(test, recorded, trim).selected


def _kinematics(r_rate: float, q_rate: float, dV: float, daz: float, seed: int = 5):
    """Stacked v̇ and ẇ residuals of a record whose airspeed reads ``dV`` high and whose a_z
    reads ``daz`` (ft/s²) high, the rates steady at ``r_rate``, ``q_rate`` (a turn) plus a
    small maneuver; the forced accelerometer biases' and the airspeed bias's columns."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) * DT
    r = r_rate + 0.02 * np.sin(0.9 * t)
    q = q_rate + 0.02 * np.sin(1.7 * t + 1.0)
    one, zero = np.ones(N), np.zeros(N)
    cols = {"bias_ay": np.concatenate([one, zero]), "bias_az": np.concatenate([zero, one]),
            "bias_V": np.concatenate([-r, q])}
    start = dV * cols["bias_V"] + daz * cols["bias_az"] + 0.05 * rng.normal(size=2 * N)
    kin = SimpleNamespace(columns=cols, start=start, forced=("bias_ay", "bias_az"),
                          selection=SimpleNamespace(names=()))
    cands = [Candidate("sensor_bias", None, c[5:], c, 0.0, 0.01, 10.0, 0.0, "g", "kinematic consistency (bias always "
                       "fitted)", selected=True) for c in ("bias_ay", "bias_az")]
    return kin, cands


def test_accelerometer_biases_an_airspeed_bias_makes_in_a_turn_are_not_named():
    """sensor_rules.withhold_biases_an_airspeed_bias_makes: in a steady 30° turn at 153 ft/s
    (r 0.105, q 0.061 rad/s) an airspeed 10 ft/s high reads as a_y and a_z biases; beside an
    airspeed bias they fall under the entry t and are withheld. In level flight a true a_z
    bias (0.7 ft/s², 0.02 g) stands beside it."""
    from harness.diagnosis.sensor_rules import withhold_biases_an_airspeed_bias_makes
    kin, cands = _kinematics(0.105, 0.061, 10.0, 0.0)
    withhold_biases_an_airspeed_bias_makes(cands, kin)
    assert not any(c.selected for c in cands) and "airspeed bias" in cands[0].reason
    kin, cands = _kinematics(0.0, 0.0, 0.0, 0.7)
    withhold_biases_an_airspeed_bias_makes(cands, kin)
    assert cands[1].selected
