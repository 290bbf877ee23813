"""The airspeed the rate terms are normalised by: a rate derivative or α̇ term is named only
when it stands beside what an airspeed error the kinematics allow would put in the mismatch."""
from __future__ import annotations

import numpy as np

from estimators.colored_stepwise import colored_fit
from estimators.least_squares import SingularRegressorsError
from harness.diagnosis import candidates as cand
from harness.diagnosis.along import corrected_recording, interior, model_along
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.kinematics import AIRSPEED_ERROR_FLOOR_FPS, PLAUSIBLE, KinematicResult
from harness.diagnosis.prepare import Prepared
from harness.diagnosis.sensor_rules import kinematic_estimate, kinematic_std_error
from harness.diagnosis.stepwise_axes import StepwiseFits
from harness.diagnosis.term_rules import IMITATION_Z
from models.aircraft import Aircraft
from models.replay import InitialCondition

__all__ = ["AIRSPEED_BIAS", "airspeed_signature", "normalised_by_airspeed", "withhold_on_the_airspeed"]


# The kinematic check's airspeed error (effects.md's sensor_bias of V): over a maneuver that
# hardly moves V a scale factor is the same error, k·V.
AIRSPEED_BIAS = "bias_V"

# The regressors normalised by the airspeed: p̂ = p b/2V, q̂ = q c̄/2V, r̂ = r b/2V, α̇ c̄/2V.
NORMALISED = ("phat", "qhat", "rhat")

# The airspeed error probed for the signature, as a share of the airspeed (it is linear there).
SIGNATURE_SHARE = 0.01


def normalised_by_airspeed(c: Candidate) -> bool:
    """Whether term ``c``'s regressor is a rate normalised by the airspeed (a rate derivative
    or C_m,α̇)."""
    return c.effect == "unsteady_alphadot" or (c.effect == "coefficient_error"
                                               and c.parameter.split("_", 1)[-1] in NORMALISED)


def airspeed_signature(p: Prepared, kin: KinematicResult, aircraft: Aircraft, ic: InitialCondition,
                       mismatch: dict[str, np.ndarray]) -> tuple[dict[str, np.ndarray], float]:
    """What an airspeed bias puts in each coefficient's mismatch, per ft/s: the channels
    corrected by a bias of :data:`SIGNATURE_SHARE` of the airspeed, the model evaluated again
    (the rates normalised by the other V, the kinematic α̇, q̄ where it is built from V), the
    difference divided by it. Returns the columns and the airspeed (ft/s)."""
    V0 = float(np.mean(p.smooth["V"]))
    dv = SIGNATURE_SHARE * V0
    changed = model_along(corrected_recording(p, kin, {AIRSPEED_BIAS: dv}), aircraft, ic, inertial_from=p).mismatch()
    return {c: (changed[c] - mismatch[c]) / dv for c in mismatch}, V0


def withhold_on_the_airspeed(cands: list[Candidate], p: Prepared, kin: KinematicResult, aircraft: Aircraft,
                             ic: InitialCondition, mismatch: dict[str, np.ndarray], step: StepwiseFits) -> None:
    """Deselect a rate term (:func:`normalised_by_airspeed`) that does not stand beside an
    airspeed error the kinematics allow. The model evaluated along an airspeed k·V too high
    normalises every rate by it, and the mismatch then holds −k/(1+k) of each rate term, in
    its shape. The axis's mismatch is fitted on the error's signature
    (:func:`airspeed_signature`) in the term's place (with the axis's other selected terms and
    its nuisance columns); when the airspeed error so sized is one an instrument could make
    (within :data:`kinematics.PLAUSIBLE`'s 10 % of V for an airspeed scale, which over a
    maneuver that hardly moves V is the same error, or
    :data:`kinematics.AIRSPEED_ERROR_FLOOR_FPS`) and lies within
    :data:`term_rules.IMITATION_Z` standard errors of the kinematics' bias estimate (the two
    estimates' colored standard errors taken together, as independent), and the term fitted
    beside the signature falls below the entry t (:data:`candidates.T_IN`), it is withheld.
    An independent script's pa28 (154 ft/s, lateral sweep at 50 Hz) with V 10 ft/s high had
    a C_l,p̂ change of −0.026 on −0.47 named (t −17); the kinematics put the bias at −3.2 ±
    4.8 ft/s. A c182 (185 ft/s, three-axis doublets) with V 10 ft/s high had
    C_m,α̇ −1.26 named (t −9): the signature asks +12.6 ± 1.4 ft/s in its place, the
    kinematics +5.7 ± 2.0, 3.4 of the kinematics' standard errors apart but 2.8 of both."""
    terms = [c for c in cands if c.selected and c.test.startswith("stepwise") and normalised_by_airspeed(c)]
    found = kinematic_estimate(kin, AIRSPEED_BIAS)
    if not terms or found is None:
        return
    v, se = found[0], kinematic_std_error(kin, AIRSPEED_BIAS)
    signature, V0 = airspeed_signature(p, kin, aircraft, ic, mismatch)
    inner = interior(p)
    for c in terms:
        sel, by_key = step.selections.get(c.channel, (None, {}))
        key = next((k for k, t in by_key.items() if t.parameter == c.parameter), None)
        if sel is None or key is None:
            continue
        sig = signature[c.channel][inner]
        others = [by_key[k].column[inner] for k in sel.names if k != key and k in by_key]
        others += [x[inner] for x in step.nuisances.get(c.channel, {}).values() if np.ptp(x[inner]) > 0]
        z = mismatch[c.channel][inner]
        try:
            # the error's size in the term's place, with its own colored standard error
            alone, se_alone, _ = colored_fit(z, [sig] + others, ["airspeed"] + [f"o{i}" for i in range(len(others))])
            both, se_both, _ = colored_fit(z, [by_key[key].column[inner], sig] + others,
                                           ["term", "airspeed"] + [f"o{i}" for i in range(len(others))])
        except (SingularRegressorsError, np.linalg.LinAlgError):
            continue
        # the signature is what correcting the channels by a bias changes, so a recorded bias b
        # puts −b times it into the mismatch: the bias the fit says is minus its coefficient
        u, t_term = -float(alone[0]), float(both[0] / se_both[0]) if se_both[0] > 0 else 0.0
        plausible = abs(u) <= max(PLAUSIBLE["scale"]["V"] * V0, AIRSPEED_ERROR_FLOOR_FPS)
        spread = float(np.hypot(se, se_alone[0]))
        allowed = np.isfinite(spread) and abs(u - v) <= IMITATION_Z * spread
        c.details["beside_the_airspeed"] = {"bias_fps": u, "std_error": float(se_alone[0]), "t": t_term}
        if not (plausible and allowed and abs(t_term) < cand.T_IN):
            continue
        c.selected = False
        c.details["sensor_rival"] = AIRSPEED_BIAS
        c.reason = (f"entered, but not named: an airspeed error of {u:+.3g} ± {se_alone[0]:.2g} ft/s "
                    f"({100 * u / V0:+.1f} % of V; the kinematics put it at {v:.3g} ± {se:.2g}, within "
                    f"{IMITATION_Z:g} of the two standard errors together), normalising the rates, fits the "
                    f"mismatch in its place, and beside it this term stands at t = {t_term:.1f}")
