"""Studies that are not campaigns of flights: the seed's Fig. 1 differentiation experiment."""
from __future__ import annotations

import numpy as np
import pandas as pd

from estimators.differentiation import interior_mask, smooth_derivative


def random_band_limited(rng: np.random.Generator, t: np.ndarray, n_sines: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """A random sum of sines with frequencies in (0, 1] Hz and its exact derivative."""
    freqs = 1.0 - rng.uniform(0.0, 1.0, n_sines)
    amps = rng.normal(size=n_sines)
    phases = rng.uniform(0.0, 2 * np.pi, n_sines)
    arg = 2 * np.pi * np.multiply.outer(t, freqs) + phases
    return (amps * np.sin(arg)).sum(axis=1), (amps * 2 * np.pi * freqs * np.cos(arg)).sum(axis=1)


def differentiation_study(n_runs: int = 100, seed: int = 0, noise_to_signal: float = 0.10,
                          dt: float = 0.02, length_s: float = 22.0) -> pd.DataFrame:
    """The seed's Fig. 1: the three differentiation methods on random colored sequences.

    Each sequence: ``length_s`` at 1/dt Hz (20 s of interest + 1 s buffer at each end), a
    band-limited deterministic part in (0, 1] Hz with a known derivative, plus white noise at
    ``noise_to_signal`` of its RMS. The error is the RMS of (estimate − true derivative) over
    the interior divided by the RMS of the true derivative there, in %. Sequence ``k`` uses the
    random stream ``(seed, k)``.
    """
    t = np.arange(0, length_s + dt / 2, dt)
    inner = interior_mask(t.size, dt, 1.0)
    rows = []
    for k in range(n_runs):
        rng = np.random.default_rng((seed, k))
        x, dx = random_band_limited(rng, t)
        z = x + noise_to_signal * np.sqrt(np.mean(x**2)) * rng.normal(size=t.size)
        ref = dx[inner]
        for method in (1, 2, 3):
            d = smooth_derivative(z, dt, method, end_buffer_s=1.0)
            rows.append({"method": method, "sequence": k,
                         "rms_error_pct": 100 * float(np.sqrt(np.mean((d - ref) ** 2) / np.mean(ref**2)))})
    return pd.DataFrame(rows)
