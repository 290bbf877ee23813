"""A model under test, set against a recording: trim to its initial condition, replay its
measured surfaces, and evaluate the model's aerodynamics along its measured states.

These are the simulation halves of the discrepancy diagnosis (``harness.diagnosis``): the
recording supplies the inputs and states, this module says what the model makes of them.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from models.aircraft import Aircraft, has_propeller, load_fdm
from models.conditions import FlightCondition
from models.flight import FlightError, FlightHistory, fly
from models.hidden import hidden_root, needs_copy
from models.trim import TrimError, TrimPoint, trim
from models.truth import CoefficientProbe, central_differences, differencing_instance
from models.constants import BODY_COEFFICIENTS, SURFACES
from models.configuration import SECONDARY_SURFACE_LAWS

START_WINDOW_S = 0.5  # the recording's start: the span its initial condition and surface levels average


def start_samples(t: np.ndarray, window_s: float = START_WINDOW_S) -> int:
    """How many samples of ``t`` the first ``window_s`` seconds hold (at least one)."""
    return max(1, int(math.ceil(window_s / float(np.median(np.diff(t))))))


@dataclass(frozen=True)
class InitialCondition:
    """Where the recording starts: the model is trimmed here, wings level, or in a steady
    coordinated turn at the recording's bank when that is :data:`TURN_BANK_MIN_DEG` or more."""

    h_ft: float
    V_fps: float
    alpha_rad: float = 0.0  # the recording's own α at the start (a reference, not imposed)
    phi_rad: float = 0.0    # the recording's bank at the start

    def condition(self) -> FlightCondition:
        bank = math.degrees(self.phi_rad)
        return FlightCondition("recording", self.h_ft, self.V_fps, "the recording's initial condition",
                               bank_deg=bank if abs(bank) >= TURN_BANK_MIN_DEG else 0.0)


# A recording that starts banked this much (deg) or more is taken to start in a steady turn,
# where the model is trimmed (models.trim): an engine trimmed wings level gives a banked
# record's propeller too little power (a J-3 Cub at 45°, 99 ft/s, needs n = 1.41), and the
# slipstream over its tail reads as a control-derivative change (its C_n,δr off by 8 %).
TURN_BANK_MIN_DEG = 5.0


def _instance(aircraft: Aircraft, ic: InitialCondition, refs: Mapping[str, float] | None):
    cond = ic.condition()
    kwargs: dict = {}
    if aircraft.hidden and needs_copy(tuple(aircraft.hidden)):
        root, name = hidden_root(aircraft, cond, dict(refs or {}))
        kwargs = {"root": root, "name": name}
    return cond, kwargs


def trim_at(aircraft: Aircraft, ic: InitialCondition, refs: Mapping[str, float] | None = None) -> TrimPoint:
    """Trim ``aircraft`` (with any added physics) at the recording's initial condition."""
    cond, kwargs = _instance(aircraft, ic, refs)
    return trim(load_fdm(aircraft, 1 / 120, **kwargs), aircraft, cond)


def replay(aircraft: Aircraft, ic: InitialCondition, t: np.ndarray, surfaces: Mapping[str, np.ndarray], *,
           refs: Mapping[str, float] | None = None, sim_rate_hz: float = 120.0,
           wind_ned_fps: Mapping[str, np.ndarray] | None = None, root: Path | None = None,
           name: str | None = None, delays_s: Mapping[str, float] | None = None, hold: str = "linear"
           ) -> tuple[FlightHistory, TrimPoint]:
    """Fly ``aircraft`` from trim at ``ic`` with the recording's surface motions.

    ``wind_ned_fps`` flies it through a given wind history (:func:`models.flight.fly`).
    ``root``/``name`` load another XML of the same aircraft (a calibrated copy,
    :mod:`models.calibration_xml`) while ``aircraft`` still says how to trim and fly it.
    ``delays_s`` (surface -> s) feeds the aerodynamics δ(t − τ): the recorded motion shifted
    by τ, so the response is continuous in τ. ``hold='linear'`` interpolates the recorded
    surfaces linearly between samples (a continuously moving surface); ``hold='sample'`` holds
    each sample until the next (a stepped input sampled at its edges, as the project's own
    recordings are), each frame then getting the mean of that held signal over the frame
    (:func:`held_mean`).
    Each surface moves by the recorded change from its first sample (linear interpolation
    between samples onto the simulation frames), about the model's own trim position: a
    model that needs another trim deflection still starts in equilibrium.

    Raises
    ------
    models.trim.TrimError, models.flight.FlightError
        When the model cannot trim there or diverges while replaying.
    """
    cond, kwargs = _instance(aircraft, ic, refs)
    if root is not None:
        kwargs = {"root": root, "name": name}
    fdm = load_fdm(aircraft, 1 / 120, **kwargs)
    tp = trim(fdm, aircraft, cond)
    t = np.asarray(t, dtype=float)
    moves = {s: np.asarray(x, dtype=float) - float(x[0]) for s, x in surfaces.items() if s in SURFACES}
    rel = t - t[0]
    late = dict(delays_s or {})

    if hold not in ("linear", "sample"):
        raise ValueError(f"hold must be 'linear' or 'sample', not {hold!r}")

    def deflections(tf: np.ndarray) -> dict[str, np.ndarray]:
        if hold == "sample":
            w = float(tf[1] - tf[0]) if len(tf) > 1 else 1.0
            return {s: held_mean(tf - late.get(s, 0.0), w, rel, x) for s, x in moves.items()}
        return {s: np.interp(tf - late.get(s, 0.0), rel, x) for s, x in moves.items()}

    dt = float(np.median(np.diff(t)))
    hist = fly(fdm, aircraft, tp, deflections, rel[-1], sample_rate_hz=1.0 / dt, sim_rate_hz=sim_rate_hz,
               wind_ned_fps=wind_ned_fps)
    return hist, tp


def start_level(x: np.ndarray, t: np.ndarray, window_s: float = START_WINDOW_S) -> float:
    """The level ``x`` starts at: the median of its first ``window_s`` seconds (robust to an
    input that begins inside the window)."""
    return float(np.median(np.asarray(x, dtype=float)[:start_samples(t, window_s)]))


def steady_start(x: np.ndarray, t: np.ndarray, window_s: float = START_WINDOW_S,
                 level_of: np.ndarray | None = None) -> np.ndarray:
    """``x`` with its first sample replaced by :func:`start_level` (of ``level_of`` when given,
    e.g. the raw channel of a smoothed ``x``).

    :func:`replay` moves each surface by its recorded change from the first sample: with a
    noisy potentiometer that one sample's noise would become a constant deflection for the
    whole flight. On the outside sweep's 0.05° elevator noise, the F-16's replay of its own
    flight at 420 ft/s then drifted 10 ft/s and 1.4° of pitch attitude (RMS over 30 s); from
    the start level, 0.3 ft/s and 0.08°."""
    out = np.array(x, dtype=float)
    out[0] = start_level(x if level_of is None else level_of, t, window_s)
    return out


def held_mean(a: np.ndarray, w: float, t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Mean over [a, a + w) of the signal that holds each sample x_k from t_k to t_{k+1}
    (x_0 before t_0, the last sample after the end): [F(a + w) − F(a)]/w with F its integral,
    piecewise linear through F(t_k) = Σ_{i<k} x_i (t_{i+1} − t_i). Continuous in a (so in a
    delay that shifts it).

    The flight loop applies the value computed at a frame's time t_f over the step that ends
    at t_f (:func:`models.flight.fly`): with ``a`` = t_f and ``w`` = the frame step, a stepped
    input whose edges fall on samples is replayed exactly as it was flown."""
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    F = np.concatenate([[0.0], np.cumsum(x[:-1] * np.diff(t))])

    def integral(s: np.ndarray) -> np.ndarray:
        inside = np.interp(s, t, F)
        before = x[0] * (s - t[0])
        after = F[-1] + x[-1] * (s - t[-1])
        return np.where(s < t[0], before, np.where(s > t[-1], after, inside))

    return (integral(a + w) - integral(a)) / w


@dataclass(frozen=True)
class AeroAlong:
    """The model's aerodynamic coefficients along a recording's states.

    ``coefficients[C]`` per sample (C in CX, CY, CZ, Cl, Cm, Cn, about the c.g.; the moments
    with the propellers' moments beyond the thrust line, ``propulsion``);
    ``derivatives`` the model's local slopes at the trim point (truth.central_differences
    names, e.g. ``Cm_alpha``, per rad, rates normalised); ``unsteady`` its α̇ derivatives.
    """

    coefficients: dict[str, np.ndarray]
    derivatives: dict[str, float]
    unsteady: dict[str, float]
    trim: TrimPoint
    trim_failed: str = ""  # why the model could not trim there (derivatives then at the recorded start)
    # the part of the moment coefficients that is the propellers' beyond the thrust line
    # (truth.CoefficientProbe.propulsion_moments: gyroscopic and inflow moments), included above
    propulsion: dict[str, np.ndarray] = field(default_factory=dict)


def aero_along(aircraft: Aircraft, ic: InitialCondition, states: Mapping[str, np.ndarray],
               surfaces: Mapping[str, np.ndarray], alphadot: np.ndarray | None = None, *,
               refs: Mapping[str, float] | None = None) -> AeroAlong:
    """Evaluate the model's aerodynamics at every recorded state (one ``run_ic`` per sample).

    ``states`` holds ``V, alpha, beta, p, q, r, phi, theta`` (and optionally ``h``) in the
    canonical units; ``surfaces`` absolute positions ``de, da, dr`` (rad). Any α̇ term of the
    model is gated off for the evaluation and added back as its α̇ derivative times the
    recorded ``alphadot`` (rad/s), since ``run_ic`` cannot know the α̇ of a recorded sample.

    A propeller's engine is settled at each state (JSBSim's ``FGPropulsion::GetSteadyState``,
    the throttle as trimmed) before the forces are read: ``run_ic`` keeps the propeller turning
    at the trim's rpm, and an aerodynamic term that reads the propeller (the DHC6's slipstream
    moment CmT reads its thrust coefficient) then follows a propeller the aircraft never flew.
    The DHC6 trimmed at 230 ft/s and evaluated at 375 ft/s so windmills at 1,431 rpm (thrust
    coefficient 0.005 where its flight, at 1,883 rpm, had 0.052; C_m 0.008 apart), settled at
    1,894 rpm and 0.055; a spiral dive from 230 to 367 ft/s then put a C_m mismatch of 0.025
    into a noise-free flight of the model itself, read as C_m,ΔV (t 12-19).

    With ``aircraft.secondary_surfaces == "fcs"`` the surfaces its FCS moves beside δe, δa, δr
    (:data:`models.configuration.SECONDARY_SURFACE_LAWS`: the F-16's leading-edge flap and
    flaperons) are set at each state by the FCS's laws (a second ``run_ic``), not held at trim.
    """
    cond, kwargs = _instance(aircraft, ic, refs)
    trim_failed = ""
    try:
        fdm, tp, gated = differencing_instance(aircraft, cond, **kwargs)
    except TrimError as exc:  # the coefficients along the states need no equilibrium
        trim_failed = str(exc)
        start = {k: float(np.asarray(states[k])[0]) for k in ("alpha", "beta", "theta", "phi") if k in states}
        start.update({s: float(np.asarray(v)[0]) for s, v in surfaces.items()})
        fdm, tp, gated = differencing_instance(aircraft, cond, at=start, **kwargs)
    probe = CoefficientProbe(fdm, aircraft, tp, gated)
    derivatives = central_differences(probe)
    unsteady = probe.unsteady_derivatives()
    n = len(states["V"])
    h = np.asarray(states.get("h", np.full(n, ic.h_ft)), dtype=float)
    cols = {k: np.asarray(states[k], dtype=float) for k in ("V", "alpha", "beta", "p", "q", "r", "phi", "theta")}
    surf = aircraft.surfaces
    trim_surface = {"de": tp.de_rad, "da": tp.da_rad, "dr": tp.dr_rad}
    sv = {s: np.asarray(surfaces.get(s, np.full(n, trim_surface[s])), dtype=float) for s in SURFACES}
    pm = fdm.get_property_manager()
    setters = {p: pm.get_node(p).set_double_value for p in
               ("ic/h-sl-ft", "ic/vt-fps", "ic/alpha-rad", "ic/beta-rad", "ic/theta-rad", "ic/phi-rad",
                "ic/p-rad_sec", "ic/q-rad_sec", "ic/r-rad_sec", surf["de"], surf["da"], surf["dr"])}
    out = {c: np.empty(n) for c in BODY_COEFFICIENTS}
    propulsion = {c: np.empty(n) for c in ("Cl", "Cm", "Cn")}
    engines = fdm.get_propulsion() if has_propeller(aircraft.model) else None
    law = SECONDARY_SURFACE_LAWS.get(aircraft.name) if aircraft.secondary_surfaces == "fcs" else None
    fdm["ic/lat-gc-deg"] = 0.0
    fdm["ic/long-gc-deg"] = 0.0
    for k in range(n):
        setters["ic/h-sl-ft"](float(h[k]))
        setters["ic/vt-fps"](float(cols["V"][k]))
        setters["ic/alpha-rad"](float(cols["alpha"][k]))
        setters["ic/beta-rad"](float(cols["beta"][k]))
        setters["ic/theta-rad"](float(cols["theta"][k]))
        setters["ic/phi-rad"](float(cols["phi"][k]))
        setters["ic/p-rad_sec"](float(cols["p"][k]))
        setters["ic/q-rad_sec"](float(cols["q"][k]))
        setters["ic/r-rad_sec"](float(cols["r"][k]))
        for s in SURFACES:
            setters[surf[s]](float(sv[s][k]))
        fdm.run_ic()
        if law is not None:  # the FCS's other surfaces at this state, then the forces again
            for prop, v in law(float(cols["alpha"][k]), fdm["velocities/mach"], fdm["velocities/vc-kts"],
                               float(sv["da"][k])).items():
                fdm[prop] = v
            fdm.run_ic()
        if engines is not None:  # the propeller settled at this state (docstring), then the forces again
            engines.get_steady_state()
            fdm.run_ic()
        row = probe.read()
        for c in out:
            out[c][k] = row[c]
        for c, v in probe.propulsion_moments().items():
            propulsion[c][k] = v
    for c, v in propulsion.items():  # the model's moments are its airframe's and its propellers'
        out[c] = out[c] + v
    if unsteady and alphadot is not None:
        adot_hat = np.asarray(alphadot, dtype=float) * tp.cbar_ft / (2.0 * cols["V"])
        for c in ("CX", "CZ", "Cm"):
            out[c] = out[c] + unsteady.get(f"{c}_alphadot", 0.0) * adot_hat
    bad = [c for c, v in out.items() if not np.all(np.isfinite(v))]
    if bad:
        k = int(np.argmax(~np.all(np.isfinite(np.vstack([out[c] for c in bad])), axis=0)))
        raise FlightError(
            f"the model's aerodynamics are not finite along the recording ({', '.join(bad)}) from sample {k + 1} "
            f"(α {math.degrees(cols['alpha'][k]):.1f}°, β {math.degrees(cols['beta'][k]):.1f}°, "
            f"V {cols['V'][k]:.0f} ft/s, h {h[k]:.0f} ft): the recorded states leave the model's tables "
            "(a departure from controlled flight, or another aircraft's envelope)")
    return AeroAlong(coefficients=out, derivatives=derivatives, unsteady=unsteady, trim=tp, trim_failed=trim_failed,
                     propulsion=propulsion)


def initial_condition(t: np.ndarray, V: np.ndarray, alpha: np.ndarray, h: np.ndarray | None,
                      window_s: float = START_WINDOW_S, phi: np.ndarray | None = None) -> InitialCondition:
    """The recording's initial condition: means over its first ``window_s`` seconds."""
    k = start_samples(t, window_s)
    return InitialCondition(h_ft=float(np.mean(h[:k])) if h is not None else 10_000.0,
                            V_fps=float(np.mean(V[:k])), alpha_rad=float(np.mean(alpha[:k])),
                            phi_rad=float(np.mean(phi[:k])) if phi is not None else 0.0)
