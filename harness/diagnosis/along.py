"""The model evaluated along a recording's states (seed Eqs. 1-5 on both sides): which states
it follows (the inertial sideslip, undriven states held), the measured coefficients beside
its own, the maneuver's interior, a recording corrected for sensor values, and the model's
local slopes along the states."""
from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from estimators.smoothing import sine_series_filter
from harness.diagnosis import rivals
from harness.diagnosis import candidates as cand
from harness.diagnosis.kinematics import (INERTIAL_CHANNELS, KinematicResult, corrected_channels, inertial_angles,
                                          kinematic_alpha_rate)
from harness.diagnosis.prepare import (COEFFICIENTS, DRIVEN_BY, Prepared, clean_channels, interior_slice,
                                       measured_coefficients, recarried_accelerations, stand_in_altitude)
from models.aircraft import Aircraft
from models.constants import SURFACES
from models.replay import AeroAlong, InitialCondition, aero_along, initial_condition


def corrected_recording(p: Prepared, kin: KinematicResult, values: dict[str, float]) -> Prepared:
    """The recording with its channels corrected for the sensor ``values`` (re-smoothed and
    re-differentiated); ``p`` itself when there are none. Without an ``h`` channel the
    altitude stood in from q̄ and V (:func:`prepare.stand_in_altitude`) is taken again from
    the corrected ones: a probe's J-3 Cub (3,350 ft / 97 ft/s, lateral multisine, no h) with V
    8.0 ft/s low stood in −2,780 ft for it, and the model flown there, its propeller's power
    with it, had four lateral derivatives named (probe seed 4453). Where the accelerometer is
    off the c.g., a corrected rate carries it there again (:func:`prepare.recarried_accelerations`):
    a probe's c172x (lateral 3-2-1-1s, accelerometer 2.5 ft below the c.g.) with p 68 ms late
    had the skew named and a C_Y,δa change of +0.070 beside it, the late ṗ·z left in a_y
    (probe seed 4544)."""
    if not values:
        return p
    ch = corrected_channels(p.raw, p, kin.parameters, values)
    ch.update(recarried_accelerations(p, ch))
    smooth = {c: p.filt(x) for c, x in ch.items()}
    deriv = {c: p.differentiate(x) for c, x in ch.items()}
    k = max(1, int(round(0.5 / p.dt)))
    start = {c: float(np.mean(x[:k])) for c, x in smooth.items()}
    altitude = p.altitude
    if "h" not in ch and any(ch[c] is not p.raw.get(c) for c in ("V", "qbar") if c in ch):
        altitude = stand_in_altitude(ch, p.own_noise)
    return replace(p, raw=ch, smooth=smooth, deriv=deriv, start=start, altitude=altitude)


def rate_derivatives_advanced(p: Prepared, tau: float) -> Prepared:
    """The recording with the derivatives of its rates (ṗ, q̇, ṙ, from which the measured
    moment coefficients are built) advanced by ``tau`` seconds: what they would be had they
    not lagged the moments by ``tau``. A simulation that integrates the rates by rectangular
    Euler (JSBSim's default), x[k+1] = x[k] + h·ẋ[k], records rates whose central difference
    at k is the mean of ẋ[k−1] and ẋ[k]: it lags the moments of step k by h/2."""
    deriv = dict(p.deriv)
    for g in ("p", "q", "r"):
        if g in deriv:
            deriv[g] = np.interp(p.t + tau, p.t, deriv[g])
    return replace(p, deriv=deriv)


def model_states(p: Prepared, inertial_from: Prepared | None = None, vane_beta: bool = False,
                 vanes: bool = False) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """The states and surfaces the model is evaluated along: the recorded ones, unfiltered;
    the model's coefficients then go through the common filter (:func:`model_along`).

    The measured coefficients are Eqs. 1-5 on the filtered channels: the filter applied to
    what the aerodynamics did along the true states. The model must see the same operator in
    the same place. Evaluated along filtered states, a nonlinear model is not the filter of
    itself: filt(α²) − filt(α)² is the power the filter removed from α, and a drag polar's
    α² turned it into a C_X mismatch that an α² column fits (a noise-free c172x 3-2-1-1 at
    173 ft/s, C_X α² −0.16 at the recording's own 14.6 Hz cut-off, −0.6 at the 1.8 Hz that
    white gyro noise set; probe 71's 90 s c172x multisine at 1.1 Hz, −2.4 at t −6.9, had its
    sum frequencies limited away by a band of ones until 7 Dec 2026). Along the raw states and
    filtered after, both sides are the same filter of the same functions; a linear model's
    mismatch is what it was (the filter of a linear function of the raw states is that
    function of the filtered states), and noise reaches a nonlinear term only as its square
    (a constant, in the bias) and a product with the state, which the filter takes as it takes
    the noise of the linear terms.

    A state the maneuver did not drive is held at its start: evaluated along its noise, the
    model would pass that noise on through its derivative (errors in variables), and the
    mismatch would then show the derivative itself as "wrong" (unless it drifted far from its
    start all the same, :attr:`Prepared.moved`: then holding it would be the larger error).
    Surfaces are measured with
    little noise: always as recorded (holding one that moves, say by a feedback loop, would
    be far worse than its noise). Airspeed and altitude are slow: their own optimal
    smoothing (a far lower cut-off than the common filter's) keeps their noise out of the
    model's coefficients (through q̂ = qc̄/2V, dynamic pressure and Mach-scheduled terms).

    A driven sideslip is the inertial one (:func:`kinematics.inertial_angles`: the v̇ equation
    integrated from a_y, the rates and attitude, placed on the vane by a constant and trend;
    the model's coefficients along it pass through the common filter as the measured ones do:
    at a low common cut-off, 0.3-0.7 Hz on a slow F-16 at α 11°, an unfiltered angle's Dutch
    roll against the filtered C_l turned a C_l,β change of −0.03 into +0.03):
    a vane's slow wander survives any smoother and reaches the mismatch through C_n,β, C_l,β
    and C_Y,β, where it buried the outside sweep's lateral coefficient errors (C_l,β −0.02,
    C_n,β +0.03, C_n,r̂ −0.3, C_l,p̂ −0.1 at |t| 1.6–4.7; 5.9–22 along the inertial β). A β-vane
    scale then leaves the mismatch alone; the kinematic check names it. With ``vane_beta``
    the sideslip is the vane's; with ``vanes`` α and β are both the vanes' own records,
    driven or not (the vane-bias tests on the coefficient means)."""
    states = {k: p.raw[k] for k in ("V", "alpha", "beta", "p", "q", "r", "phi", "theta") if k in p.smooth}
    for k in ("alpha", "beta", "p", "q", "r"):
        if k in states and k not in p.driven and k not in p.moved and not (vanes and k in ("alpha", "beta")):
            states[k] = np.full(p.n, p.start[k])
    inertial = [] if (vane_beta or vanes) else (["beta"] if inertial_beta(p) else []) + undriven_inertial(p)
    if inertial:
        src = inertial_from or p
        angles = inertial_angles(clean_channels(src, INERTIAL_CHANNELS), src)
        for k in inertial:
            states[k] = angles[k]
    surfaces = {s: p.raw[s] for s in SURFACES if s in p.smooth}
    if "V" in p.own_noise:
        states["V"] = p.raw["V"] - p.own_noise["V"]
    if p.altitude is not None:
        states["h"] = p.altitude
    return states, surfaces


class ModelAlong(NamedTuple):
    """The model evaluated along a recording's states (seed Eqs. 1-5 on both sides)."""

    states: dict[str, np.ndarray]
    surfaces: dict[str, np.ndarray]
    alphadot: np.ndarray | None
    aero: AeroAlong
    measured: dict[str, np.ndarray]
    weights: np.ndarray  # the common filter the model's coefficients went through (sine-series weights)

    def mismatch(self) -> dict[str, np.ndarray]:
        """Measured less model coefficients (both through the common filter)."""
        return {c: self.measured[c] - self.aero.coefficients[c] for c in COEFFICIENTS}


def model_along(p: Prepared, aircraft: Aircraft, ic: InitialCondition,
                inertial_from: Prepared | None = None, vane_beta: bool = False, vanes: bool = False) -> ModelAlong:
    """The measured coefficients and the model's along the states of :func:`model_states`
    (its inertial sideslip integrated from ``inertial_from``, default ``p``; the vane's
    sideslip with ``vane_beta``; both vanes' own records with ``vanes``), its α̇ terms on
    :func:`model_alpha_rate` where α is driven or moved. (Where α follows the maneuver only
    inertially, :func:`undriven_inertial`, the model's own α̇ terms stay in the mismatch, and
    no α̇ term is offered there, :func:`candidates.offered`. Evaluated there on the raw
    channels' kinematic α̇ they passed a probe F-4N's 10.5 Hz mode ringing in q and a_z into
    C_m's model, and C_m,δe was named beside the mode.)"""
    states, surfaces = model_states(p, inertial_from, vane_beta, vanes)
    alphadot = model_alpha_rate(p) if "alpha" in p.driven or "alpha" in p.moved else None
    aero = filtered(aero_along(aircraft, ic, states, surfaces, alphadot), p.weights)
    measured = measured_coefficients(p.smooth, p.deriv, p.meta, p.mass, thrust_stand_in(p, aero.trim.thrust_lbf))
    return ModelAlong(states, surfaces, alphadot, aero, measured, p.weights)


def filtered(aero: AeroAlong, weights: np.ndarray) -> AeroAlong:
    """The model's coefficients through the common filter, as the measured ones are."""
    return replace(aero, coefficients={c: sine_series_filter(x, weights) for c, x in aero.coefficients.items()})


def model_alpha_rate(p: Prepared) -> np.ndarray:
    """α̇ for the model's α̇ terms: the kinematic one from the recorded channels
    (:func:`kinematics.kinematic_alpha_rate`; the common filter comes after the model), else
    the α record's derivative through the common filter."""
    if all(c in p.raw for c in cand.ALPHA_RATE_CHANNELS):
        return kinematic_alpha_rate(p.raw)
    return p.deriv["alpha"]


def undriven_inertial(p: Prepared) -> list[str]:
    """The vane angles the maneuver's own input moved but not clear of the vane's noise
    (their group's surface moved, :data:`prepare.DRIVEN_BY`, and they are neither driven nor
    moved): the model is evaluated along their inertial reconstruction rather than held at
    their start. Held, their true motion stays in the mismatch and reads as whatever column
    follows it: an F-16 lateral multisine at 40 Hz with twice the noise moved β 0.27° (the
    vane's noise 0.2° white and 0.2° of wander), and the C_Y the held β left out, C_Y,β·β,
    was read as an accelerometer 11 ft aft (t −10, two of four seeds). Inertially the angle
    carries integrated accelerometer noise, not the vane's; no term is built on it."""
    if not all(c in p.raw for c in INERTIAL_CHANNELS):
        return []
    return [k for k in ("alpha", "beta") if k not in p.driven and k not in p.moved
            and any(s in p.driven for s in DRIVEN_BY[k])]


def inertial_beta(p: Prepared) -> bool:
    """Whether the model is evaluated along the inertial sideslip (:func:`model_states`)."""
    return "beta" in p.driven and all(c in p.raw for c in INERTIAL_CHANNELS)


def interior(p: Prepared) -> slice:
    """The maneuver's interior: the first and last second are where the smoother is least
    accurate (:func:`prepare.interior_slice`)."""
    return interior_slice(p.n, p.dt)


def slope_function(aircraft: Aircraft, ic: InitialCondition, states: dict[str, np.ndarray],
                   surfaces: dict[str, np.ndarray], alphadot: np.ndarray | None, aero: AeroAlong,
                   weights: np.ndarray):
    """``slope_of(x)``: the model's ∂C/∂x along the states (:mod:`rivals`), through the common
    filter ``weights`` as ``aero``'s coefficients are (:func:`model_along`), evaluated on first
    use and kept."""
    slopes: dict[str, dict[str, np.ndarray]] = {}

    def slope_of(x: str) -> dict[str, np.ndarray]:
        if x not in slopes:
            shifted = dict(states)
            shifted[x] = np.asarray(states[x], dtype=float) + rivals.SLOPE_STEP_RAD
            moved = filtered(aero_along(aircraft, ic, shifted, surfaces, alphadot), weights)
            slopes[x] = {c: (moved.coefficients[c] - aero.coefficients[c]) / rivals.SLOPE_STEP_RAD
                         for c in COEFFICIENTS}
        return slopes[x]
    return slope_of


def thrust_stand_in(p: Prepared, model_trim_thrust_lbf: float) -> float:
    """Thrust for Eqs. 1 and 4 when the recording has no thrust channel: constant at trim
    (recording-format.md), the metadata's trim thrust when given, else the model's."""
    given = (p.meta.get("trim") or {}).get("thrust_lbf")
    return float(given) if given is not None else float(model_trim_thrust_lbf)


def corrected_start(p: Prepared, values: dict[str, float], ic: InitialCondition) -> InitialCondition:
    """The initial condition of the corrected recording ``p`` when a correction in ``values``
    changed its airspeed or angle of attack, else ``ic``. The model is trimmed there (its
    thrust, and with it a propeller's slipstream over the tail), so it must start where the
    aircraft was, not where its instruments said it was: a probe's J-3 Cub (103 ft/s, pitch
    doublet, noise-free) with V 8.8 ft/s high, trimmed at the recorded airspeed with the bias
    named and taken out of the channels, had C_m,δe named 2.3 % weaker than the model (t 23),
    the slipstream of the faster trim's thrust (probe seed 3998)."""
    if not any(n.split("_", 1)[-1] in ("V", "alpha") for n in values):
        return ic
    return initial_condition(p.t, p.smooth["V"], p.smooth["alpha"], p.altitude, phi=p.smooth.get("phi"))
