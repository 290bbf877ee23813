"""How well a flown model follows a recording: per output channel, the RMS error against the
recording with its noise removed (the optimal Fourier smoother, seed §III.A) and Theil's
inequality coefficient, after a constant offset (a sensor bias, a trim mismatch) is taken out."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from estimators.smoothing import optimal_fourier_smoother


def smoothed(z: np.ndarray, dt: float) -> np.ndarray:
    """Each column of ``z`` through the optimal Fourier smoother."""
    return np.column_stack([optimal_fourier_smoother(z[:, j], dt).smoothed for j in range(z.shape[1])])


def theil_u(measured: np.ndarray, model: np.ndarray) -> float:
    """U = RMS(z − y) / (RMS(z) + RMS(y)): 0 for a perfect fit, 1 at worst."""
    den = float(np.sqrt(np.mean(measured ** 2)) + np.sqrt(np.mean(model ** 2)))
    return float(np.sqrt(np.mean((measured - model) ** 2))) / den if den > 0 else 0.0


def channel_fit(zs: Sequence[np.ndarray], ys: Sequence[np.ndarray], outputs: Sequence[str]) -> dict[str, dict]:
    """``{channel: {"rms", "theil_u"}}`` over the maneuvers ``zs`` (smoothed) against flights
    ``ys``, each maneuver's mean error removed first (None for a flight that failed)."""
    out = {}
    for j, o in enumerate(outputs):
        e, zz, yy = [], [], []
        for z, y in zip(zs, ys):
            if y is None:
                return {o: {"rms": None, "theil_u": None} for o in outputs}
            off = float(np.mean(z[:, j] - y[:, j]))
            e.append(z[:, j] - y[:, j] - off)
            zz.append(z[:, j])
            yy.append(y[:, j] + off)
        err = np.concatenate(e)
        out[o] = {"rms": float(np.sqrt(np.mean(err ** 2))), "theil_u": theil_u(np.concatenate(zz), np.concatenate(yy))}
    return out
