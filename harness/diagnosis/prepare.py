"""A recording made ready for the diagnosis: one common zero-phase filter for every channel,
the noise level of each channel, the kinematic derivatives and the measured coefficients."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from estimators.coefficients import accelerometer_at_cg, force_coefficients, moment_coefficients
from estimators.smoothing import optimal_fourier_smoother, sine_series_derivative, sine_series_filter
from maneuvers.recording import Recording

OUTPUTS = ("alpha", "beta", "p", "q", "r", "phi", "theta", "V", "ax", "ay", "az")
UNITS = {"alpha": "rad", "beta": "rad", "p": "rps", "q": "rps", "r": "rps", "phi": "rad", "theta": "rad",
         "psi": "rad", "V": "fps", "ax": "g", "ay": "g", "az": "g", "h": "ft", "de": "rad", "da": "rad",
         "dr": "rad", "qbar": "psf", "thrust": "lbf"}
# Channels whose bandwidth sets the common filter (when excited): the states.
BANDWIDTH_CHANNELS = ("alpha", "beta", "p", "q", "r")
COEFFICIENTS = ("CX", "CY", "CZ", "Cl", "Cm", "Cn")
START_WINDOW_S = 0.5


@dataclass(frozen=True)
class Prepared:
    """One recording, filtered and differentiated by one linear operator.

    Attributes
    ----------
    t, dt : sample times (from 0) and step.
    raw : the recorded channels by quantity (``alpha``, ``q`` ...), canonical units.
    smooth, deriv : the common-filter estimate of each channel and its time derivative.
    noise_std, cutoff_hz : each channel's own optimal-smoother noise level and cut-off.
    weights, common_cutoff_hz : the common filter (sine-series weights) and its cut-off.
    excited : the channels whose signal stands clear of their noise.
    measured : coefficients (Eqs. 1-5) from the filtered channels.
    start : the recording's initial values (means over the first 0.5 s of ``smooth``).
    meta : the recording's metadata.
    mass : mass and inertia per sample (``Recording.mass_at``: metadata constants or channels).
    own_noise : each channel minus its own optimal smoothing (what the smoother calls noise).
    """

    name: str
    t: np.ndarray
    dt: float
    raw: dict[str, np.ndarray]
    smooth: dict[str, np.ndarray]
    deriv: dict[str, np.ndarray]
    noise_std: dict[str, float]
    cutoff_hz: dict[str, float]
    weights: np.ndarray
    common_cutoff_hz: float
    excited: tuple[str, ...]
    measured: dict[str, np.ndarray]
    start: dict[str, float]
    meta: dict = field(default_factory=dict)
    own_noise: dict[str, np.ndarray] = field(default_factory=dict)  # raw − each channel's own optimal smoothing
    mass: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def n(self) -> int:
        return self.t.size

    def filt(self, x: np.ndarray) -> np.ndarray:
        """Apply the common filter to another record."""
        return sine_series_filter(x, self.weights)

    def differentiate(self, x: np.ndarray) -> np.ndarray:
        """The common filter's derivative of another record."""
        return sine_series_derivative(x, self.weights, self.dt)


def _channels(rec: Recording) -> dict[str, np.ndarray]:
    out = {}
    for q, unit in UNITS.items():
        col = f"{q}_{unit}"
        if col in rec.data.columns:
            out[q] = rec.data[col].to_numpy(dtype=float)
    return out


def common_weights(fits: dict, excited: tuple[str, ...], n: int) -> np.ndarray:
    """The element-wise minimum of the excited states' Wiener weights (all ones beyond
    their last cut-off is never needed: a weight is at most 1).

    The same rule as the smoothed equation-error estimator: one linear filter for every
    record keeps z = Xθ exact through the filter."""
    chosen = [fits[c].weights for c in BANDWIDTH_CHANNELS if c in excited]
    if not chosen:
        chosen = [fits[c].weights for c in BANDWIDTH_CHANNELS if c in fits]
    return np.min(chosen, axis=0) if chosen else np.ones(n - 2)


def prepare(rec: Recording, name: str = "identification") -> Prepared:
    """Filter, differentiate and turn ``rec`` into measured coefficients.

    Raises
    ------
    ValueError
        When the recording is too short (under 4 s) or lacks what Eqs. 1-5 need.
    """
    raw = _channels(rec)
    t = rec.data["t_s"].to_numpy(dtype=float)
    t = t - t[0]
    if t[-1] < 4.0:
        raise ValueError(f"recording {rec.name!r} is {t[-1]:.1f} s long; the diagnosis needs at least 4 s")
    dt = float((t[-1] - t[0]) / (t.size - 1))
    fits = {c: optimal_fourier_smoother(x, dt) for c, x in raw.items()}
    noise = {c: float(np.sqrt(max(f.noise_variance, 0.0))) for c, f in fits.items()}
    excited = tuple(c for c, f in fits.items()
                    if np.std(f.smoothed - np.linspace(f.smoothed[0], f.smoothed[-1], t.size))
                    > 5.0 * max(noise[c], 1e-12))
    w = common_weights(fits, excited, t.size)
    smooth = {c: sine_series_filter(x, w) for c, x in raw.items()}
    deriv = {c: sine_series_derivative(x, w, dt) for c, x in raw.items()}
    k = max(1, int(round(START_WINDOW_S / dt)))
    start = {c: float(np.mean(x[:k])) for c, x in smooth.items()}
    cutoff = float(np.max(np.nonzero(w > 1e-6)[0], initial=0) + 1) / (2.0 * t[-1])
    try:
        mass = {k: np.asarray(v, dtype=float) for k, v in rec.mass_at().items()}
    except (KeyError, ValueError) as exc:
        raise ValueError(f"recording {rec.name!r} lacks mass properties Eqs. 1-5 need: {exc}") from exc
    measured = measured_coefficients(smooth, deriv, rec.meta, mass)
    return Prepared(name=name, t=t, dt=dt, raw=raw, smooth=smooth, deriv=deriv, noise_std=noise,
                    cutoff_hz={c: f.cutoff_hz for c, f in fits.items()}, weights=w, common_cutoff_hz=cutoff,
                    excited=excited, measured=measured, start=start, meta=dict(rec.meta),
                    own_noise={c: np.asarray(f.noise) for c, f in fits.items()}, mass=mass)


def measured_coefficients(s: dict[str, np.ndarray], d: dict[str, np.ndarray], meta: dict,
                          mass: dict[str, np.ndarray], thrust_lbf: float | None = None) -> dict[str, np.ndarray]:
    """Seed Eqs. 1 and 3-5 from filtered channels ``s`` and their derivatives ``d``.

    Thrust is the recorded channel when present, else ``thrust_lbf`` (the model's trim
    thrust), else zero; the accelerometer is moved to the c.g. when the metadata place it
    elsewhere."""
    geo = meta["geometry"]
    p, q, r = s["p"], s["q"], s["r"]
    pd_, qd, rd = d["p"], d["q"], d["r"]
    ax, ay, az = accelerometer_at_cg(s["ax"], s["ay"], s["az"], p, q, r, pd_, qd, rd,
                                     meta.get("sensors", {}).get("accelerometer_ft", (0.0, 0.0, 0.0)))
    thrust = s.get("thrust", np.full(p.size, thrust_lbf or 0.0))
    forces = force_coefficients(ax, ay, az, thrust, s["qbar"], mass["mass_slug"], geo["S_ft2"])
    moments = moment_coefficients(p, q, r, pd_, qd, rd, s["qbar"], geo["S_ft2"], geo["b_ft"], geo["cbar_ft"],
                                  mass["Ix_slugft2"], mass["Iy_slugft2"], mass["Iz_slugft2"], mass["Ixz_slugft2"],
                                  thrust, meta.get("thrust_offset_ft", 0.0))
    return {**forces, **{k: moments[k] for k in ("Cl", "Cm", "Cn")}}
