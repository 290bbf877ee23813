"""Trimming an aircraft at a named flight condition."""
from __future__ import annotations

from dataclasses import asdict, dataclass

import jsbsim

from models.aircraft import TRIM_MOMENT_PROPERTIES, Aircraft, is_turboprop, place_reference_point
from models.conditions import FlightCondition

G0_FPS2 = 32.17404855643  # standard gravity, ft/s^2 (9.80665 m/s^2)


class TrimError(RuntimeError):
    """The trim algorithm found no equilibrium; the message names the condition and a cause."""


@dataclass(frozen=True)
class TrimPoint:
    """The equilibrium an aircraft was trimmed to, with what is needed to normalise.

    Angles in rad, speeds in ft/s, rates zero. ``Ixz_slugft2`` uses the seed's sign
    convention (Eqs. 3-5; JSBSim's inertia matrix stores its negative).
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

    def as_dict(self) -> dict:
        return asdict(self)


def set_initial_condition(fdm: jsbsim.FGFDMExec, h_ft: float, V_fps: float) -> None:
    """Set position, altitude, then speed: the order matters (the notes: setting latitude
    after speed silently changes the speed)."""
    fdm["ic/lat-gc-deg"] = 0.0
    fdm["ic/long-gc-deg"] = 0.0
    fdm["ic/psi-true-deg"] = 0.0
    fdm["ic/h-sl-ft"] = h_ft
    fdm["ic/vt-fps"] = V_fps
    fdm["ic/gamma-deg"] = 0.0
    fdm["ic/phi-deg"] = 0.0
    fdm["ic/beta-deg"] = 0.0
    fdm["ic/p-rad_sec"] = 0.0
    fdm["ic/q-rad_sec"] = 0.0
    fdm["ic/r-rad_sec"] = 0.0


def read_trim_point(fdm: jsbsim.FGFDMExec, condition: str, surfaces: dict[str, str]) -> TrimPoint:
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
    )


def trim(fdm: jsbsim.FGFDMExec, aircraft: Aircraft, condition: FlightCondition) -> TrimPoint:
    """Trim ``fdm`` (freshly loaded) wings-level at ``condition`` and freeze its mass.

    Longitudinal trim (``do_trim(0)``: throttle, stabilator, α) with the engine running,
    which is all a symmetric aircraft needs wings level; if the lateral accelerations are not
    then zero (an asymmetric aircraft or variant) the full six-axis trim (``do_trim(1)``)
    follows. The aircraft's reference-point rule is applied before trimming. Fuel is frozen
    afterwards so mass and c.g. stay put.

    Turboprops (:func:`models.aircraft.is_turboprop`: the DHC6) deliver no shaft power while JSBSim trims,
    so they are re-trimmed with their propeller torque applied as external moments
    (:func:`_trim_with_propeller_torque`) and their engines left running at steady state
    (:func:`settle_engines`): flown from here, the first frame is in equilibrium.

    Raises
    ------
    TrimError
        Naming the aircraft, the condition and, for the F-16 near alpha = 5 deg, the
        leading-edge-flap switch that makes trim impossible there.
    """
    set_initial_condition(fdm, condition.h_ft, condition.V_fps)
    fdm["propulsion/set-running"] = -1
    fdm.run_ic()
    if place_reference_point(fdm, aircraft):
        fdm.run_ic()
    turboprop = is_turboprop(aircraft.model)
    # The propeller-torque re-trim needs the stand-in moments (the DHC6 copy has them).
    torque = turboprop and fdm.get_property_manager().hasNode(next(iter(TRIM_MOMENT_PROPERTIES.values())))
    try:
        fdm.do_trim(0)
        lateral = max(abs(fdm["accelerations/pdot-rad_sec2"]), abs(fdm["accelerations/rdot-rad_sec2"]),
                      abs(fdm["accelerations/vdot-ft_sec2"]))
        if lateral > 1e-6:
            fdm.do_trim(1)
        if torque:
            _trim_with_propeller_torque(fdm)
    except jsbsim.TrimFailureError as exc:
        hint = ""
        if aircraft.model == "f16" and 420.0 < condition.V_fps < 432.0 and abs(condition.h_ft - 10_000) < 2_000:
            hint = (" The F-16 cannot trim for alpha between about 4.94 and 5.05 deg: its "
                    "leading-edge flap switches at alpha = 0.0873 rad with no hysteresis. "
                    "Choose a speed outside about 427-429 ft/s.")
        raise TrimError(f"trim failed for {aircraft.label} at {condition.name!r} "
                        f"(h = {condition.h_ft:.0f} ft, V = {condition.V_fps:.1f} ft/s): {exc}.{hint}") from exc
    fdm["propulsion/fuel_freeze"] = 1
    if turboprop:
        settle_engines(fdm)
    return read_trim_point(fdm, condition.name, aircraft.surfaces)


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
