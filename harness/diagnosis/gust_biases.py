"""Gusts a constant instrument error makes. The gust test integrates the kinematic residuals
of the w and v equations (:func:`spectra.gust_estimate`); a vane or gyro bias does not stay
constant there: a β-vane bias b is a side velocity V·b that the body rates carry into the
w equation (−p·v), and its integral follows the bank the maneuver rolled through. Such a
'gust' is the kinematic check's own business: the test is asked again on the channels
corrected for the constant errors the kinematics find, and the recording is judged by that."""
from __future__ import annotations

from harness.diagnosis.along import corrected_recording
from harness.diagnosis.evidence import Candidate
from harness.diagnosis.gust_rules import light_gusts, turbulence_test
from harness.diagnosis.kinematics import T_IN as KIN_T_IN
from harness.diagnosis.kinematics import KinematicResult, is_plausible
from harness.diagnosis.prepare import Prepared
from harness.diagnosis.sensor_rules import kinematic_estimate
from harness.diagnosis.spectra import GustEstimate


# The kinematic scale factors and instrument positions corrected with the biases before the
# gust test is asked again.
VANE_SCALES = ("scale_alpha", "scale_beta")
POSITIONS = ("offset_x", "offset_y", "offset_z", "vane_alpha_x", "vane_beta_x")


def gusts_without_biases(p: Prepared, kin: KinematicResult, V0: float) -> tuple[GustEstimate, dict[str, float]] | None:
    """The gust estimate on the channels corrected for the biases the kinematic check finds
    (its always-fitted biases, ``kin.forced``, at the kinematic entry t and plausible sizes:
    :data:`kinematics.T_IN`, :func:`kinematics.is_plausible`), with those biases, when so
    corrected the recording shows neither turbulence nor light gusts
    (:func:`gust_rules.turbulence_test`, :func:`gust_rules.light_gusts`); None otherwise.

    A bias is a constant: it cannot take a broadband gust's energy, only the part of the
    integrated residual that follows the maneuver as the bias's own kinematic signature does.
    (An A-4 in a 3-2-1-1 on each axis at 546 ft/s with its β vane 1° off read light
    turbulence of 2.3 ft/s, the vertical gust following the bank it rolled through, and the
    β bias the kinematics put at t 16 was not applied.) A vane's scale factor, when the
    kinematics select it, is the same kind of error (:data:`VANE_SCALES`): k times the
    vane's own angle, it takes only the part of the residual that follows that angle. (A
    c172x in a 3-2-1-1 on each axis at 163 ft/s with its β vane reading 15 % high read light
    turbulence, the side 'gust' following β, and named it; the scale the kinematics put at
    0.156, t 16, was not applied.) So is an instrument's position off the c.g.
    (:data:`POSITIONS`): fixed, it takes only the part that follows the rates and their
    derivatives (a probe's c172x, lateral sweeps at 166 ft/s, with its accelerometer 9.5 ft
    left of the c.g. read light gusts of 1.2 ft/s, the 'gust' the ṗ·y it puts in a_z
    integrates to, and the position the kinematics put at −10.0 ft, t −19.9, was not applied;
    probe seed 3592)."""
    biases = {}
    for name in kin.forced + tuple(n for n in kin.selection.names if n in VANE_SCALES + POSITIONS):
        found = kinematic_estimate(kin, name)
        if found is not None and found[1] >= KIN_T_IN and is_plausible(name, found[0], V0):
            biases[name] = found[0]
    if not biases:
        return None
    gust, turbulent = turbulence_test(corrected_recording(p, kin, biases))
    if turbulent or light_gusts(gust, p, V0):
        return None
    return gust, biases


def note_gusts_of_biases(cands: list[Candidate], raw: GustEstimate, biases: dict[str, float]) -> None:
    """Say, on the turbulence candidate, that the gust the raw channels gave was the biases'
    (:func:`gusts_without_biases`)."""
    for c in cands:
        if c.effect == "turbulence":
            c.details["gusts_of_biases"] = {"sigma_w_fps": raw.sigma_w_fps, "sigma_v_fps": raw.sigma_v_fps,
                                            "ratio_to_noise": raw.ratio_to_noise, "biases": dict(biases)}
            c.reason += (f", on the channels corrected for {', '.join(sorted(biases))}, which the kinematics find; "
                         f"on the raw channels {max(raw.sigma_w_fps, raw.sigma_v_fps):.1f} ft/s (ratio "
                         f"{raw.ratio_to_noise:.1f}): the rest was those errors' kinematic signature, not air")
