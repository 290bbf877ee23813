"""The noise layer: turning a clean recording into what instruments would record.

Noise is declared per channel in a frozen :class:`ChannelNoise` and collected in a
:class:`NoiseModel`; :func:`apply_noise` applies it to a recording with an explicit seed
(a :class:`numpy.random.SeedSequence` entropy), recorded in the output's metadata. Each
channel draws from its own child stream (keyed by the channel name), so adding noise to one
channel never changes another's.

Processing order within a channel, as a sensor would: time skew → scale factor → bias →
colored noise → white noise → spikes → quantization.
"""
from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from maneuvers.recording import Recording
from models.atmosphere import Turbulence
from models.errors import OptionError


@dataclass(frozen=True)
class ChannelNoise:
    """Errors of one measured channel, in the channel's canonical unit.

    Attributes
    ----------
    white_std : standard deviation of white Gaussian noise.
    colored_std, colored_tau_s : steady-state standard deviation and correlation time of a
        first-order Gauss-Markov process, x_k = φ x_{k-1} + w_k with φ = exp(-dt/τ).
    band_hz : optional (f_lo, f_hi) of a shaped spectrum instead: white noise band-limited to
        [f_lo, f_hi] Hz (brick-wall in the frequency domain), scaled to ``colored_std``.
    bias : constant offset.
    scale : scale-factor error k, the channel reads (1 + k)·x.
    quantum : quantization step (0 for none).
    skew_s : time skew τ, the channel reads x(t − τ) (positive: lags the others), by linear
        interpolation with the first value held before the start.
    spike_rate_hz, spike_std : occasional spikes (bad data): a Poisson number of samples
        per second each offset by a Gaussian of this standard deviation.
    """

    white_std: float = 0.0
    colored_std: float = 0.0
    colored_tau_s: float = 1.0
    band_hz: tuple[float, float] | None = None
    bias: float = 0.0
    scale: float = 0.0
    quantum: float = 0.0
    skew_s: float = 0.0
    spike_rate_hz: float = 0.0
    spike_std: float = 0.0

    def __post_init__(self) -> None:
        for name in ("white_std", "colored_std", "quantum", "spike_rate_hz", "spike_std"):
            if not (getattr(self, name) >= 0.0):
                raise OptionError(f"noise {name} must be non-negative, not {getattr(self, name)!r}")
        if self.colored_tau_s <= 0:
            raise OptionError("colored_tau_s must be positive")
        if self.band_hz is not None and not (0 <= self.band_hz[0] < self.band_hz[1]):
            raise OptionError(f"band_hz must be (f_lo, f_hi) with 0 <= f_lo < f_hi, not {self.band_hz}")

    @property
    def is_zero(self) -> bool:
        return self == ChannelNoise()

    def scaled(self, factor: float) -> "ChannelNoise":
        """The same errors with every random level multiplied by ``factor``."""
        return ChannelNoise(self.white_std * factor, self.colored_std * factor, self.colored_tau_s, self.band_hz,
                            self.bias * factor, self.scale * factor, self.quantum, self.skew_s,
                            self.spike_rate_hz, self.spike_std * factor)


@dataclass(frozen=True)
class NoiseModel:
    """A named set of channel errors, plus optional turbulence.

    ``channels`` maps a recording quantity (``'alpha'``, ``'q'``, ``'az'``, ``'de'`` …) to its
    :class:`ChannelNoise`; it is stored as a sorted tuple of pairs so the model is frozen and
    hashable. ``output`` maps dependent variables of equation error (``'Cm'``, ``'CZ'`` …) to
    noise added directly to them (the seed's §III.C design: noise on the output alone, with
    the regressors clean or noisy as ``channels`` says).
    """

    name: str
    channels: tuple[tuple[str, ChannelNoise], ...] = ()
    output: tuple[tuple[str, ChannelNoise], ...] = ()
    turbulence: Turbulence | None = None
    source: str = ""
    drop: tuple[str, ...] = ()

    @classmethod
    def build(cls, name: str, channels: Mapping[str, ChannelNoise] | None = None,
              output: Mapping[str, ChannelNoise] | None = None, turbulence: Turbulence | None = None,
              source: str = "", drop: tuple[str, ...] = ()) -> "NoiseModel":
        return cls(name, tuple(sorted((channels or {}).items())), tuple(sorted((output or {}).items())),
                   turbulence, source, tuple(drop))

    @property
    def channel_map(self) -> dict[str, ChannelNoise]:
        return dict(self.channels)

    @property
    def output_map(self) -> dict[str, ChannelNoise]:
        return dict(self.output)

    def only(self, quantities: tuple[str, ...]) -> "NoiseModel":
        """The same model restricted to some channels (regressor noise set apart)."""
        return NoiseModel(self.name, tuple((k, v) for k, v in self.channels if k in quantities), self.output,
                          self.turbulence, self.source, self.drop)

    def scaled(self, factor: float) -> "NoiseModel":
        return NoiseModel(f"{self.name}x{factor:g}", tuple((k, v.scaled(factor)) for k, v in self.channels),
                          tuple((k, v.scaled(factor)) for k, v in self.output), self.turbulence, self.source,
                          self.drop)

    def as_dict(self) -> dict:
        return {"name": self.name, "channels": {k: asdict(v) for k, v in self.channels},
                "output": {k: asdict(v) for k, v in self.output},
                "turbulence": None if self.turbulence is None else asdict(self.turbulence),
                "source": self.source, "drop": list(self.drop)}


def stream(seed: int | tuple[int, ...], *keys: str) -> np.random.Generator:
    """An independent random stream for ``seed`` and the names ``keys`` (order-free of use)."""
    words = [int.from_bytes(hashlib.sha256(k.encode()).digest()[:4], "little") for k in keys]
    base = list(seed) if isinstance(seed, tuple) else [int(seed)]
    return np.random.default_rng(np.random.SeedSequence(base + words))


def gauss_markov(n: int, dt: float, std: float, tau_s: float, rng: np.random.Generator) -> np.ndarray:
    """First-order Gauss-Markov sequence with steady-state standard deviation ``std``,
    started in its stationary distribution: x_k = φ x_{k−1} + sqrt(1 − φ²)·std·w_k."""
    import scipy.signal
    phi = float(np.exp(-dt / tau_s))
    w = rng.standard_normal(n) * std * np.sqrt(1.0 - phi * phi)
    w[0] = rng.standard_normal() * std
    return scipy.signal.lfilter([1.0], [1.0, -phi], w)


def band_limited(n: int, dt: float, std: float, band_hz: tuple[float, float], rng: np.random.Generator) -> np.ndarray:
    """White Gaussian noise limited to ``band_hz`` in the frequency domain, scaled to ``std``."""
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, dt)
    spec[(f < band_hz[0]) | (f > band_hz[1])] = 0.0
    x = np.fft.irfft(spec, n)
    s = x.std()
    return x * (std / s) if s > 0 else x


def corrupt(x: np.ndarray, t: np.ndarray, spec: ChannelNoise, rng: np.random.Generator) -> np.ndarray:
    """Apply one channel's errors (see the module docstring for the order)."""
    dt = float(t[1] - t[0])
    y = np.interp(t - spec.skew_s, t, x) if spec.skew_s else x.astype(float, copy=True)
    y = (1.0 + spec.scale) * y + spec.bias
    n = len(y)
    if spec.colored_std:
        y = y + (band_limited(n, dt, spec.colored_std, spec.band_hz, rng) if spec.band_hz
                 else gauss_markov(n, dt, spec.colored_std, spec.colored_tau_s, rng))
    if spec.white_std:
        y = y + spec.white_std * rng.standard_normal(n)
    if spec.spike_rate_hz and spec.spike_std:
        k = rng.poisson(spec.spike_rate_hz * (t[-1] - t[0]))
        idx = rng.choice(n, size=min(k, n), replace=False)
        y[idx] += spec.spike_std * rng.standard_normal(len(idx))
    if spec.quantum:
        y = spec.quantum * np.round(y / spec.quantum)
    return y


def apply_noise(rec: Recording, model: NoiseModel, seed: int | tuple[int, ...]) -> Recording:
    """A copy of ``rec`` with ``model``'s sensor errors applied, drawn from ``seed``.

    Truth columns are left clean. The metadata gains ``noise``: the model, the seed and which
    channels were corrupted, so the realization can be reproduced exactly. (Output noise on
    equation-error dependent variables is applied by :func:`output_noise` where the dependent
    is formed; turbulence is flown, not added: see the campaign runner.)
    """
    data = rec.data.copy()
    t = rec.t
    done = []
    for quantity, spec in model.channels:
        if spec.is_zero or not rec.has(quantity):
            continue  # a preset covers channels a given recording may not have
        col = rec.column(quantity)
        data[col] = corrupt(data[col].to_numpy(), t, spec, stream(seed, "channel", quantity))
        done.append(quantity)
    for quantity in model.drop:
        if rec.has(quantity):
            del data[rec.column(quantity)]
    meta = dict(rec.meta)
    meta["noise"] = {"model": model.as_dict(), "seed": list(seed) if isinstance(seed, tuple) else int(seed),
                     "channels": done, "dropped": [q for q in model.drop if rec.has(q)]}
    return Recording(data=pd.DataFrame(data), meta=meta, name=rec.name).validate(f"{rec.name} + noise {model.name}")


def output_noise(z: np.ndarray, t: np.ndarray, dependent: str, model: NoiseModel,
                 seed: int | tuple[int, ...]) -> np.ndarray:
    """Add ``model.output[dependent]`` noise to an equation-error dependent variable."""
    spec = model.output_map.get(dependent)
    if spec is None or spec.is_zero:
        return z
    return corrupt(z, t, spec, stream(seed, "output", dependent))
