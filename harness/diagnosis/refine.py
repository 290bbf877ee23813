"""The diagnosis's last step: the terms it names, refined with JSBSim in the loop.

The kept aerodynamic and delay findings start the output-error calibration
(:func:`harness.calibrate.calibrate`) at their equation-error sizes, matching the outputs the
terms drive (the ones the decision judges, :func:`matched_outputs`). The calibrated sizes
replace them only when they fit at least as well: the identification maneuver's output-error
cost is not higher, and the validation maneuver's RMS error of the outputs the terms drive
(flown by the diagnosis's own replay) is not higher for any of them. Otherwise the
equation-error sizes stay, and the reason is reported.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from models.hidden import AERO_TERMS, HiddenEffect

# The output each term's coefficient (or delayed surface) drives most directly: the one the
# gallery and the sweeps score a term's validation on.
AXIS_OUTPUT = {"Cm": "q", "Cl": "p", "Cn": "r", "CZ": "az", "CY": "ay", "CX": "V"}
SURFACE_OUTPUT = {"de": "q", "da": "p", "dr": "r"}


def surface_hold(meta: dict) -> tuple[str, str]:
    """How the calibration replays the recorded surfaces, and the assumption in words.

    A recording the project simulated (its metadata carry a ``simulation`` block) has stepped
    inputs sampled on their edges: each sample is held until the next (``'sample'``). Any
    other recording is taken as flight data, whose surfaces move continuously after their
    actuators: linear interpolation (``'linear'``).

    Returns
    -------
    (hold, reason)
    """
    if isinstance(meta.get("simulation"), dict):
        return "sample", ("the recording's metadata carry a 'simulation' block: a simulated recording, whose "
                          "stepped surfaces are held sample to sample in the calibration's replay")
    return "linear", ("the recording's metadata carry no 'simulation' block: taken as flight data, its surfaces "
                      "interpolated linearly between samples in the calibration's replay")


def calibratable(pairs) -> list[tuple[object, HiddenEffect]]:
    """The ``(finding, term)`` pairs whose term is an aircraft parameter: an aerodynamic term of
    the vocabulary or a surface delay (sensor effects, a mode, turbulence are not)."""
    return [(f, e) for f, e in pairs if e is not None and (e.effect in AERO_TERMS or e.effect == "control_delay")]


def parameter_spec(terms: list[HiddenEffect]) -> str:
    """The calibration's ``--parameters``: each term's name started at its equation-error size."""
    return ",".join(f"{e.parameter}={float(e.size)!r}" for e in terms)


def affected_outputs(terms: list[HiddenEffect]) -> list[str]:
    """The outputs the terms drive (:data:`AXIS_OUTPUT`, :data:`SURFACE_OUTPUT`; a moment
    reference shift: q), in order, without repeats."""
    out = []
    for e in terms:
        if e.effect == "control_delay":
            out.append(SURFACE_OUTPUT[e.surface])
        elif e.effect == "cg_offset":
            out.append("q")
        else:
            out.append(AXIS_OUTPUT[e.coefficient])
    return list(dict.fromkeys(out))


def matched_outputs(terms: list[HiddenEffect], rec) -> tuple[str, ...] | None:
    """The outputs the calibration matches: those the terms drive (:func:`affected_outputs`),
    the outputs the decision judges, that recording ``rec`` has; None (every output the
    recording has) when it has none of them.

    Matching every output instead weighs in channels the named terms hardly drive, whose
    errors from whatever else the model lacks then pull the sizes: on the sweeps that made
    the calibrated sizes fit the judged output worse on both maneuvers (an α·β term sized
    −2.61 for −2 on a coupled maneuver; an equation-error Cl_|β| that could not be moved).
    """
    out = tuple(o for o in affected_outputs(terms) if rec.has(o))
    return out or None


def output_cost(fit: dict) -> float | None:
    """The output-error cost of a flight with the noise variances estimated (Eq. 26 at its
    minimum over R, per sample and up to a constant): Σ_o ln RMS_o over the channels of
    ``fit`` (``{channel: {"rms"}}``); None when a flight failed."""
    rms = [v.get("rms") for v in fit.values()]
    if not rms or any(r is None or not r > 0 for r in rms):
        return None
    return float(sum(math.log(r) for r in rms))


def refined_terms(added: tuple[HiddenEffect, ...], sizes: dict[str, float]) -> tuple[HiddenEffect, ...]:
    """``added`` with the sizes of the terms named in ``sizes`` replaced (a delay at least 0)."""
    out = []
    for e in added:
        if e.parameter in sizes and (e.effect in AERO_TERMS or e.effect == "control_delay"):
            size = float(sizes[e.parameter])
            e = replace(e, size=max(size, 0.0) if e.effect == "control_delay" else size)
        out.append(e)
    return tuple(out)


def refined_finding(f, size: float):
    """A copy of finding ``f`` (:class:`~harness.diagnosis.evidence.Candidate`) at the
    calibrated term size: a coefficient error's estimate is its model value plus the new
    change; the other terms' estimate is the size itself."""
    if f.effect == "coefficient_error":
        old = float(f.details["change"])
        return replace(f, estimate=float(f.estimate) - old + size, details=dict(f.details, change=size))
    return replace(f, estimate=size)


def _rms(fits: dict, role: str, channel: str) -> float | None:
    return (((fits.get(role) or {}).get("outputs") or {}).get(channel) or {}).get("rms")


# An output the terms do not drive may move a little when their sizes change (the replay's
# trim moves with them); more than this fraction of its RMS error is a worse fit, accepted
# only when the maneuver's cost over every output still falls.
UNJUDGED_TOLERANCE = 0.02


def _raised_elsewhere(fits_ee: dict, fits_cal: dict, role: str, judged: list[str]) -> dict:
    """The outputs besides ``judged`` whose ``role`` RMS error the calibrated sizes raise by
    more than :data:`UNJUDGED_TOLERANCE`: {output: {"equation_error", "calibrated"}}."""
    names = set((fits_ee.get(role) or {}).get("outputs") or {}) & set((fits_cal.get(role) or {}).get("outputs") or {})
    out = {}
    for o in sorted(names - set(judged)):
        e, c = _rms(fits_ee, role, o), _rms(fits_cal, role, o)
        if e is not None and c is not None and np.isfinite(e) and np.isfinite(c) and c > e * (1 + UNJUDGED_TOLERANCE):
            out[o] = {"equation_error": e, "calibrated": c}
    return out


def _total_cost(fits_ee: dict, fits_cal: dict, role: str) -> dict:
    """Σ ln RMS over every output both replays of ``role`` give (the output-error likelihood
    with the noise estimated, per sample): {"equation_error", "calibrated", "outputs"}."""
    e_out = (fits_ee.get(role) or {}).get("outputs") or {}
    c_out = (fits_cal.get(role) or {}).get("outputs") or {}
    names = [o for o in sorted(set(e_out) & set(c_out))
             if all(isinstance(v, (int, float)) and np.isfinite(v) and v > 0
                    for v in (_rms(fits_ee, role, o), _rms(fits_cal, role, o)))]
    return {"equation_error": float(sum(math.log(_rms(fits_ee, role, o)) for o in names)),
            "calibrated": float(sum(math.log(_rms(fits_cal, role, o)) for o in names)), "outputs": names}


def decide(cal, fits_ee: dict, fits_cal: dict, outputs: list[str]) -> tuple[bool, str, dict]:
    """Whether the calibrated sizes are kept, why, and the figures compared.

    Parameters
    ----------
    cal : the :class:`~harness.calibrate.CalibrationResult` (its identification fits at the
        equation-error start and at the estimate give the output-error cost).
    fits_ee, fits_cal : the diagnosis's own "after" fits with the equation-error and the
        calibrated sizes (``{"identification"|"validation": {"outputs": ...}}``).
    outputs : the outputs the terms drive; judged on the validation maneuver when there is one,
        else on the identification maneuver.

    Returns
    -------
    (used, reason, figures)
    """
    cost_ee = output_cost(cal.fit_before.get("identification", {}))
    cost_cal = output_cost(cal.fit_after.get("identification", {}))
    role = "validation" if "validation" in fits_ee else "identification"
    rms = {o: {"equation_error": _rms(fits_ee, role, o), "calibrated": _rms(fits_cal, role, o)} for o in outputs}
    figures = {"identification_cost": {"equation_error": cost_ee, "calibrated": cost_cal,
                                       "definition": "sum over the matched outputs of ln RMS error (the "
                                                     "output-error likelihood with the noise estimated, per sample)"},
               "judged_on": role, "affected_outputs": outputs, "rms": rms}
    if cost_ee is None or cost_cal is None:
        return False, "a calibration flight failed, so the fits cannot be compared", figures
    if all(float(e) == float(s) for e, s in zip(cal.estimate, cal.start)):
        return False, ("the calibration did not move the sizes from their equation-error values (no step lowered "
                       "the output-error cost)"), figures
    if cost_cal > cost_ee:
        return False, (f"by the fit statistics the calibrated sizes fit the identification maneuver worse (sum of ln "
                       f"RMS error against the smoothed recording {cost_cal:.4f}, against {cost_ee:.4f} at the "
                       "equation-error sizes): the equation-error sizes are kept"), figures
    missing = [o for o, v in rms.items() if v["equation_error"] is None or v["calibrated"] is None]
    if missing:
        return False, f"the {role} replay gives no RMS error for {', '.join(missing)} to compare", figures
    worse = [o for o, v in rms.items() if v["calibrated"] > v["equation_error"]]
    if worse:
        detail = ", ".join(f"{o} {rms[o]['equation_error']:.4g} → {rms[o]['calibrated']:.4g}" for o in worse)
        return False, (f"the calibrated sizes fit the identification maneuver better but the {role} maneuver's "
                       f"{', '.join(worse)} worse ({detail}): the equation-error sizes are kept"), figures
    raised = _raised_elsewhere(fits_ee, fits_cal, role, outputs)
    total = _total_cost(fits_ee, fits_cal, role)
    figures["unjudged_raised"] = raised
    figures[f"{role}_cost"] = total
    if raised and total["calibrated"] > total["equation_error"]:
        detail = ", ".join(f"{o} {v['equation_error']:.4g} → {v['calibrated']:.4g}" for o, v in raised.items())
        return False, (f"the calibrated sizes fit the terms' own outputs no worse, but raise the {role} maneuver's "
                       f"{', '.join(raised)} by more than {100 * UNJUDGED_TOLERANCE:.0f} % ({detail}) and its "
                       f"output-error cost over every output ({total['equation_error']:.4f} → "
                       f"{total['calibrated']:.4f}): the equation-error sizes are kept"), figures
    detail = ", ".join(f"{o} {v['equation_error']:.4g} → {v['calibrated']:.4g}" for o, v in rms.items())
    return True, (f"the calibrated sizes fit the identification maneuver better (output-error cost {cost_ee:.4f} → "
                  f"{cost_cal:.4f}) and the {role} maneuver's {', '.join(outputs)} no worse ({detail})"), figures


def refined_findings(pairs, sizes: dict[str, float], std: dict[str, float]) -> dict[int, tuple[object, dict]]:
    """Per calibrated finding (keyed by ``id``): its copy at the calibrated size
    (:func:`refined_finding`) and the ``calibrated`` entry findings.json gives it."""
    out = {}
    for f, e in pairs:
        if e.parameter in sizes:
            g = refined_finding(f, sizes[e.parameter])
            out[id(f)] = (g, {"estimate": float(g.estimate), "size": sizes[e.parameter],
                              "std_error": float(std[e.parameter]), "equation_error_estimate": float(f.estimate)})
    return out


def calibration_detail(cal, terms: list[HiddenEffect], fits_ee: dict, fits_cal: dict) -> dict:
    """The calibration's part of findings.json's ``calibration`` block: the parameters, the
    diagnosis's own fits after either set of sizes, the calibration's own fits, its references
    and its effort."""
    return {"parameters": parameter_rows(cal, terms), "fit_after_calibration": fits_cal,
            "fit_after_equation_error": fits_ee,
            "calibrator_fit": {"equation_error": cal.fit_before, "calibrated": cal.fit_after,
                               "definition": "the calibration's own flights (surfaces held as 'hold' says), RMS error "
                                             "against the smoothed recording with each flight's mean offset removed"},
            "references": dict(cal.refs), "iterations": cal.iterations, "converged": cal.converged,
            "flights": cal.flights, "seconds": cal.seconds, "notes": list(cal.notes)}


def parameter_rows(cal, terms: list[HiddenEffect]) -> list[dict]:
    """``calibration.parameters`` of findings.json: each term's equation-error and calibrated
    size with the calibration's standard errors."""
    start = {t.parameter: float(t.size) for t in terms}
    return [{"name": a.name, "equation_error": start.get(a.name), "calibrated": float(est), "std_error": float(se),
             "crb_std_error": float(crb), "units": a.units}
            for a, est, se, crb in zip(cal.adjustments, cal.estimate, cal.std_error, cal.crb_std_error)]


def validation_rms_pair(calibration: dict, channel: str) -> dict | None:
    """From findings.json's ``calibration`` block: ``{"used", "channel", "equation_error",
    "calibrated", "reason"}`` with the validation RMS of ``channel`` after the equation-error
    and after the calibrated sizes (the diagnosis's own replay); None when nothing was
    calibrated (no aircraft term, or the calibration could not run)."""
    ee, cal = calibration.get("fit_after_equation_error"), calibration.get("fit_after_calibration")
    if not channel or not ee or not cal:
        return None
    role = "validation" if "validation" in ee else "identification"
    return {"used": bool(calibration.get("used")), "channel": channel, "role": role,
            "equation_error": _rms(ee, role, channel), "calibrated": _rms(cal, role, channel),
            "reason": calibration.get("reason", "")}
