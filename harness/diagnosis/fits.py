"""Fit statistics before and after a model change: Theil's inequality coefficient and RMS
error per output channel, coefficient-residual RMS and PSE, and residual whiteness."""
from __future__ import annotations

import numpy as np


def theil_u(measured: np.ndarray, model: np.ndarray) -> float:
    """Theil's inequality coefficient, U = RMS(y − ŷ) / (RMS(y) + RMS(ŷ)), 0 for a perfect
    fit and 1 at worst."""
    num = float(np.sqrt(np.mean((measured - model) ** 2)))
    den = float(np.sqrt(np.mean(measured ** 2)) + np.sqrt(np.mean(model ** 2)))
    return num / den if den > 0 else 0.0


def whiteness(residual: np.ndarray, lags: int = 25) -> dict[str, float]:
    """Share of the normalised autocorrelation lags 1..``lags`` inside the 95 % band
    ±1.96/√N of white noise, and the lag-1 autocorrelation."""
    v = np.asarray(residual, dtype=float) - np.mean(residual)
    n = v.size
    c0 = float(v @ v)
    if c0 <= 0 or n <= lags + 1:
        return {"lag_fraction_inside": 1.0, "lag1": 0.0}
    rho = np.array([float(v[:-k] @ v[k:]) / c0 for k in range(1, lags + 1)])
    return {"lag_fraction_inside": float(np.mean(np.abs(rho) <= 1.96 / np.sqrt(n))), "lag1": float(rho[0])}


def output_fit(smooth: dict[str, np.ndarray], raw: dict[str, np.ndarray], sim: dict[str, np.ndarray],
               channels: tuple[str, ...], inner: slice) -> dict[str, dict[str, float]]:
    """Per output channel: RMS error against the smoothed recording (the noise removed),
    against the raw recording, Theil's U, and the whiteness of the raw residual."""
    out = {}
    for c in channels:
        if c not in sim or c not in smooth:
            continue
        e = smooth[c][inner] - sim[c][inner]
        er = raw[c][inner] - sim[c][inner]
        out[c] = {"rms": float(np.sqrt(np.mean(e ** 2))), "rms_raw": float(np.sqrt(np.mean(er ** 2))),
                  "theil_u": theil_u(smooth[c][inner], sim[c][inner]), **whiteness(er)}
    return out


def coefficient_fit(before: dict[str, np.ndarray], after: dict[str, np.ndarray], n_terms: dict[str, int],
                    inner: slice) -> dict[str, dict[str, float]]:
    """Per axis: RMS of the coefficient residual and its PSE = SSE/N + σ²_max p/N (seed's
    predicted square error, σ²_max the variance of the mismatch before any term)."""
    out = {}
    for c, r in after.items():
        v = r[inner]
        s2max = float(np.var(before[c][inner]))
        p = n_terms.get(c, 0) + 1
        out[c] = {"rms": float(np.sqrt(np.mean((v - v.mean()) ** 2))),
                  "pse": float(np.mean((v - v.mean()) ** 2) + s2max * p / v.size), **whiteness(v)}
    return out
