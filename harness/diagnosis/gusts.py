"""Turbulence as a process-noise model: the filter-error method on the recording itself.

When the kinematics show gusts (:func:`harness.diagnosis.spectra.gust_estimate`), the
deterministic model cannot follow the flight, however right its aerodynamics: the gust
drives the aircraft, and a replay without it drifts away. The filter-error method
(:class:`estimators.filter_error.FilterError`) puts the gust into the likelihood as a
first-order (Dryden) state disturbing α, σ and τ estimated with the derivatives, and its
Kalman filter follows the flight through the gusts. Fitted to the same recording with and
without it (output error), the two say how much of the mismatch the process-noise model
accounts for, and σ_w = V σ_α (σ_v = V σ_β on the lateral-directional model) estimates the
gust a second way. Each model is fitted only when its surfaces drove the maneuver.
"""
from __future__ import annotations

import numpy as np

from estimators.filter_error import FilterError
from estimators.output_error import OutputError
from harness.diagnosis.prepare import Prepared


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x - np.mean(x)))))


# The filter-error models tried, by the surfaces that must have driven the maneuver: the
# gust state on α (the vertical gust, σ_w = V σ_α) for the short period, on β (the lateral
# gust, σ_v = V σ_β) for the lateral-directional model.
AXES = (("short_period", "short-period", "alpha", ("de",), "sigma_w_fps"),
        ("lateral", "lateral", "beta", ("da", "dr"), "sigma_v_fps"))


def process_noise_model(p: Prepared) -> dict:
    """Filter error against output error on the short period and the lateral-directional
    motion of ``p``, each where its surfaces drove the maneuver (:data:`AXES`; module
    docstring).

    Returns ``{"fitted": bool, "short_period": {...}, "lateral": {...}}`` (an axis is left out
    when its surfaces did not drive the maneuver; ``reason`` says why none was fitted). Each
    fitted axis gives the gust's σ (``sigma_w_fps`` or ``sigma_v_fps``, ft/s, with its standard
    error by the delta method), τ (s), its length scale V τ (ft), and per output the RMS of
    output error's residuals ("before": no gust) and of the Kalman filter's innovations
    ("after": with the gust state)."""
    out: dict = {}
    if p.recording is not None:
        for key, model, gust, surfaces, sigma_name in AXES:
            if any(s in p.driven for s in surfaces):
                out[key] = _axis_model(p, model, gust, sigma_name)
    fitted = any(m.get("fitted") for m in out.values())
    if not out:
        out["reason"] = "no surface drove the maneuver (or the recording is not at hand): no gust model is fitted"
    return {"fitted": fitted, **out}


def _axis_model(p: Prepared, model: str, gust: str, sigma_name: str) -> dict:
    """One axis's filter-error fit with a first-order gust on ``gust`` against output error."""
    try:
        fe = FilterError(model=model, gust=gust).fit(p.recording)
        oe = OutputError(model=model).fit(p.recording)
    except (ValueError, np.linalg.LinAlgError, RuntimeError) as exc:
        return {"fitted": False, "reason": f"the filter-error fit failed: {exc}"}
    V = float(np.mean(p.smooth["V"]))
    ln_s, ln_tau = float(fe.params["ln_sigma_gust"]), float(fe.params["ln_tau_gust"])
    se_ln = float(fe.bse["ln_sigma_gust"])
    sigma = V * np.exp(ln_s)
    outputs = fe.dependent.split(",")  # the model's outputs, in the residuals' column order
    before = {o: _rms(oe.residuals[:, i]) for i, o in enumerate(outputs)}
    after = {o: _rms(fe.residuals[:, i]) for i, o in enumerate(outputs)}
    return {"fitted": True, "method": f"filter error (fe), {model} model with a first-order gust on {gust}",
            sigma_name: float(sigma), f"{sigma_name[:-4]}_std_error_fps": float(sigma * se_ln) if np.isfinite(se_ln)
            else None, "tau_s": float(np.exp(ln_tau)), "length_scale_ft": float(V * np.exp(ln_tau)),
            "rms_output_error": before, "rms_filter_error": after,
            "change": {o: after[o] / before[o] - 1.0 for o in outputs if before[o] > 0}}
