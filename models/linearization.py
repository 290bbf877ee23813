"""Cross-check of the truth derivatives through ``jsbsim.FGLinearization``.

FGLinearization returns the state matrix A in the states (Vt, α, θ, q, β, φ, p, ψ, r, ...)
at the current (trimmed) point. With the FCS disabled its input matrix is zero, so only
derivatives with respect to states can be checked this way. Each is recovered from A by
undoing the rigid-body kinematics exactly, at wings-level trim (β = p = q = r = 0):

- q̇ = M/Iy                                  ⇒ Cm_α = A[q,α] Iy/(q̄Sc̄), Cm_q̂ = A[q,q] Iy/(q̄Sc̄) · 2V/c̄
- Ix ṗ − Ixz ṙ = L,  Iz ṙ − Ixz ṗ = N         ⇒ L_x = Ix A[p,x] − Ixz A[r,x], N_x = Iz A[r,x] − Ixz A[p,x]
- β̇ = (Y/m + p w − r u + g cosθ sinφ)/V      ⇒ CY_β = A[β,β] mV/(q̄S), CY_p̂ = (A[β,p]V − w) m/(q̄S) · 2V/b,
                                               CY_r̂ = (A[β,r]V + u) m/(q̄S) · 2V/b
- α̇ = q − (q̄S C_L + T sinα)/(mV) + g cos(θ−α)/V
                                             ⇒ C_Lα = −((A[α,α] + A[α,θ]) mV + T cosα)/(q̄S),
                                               C_Lq̂ = (1 − A[α,q]) mV/(q̄S) · 2V/c̄
- V̇ = (T cosα − q̄S C_D)/m − g sin(θ−α)       ⇒ C_Dα = (m g cos(θ−α) − T sinα − m A[V,α])/(q̄S),
                                               C_Dq̂ = −A[V,q] m/(q̄S) · 2V/c̄

Gravity depends on θ − α, so its α-derivative is taken as minus A's θ column: that is
JSBSim's effective gravity, centrifugal term included (0.11 ft/s² at the equator).
The linearization re-initialises the model and leaves dt = 0, so it runs on an instance of
its own.
"""
from __future__ import annotations

import math

import jsbsim
import numpy as np

from models.aircraft import Aircraft
from models.conditions import FlightCondition
from models.truth import differencing_instance

CHECKED = ("CL_alpha", "CL_qhat", "CD_alpha", "CD_qhat", "Cm_alpha", "Cm_qhat",
           "CY_beta", "CY_phat", "CY_rhat", "Cl_beta", "Cl_phat", "Cl_rhat",
           "Cn_beta", "Cn_phat", "Cn_rhat")


def linearization_derivatives(aircraft: Aircraft, condition: FlightCondition, *,
                              root=None, name=None) -> dict[str, float]:
    """The derivatives in :data:`CHECKED`, recovered from FGLinearization's A matrix."""
    fdm, tp, gated = differencing_instance(aircraft, condition, root=root, name=name)
    if gated:
        # Linearize the aircraft without its α̇ terms, like the central differences.
        fdm["sidbench/unsteady-gain"] = 0.0
    fdm["simulation/models/FGFCS/enabled"] = 0
    lin = jsbsim.FGLinearization(fdm)
    A = np.asarray(lin.system_matrix)
    ix = {n: i for i, n in enumerate(lin.x_names)}

    def a(row: str, col: str) -> float:
        return float(A[ix[row], ix[col]])

    m, V, T = tp.mass_slug, tp.V_fps, tp.thrust_lbf
    qS = tp.qbar_psf * tp.S_ft2
    al = tp.alpha_rad
    u, w = V * math.cos(al), V * math.sin(al)
    kq, kp = 2 * V / tp.cbar_ft, 2 * V / tp.b_ft
    Ix, Iy, Iz, Ixz = tp.Ix_slugft2, tp.Iy_slugft2, tp.Iz_slugft2, tp.Ixz_slugft2
    out = {
        "Cm_alpha": a("Q", "Alpha") * Iy / (qS * tp.cbar_ft),
        "Cm_qhat": a("Q", "Q") * Iy / (qS * tp.cbar_ft) * kq,
        # Gravity enters α̇ and V̇ through θ − α, so its α-derivative is minus the θ column:
        # this takes JSBSim's own effective gravity (with the centrifugal term) from A itself.
        "CL_alpha": -((a("Alpha", "Alpha") + a("Alpha", "Theta")) * m * V + T * math.cos(al)) / qS,
        "CL_qhat": (1.0 - a("Alpha", "Q")) * m * V / qS * kq,
        "CD_alpha": (-T * math.sin(al) - m * (a("Vt", "Alpha") + a("Vt", "Theta"))) / qS,
        "CD_qhat": -a("Vt", "Q") * m / qS * kq,
        "CY_beta": a("Beta", "Beta") * m * V / qS,
        "CY_phat": (a("Beta", "P") * V - w) * m / qS * kp,
        "CY_rhat": (a("Beta", "R") * V + u) * m / qS * kp,
    }
    for var, col, k in (("beta", "Beta", 1.0), ("phat", "P", kp), ("rhat", "R", kp)):
        L = Ix * a("P", col) - Ixz * a("R", col)
        N = Iz * a("R", col) - Ixz * a("P", col)
        out[f"Cl_{var}"] = L / (qS * tp.b_ft) * k
        out[f"Cn_{var}"] = N / (qS * tp.b_ft) * k
    return out
