"""Force and moment coefficients from measured quantities (seed Eqs. 1-5).

These are the "measured" coefficients of equation error: computed from accelerometers,
rates, angular accelerations, air data, thrust, mass, inertia and geometry.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from maneuvers.recording import Recording
from models.constants import G0_FPS2
from models.axes import wind_axis_coefficients


def accelerometer_at_cg(ax_g, ay_g, az_g, p, q, r, pdot, qdot, rdot, r_ft) -> tuple[np.ndarray, ...]:
    """Move accelerometer readings (g) from the sensor position ``r_ft`` (body axes, from
    the c.g.) to the c.g.: a_cg = a_s − [ω̇ × r + ω × (ω × r)] / g₀."""
    x, y, z = (float(v) for v in r_ft)
    if x == y == z == 0.0:
        return np.asarray(ax_g), np.asarray(ay_g), np.asarray(az_g)
    w = np.stack([p, q, r], axis=-1)
    wd = np.stack([pdot, qdot, rdot], axis=-1)
    rv = np.array([x, y, z])
    extra = np.cross(wd, rv) + np.cross(w, np.cross(w, rv))
    return ax_g - extra[:, 0] / G0_FPS2, ay_g - extra[:, 1] / G0_FPS2, az_g - extra[:, 2] / G0_FPS2


def force_coefficients(ax_g, ay_g, az_g, thrust_lbf, qbar_psf, mass_slug, S_ft2) -> dict[str, np.ndarray]:
    """Seed Eq. 1: CX = (m a_x − T)/(q̄S), CY = m a_y/(q̄S), CZ = m a_z/(q̄S).

    Accelerations are specific forces at the c.g. in g (a_z ≈ −1 in level flight); thrust
    acts along body x."""
    qS = np.asarray(qbar_psf) * S_ft2
    m = np.asarray(mass_slug) * G0_FPS2
    return {"CX": (m * ax_g - thrust_lbf) / qS, "CY": m * ay_g / qS, "CZ": m * az_g / qS}


def moment_coefficients(p, q, r, pdot, qdot, rdot, qbar_psf, S_ft2, b_ft, cbar_ft,
                        Ix, Iy, Iz, Ixz, thrust_lbf=0.0, thrust_offset_ft=0.0,
                        which=("Cl", "Cm", "Cn")) -> dict[str, np.ndarray]:
    """Seed Eqs. 3-5, with the thrust line's pitching moment removed from Cm.

    Cl = Ix/(q̄Sb) [ṗ − Ixz/Ix (pq + ṙ) + (Iz − Iy)/Ix qr]
    Cm = Iy/(q̄Sc̄) [q̇ + (Ix − Iz)/Iy pr + Ixz/Iy (p² − r²)] − T z_T/(q̄Sc̄)
    Cn = Iz/(q̄Sb) [ṙ − Ixz/Iz (ṗ − qr) + (Iy − Ix)/Iz pq]

    ``Ixz`` has the seed's sign (positive 982 slug·ft² in its F-16 Table 1); ``thrust_offset_ft``
    is the thrust line's body-z position (positive below the c.g.), so the thrust moment is
    +T·z_T. ``which`` names the coefficients wanted (the others, and the angular accelerations
    only they use, may be ``None``).
    """
    qS = np.asarray(qbar_psf) * S_ft2
    out = {}
    if "Cl" in which:
        out["Cl"] = Ix / (qS * b_ft) * (pdot - Ixz / Ix * (p * q + rdot) + (Iz - Iy) / Ix * q * r)
    if "Cm" in which:
        out["Cm"] = (Iy / (qS * cbar_ft) * (qdot + (Ix - Iz) / Iy * p * r + Ixz / Iy * (p**2 - r**2))
                     - np.asarray(thrust_lbf) * thrust_offset_ft / (qS * cbar_ft))
    if "Cn" in which:
        out["Cn"] = Iz / (qS * b_ft) * (rdot - Ixz / Iz * (pdot - q * r) + (Iy - Ix) / Iz * p * q)
    return out


Differentiator = Callable[[np.ndarray, float], np.ndarray]

# Coefficients whose Eqs. 1-5 involve thrust: CX (Eq. 1) and, through it, CL and CD (Eq. 2);
# Cm through the thrust line's moment T z_T when the offset is not zero.
THRUST_COEFFICIENTS = ("CX", "CL", "CD")


def thrust_source(rec: Recording) -> tuple[np.ndarray | float, str]:
    """Thrust for Eqs. 1 and 4, and where it came from.

    ``../shared/recording-format.md``: thrust is optional and "assumed constant at trim if
    absent". So: the ``thrust`` channel when recorded (``'recorded'``); else the constant
    ``meta['trim']['thrust_lbf']`` (``'trim'``); else 0 (``'unknown'``), the only value
    left when the trim thrust is not known either. A constant thrust T left out shifts CX by
    ``-T/(q̄S)`` (and CL, CD by its projections, Cm by ``-T z_T/(q̄Sc̄)``): a bias-term shift,
    exact when q̄ is constant.
    """
    if rec.has("thrust"):
        return rec.channel("thrust"), "recorded"
    trim = rec.meta.get("trim", {})
    if "thrust_lbf" in trim:
        return float(trim["thrust_lbf"]), "trim"
    return 0.0, "unknown"


def thrust_assumption(rec: Recording, coefficient: str) -> tuple[str, ...]:
    """What ``coefficient`` computed by Eqs. 1-5 assumes about thrust (empty when nothing)."""
    offset = float(rec.meta.get("thrust_offset_ft", 0.0))
    if coefficient not in THRUST_COEFFICIENTS and not (coefficient == "Cm" and offset != 0.0):
        return ()
    thrust, source = thrust_source(rec)
    if source == "recorded":
        return ()
    if source == "trim":
        return (f"thrust not recorded: assumed constant at its trim value, {thrust:.6g} lbf "
                "(recording format)",)
    shift = "-T z_T/(q̄S c̄)" if coefficient == "Cm" else "-T/(q̄S)"
    return (f"thrust neither recorded nor known at trim (meta trim.thrust_lbf): taken as 0 lbf, so "
            f"{coefficient} lacks the term {shift} of the constant trim thrust T, which the bias "
            "term absorbs (exactly when q̄ is constant)",)


ALL_COEFFICIENTS = ("CX", "CY", "CZ", "CD", "CL", "Cl", "Cm", "Cn")


def coefficients_from_recording(rec: Recording, differentiate: Differentiator | None = None,
                                names: tuple[str, ...] | list[str] | None = None) -> pd.DataFrame:
    """CX, CY, CZ, CL, CD, Cl, Cm, Cn from a recording's channels (Eqs. 1-5).

    Parameters
    ----------
    rec : Recording
        Canonical recording; thrust is taken as recorded, or as ``meta['trim']['thrust_lbf']``
        (constant) when the channel is absent, or zero when neither is known
        (:func:`thrust_source`; :func:`thrust_assumption` says what that assumes).
    differentiate : callable or None
        ``(x, dt) -> dx/dt`` used for the angular accelerations. ``None`` uses the recorded
        ``pdot``, ``qdot``, ``rdot`` channels (refused, naming them, if absent).
    names : the coefficients wanted (all eight when None), in the frame's column order.
    """
    wanted = ALL_COEFFICIENTS if names is None else tuple(names)
    return pd.DataFrame(_coefficients(rec, differentiate, wanted), columns=list(wanted))


def coefficient_from_recording(rec: Recording, name: str, differentiate: Differentiator | None = None,
                               *, accelerations: dict[str, np.ndarray] | None = None) -> np.ndarray:
    """One of the coefficients of :func:`coefficients_from_recording`, computed alone: only the
    channels (and angular accelerations) its equation uses, no frame. Bit-identical to the frame's
    column. ``accelerations`` (``{'pdot': ..., 'qdot': ..., 'rdot': ...}``, any subset) replaces
    the recorded or differentiated angular accelerations it names: Eqs. 3-5 are affine in them,
    so setting them to 0 and 1 gives the coefficient's parts (used by the frequency-domain
    method to differentiate in the frequency domain)."""
    return _coefficients(rec, differentiate, (name,), accelerations)[name]


def _coefficients(rec: Recording, differentiate: Differentiator | None,
                  names: tuple[str, ...],
                  accelerations: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    unknown = [n for n in names if n not in ALL_COEFFICIENTS]
    if unknown:
        raise ValueError(f"unknown coefficient(s) {unknown}: use {ALL_COEFFICIENTS}")
    rates: dict[str, np.ndarray] = {}

    def rate(name: str) -> np.ndarray:  # p, q, r and (recorded or differentiated) pdot, qdot, rdot
        if name not in rates:
            if accelerations is not None and name in accelerations:
                rates[name] = np.broadcast_to(np.asarray(accelerations[name], dtype=float), (rec.n,))
            elif len(name) == 1 or differentiate is None:
                rates[name] = rec.channel(name)
            else:
                rates[name] = differentiate(rate(name[0]), rec.dt)
        return rates[name]

    g = rec.geometry
    # constant mass properties stay scalars (the same arithmetic as broadcast arrays, less memory)
    m = rec.mass_at(0) if rec.mass_is_constant else rec.mass_at()
    thrust, _ = thrust_source(rec)
    qbar = rec.channel("qbar")
    out: dict[str, np.ndarray] = {}
    if any(n in ("CX", "CY", "CZ", "CD", "CL") for n in names):
        r_acc = rec.meta.get("sensors", {}).get("accelerometer_ft", [0.0, 0.0, 0.0])
        if any(float(v) != 0.0 for v in r_acc):
            ax, ay, az = accelerometer_at_cg(rec.channel("ax"), rec.channel("ay"), rec.channel("az"),
                                             *(rate(k) for k in ("p", "q", "r", "pdot", "qdot", "rdot")), r_acc)
        else:
            ax, ay, az = rec.channel("ax"), rec.channel("ay"), rec.channel("az")
        forces = force_coefficients(ax, ay, az, thrust, qbar, m["mass_slug"], g["S_ft2"])
        out.update(forces)
        if any(n in ("CD", "CL") for n in names):
            out.update(wind_axis_coefficients(forces["CX"], forces["CZ"], rec.channel("alpha")))
    moments = [n for n in ("Cl", "Cm", "Cn") if n in names]
    if moments:
        need = {"Cl": ("pdot", "rdot"), "Cm": ("qdot",), "Cn": ("rdot", "pdot")}
        acc = {k: rate(k) for n in moments for k in need[n]}
        out.update(moment_coefficients(rate("p"), rate("q"), rate("r"), acc.get("pdot"), acc.get("qdot"),
                                       acc.get("rdot"), qbar, g["S_ft2"], g["b_ft"], g["cbar_ft"],
                                       m["Ix_slugft2"], m["Iy_slugft2"], m["Iz_slugft2"], m["Ixz_slugft2"],
                                       thrust, float(rec.meta.get("thrust_offset_ft", 0.0)), which=moments))
    return {n: out[n] for n in names}


def normalized_rates(rec: Recording, V_ref: float | None = None) -> dict[str, np.ndarray]:
    """p̂ = pb/2V, q̂ = qc̄/2V, r̂ = rb/2V with the instantaneous airspeed (or ``V_ref``, the
    seed's V_o of Eqs. 8-11)."""
    V = rec.channel("V") if V_ref is None else V_ref
    g = rec.geometry
    return {"phat": rec.channel("p") * g["b_ft"] / (2 * V), "qhat": rec.channel("q") * g["cbar_ft"] / (2 * V),
            "rhat": rec.channel("r") * g["b_ft"] / (2 * V)}
