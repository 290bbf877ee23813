"""Common protocol and validation helpers for flight-test input signals.

Every input design in :mod:`maneuvers` is a frozen specification that maps a
time grid (seconds from the start of the recording) to control-surface
deflections in radians, as perturbations from trim.  Outside its active window
a specification evaluates to exactly zero, so it can be sampled on any grid.

Surface names follow JSBSim's flight-control conventions:

``de``
    stabilator / elevator, positive trailing edge down (nose-down moment).
``da``
    aileron.
``dr``
    rudder.
"""

from __future__ import annotations

import math
from types import MappingProxyType
from typing import Protocol, runtime_checkable

import numpy as np
import numpy.typing as npt

from models.constants import SURFACES
from models.errors import UserError

# SURFACES (models.constants): valid surface names, in pitch, roll, yaw order.

SURFACE_WORDS: MappingProxyType[str, str] = MappingProxyType(
    {"de": "stabilator", "da": "aileron", "dr": "rudder"}
)
"""Human-readable word for each surface, used by ``describe()`` and names."""


class InputSpecError(UserError):
    """An input specification is invalid (bad surface, negative duration, ...)."""


@runtime_checkable
class InputSignal(Protocol):
    """Protocol implemented by every input specification.

    The active window is ``[start_s, start_s + active_duration_s)``; the
    quiet time after it is ``duration_s - start_s - active_duration_s``.
    """

    @property
    def name(self) -> str:
        """Short identifier, e.g. ``'stabilator_2112'``."""
        ...

    @property
    def surfaces(self) -> tuple[str, ...]:
        """Driven surfaces, a subset of :data:`SURFACES`."""
        ...

    @property
    def start_s(self) -> float:
        """Time of the first motion, seconds from the start of the recording."""
        ...

    @property
    def active_duration_s(self) -> float:
        """Time from the start of the first motion to the end of the last."""
        ...

    @property
    def duration_s(self) -> float:
        """Quiet time before + active duration + quiet time after."""
        ...

    def deflections(self, t: npt.ArrayLike) -> dict[str, np.ndarray]:
        """Deflections in radians (one array per surface, shaped like ``t``)."""
        ...

    def describe(self) -> str:
        """One-line human-readable description."""
        ...


def require_surface(surface: str) -> str:
    """Return ``surface`` if it is a valid surface name, else raise.

    Raises
    ------
    InputSpecError
        If ``surface`` is not one of :data:`SURFACES`.
    """
    if surface not in SURFACES:
        raise InputSpecError(
            f"unknown surface {surface!r}; valid surfaces: {', '.join(SURFACES)} "
            "(de stabilator/elevator, da aileron, dr rudder)"
        )
    return surface


def require_positive(what: str, value: float) -> float:
    """Return ``value`` as float if finite and strictly positive, else raise."""
    v = float(value)
    if not math.isfinite(v) or v <= 0.0:
        raise InputSpecError(f"{what} must be a finite number > 0, got {value!r}")
    return v


def require_nonnegative(what: str, value: float) -> float:
    """Return ``value`` as float if finite and >= 0, else raise."""
    v = float(value)
    if not math.isfinite(v) or v < 0.0:
        raise InputSpecError(f"{what} must be a finite number >= 0, got {value!r}")
    return v


def require_below_nyquist(what: str, f_hz: float, sample_rate_hz: float | None) -> None:
    """Raise if ``f_hz`` is not strictly below the Nyquist frequency ``fs / 2``.

    Does nothing when ``sample_rate_hz`` is ``None`` (no sampling constraint).
    """
    if sample_rate_hz is None:
        return
    fs = require_positive("sample_rate_hz", sample_rate_hz)
    if f_hz >= 0.5 * fs:
        raise InputSpecError(
            f"{what} = {f_hz:g} Hz is not below the Nyquist frequency "
            f"{0.5 * fs:g} Hz of the {fs:g} Hz sample rate"
        )


def as_time(t: npt.ArrayLike) -> np.ndarray:
    """Convert a time grid to a float array, rejecting non-finite values."""
    tt = np.asarray(t, dtype=float)
    if not np.all(np.isfinite(tt)):
        raise InputSpecError("time grid contains NaN or infinite values")
    return tt


def in_window(t: np.ndarray, start: float, end: float) -> np.ndarray:
    """Boolean mask of the half-open window ``start <= t < end``."""
    return (t >= start) & (t < end)


def fmt(x: float) -> str:
    """Compact number formatting for descriptions (``%g``)."""
    return f"{x:g}"
