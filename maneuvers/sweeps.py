"""Frequency sweeps (chirps) with linear or logarithmic frequency laws.

With ``τ = t - start_s`` the time into the sweep and ``T`` its duration, the
instantaneous frequency is

* linear:       ``f(τ) = f0 + (f1 - f0) τ / T``
* logarithmic:  ``f(τ) = f0 r^(τ/T)``, ``r = f1 / f0`` (an exponential law,
  equal time per octave),

and the phase is its exact integral, ``φ(τ) = 2π ∫_0^τ f(s) ds``:

* linear:       ``φ(τ) = 2π (f0 τ + (f1 - f0) τ² / (2T))``
* logarithmic:  ``φ(τ) = 2π f0 T (r^(τ/T) - 1) / ln r``.

The deflection is ``A w(τ) sin φ(τ)``, which starts at zero.  To also *end* at
zero the total phase ``φ(T) = 2π T f̄`` (``f̄`` the mean frequency, which
depends only on ``f0`` and ``f1``) must be a whole number of half cycles; the
requested ``sweep_duration_s`` is therefore rounded *up* to the next half
cycle, by at most ``1 / (2 f̄)``.  ``f(0) = f0`` and ``f(T) = f1`` hold exactly
for the rounded ``T``.  ``w`` is an optional raised-cosine fade in/out of
length ``taper_s`` (``w = 1`` when ``taper_s = 0``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from maneuvers.base import (
    SURFACE_WORDS,
    InputSpecError,
    as_time,
    fmt,
    in_window,
    require_below_nyquist,
    require_nonnegative,
    require_positive,
    require_surface,
)

SweepKind = Literal["linear", "logarithmic"]
SWEEP_KINDS: tuple[str, ...] = ("linear", "logarithmic")


@dataclass(frozen=True)
class FrequencySweep:
    """Sine sweep from ``f0_hz`` to ``f1_hz`` on one surface.

    Parameters
    ----------
    surface
        ``'de'``, ``'da'`` or ``'dr'``.
    f0_hz, f1_hz
        Start and end frequencies, ``0 <= f0 < f1`` (``f0 > 0`` for
        logarithmic sweeps).
    sweep_duration_s
        Requested sweep duration; rounded up to end on a zero crossing
        (see :attr:`active_duration_s`).
    amplitude_deg
        Sine amplitude in degrees (> 0).  Output is in radians.
    kind
        ``'linear'`` or ``'logarithmic'``.
    start_s, quiet_after_s
        Quiet time before and after the sweep, seconds.
    taper_s
        Raised-cosine fade-in and fade-out length (0 = none).
    sample_rate_hz
        Optional sample rate; if given ``f1_hz`` must be below its Nyquist
        frequency.
    name
        Identifier; derived when empty.
    """

    surface: str
    f0_hz: float
    f1_hz: float
    sweep_duration_s: float
    amplitude_deg: float = 1.0
    kind: SweepKind = "linear"
    start_s: float = 1.0
    quiet_after_s: float = 1.0
    taper_s: float = 0.0
    sample_rate_hz: float | None = None
    name: str = ""

    def __post_init__(self) -> None:
        require_surface(self.surface)
        if self.kind not in SWEEP_KINDS:
            raise InputSpecError(
                f"unknown sweep kind {self.kind!r}; valid kinds: {', '.join(SWEEP_KINDS)}"
            )
        if self.kind == "logarithmic":
            require_positive("f0_hz (logarithmic sweep)", self.f0_hz)
        else:
            require_nonnegative("f0_hz", self.f0_hz)
        require_positive("f1_hz", self.f1_hz)
        if self.f0_hz >= self.f1_hz:
            raise InputSpecError(
                f"sweep needs f0_hz < f1_hz, got f0_hz={self.f0_hz:g}, f1_hz={self.f1_hz:g}"
            )
        require_below_nyquist("f1_hz", self.f1_hz, self.sample_rate_hz)
        require_positive("sweep_duration_s", self.sweep_duration_s)
        require_positive("amplitude_deg", self.amplitude_deg)
        require_nonnegative("start_s", self.start_s)
        require_nonnegative("quiet_after_s", self.quiet_after_s)
        require_nonnegative("taper_s", self.taper_s)
        if 2.0 * self.taper_s > self.sweep_duration_s:
            raise InputSpecError(
                f"taper_s={self.taper_s:g} s fade in + fade out exceeds "
                f"sweep_duration_s={self.sweep_duration_s:g} s"
            )
        if not self.name:
            short = "linear" if self.kind == "linear" else "log"
            object.__setattr__(self, "name", f"{SURFACE_WORDS[self.surface]}_sweep_{short}")

    # -- frequency law ----------------------------------------------------
    @property
    def mean_frequency_hz(self) -> float:
        """Time-averaged frequency ``f̄``: ``(f0+f1)/2`` or ``(f1-f0)/ln(f1/f0)``."""
        if self.kind == "linear":
            return 0.5 * (self.f0_hz + self.f1_hz)
        return (self.f1_hz - self.f0_hz) / math.log(self.f1_hz / self.f0_hz)

    @property
    def half_cycles(self) -> int:
        """Number of half cycles in the sweep (``φ(T) = π * half_cycles``)."""
        n = 2.0 * self.sweep_duration_s * self.mean_frequency_hz
        return max(1, math.ceil(n - 1e-9 * max(1.0, n)))

    @property
    def active_duration_s(self) -> float:
        """Actual sweep duration ``T = half_cycles / (2 f̄) >= sweep_duration_s``."""
        return self.half_cycles / (2.0 * self.mean_frequency_hz)

    @property
    def duration_s(self) -> float:
        """``start_s + active_duration_s + quiet_after_s``."""
        return self.start_s + self.active_duration_s + self.quiet_after_s

    @property
    def surfaces(self) -> tuple[str, ...]:
        """The single driven surface."""
        return (self.surface,)

    def instantaneous_frequency_hz(self, tau: npt.ArrayLike) -> np.ndarray:
        """``f(τ)`` in Hz for ``τ`` seconds into the sweep."""
        tau_a = np.asarray(tau, dtype=float)
        big_t = self.active_duration_s
        if self.kind == "linear":
            return self.f0_hz + (self.f1_hz - self.f0_hz) * tau_a / big_t
        return self.f0_hz * (self.f1_hz / self.f0_hz) ** (tau_a / big_t)

    def phase_rad(self, tau: npt.ArrayLike) -> np.ndarray:
        """Exact phase ``φ(τ) = 2π ∫_0^τ f(s) ds`` in radians."""
        tau_a = np.asarray(tau, dtype=float)
        big_t = self.active_duration_s
        if self.kind == "linear":
            k = (self.f1_hz - self.f0_hz) / big_t
            return 2.0 * np.pi * (self.f0_hz * tau_a + 0.5 * k * tau_a**2)
        log_r = math.log(self.f1_hz / self.f0_hz)
        return 2.0 * np.pi * self.f0_hz * big_t * np.expm1(log_r * tau_a / big_t) / log_r

    def taper(self, tau: npt.ArrayLike) -> np.ndarray:
        """Raised-cosine fade ``w(τ) ∈ [0, 1]``.

        ``w = (1 - cos(π d / taper_s)) / 2`` within ``taper_s`` of either end,
        ``d`` the distance to that end; ``w = 1`` elsewhere.
        """
        tau_a = np.asarray(tau, dtype=float)
        w = np.ones_like(tau_a)
        if self.taper_s > 0.0:
            edge = np.minimum(tau_a, self.active_duration_s - tau_a) / self.taper_s
            ramp = edge < 1.0
            w[ramp] = 0.5 * (1.0 - np.cos(np.pi * np.clip(edge[ramp], 0.0, 1.0)))
        return w

    # -- protocol ---------------------------------------------------------
    def deflections(self, t: npt.ArrayLike) -> dict[str, np.ndarray]:
        """``A w(τ) sin φ(τ)`` in radians on ``[start_s, start_s + T)``, zero elsewhere."""
        tt = as_time(t)
        out = np.zeros_like(tt)
        mask = in_window(tt, self.start_s, self.start_s + self.active_duration_s)
        tau = tt[mask] - self.start_s
        amp = np.deg2rad(self.amplitude_deg)
        out[mask] = amp * self.taper(tau) * np.sin(self.phase_rad(tau))
        return {self.surface: out}

    def describe(self) -> str:
        """E.g. ``'stabilator linear sweep 0.1-2 Hz over 15.1 s, 1 deg'``."""
        taper = f", {fmt(self.taper_s)} s taper" if self.taper_s > 0 else ""
        return (
            f"{SURFACE_WORDS[self.surface]} {self.kind} sweep "
            f"{fmt(self.f0_hz)}-{fmt(self.f1_hz)} Hz over "
            f"{self.active_duration_s:.3g} s, {fmt(self.amplitude_deg)} deg{taper}"
        )
