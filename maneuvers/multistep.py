"""Multi-step (square-wave) inputs: doublet, 2-1-1, 2-1-1-2, 3-2-1-1.

A multi-step input is a sequence of constant-level pulses.  Pulse ``i`` has
width ``w_i * Δ`` (``Δ`` the unit-pulse width) and level ``s_i * A`` with
``s_i = ±1``.  With edges

.. math::  t_0 = t_s, \\qquad t_{i+1} = t_s + Δ \\sum_{j \\le i} w_j,

the deflection is ``s_i A`` on the half-open interval ``[t_i, t_{i+1})`` and
zero before ``t_0`` and from ``t_n`` on.  Evaluation is exact: each sample is
assigned to the pulse containing it by comparison with the edges, no
interpolation.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
import numpy.typing as npt

from maneuvers.base import (
    SURFACE_WORDS,
    InputSpecError,
    as_time,
    fmt,
    require_nonnegative,
    require_positive,
    require_surface,
)

MULTISTEP_PATTERNS: MappingProxyType[str, tuple[tuple[float, ...], tuple[int, ...]]] = (
    MappingProxyType(
        {
            "doublet": ((1, 1), (1, -1)),
            "2-1-1": ((2, 1, 1), (1, -1, 1)),
            "2-1-1-2": ((2, 1, 1, 2), (1, -1, 1, -1)),
            "3-2-1-1": ((3, 2, 1, 1), (1, -1, 1, -1)),
        }
    )
)
"""Standard patterns: name -> (pulse widths in unit pulses, signs)."""


@dataclass(frozen=True)
class MultiStep:
    """Piecewise-constant multi-step input on one surface.

    Parameters
    ----------
    surface
        ``'de'``, ``'da'`` or ``'dr'``.
    pulse_widths
        Width of each pulse in units of ``unit_pulse_s`` (all > 0).
    signs
        Sign of each pulse, ``+1`` or ``-1`` (same length as the widths).
    unit_pulse_s
        Duration of a unit pulse, seconds.
    amplitude_deg
        Pulse height, degrees (> 0).  Output is in radians.
    start_s
        Quiet time before the first pulse, seconds.
    quiet_after_s
        Quiet time after the last pulse, seconds.
    name
        Identifier; derived from surface and pattern when empty.
    """

    surface: str
    pulse_widths: tuple[float, ...]
    signs: tuple[int, ...]
    unit_pulse_s: float = 1.0
    amplitude_deg: float = 1.0
    start_s: float = 1.0
    quiet_after_s: float = 1.0
    name: str = ""

    def __post_init__(self) -> None:
        require_surface(self.surface)
        widths = tuple(float(w) for w in self.pulse_widths)
        signs = tuple(int(s) for s in self.signs)
        if not widths:
            raise InputSpecError("a multi-step input needs at least one pulse")
        if len(widths) != len(signs):
            raise InputSpecError(
                f"pulse_widths has {len(widths)} entries but signs has {len(signs)}"
            )
        for i, w in enumerate(widths):
            require_positive(f"pulse_widths[{i}]", w)
        if any(s not in (-1, 1) for s in self.signs):
            raise InputSpecError(f"signs must each be +1 or -1, got {self.signs!r}")
        require_positive("unit_pulse_s", self.unit_pulse_s)
        require_positive("amplitude_deg", self.amplitude_deg)
        require_nonnegative("start_s", self.start_s)
        require_nonnegative("quiet_after_s", self.quiet_after_s)
        object.__setattr__(self, "pulse_widths", widths)
        object.__setattr__(self, "signs", signs)
        if not self.name:
            object.__setattr__(
                self, "name", f"{SURFACE_WORDS[self.surface]}_{self._slug()}"
            )

    # -- naming -----------------------------------------------------------
    def pattern_label(self) -> str:
        """Pattern name: ``'doublet'``, ``'2-1-1-2'``, ... (signs noted if unusual)."""
        label = "doublet" if self.pulse_widths == (1.0, 1.0) else "-".join(
            fmt(w) for w in self.pulse_widths
        )
        standard = tuple(1 if i % 2 == 0 else -1 for i in range(len(self.signs)))
        if self.signs != standard:
            label += " (signs " + "".join("+" if s > 0 else "-" for s in self.signs) + ")"
        return label

    def _slug(self) -> str:
        if self.pulse_widths == (1.0, 1.0):
            slug = "doublet"
        elif all(w.is_integer() and w < 10 for w in self.pulse_widths):
            slug = "".join(str(int(w)) for w in self.pulse_widths)
        else:
            slug = "multistep"
        if self.signs[0] < 0:
            slug += "_inverted"
        return slug

    # -- protocol ---------------------------------------------------------
    @property
    def surfaces(self) -> tuple[str, ...]:
        """The single driven surface."""
        return (self.surface,)

    @property
    def active_duration_s(self) -> float:
        """``unit_pulse_s * sum(pulse_widths)``."""
        return self.unit_pulse_s * float(sum(self.pulse_widths))

    @property
    def duration_s(self) -> float:
        """``start_s + active_duration_s + quiet_after_s``."""
        return self.start_s + self.active_duration_s + self.quiet_after_s

    @property
    def edges_s(self) -> np.ndarray:
        """Pulse edges ``t_0 .. t_n`` in seconds from the recording start."""
        cum = np.concatenate(([0.0], np.cumsum(self.pulse_widths)))
        return self.start_s + self.unit_pulse_s * cum

    def deflections(self, t: npt.ArrayLike) -> dict[str, np.ndarray]:
        """Exact piecewise-constant deflection in radians on half-open pulses."""
        tt = as_time(t)
        amp = np.deg2rad(self.amplitude_deg)
        levels = np.concatenate(([0.0], np.asarray(self.signs, float) * amp, [0.0]))
        # side='right': index i satisfies edges[i-1] <= t < edges[i].
        idx = np.searchsorted(self.edges_s, tt, side="right")
        return {self.surface: levels[idx]}

    def describe(self) -> str:
        """E.g. ``'stabilator 2-1-1-2, 1 deg, 1 s unit pulse'``."""
        return (
            f"{SURFACE_WORDS[self.surface]} {self.pattern_label()}, "
            f"{fmt(self.amplitude_deg)} deg, {fmt(self.unit_pulse_s)} s unit pulse"
        )


def multistep(
    pattern: str,
    surface: str = "de",
    amplitude_deg: float = 1.0,
    unit_pulse_s: float = 1.0,
    start_s: float = 1.0,
    quiet_after_s: float = 1.0,
) -> MultiStep:
    """Build a standard multi-step input from its pattern name.

    Parameters
    ----------
    pattern
        One of :data:`MULTISTEP_PATTERNS` (``'doublet'``, ``'2-1-1'``,
        ``'2-1-1-2'``, ``'3-2-1-1'``).
    surface, amplitude_deg, unit_pulse_s, start_s, quiet_after_s
        As in :class:`MultiStep`.
    """
    if pattern not in MULTISTEP_PATTERNS:
        raise InputSpecError(
            f"unknown multi-step pattern {pattern!r}; valid patterns: "
            f"{', '.join(MULTISTEP_PATTERNS)}"
        )
    widths, signs = MULTISTEP_PATTERNS[pattern]
    return MultiStep(
        surface=surface,
        pulse_widths=widths,
        signs=signs,
        unit_pulse_s=unit_pulse_s,
        amplitude_deg=amplitude_deg,
        start_s=start_s,
        quiet_after_s=quiet_after_s,
    )


def doublet(
    surface: str = "de",
    amplitude_deg: float = 1.0,
    unit_pulse_s: float = 1.0,
    start_s: float = 1.0,
    quiet_after_s: float = 1.0,
) -> MultiStep:
    """Doublet: pulses of width 1, 1 with signs +, -."""
    return multistep("doublet", surface, amplitude_deg, unit_pulse_s, start_s, quiet_after_s)


def stabilator_2112(
    amplitude_deg: float = 1.0, unit_pulse_s: float = 1.0, start_s: float = 1.0
) -> MultiStep:
    """The seed's default input: stabilator 2-1-1-2, 1 deg, 1 s unit pulse, at 1 s."""
    return multistep("2-1-1-2", "de", amplitude_deg, unit_pulse_s, start_s)
