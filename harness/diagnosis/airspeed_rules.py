"""The airspeed the rate terms are normalised by: a rate derivative or α̇ term is named only
when an airspeed error the kinematics allow would not imitate it."""
from __future__ import annotations

from harness.diagnosis.evidence import Candidate
from harness.diagnosis.kinematics import KinematicResult
from harness.diagnosis.term_rules import IMITATION_SHARE, IMITATION_Z, term_change

__all__ = ["AIRSPEED_ERRORS", "normalised_by_airspeed", "withhold_on_the_airspeed"]


# The airspeed errors the kinematic check sizes (effects.md's sensor_bias and sensor_scale of V).
AIRSPEED_ERRORS = ("bias_V", "scale_V")

# The regressors normalised by the airspeed: p̂ = p b/2V, q̂ = q c̄/2V, r̂ = r b/2V, α̇ c̄/2V.
NORMALISED = ("phat", "qhat", "rhat")


def normalised_by_airspeed(c: Candidate) -> bool:
    """Whether term ``c``'s regressor is a rate normalised by the airspeed (a rate derivative
    or C_m,α̇)."""
    return c.effect == "unsteady_alphadot" or (c.effect == "coefficient_error"
                                               and c.parameter.split("_", 1)[-1] in NORMALISED)


def withhold_on_the_airspeed(cands: list[Candidate], kin: KinematicResult, imitated) -> None:
    """Deselect a rate term (:func:`normalised_by_airspeed`) that an airspeed error would
    imitate: the V bias or scale anywhere within :data:`term_rules.IMITATION_Z` standard
    errors of its kinematic estimate, whatever its t (``imitated``,
    :func:`term_rules.imitation`: the channels corrected, the model evaluated again), takes at
    least :data:`term_rules.IMITATION_SHARE` of the term's change. The model evaluated along
    an airspeed k·V too high normalises every rate by it, and the mismatch then holds a
    change of −k/(1+k) of each rate derivative, in its own shape; a maneuver that hardly moves
    V cannot size the error (an independent script's pa28, 154 ft/s, lateral sweep at 50 Hz,
    with V 10 ft/s high had a C_l,p̂ change of −0.026 on −0.47 named, t −17; the kinematics put
    the bias at −3.2 ± 4.8 ft/s)."""
    if imitated is None:
        return
    for c in cands:
        if not (c.selected and c.test.startswith("stepwise") and normalised_by_airspeed(c)):
            continue
        change = abs(term_change(c))
        for name in AIRSPEED_ERRORS:
            size = imitated(c, name) if name in kin.parameters else None
            if size is None or size < IMITATION_SHARE * change:
                continue
            c.selected = False
            c.details["sensor_rival"] = name
            c.details["airspeed_rival"] = {"parameter": name, "imitates_at_most": size, "change": change}
            c.reason = (f"entered, but not named: the airspeed its rate is normalised by is not known well "
                        f"enough; an airspeed {name.split('_')[0]} within {IMITATION_Z:g} standard errors of the "
                        f"kinematics' estimate would imitate {size:.2g} of this change of {change:.3g}")
            break
