"""Combinations of inputs: one after another (:class:`Sequence`) or at once
on different surfaces (:class:`Simultaneous`).  Both implement
:class:`maneuvers.base.InputSignal` and nest freely.

Timing conventions
------------------
*Sequence*: each part keeps its own whole timeline (its quiet time before,
its active window and its quiet time after); part ``i + 1``'s timeline starts
``gap_s`` seconds after part ``i``'s ends.  Part ``i`` therefore has time
origin

.. math::  o_0 = 0, \\qquad o_{i+1} = o_i + D_i + g,

with ``D_i`` its ``duration_s`` and ``g = gap_s``, and the quiet time between
two motions is ``quiet_after_i + g + start_{i+1}``.

*Simultaneous*: all parts share time origin 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from maneuvers.base import InputSignal, InputSpecError, as_time, require_nonnegative


def _check_parts(parts: object) -> tuple[InputSignal, ...]:
    """Return ``parts`` as a non-empty tuple of :class:`InputSignal`, else raise."""
    if isinstance(parts, InputSignal):
        raise InputSpecError("parts must be a tuple of inputs, got a single input")
    tup = tuple(parts)  # type: ignore[call-overload]
    if not tup:
        raise InputSpecError("a combination needs at least one part")
    for i, p in enumerate(tup):
        if not isinstance(p, InputSignal):
            raise TypeError(f"part {i} ({type(p).__name__}) does not implement InputSignal")
    return tup


def _unique(items: list[str]) -> tuple[str, ...]:
    """Items in order of first appearance, without repeats."""
    return tuple(dict.fromkeys(items))


@dataclass(frozen=True)
class Sequence:
    """Parts played one after another (see module notes for timing).

    Parameters
    ----------
    parts
        Inputs in playing order.  The same surface may appear in several.
    gap_s
        Extra quiet time between one part's timeline and the next, seconds.
    name
        Identifier; ``'<part>_then_<part>...'`` when empty.
    """

    parts: tuple[InputSignal, ...]
    gap_s: float = 0.0
    name: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "parts", _check_parts(self.parts))
        require_nonnegative("gap_s", self.gap_s)
        if not self.name:
            object.__setattr__(self, "name", "_then_".join(p.name for p in self.parts))

    @property
    def offsets_s(self) -> tuple[float, ...]:
        """Time origin ``o_i`` of each part within the sequence, seconds."""
        out, o = [], 0.0
        for p in self.parts:
            out.append(o)
            o += p.duration_s + self.gap_s
        return tuple(out)

    @property
    def active_windows_s(self) -> tuple[tuple[float, float], ...]:
        """``(start, end)`` of each part's active window, seconds."""
        return tuple(
            (o + p.start_s, o + p.start_s + p.active_duration_s)
            for o, p in zip(self.offsets_s, self.parts)
        )

    @property
    def surfaces(self) -> tuple[str, ...]:
        """Surfaces driven by any part, in order of first appearance."""
        return _unique([s for p in self.parts for s in p.surfaces])

    @property
    def start_s(self) -> float:
        """Start of the first part's motion."""
        return self.active_windows_s[0][0]

    @property
    def active_duration_s(self) -> float:
        """From the first part's first motion to the last part's last motion."""
        return self.active_windows_s[-1][1] - self.start_s

    @property
    def duration_s(self) -> float:
        """``o_last + D_last``."""
        return self.offsets_s[-1] + self.parts[-1].duration_s

    def deflections(self, t: npt.ArrayLike) -> dict[str, np.ndarray]:
        """Sum over parts of ``part.deflections(t - o_i)``, radians.

        Parts do not overlap in time, so at most one part is non-zero at
        any instant.
        """
        tt = as_time(t)
        out = {s: np.zeros_like(tt) for s in self.surfaces}
        for o, p in zip(self.offsets_s, self.parts):
            for s, v in p.deflections(tt - o).items():
                out[s] += v
        return out

    def describe(self) -> str:
        """Part descriptions joined by ``'; then '``."""
        gap = f" (gap {self.gap_s:g} s)" if self.gap_s > 0 else ""
        return "; then ".join(p.describe() for p in self.parts) + gap


@dataclass(frozen=True)
class Simultaneous:
    """Parts played at the same time on different surfaces.

    Parameters
    ----------
    parts
        Inputs sharing time origin 0.  No surface may be driven by two parts.
    name
        Identifier; ``'<part>_with_<part>...'`` when empty.

    Raises
    ------
    InputSpecError
        If two parts drive the same surface.
    """

    parts: tuple[InputSignal, ...]
    name: str = ""

    def __post_init__(self) -> None:
        parts = _check_parts(self.parts)
        owner: dict[str, int] = {}
        for i, p in enumerate(parts):
            for s in p.surfaces:
                if s in owner:
                    j = owner[s]
                    raise InputSpecError(
                        f"surface {s!r} is driven by both part {j} ({parts[j].name}) and "
                        f"part {i} ({p.name}); simultaneous parts must use different "
                        "surfaces (use Sequence to play them one after another)"
                    )
                owner[s] = i
        object.__setattr__(self, "parts", parts)
        if not self.name:
            object.__setattr__(self, "name", "_with_".join(p.name for p in parts))

    @property
    def surfaces(self) -> tuple[str, ...]:
        """All parts' surfaces, in part order."""
        return tuple(s for p in self.parts for s in p.surfaces)

    @property
    def start_s(self) -> float:
        """Earliest part start."""
        return min(p.start_s for p in self.parts)

    @property
    def active_duration_s(self) -> float:
        """From the earliest motion to the latest end of motion."""
        return max(p.start_s + p.active_duration_s for p in self.parts) - self.start_s

    @property
    def duration_s(self) -> float:
        """Longest part duration."""
        return max(p.duration_s for p in self.parts)

    def deflections(self, t: npt.ArrayLike) -> dict[str, np.ndarray]:
        """Union of the parts' deflections, radians."""
        tt = as_time(t)
        out: dict[str, np.ndarray] = {}
        for p in self.parts:
            out.update(p.deflections(tt))
        return out

    def describe(self) -> str:
        """Part descriptions joined by ``'; with '``."""
        return "; with ".join(p.describe() for p in self.parts)
