"""Mutually orthogonal flat-spectrum multisine inputs on one or more surfaces.

Surface ``i`` receives, over the active window ``τ = t - start_s ∈ [0, T)``,

.. math::  δ_i(τ) = a_i \\sum_{k \\in K_i} \\sin(2π k τ / T + φ_{i,k}),

a sum of equal-amplitude sines at harmonics ``k`` of ``1/T``.  The harmonic
sets ``K_i`` are disjoint, so for ``i ≠ j``

.. math::  \\int_0^T δ_i δ_j \\, dτ = 0

exactly (and likewise for the sum over any uniform grid of ``M > 2 k_max``
samples on ``[0, T)``): the inputs are mutually orthogonal and their effects
separable in the frequency domain.  With a band ``f_min..f_max`` the band's
harmonics ``k_lo..k_hi`` are interleaved: surface ``i`` (0-based) gets every
``k`` with ``(k - k_lo) ≡ i (mod n_surfaces)``.

Phases are Schroeder's, optionally optimised for low relative peak factor,
then time-shifted so each surface starts (and, by periodicity, ends) at zero;
see :mod:`maneuvers.multisine_phases`.  The scale ``a_i`` is set so the
*peak* deflection ``max_τ |δ_i(τ)|`` (continuous time, Newton-refined)
equals ``amplitude_deg`` of that surface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from numbers import Integral, Real
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
from maneuvers.multisine_phases import design_phases, extrema, synthesize

PhaseMethod = Literal["schroeder", "optimized"]
PHASE_METHODS: tuple[str, ...] = ("schroeder", "optimized")


def allocate_harmonics(
    period_s: float, f_min_hz: float, f_max_hz: float, n_surfaces: int
) -> tuple[tuple[int, ...], ...]:
    """Interleave the harmonics of ``1/period_s`` in ``[f_min, f_max]`` over surfaces.

    The band holds ``k_lo = max(1, ceil(f_min T))`` .. ``k_hi = floor(f_max T)``
    (1e-9 tolerance for round-off); surface ``i`` gets ``k_lo + i``,
    ``k_lo + i + n``, ...  Raises if any surface would get no harmonic.
    """
    big_t = require_positive("period_s", period_s)
    f_lo = require_nonnegative("f_min_hz", f_min_hz)
    f_hi = require_positive("f_max_hz", f_max_hz)
    if f_lo >= f_hi:
        raise InputSpecError(f"multisine needs f_min_hz < f_max_hz, got {f_lo:g} >= {f_hi:g}")
    k_lo = max(1, math.ceil(f_lo * big_t - 1e-9))
    k_hi = math.floor(f_hi * big_t + 1e-9)
    band = list(range(k_lo, k_hi + 1))
    if len(band) < n_surfaces:
        raise InputSpecError(
            f"band {f_lo:g}-{f_hi:g} Hz holds {len(band)} harmonic(s) of 1/T = "
            f"{1.0 / big_t:g} Hz, fewer than the {n_surfaces} surface(s); "
            "widen the band or lengthen period_s"
        )
    return tuple(tuple(band[i::n_surfaces]) for i in range(n_surfaces))


@dataclass(frozen=True)
class MultisineDesign:
    """Resolved multisine: per-surface harmonics, phases, scale and RPF.

    Attributes
    ----------
    harmonics
        Harmonic indices ``K_i`` (multiples of ``1/T``) per surface.
    phases_rad
        Phases ``φ_{i,k}`` per surface, radians.
    component_amplitude_rad
        Amplitude ``a_i`` of each sine, radians, per surface.
    rpf_schroeder
        Relative peak factor with Schroeder phases, per surface.
    rpf
        Relative peak factor of the phases used, per surface.
    """

    harmonics: tuple[tuple[int, ...], ...]
    phases_rad: tuple[tuple[float, ...], ...]
    component_amplitude_rad: tuple[float, ...]
    rpf_schroeder: tuple[float, ...]
    rpf: tuple[float, ...]


@dataclass(frozen=True)
class Multisine:
    """Orthogonal multisine input on one or more surfaces simultaneously.

    Parameters
    ----------
    surfaces
        Driven surfaces, e.g. ``('de', 'da', 'dr')`` (a single name is accepted).
    period_s
        Active duration ``T``; frequencies are harmonics of ``1/T``.
    f_min_hz, f_max_hz
        Band whose harmonics are interleaved over the surfaces.  Give either
        the band or ``harmonics``.
    harmonics
        Explicit disjoint harmonic indices per surface, e.g. ``((1, 3), (2, 4))``.
    amplitude_deg
        Peak deflection in degrees, one value for all surfaces or one per
        surface.  Output is in radians.
    phases
        ``'schroeder'`` or ``'optimized'`` (low relative peak factor).
    start_s, quiet_after_s
        Quiet time before and after, seconds.
    sample_rate_hz
        Optional; if given the highest frequency must be below its Nyquist.
    name
        Identifier; derived when empty.

    Notes
    -----
    The phase design runs once per instance, lazily, on first use of
    :attr:`design` (or of :meth:`deflections`/:meth:`describe`).
    """

    surfaces: tuple[str, ...]
    period_s: float = 10.0
    f_min_hz: float | None = None
    f_max_hz: float | None = None
    harmonics: tuple[tuple[int, ...], ...] | None = None
    amplitude_deg: float | tuple[float, ...] = 1.0
    phases: PhaseMethod = "optimized"
    start_s: float = 1.0
    quiet_after_s: float = 1.0
    sample_rate_hz: float | None = None
    name: str = ""

    def __post_init__(self) -> None:
        surfaces = (self.surfaces,) if isinstance(self.surfaces, str) else tuple(self.surfaces)
        if not surfaces:
            raise InputSpecError("a multisine needs at least one surface")
        for s in surfaces:
            require_surface(s)
        if len(set(surfaces)) != len(surfaces):
            raise InputSpecError(f"surfaces listed more than once: {surfaces!r}")
        object.__setattr__(self, "surfaces", surfaces)
        require_positive("period_s", self.period_s)
        require_nonnegative("start_s", self.start_s)
        require_nonnegative("quiet_after_s", self.quiet_after_s)
        if self.phases not in PHASE_METHODS:
            raise InputSpecError(
                f"unknown phase method {self.phases!r}; valid: {', '.join(PHASE_METHODS)}"
            )
        for s, a in zip(surfaces, self.amplitudes_deg):
            require_positive(f"amplitude_deg for {s}", a)
        k_max = max(max(k) for k in self.harmonic_sets)
        require_below_nyquist(
            "highest multisine frequency", k_max / self.period_s, self.sample_rate_hz
        )
        if not self.name:
            object.__setattr__(self, "name", "multisine_" + "_".join(surfaces))

    @cached_property
    def amplitudes_deg(self) -> tuple[float, ...]:
        """Peak deflection per surface, degrees."""
        amps = self.amplitude_deg
        if isinstance(amps, Real):
            return (float(amps),) * len(self.surfaces)
        amps_t = tuple(float(a) for a in amps)
        if len(amps_t) != len(self.surfaces):
            raise InputSpecError(
                f"{len(amps_t)} amplitudes given for {len(self.surfaces)} surfaces"
            )
        return amps_t

    @cached_property
    def harmonic_sets(self) -> tuple[tuple[int, ...], ...]:
        """Resolved harmonic indices per surface (from the band or as given)."""
        n = len(self.surfaces)
        band_given = self.f_min_hz is not None or self.f_max_hz is not None
        if self.harmonics is None:
            if self.f_min_hz is None or self.f_max_hz is None:
                raise InputSpecError("give a band (f_min_hz and f_max_hz) or explicit harmonics")
            return allocate_harmonics(self.period_s, self.f_min_hz, self.f_max_hz, n)
        if band_given:
            raise InputSpecError("give either a band (f_min_hz, f_max_hz) or harmonics, not both")
        raw = self.harmonics
        if n == 1 and raw and all(isinstance(k, Integral) for k in raw):
            raw = (raw,)  # a flat tuple of ints for a single surface
        if any(isinstance(ks, Integral) for ks in raw):
            raise InputSpecError(
                f"harmonics must be one tuple of integers per surface, got {raw!r}"
            )
        sets = tuple(tuple(ks) for ks in raw)
        if len(sets) != n:
            raise InputSpecError(f"{len(sets)} harmonic sets given for {n} surfaces")
        seen: set[int] = set()
        for s, ks in zip(self.surfaces, sets):
            if not ks:
                raise InputSpecError(f"empty harmonic set for surface {s!r}")
            if any(not isinstance(k, Integral) or k < 1 for k in ks) or len(set(ks)) != len(ks):
                raise InputSpecError(f"harmonics for {s!r} must be distinct integers >= 1: {ks}")
            if seen & set(ks):
                raise InputSpecError(
                    f"harmonic sets overlap ({sorted(seen & set(ks))}); they must be "
                    "disjoint for the inputs to be orthogonal"
                )
            seen |= set(ks)
        return tuple(tuple(sorted(int(k) for k in ks)) for ks in sets)

    # -- design -----------------------------------------------------------
    @cached_property
    def design(self) -> MultisineDesign:
        """Phases, per-sine amplitudes and RPFs (computed once per instance)."""
        phases, scales, rpf0, rpf1 = [], [], [], []
        for ks, amp_deg in zip(self.harmonic_sets, self.amplitudes_deg):
            phi, r0, r1 = design_phases(ks, optimize=self.phases == "optimized")
            hi, lo = extrema(ks, phi)
            phases.append(tuple(float(p) for p in phi))
            scales.append(float(np.deg2rad(amp_deg)) / max(hi, -lo))
            rpf0.append(r0)
            rpf1.append(r1)
        return MultisineDesign(
            harmonics=self.harmonic_sets,
            phases_rad=tuple(phases),
            component_amplitude_rad=tuple(scales),
            rpf_schroeder=tuple(rpf0),
            rpf=tuple(rpf1),
        )

    def frequencies_hz(self) -> tuple[np.ndarray, ...]:
        """Excited frequencies ``k / T`` per surface, Hz."""
        return tuple(np.asarray(ks, float) / self.period_s for ks in self.harmonic_sets)

    # -- protocol ---------------------------------------------------------
    @property
    def active_duration_s(self) -> float:
        """One period ``T``."""
        return float(self.period_s)

    @property
    def duration_s(self) -> float:
        """``start_s + T + quiet_after_s``."""
        return self.start_s + self.period_s + self.quiet_after_s

    def deflections(self, t: npt.ArrayLike) -> dict[str, np.ndarray]:
        """Deflections in radians on ``[start_s, start_s + T)``, zero elsewhere."""
        tt = as_time(t)
        mask = in_window(tt, self.start_s, self.start_s + self.period_s)
        u = (tt[mask] - self.start_s) / self.period_s
        d = self.design
        out: dict[str, np.ndarray] = {}
        for s, ks, phi, a in zip(self.surfaces, d.harmonics, d.phases_rad,
                                 d.component_amplitude_rad):
            x = np.zeros_like(tt)
            x[mask] = a * synthesize(ks, phi, u)
            out[s] = x
        return out

    def describe(self) -> str:
        """E.g. ``'multisine stabilator+aileron, 0.1-2 Hz, T 10 s, 1 deg peak, ...'``."""
        d = self.design
        words = "+".join(SURFACE_WORDS[s] for s in self.surfaces)
        f_all = np.concatenate(self.frequencies_hz())
        amps = "/".join(fmt(a) for a in self.amplitudes_deg)
        rpf = "/".join(f"{r:.2f}" for r in d.rpf)
        return (
            f"multisine {words}, {fmt(f_all.min())}-{fmt(f_all.max())} Hz, "
            f"T {fmt(self.period_s)} s, {amps} deg peak, {self.phases} phases (RPF {rpf})"
        )
