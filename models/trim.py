"""Trimming an aircraft at a named flight condition."""
from __future__ import annotations

import contextlib
import math
import os
import sys
from dataclasses import asdict, dataclass, field

import jsbsim
import numpy as np
from scipy.optimize import least_squares

from models.aircraft import (TRIM_MOMENT_PROPERTIES, Aircraft, AircraftError, is_turboprop, is_xml_model, model_xml,
                             place_reference_point)
from models.conditions import FlightCondition
from models.configuration import (SCHEDULED_SURFACES, command_configuration, configuration_record,
                                  cruise_configuration, place_configuration)
from models.constants import G0_FPS2


class TrimError(RuntimeError):
    """The trim algorithm found no equilibrium; the message names the condition and a cause."""


@dataclass(frozen=True)
class TrimPoint:
    """The equilibrium an aircraft was trimmed to, with what is needed to normalise.

    Angles in rad, speeds in ft/s, rates zero. ``Ixz_slugft2`` uses the seed's sign
    convention (Eqs. 3-5; JSBSim's inertia matrix stores its negative). ``configuration``
    is the cruise configuration flown (:mod:`models.configuration`); ``held`` names any
    scheduled surface held on one side of its switch because the schedule leaves no
    equilibrium there (empty otherwise); ``method`` is ``'jsbsim'`` (JSBSim's own trim) or
    ``'surfaces'`` (the project's trim with the FCS disabled, :func:`trim_surfaces`).
    """

    condition: str
    h_ft: float
    V_fps: float
    alpha_rad: float
    beta_rad: float
    theta_rad: float
    phi_rad: float
    qbar_psf: float
    mach: float
    de_rad: float
    da_rad: float
    dr_rad: float
    throttle: float
    thrust_lbf: float
    thrust_offset_ft: float
    mass_slug: float
    Ix_slugft2: float
    Iy_slugft2: float
    Iz_slugft2: float
    Ixz_slugft2: float
    S_ft2: float
    b_ft: float
    cbar_ft: float
    cg_in: tuple[float, float, float]
    aero_rp_in: tuple[float, float, float]
    configuration: dict = field(default_factory=dict)
    held: dict = field(default_factory=dict)
    method: str = "jsbsim"

    def as_dict(self) -> dict:
        return asdict(self)


# Under this altitude (ft above sea level) the terrain is put this far below the aircraft
# (JSBSim's terrain is at sea level): an altitude standing in from the density (a cold day's,
# or an airspeed read low) can be under sea level, where the gear stood on the ground and no
# trim existed (a probe's J-3 Cub at a stand-in -2,780 ft: JSBSim's trim and the project's
# each failed, taking a second apiece, before the untrimmed fall-back).
LOW_ALTITUDE_FT = 500.0
TERRAIN_CLEARANCE_FT = 1000.0


def set_initial_condition(fdm: jsbsim.FGFDMExec, h_ft: float, V_fps: float) -> None:
    """Set position, altitude, then speed: the order matters (the notes: setting latitude
    after speed silently changes the speed). Under :data:`LOW_ALTITUDE_FT` the terrain is
    lowered to :data:`TERRAIN_CLEARANCE_FT` below the aircraft: the project flies in the air."""
    fdm["ic/lat-gc-deg"] = 0.0
    fdm["ic/long-gc-deg"] = 0.0
    fdm["ic/psi-true-deg"] = 0.0
    if h_ft < LOW_ALTITUDE_FT:
        fdm["ic/terrain-elevation-ft"] = h_ft - TERRAIN_CLEARANCE_FT
    fdm["ic/h-sl-ft"] = h_ft
    fdm["ic/vt-fps"] = V_fps
    fdm["ic/gamma-deg"] = 0.0
    fdm["ic/phi-deg"] = 0.0
    fdm["ic/beta-deg"] = 0.0
    fdm["ic/p-rad_sec"] = 0.0
    fdm["ic/q-rad_sec"] = 0.0
    fdm["ic/r-rad_sec"] = 0.0


def read_trim_point(fdm: jsbsim.FGFDMExec, condition: str, surfaces: dict[str, str], *,
                    configuration: dict | None = None, held: dict | None = None,
                    method: str = "jsbsim") -> TrimPoint:
    """Read the current state of a trimmed instance as a :class:`TrimPoint`."""
    thrust = fdm["forces/fbx-prop-lbs"]
    return TrimPoint(
        condition=condition,
        h_ft=fdm["position/h-sl-ft"], V_fps=fdm["velocities/vt-fps"],
        alpha_rad=fdm["aero/alpha-rad"], beta_rad=fdm["aero/beta-rad"],
        theta_rad=fdm["attitude/theta-rad"], phi_rad=fdm["attitude/phi-rad"],
        qbar_psf=fdm["aero/qbar-psf"], mach=fdm["velocities/mach"],
        de_rad=fdm[surfaces["de"]], da_rad=fdm[surfaces["da"]], dr_rad=fdm[surfaces["dr"]],
        throttle=fdm["fcs/throttle-pos-norm"], thrust_lbf=thrust,
        # Thrust line's body-z position: pitching moment of thrust = thrust * offset.
        thrust_offset_ft=fdm["moments/m-prop-lbsft"] / thrust if thrust else 0.0,
        mass_slug=fdm["inertia/mass-slugs"],
        Ix_slugft2=fdm["inertia/ixx-slugs_ft2"], Iy_slugft2=fdm["inertia/iyy-slugs_ft2"],
        Iz_slugft2=fdm["inertia/izz-slugs_ft2"], Ixz_slugft2=-fdm["inertia/ixz-slugs_ft2"],
        S_ft2=fdm["metrics/Sw-sqft"], b_ft=fdm["metrics/bw-ft"], cbar_ft=fdm["metrics/cbarw-ft"],
        cg_in=tuple(fdm[f"inertia/cg-{a}-in"] for a in "xyz"),
        aero_rp_in=tuple(fdm[f"metrics/aero-rp-{a}-in"] for a in "xyz"),
        configuration=dict(configuration or {}), held=dict(held or {}), method=method,
    )


def trim(fdm: jsbsim.FGFDMExec, aircraft: Aircraft, condition: FlightCondition) -> TrimPoint:
    """Trim ``fdm`` (freshly loaded) wings-level at ``condition`` in cruise configuration and
    freeze its mass.

    The aircraft is first put into its cruise configuration (:mod:`models.configuration`:
    retractable gear up and locked, flaps up, speed brake closed). Longitudinal trim
    (``do_trim(0)``: throttle, stabilator, α) with the engine running is all a symmetric
    aircraft needs wings level; if the lateral accelerations are not then zero (an
    asymmetric aircraft or variant) the full six-axis trim (``do_trim(1)``) follows. The
    aircraft's reference-point rule is applied before trimming. Fuel is frozen afterwards so
    mass and c.g. stay put.

    Where JSBSim's trim fails, :func:`trim_surfaces` solves for the equilibrium itself with
    the FCS disabled and any discontinuously scheduled surface (the F-16's leading-edge flap)
    at each of its positions: a position consistent with its schedule is taken; where none
    is (near a switch with no hysteresis, the F-16 between α ≈ 4.99° and 5.02°), the surface
    is held on one side of the switch and :attr:`TrimPoint.held` says so.

    Turboprops (:func:`models.aircraft.is_turboprop`: the DHC6) deliver no shaft power while JSBSim trims,
    so they are re-trimmed with their propeller torque applied as external moments
    (:func:`_trim_with_propeller_torque`) and their engines left running at steady state
    (:func:`settle_engines`): flown from here, the first frame is in equilibrium.

    Raises
    ------
    TrimError
        Naming the aircraft, the condition and why no equilibrium exists there (not enough
        thrust, not enough lift or pitch control within the surfaces' travel).
    """
    config, written = _initialise_in_cruise(fdm, aircraft, condition)
    if place_reference_point(fdm, aircraft):
        fdm.run_ic()
    turboprop = is_turboprop(aircraft.model)
    # The propeller-torque re-trim needs the stand-in moments (the DHC6 copy has them).
    torque = turboprop and fdm.get_property_manager().hasNode(next(iter(TRIM_MOMENT_PROPERTIES.values())))
    held: dict = {}
    method = "jsbsim"
    if condition.bank_deg and not turboprop and _trim_in_turn(fdm, condition.bank_deg):
        fdm["propulsion/fuel_freeze"] = 1
        return read_trim_point(fdm, condition.name, aircraft.surfaces,
                               configuration=configuration_record(fdm, config, written), method="jsbsim-turn")
    try:
        with _quiet_stdout():
            fdm.do_trim(0)
            lateral = max(abs(fdm["accelerations/pdot-rad_sec2"]), abs(fdm["accelerations/rdot-rad_sec2"]),
                          abs(fdm["accelerations/vdot-ft_sec2"]))
            if lateral > 1e-6:
                fdm.do_trim(1)
            if torque:
                _trim_with_propeller_torque(fdm)
    except jsbsim.TrimFailureError as exc:
        if turboprop:
            raise TrimError(_where(aircraft, condition) + f": JSBSim's trim failed ({exc}) and a "
                            "turboprop is trimmed by JSBSim only") from exc
        held = trim_surfaces(fdm, aircraft, condition)
        method = "surfaces"
    fdm["propulsion/fuel_freeze"] = 1
    if turboprop:
        settle_engines(fdm)
    return read_trim_point(fdm, condition.name, aircraft.surfaces,
                           configuration=configuration_record(fdm, config, written), held=held, method=method)


def _first_run_ic(fdm: jsbsim.FGFDMExec, aircraft: Aircraft) -> None:
    """The instance's first ``run_ic``. An aircraft given by path whose own XML JSBSim cannot
    initialise is bad input, refused with JSBSim's reason (AircraftError): the package's
    fokker50 and f104 read properties only FlightGear defines
    (``/controls/engines/engine/throttle``, ``systems/radar/range``). For the project's own
    models such a failure is a bug and keeps its traceback."""
    try:
        fdm.run_ic()
    except jsbsim.BaseError as exc:
        if not is_xml_model(aircraft.model) or isinstance(exc, jsbsim.TrimFailureError):
            raise
        raise AircraftError(f"{aircraft.model}: JSBSim cannot initialise this aircraft as it stands "
                            f"(JSBSim: {str(exc).strip()}): its XML reads something JSBSim alone does not define "
                            "(FlightGear may); sidbench needs a model JSBSim can fly by itself") from exc


def _trim_in_turn(fdm: jsbsim.FGFDMExec, bank_deg: float) -> bool:
    """JSBSim's steady coordinated turn at ``bank_deg`` (``do_trim(5)``); False, the instance
    back at wings level, where it fails (the wings-level trim follows)."""
    fdm["ic/phi-deg"] = bank_deg
    fdm.run_ic()
    try:
        with _quiet_stdout():
            fdm.do_trim(5)
        return True
    except jsbsim.TrimFailureError:
        fdm["ic/phi-deg"] = 0.0
        fdm.run_ic()
        return False


def _initialise_in_cruise(fdm: jsbsim.FGFDMExec, aircraft: Aircraft, condition: FlightCondition):
    """Initial condition, cruise configuration (:mod:`models.configuration`) and running
    engines; returns the configuration and the properties written."""
    set_initial_condition(fdm, condition.h_ft, condition.V_fps)
    config = cruise_configuration(model_xml(aircraft.model))
    written = command_configuration(fdm, config)
    fdm["propulsion/set-running"] = -1
    _first_run_ic(fdm, aircraft)
    # again after run_ic: it re-initialises some piston engines stopped (JSBSim 1.3: the c310's
    # and c182's), and a stopped engine leaves trim no equilibrium to find; for an engine
    # already running the property does nothing
    fdm["propulsion/set-running"] = -1
    written.update(place_configuration(fdm, config))
    return config, written


def _where(aircraft: Aircraft, condition: FlightCondition) -> str:
    return (f"{aircraft.label} cannot trim at {condition.name!r} "
            f"(h = {condition.h_ft:.0f} ft, V = {condition.V_fps:.1f} ft/s true airspeed)")


@contextlib.contextmanager
def _quiet_stdout():
    """Silence what JSBSim's C++ trim prints to the process's standard output (e.g. "Sorry,
    wdot doesn't appear to be trimmable"): the failure is reported by the exception."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):
        yield
        return
    sys.stdout.flush()
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
            yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


# Bounds of the surface trim's unknowns: alpha (rad), stabilator (rad), throttle (0-1).
_ALPHA_BOUNDS = (-0.3, 0.8)
_DE_BOUNDS = (-0.5, 0.5)
_TRIM_TOL = 1e-8  # residual (udot/g, wdot/g, qdot in rad/s^2) accepted as equilibrium


@dataclass(frozen=True)
class _Equilibrium:
    x: np.ndarray  # alpha, de, throttle
    residual: float
    at_bound: tuple[str, ...]


def _engines(fdm: jsbsim.FGFDMExec) -> int:
    return int(fdm.get_propulsion().get_num_engines())


def _level_residual(fdm: jsbsim.FGFDMExec, aircraft: Aircraft, condition: FlightCondition,
                    hold: dict[str, float], x: np.ndarray) -> list[float]:
    """Put the instance at α, stabilator, throttle = ``x`` in wings-level flight (γ = 0,
    β = 0, rates zero, ``hold`` surfaces written) and return u̇/g, ẇ/g and q̇ (rad/s²)."""
    alpha, de, throttle = (float(v) for v in x)
    set_initial_condition(fdm, condition.h_ft, condition.V_fps)
    fdm["ic/alpha-rad"] = alpha
    fdm["ic/theta-rad"] = alpha
    fdm[aircraft.surfaces["de"]] = de
    for i in range(_engines(fdm)):
        fdm[f"fcs/throttle-pos-norm[{i}]"] = throttle
    for prop, v in hold.items():
        fdm[prop] = v
    fdm.run_ic()
    return [fdm["accelerations/udot-ft_sec2"] / G0_FPS2, fdm["accelerations/wdot-ft_sec2"] / G0_FPS2,
            fdm["accelerations/qdot-rad_sec2"]]


def _solve_level(fdm: jsbsim.FGFDMExec, aircraft: Aircraft, condition: FlightCondition,
                 hold: dict[str, float]) -> _Equilibrium:
    """Wings-level, 1-g equilibrium with the FCS disabled: the α, stabilator and throttle
    that zero u̇, ẇ and q̇ (bounded least squares on ``run_ic`` evaluations,
    :func:`_level_residual`). The instance is left at the solution."""
    qS = 0.5 * fdm["atmosphere/rho-slugs_ft3"] * condition.V_fps ** 2 * fdm["metrics/Sw-sqft"]
    # Start from the alpha a lift slope of 4.5 per rad would need (a typical wing's).
    alpha0 = float(np.clip(fdm["inertia/mass-slugs"] * G0_FPS2 / max(qS, 1e-9) / 4.5, 0.0, 0.5))
    lo = [_ALPHA_BOUNDS[0], _DE_BOUNDS[0], 0.0]
    hi = [_ALPHA_BOUNDS[1], _DE_BOUNDS[1], 1.0]
    start = _level_residual(fdm, aircraft, condition, hold, [alpha0, 0.0, 0.5])
    if not np.all(np.isfinite(start)):
        # no equilibrium can be searched from accelerations that are not numbers (scipy would
        # stop with a ValueError, an internal error to the user; seen on an augmented F-16 whose
        # added terms had been sized from a recording flown with its FCS on)
        raise TrimError(_where(aircraft, condition) + f": the model's accelerations are not finite at alpha = "
                        f"{math.degrees(alpha0):.1f} deg, stabilator 0, throttle 0.5 (its aerodynamics, or a term "
                        "added to them, give no number there)")
    sol = least_squares(lambda x: _level_residual(fdm, aircraft, condition, hold, x), [alpha0, 0.0, 0.5],
                        bounds=(lo, hi), xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=200)
    _level_residual(fdm, aircraft, condition, hold, sol.x)
    names = ("alpha", "stabilator", "throttle")
    at_bound = tuple(n for n, v, a, b in zip(names, sol.x, lo, hi) if min(v - a, b - v) < 1e-6)
    return _Equilibrium(sol.x, float(np.max(np.abs(sol.fun))), at_bound)


def _scheduled_positions(fdm: jsbsim.FGFDMExec, surfaces: tuple[str, ...]) -> dict[str, float]:
    """What the FCS schedules the ``surfaces`` to at the instance's current state (one
    ``run_ic`` with the FCS enabled; the caller re-evaluates with it disabled)."""
    fdm["simulation/models/FGFCS/enabled"] = 1
    fdm.run_ic()
    out = {s: float(fdm[s]) for s in surfaces}
    fdm["simulation/models/FGFCS/enabled"] = 0
    return out


def trim_surfaces(fdm: jsbsim.FGFDMExec, aircraft: Aircraft, condition: FlightCondition) -> dict:
    """Trim with the FCS disabled, holding discontinuously scheduled surfaces where needed.

    For each combination of the aircraft's scheduled-surface positions
    (:data:`models.configuration.SCHEDULED_SURFACES`), the equilibrium is solved by
    :func:`_solve_level`; the first whose positions are the ones the schedule gives at that
    equilibrium is taken. If none is consistent (the schedule switches with no hysteresis
    between two equilibria), the first converged one is kept with its surface held, and the
    returned dict says which surface, where it is held, what the schedule would set there
    and why. The instance is left at the equilibrium with the FCS disabled.

    Returns
    -------
    dict
        ``{}`` when nothing had to be held, else ``{surface: {"held", "scheduled", "alpha_rad",
        "reason"}}``.

    Raises
    ------
    TrimError
        When no equilibrium exists, naming the condition and what runs out (the variable at
        its limit: thrust, lift or stabilator travel).
    """
    fdm["simulation/models/FGFCS/enabled"] = 0
    schedule = SCHEDULED_SURFACES.get(aircraft.name, {})
    candidates = _position_combinations(schedule)
    converged: list[tuple[dict[str, float], _Equilibrium, dict[str, float]]] = []
    last = None
    for hold in candidates:
        eq = _solve_level(fdm, aircraft, condition, hold)
        last = eq
        if eq.residual > _TRIM_TOL:
            continue
        scheduled = _scheduled_positions(fdm, tuple(hold)) if hold else {}
        if all(abs(scheduled[s] - v) < 1e-9 for s, v in hold.items()):
            _level_residual(fdm, aircraft, condition, hold, eq.x)
            return {}
        converged.append((hold, eq, scheduled))
    if converged:
        hold, eq, scheduled = converged[0]
        _level_residual(fdm, aircraft, condition, hold, eq.x)
        return {s: {"held": v, "scheduled": scheduled[s], "alpha_rad": float(eq.x[0]),
                    "reason": (f"no equilibrium is consistent with the schedule of {s} here (it switches "
                               f"with no hysteresis): trimmed with it held at {v:g}, where the schedule "
                               f"would set {scheduled[s]:g} at the trimmed alpha = "
                               f"{math.degrees(eq.x[0]):.3f} deg")}
                for s, v in hold.items()}
    raise TrimError(_where(aircraft, condition) + ": " + _why_not(last))


def _position_combinations(schedule: dict[str, tuple[float, ...]]) -> list[dict[str, float]]:
    combos: list[dict[str, float]] = [{}]
    for surface, positions in schedule.items():
        combos = [{**c, surface: p} for c in combos for p in positions]
    return combos


def _why_not(eq: _Equilibrium | None) -> str:
    """Why the level-flight equilibrium does not exist, from the variables at their limits."""
    if eq is None:
        return "no equilibrium found"
    causes = {"throttle": "full throttle does not give the thrust level flight needs here",
              "alpha": "the lift level flight needs is beyond what the aerodynamic tables give "
                       f"within alpha {math.degrees(_ALPHA_BOUNDS[0]):.0f} to {math.degrees(_ALPHA_BOUNDS[1]):.0f} deg",
              "stabilator": "the stabilator's travel cannot balance the pitching moment"}
    named = [causes[n] for n in eq.at_bound]
    detail = "; ".join(named) if named else "the equations of level flight have no solution"
    return (f"no level-flight equilibrium ({detail}; closest: alpha = {math.degrees(eq.x[0]):.2f} deg, "
            f"stabilator = {math.degrees(eq.x[1]):.2f} deg, throttle = {eq.x[2]:.2f}, residual "
            f"{eq.residual:.2g})")


def place_untrimmed(fdm: jsbsim.FGFDMExec, aircraft: Aircraft, condition: FlightCondition,
                    state: dict[str, float]) -> TrimPoint:
    """Put ``fdm`` (freshly loaded) at ``condition``'s altitude and airspeed and at ``state``
    (``alpha``, ``beta``, ``theta``, ``phi`` in rad; surfaces ``de``, ``da``, ``dr``), in
    cruise configuration with the FCS disabled, without looking for an equilibrium: for
    evaluating the aerodynamics where the model cannot trim (the returned point's ``method``
    is ``'untrimmed'``; its accelerations are not zero)."""
    config, written = _initialise_in_cruise(fdm, aircraft, condition)
    place_reference_point(fdm, aircraft)
    fdm["simulation/models/FGFCS/enabled"] = 0
    set_initial_condition(fdm, condition.h_ft, condition.V_fps)
    for key, prop in (("alpha", "ic/alpha-rad"), ("beta", "ic/beta-rad"), ("theta", "ic/theta-rad"),
                      ("phi", "ic/phi-rad")):
        if key in state:
            fdm[prop] = float(state[key])
    for s, prop in aircraft.surfaces.items():
        if s in state:
            fdm[prop] = float(state[s])
    fdm.run_ic()
    fdm["propulsion/fuel_freeze"] = 1
    return read_trim_point(fdm, condition.name, aircraft.surfaces,
                           configuration=configuration_record(fdm, config, written), method="untrimmed")


_PROP_MOMENTS = ("moments/l-prop-lbsft", "moments/m-prop-lbsft", "moments/n-prop-lbsft")


def settle_engines(fdm: jsbsim.FGFDMExec) -> None:
    """Put a trimmed turboprop's engines into their running steady state.

    JSBSim's turboprop (FGTurboProp) has a 'trim' phase whenever the time step is zero
    (trim, ``run_ic``) in which it delivers no shaft power, and on the first frame after it
    resets N1 to idle: flown straight after a trim, the DHC6's thrust would drop by half in
    0.8 s and take ~8 s to recover. ``FGPropulsion::GetSteadyState`` marches the engines
    (alone, 0.5 s steps) to steady state and leaves them running, so the first frame flies
    the trimmed thrust with its shaft power and torque. Call it again after any later
    ``run_ic`` of a turboprop that is to be flown.
    """
    fdm.get_propulsion().get_steady_state()


def _trim_with_propeller_torque(fdm: jsbsim.FGFDMExec, iterations: int = 8, tol_lbsft: float = 1e-3) -> None:
    """Re-trim a turboprop with its propeller torque stood in for by external moments.

    During JSBSim's trim the turboprop delivers no shaft power, hence no propeller torque
    (for the DHC6 at 6,000 ft about -2,700 lbf*ft of roll, both propellers turning the same
    way), yet it flies with it: the moments of the running engines minus those of the trim
    are applied as body-axis external moments (``TRIM_MOMENT_PROPERTIES``) and the trim
    repeated until they stop changing (the throttle, hence the power, moves a little). The
    moments are zeroed afterwards; the caller then runs :func:`settle_engines`, after which
    the real torque replaces them.
    """
    extra = [0.0, 0.0, 0.0]
    for _ in range(iterations):
        trimmed = [fdm[p] for p in _PROP_MOMENTS]
        settle_engines(fdm)
        running = [fdm[p] for p in _PROP_MOMENTS]
        new = [r - t for r, t in zip(running, trimmed)]
        change = max(abs(a - b) for a, b in zip(new, extra))
        extra = new
        if change < tol_lbsft:
            break
        for prop, v in zip(TRIM_MOMENT_PROPERTIES.values(), extra):
            fdm[prop] = v
        fdm.do_trim(1)
    else:
        raise jsbsim.TrimFailureError(f"the propeller torque did not settle in {iterations} re-trims")
    for prop in TRIM_MOMENT_PROPERTIES.values():
        fdm[prop] = 0.0
