"""Rules on rivals and gusts: a finding whose collinear rival the validation maneuver's own fit
enters in its place is not named (validation.rival_entered_instead); an α̇ term on the inertial
α̇ is not named in light gusts (gust_rules.withhold_in_light_gusts); in turbulence no term read
off the coefficient mismatch is named (gust_rules.withhold_in_turbulence)."""
from __future__ import annotations

from types import SimpleNamespace

from harness.diagnosis.evidence import Candidate
from harness.diagnosis.gust_rules import NOT_IN_GUSTS, withhold_in_light_gusts, withhold_in_turbulence
from harness.diagnosis.validation import rival_entered_instead


def _term(channel: str, parameter: str, effect: str, t: float, selected: bool, details=None) -> Candidate:
    return Candidate(effect, "pitch", channel, parameter, 0.0, 1.0, t, 0.5, "per rad",
                     f"stepwise on the {channel} mismatch", selected, "entered" if selected else "not entered",
                     dict(details or {}))


def test_a_finding_whose_rival_the_validation_fit_enters_instead_is_ambiguous():
    """The F-15 of the docstring: C_m,q̂ named on the identification, its rival C_m,α̇ (r 0.88,
    set apart there) entered by the validation maneuver's own fit and q̂ not: ambiguous. Where
    the validation fit enters the finding too, or not the rival, nothing is said."""
    rival = {"parameter": "Cm_alphadot", "axis": "Cm", "correlation": 0.88, "t_term": -6.8}
    f = _term("Cm", "Cm_qhat", "coefficient_error", -28.0, True, {"rival": rival})
    av = SimpleNamespace(candidates=[_term("Cm", "Cm_alphadot", "unsteady_alphadot", -18.4, True),
                                     _term("Cm", "Cm_qhat", "coefficient_error", -3.1, False)])
    why = rival_entered_instead(av, f)
    assert "enters Cm_alphadot (t = -18.4) in its place" in why
    av.candidates[1].selected = True
    assert rival_entered_instead(av, f) == ""
    av.candidates[0].selected, av.candidates[1].selected = False, False
    assert rival_entered_instead(av, f) == ""
    assert rival_entered_instead(av, _term("Cm", "Cm_qhat", "coefficient_error", -28.0, True)) == ""


def test_light_gusts_withhold_an_alpha_rate_term_on_the_inertial_rate_only():
    """C_m's α̇ column is the inertial one: withheld in light gusts, saying why; C_Z's is the
    vane's (the air's) and stays, as do the other coefficient terms."""
    cm = _term("Cm", "Cm_alphadot", "unsteady_alphadot", 6.8, True)
    cz = _term("CZ", "CZ_alphadot", "unsteady_alphadot", 7.0, True)
    cq = _term("Cm", "Cm_qhat", "coefficient_error", -9.0, True)
    withhold_in_light_gusts([cm, cz, cq], "gusts of about 2.8 ft/s")
    assert not cm.selected and "inertial" in cm.reason and "gusts of about 2.8 ft/s" in cm.reason
    assert cz.selected and cq.selected


def test_turbulence_withholds_a_shift_read_off_the_mistrim_too():
    """In turbulence a moment-reference shift is withheld whether the stepwise fit entered it
    or C_m's mistrim read it (probe seed 3611: an F-16 in light Dryden turbulence, a shift of
    0.055 ft off the mistrim); a gust level and a kinematic sensor finding are not touched."""
    mistrim = Candidate("cg_offset", "pitch", "Cm", "dx_moment_reference", 0.055, 0.0036, 15.1, 0.36, "ft",
                        "the mistrim of C_m (its constant over the mean of C_Z)", True, "entered")
    stepwise = _term("Cm", "dx_moment_reference", "cg_offset", 9.0, True)
    gust = Candidate("turbulence", None, None, "sigma_gust_fps", 5.5, 1.4, 41.4, float("nan"), "ft/s",
                     "air-relative vs inertial velocity (integrated kinematic residual)", True, "gust/noise ratio 41")
    bias = Candidate("sensor_bias", None, "q", "bias_q", 0.01, 0.001, 10.0, 0.2, "rad/s", "kinematic consistency",
                     True, "significant")
    withhold_in_turbulence([mistrim, stepwise, gust, bias])
    assert not mistrim.selected and not stepwise.selected and mistrim.reason == NOT_IN_GUSTS
    assert gust.selected and bias.selected
