"""Trimming an aircraft at a named flight condition."""
from __future__ import annotations

from dataclasses import asdict, dataclass

import jsbsim

from models.aircraft import Aircraft, place_reference_point
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
    try:
        fdm.do_trim(0)
        lateral = max(abs(fdm["accelerations/pdot-rad_sec2"]), abs(fdm["accelerations/rdot-rad_sec2"]),
                      abs(fdm["accelerations/vdot-ft_sec2"]))
        if lateral > 1e-6:
            fdm.do_trim(1)
    except jsbsim.TrimFailureError as exc:
        hint = ""
        if aircraft.model == "f16" and 420.0 < condition.V_fps < 432.0 and abs(condition.h_ft - 10_000) < 2_000:
            hint = (" The F-16 cannot trim for alpha between about 4.94 and 5.05 deg: its "
                    "leading-edge flap switches at alpha = 0.0873 rad with no hysteresis. "
                    "Choose a speed outside about 427-429 ft/s.")
        raise TrimError(f"trim failed for {aircraft.label} at {condition.name!r} "
                        f"(h = {condition.h_ft:.0f} ft, V = {condition.V_fps:.1f} ft/s): {exc}.{hint}") from exc
    fdm["propulsion/fuel_freeze"] = 1
    return read_trim_point(fdm, condition.name, aircraft.surfaces)
