"""Each surface's trim level as a nuisance parameter of the replay.

The replay (:func:`models.replay.replay`) trims the model at the recording's start and moves
each surface by its recorded change from its start level. That level is known only as well as
the potentiometer's noise allows: the median of the first half second of a 0.05° white-noise
stabilator is off by about 0.015°, and a level 0.01° off holds a constant pitching moment for the
whole flight. The F-16 at 427 ft/s then drifts through its phugoid by 1.7 ft/s RMS in speed over
30 s, more than a 0.02 flight-condition drift changes it (measured on the outside sweep's F
condition).

So, as output-error practice estimates instrument biases, the levels are estimated: one replay
per surface gives the outputs' sensitivity to its level, a weighted least-squares step the levels
that best fit the recorded outputs, bounded by what the start window's noise and motion allow
(:func:`level_bound`), and the outputs at those levels follow to first order (the offsets are a
few hundredths of a degree). Each model (the one given, the augmented one) gets its own levels
and its own sensitivities, so a before/after comparison stays fair (reusing the given model's
sensitivities for the augmented one saves three replays but is wrong where the finding changes
the slow dynamics a level excites: a C_m,ΔV term's validation fit went from −41 % to −8 %); the
levels are reported with the fit.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import NamedTuple

import numpy as np

from models.flight import FlightError
from models.replay import START_WINDOW_S, start_samples
from models.trim import TrimError

LEVEL_STEP_RAD = math.radians(0.02)  # the finite-difference step of a level's sensitivity
# A level moves at most this many standard errors of the start level (median of the start
# window: √(π/2) σ/√k ≈ 1.25 σ/√k for white noise, the median's large-sample efficiency),
# plus half the surface's own motion in that window.
LEVEL_BOUND_SIGMAS = 4.0


def level_bound(smooth: np.ndarray, noise_std: float, t: np.ndarray, window_s: float = START_WINDOW_S) -> float:
    """How far (rad) a surface's start level may be wrong: :data:`LEVEL_BOUND_SIGMAS` standard
    errors of the median of the first ``window_s`` seconds (1.25 σ/√k, σ the channel's white
    noise, k samples) plus half the smoothed surface's range there (a surface already moving at
    the start). Zero for a noise-free, quiet start: nothing to estimate."""
    k = start_samples(t, window_s)
    spread = 0.5 * float(np.ptp(np.asarray(smooth, dtype=float)[:k]))
    return LEVEL_BOUND_SIGMAS * 1.25 * float(noise_std) / math.sqrt(k) + spread


def _shifted(surfaces: Mapping[str, np.ndarray], offsets: Mapping[str, float]) -> dict[str, np.ndarray]:
    """The surfaces with each start level lowered by its offset: the replay, which moves a
    surface by its change from the first sample, then flies it ``offset`` higher throughout."""
    out = {}
    for s, x in surfaces.items():
        y = np.array(x, dtype=float)
        y[0] -= offsets.get(s, 0.0)
        out[s] = y
    return out


def _stack(sim: Mapping[str, np.ndarray], channels: tuple[str, ...], inner: slice) -> np.ndarray:
    return np.concatenate([np.asarray(sim[c], dtype=float)[inner] for c in channels])


class LevelFit(NamedTuple):
    """A replay with its surface levels fitted: the outputs by quantity and the offsets (rad)
    added to each fitted surface."""

    outputs: dict[str, np.ndarray]
    offsets: dict[str, float]


def level_sensitivities(fly: Callable[[dict[str, np.ndarray]], Mapping[str, np.ndarray]],
                        surfaces: Mapping[str, np.ndarray], y0: Mapping[str, np.ndarray],
                        fitted: list[str]) -> dict[str, dict[str, np.ndarray]]:
    """Per surface of ``fitted``, d(output)/d(level) by forward difference over
    :data:`LEVEL_STEP_RAD` (one replay each), for every output ``y0`` has."""
    out = {}
    for s in fitted:
        ys = fly(_shifted(surfaces, {s: LEVEL_STEP_RAD}))
        out[s] = {c: (np.asarray(ys[c], dtype=float) - np.asarray(y0[c], dtype=float)) / LEVEL_STEP_RAD
                  for c in y0 if c in ys}
    return out


def fit_levels(fly: Callable[[dict[str, np.ndarray]], Mapping[str, np.ndarray]],
               surfaces: Mapping[str, np.ndarray], bounds: Mapping[str, float],
               measured: Mapping[str, np.ndarray], floors: Mapping[str, float], inner: slice) -> LevelFit:
    """The replay with each surface's level fitted: one weighted least-squares step on the
    outputs' sensitivities, the outputs then predicted to first order (the offsets are a few
    hundredths of a degree), kept only when it lowers the weighted cost.

    Parameters
    ----------
    fly : surfaces -> simulated outputs by quantity; raises whatever the replay raises (the
        replay at the recorded levels is not caught; a sensitivity replay that fails leaves
        the levels as recorded).
    surfaces : the recorded surfaces as the replay is given them.
    bounds : per surface, the largest |offset| (rad) (:func:`level_bound`); surfaces with 0
        are not fitted.
    measured : the smoothed recorded outputs by quantity (those in ``floors`` are matched).
    floors : per output, the smallest RMS its weight assumes (its noise level): each output is
        weighted by 1/max(RMS error at the recorded levels, floor).
    inner : the samples compared (the ends of a smoothed record left out).
    """
    y0 = {c: np.asarray(v, dtype=float) for c, v in fly(dict(surfaces)).items()}
    channels = tuple(c for c in floors if c in measured and c in y0 and np.all(np.isfinite(y0[c][inner])))
    fitted = [s for s in surfaces if bounds.get(s, 0.0) > 0.0]
    if not channels or not fitted:
        return LevelFit(y0, {})
    try:
        sens = level_sensitivities(fly, surfaces, y0, fitted)
    except (FlightError, TrimError):  # a level the step makes diverge: the recorded levels stand
        return LevelFit(y0, {})
    z = _stack(measured, channels, inner)
    r0 = z - _stack(y0, channels, inner)
    w = np.concatenate([np.full(len(part), 1.0 / max(float(np.sqrt(np.mean(part ** 2))), floors[c], 1e-12))
                        for c, part in zip(channels, np.split(r0, len(channels)))])
    cols = np.column_stack([_stack(sens[s], channels, inner) for s in fitted])
    if not np.all(np.isfinite(cols)):
        return LevelFit(y0, {})
    step, *_ = np.linalg.lstsq(cols * w[:, None], r0 * w, rcond=None)
    off = np.clip(step, [-bounds[s] for s in fitted], [bounds[s] for s in fitted])
    if np.sum(((r0 - cols @ off) * w) ** 2) >= np.sum((r0 * w) ** 2):
        return LevelFit(y0, {})
    outputs = {c: y + sum(o * sens[s][c] for s, o in zip(fitted, off) if c in sens[s]) for c, y in y0.items()}
    return LevelFit(outputs, {s: float(o) for s, o in zip(fitted, off)})
