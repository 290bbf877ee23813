"""Turbulence as a process-noise model: the filter-error method on the recording itself.

When the kinematics show gusts (:func:`harness.diagnosis.spectra.gust_estimate`), the
deterministic model cannot follow the flight, however right its aerodynamics: the gust
drives the aircraft, and a replay without it drifts away. The filter-error method
(:class:`estimators.filter_error.FilterError`) puts the gust into the likelihood as a
first-order (Dryden) state disturbing α, σ and τ estimated with the derivatives, and its
Kalman filter follows the flight through the gusts. Fitted to the same recording with and
without it (output error), the two say how much of the mismatch the process-noise model
accounts for, and σ_w = V σ_α estimates the vertical gust a second way. The short-period
model is the one the filter-error defaults were validated on (README, the ``turbulence``
campaign), so the fit is made only when the stabilator drove the maneuver.
"""
from __future__ import annotations

import numpy as np

from estimators.filter_error import FilterError
from estimators.output_error import OutputError
from harness.diagnosis.prepare import Prepared


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x - np.mean(x)))))


def process_noise_model(p: Prepared) -> dict:
    """Filter error against output error on the short period of ``p`` (module docstring).

    Returns ``{"fitted": False, "reason": ...}`` when it cannot be made, else the gust's
    σ_w (ft/s, with its standard error by the delta method), τ (s), its length scale
    L_w = V τ (ft), and per output the RMS of output error's residuals ("before": no gust)
    and of the Kalman filter's innovations ("after": with the gust state)."""
    if "de" not in p.driven or p.recording is None:
        return {"fitted": False, "reason": "the stabilator did not drive the maneuver (the gust state is fitted "
                                           "on the short period only)"}
    try:
        fe = FilterError(model="short-period").fit(p.recording)
        oe = OutputError(model="short-period").fit(p.recording)
    except (ValueError, np.linalg.LinAlgError, RuntimeError) as exc:
        return {"fitted": False, "reason": f"the filter-error fit failed: {exc}"}
    V = float(np.mean(p.smooth["V"]))
    ln_s, ln_tau = float(fe.params["ln_sigma_gust"]), float(fe.params["ln_tau_gust"])
    se_ln = float(fe.bse["ln_sigma_gust"])
    sigma = V * np.exp(ln_s)
    outputs = fe.dependent.split(",")  # the model's outputs, in the residuals' column order
    before = {o: _rms(oe.residuals[:, i]) for i, o in enumerate(outputs)}
    after = {o: _rms(fe.residuals[:, i]) for i, o in enumerate(outputs)}
    return {"fitted": True, "method": "filter error (fe), short-period model with a first-order gust on alpha",
            "sigma_w_fps": float(sigma), "sigma_w_std_error_fps": float(sigma * se_ln) if np.isfinite(se_ln) else None,
            "tau_s": float(np.exp(ln_tau)), "L_w_ft": float(V * np.exp(ln_tau)),
            "rms_output_error": before, "rms_filter_error": after,
            "change": {o: after[o] / before[o] - 1.0 for o in outputs if before[o] > 0}}
