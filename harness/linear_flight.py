"""The seed's linear models as a flight source (§III.C: "to avoid any bias in the parameter
estimates from model structure errors").

A ``linear`` flight takes the nominal JSBSim aircraft's trim point and local truth derivatives
and simulates, exactly (matrix exponential, inputs held between samples), the short-period
model of Eq. 33 with the dimensional derivatives of Eq. 34 and the linear lateral-directional
model, with the same inputs. With a pitch-rate loop δs = δs,cmd + K·q the feedback is sampled
and held per sample, as a digital flight computer would. The recording carries α, q, a_z, β, p, r, φ, a_y and the angular
accelerations, so the coefficients of Eqs. 1-5 equal the linear models' exactly (with the
rates normalised by the constant trim airspeed V_o, as in Eq. 34), and output error faces the
model it assumes.

**Turbulence** (process noise, ``turbulence=``): JSBSim's MIL-spec ("Dryden") vertical gust w_g,
with its own scales — σ_w and L_w from MIL-F-8785C as JSBSim's ``FGWinds`` takes them (the
probability-of-exceedance table, Fig. 7, above 2,000 ft; 0.1·W₂₀ and L_w = h below 1,000 ft) and
its first-order form ẇ_g = −(2V/L_w) w_g + σ_w √(4V/L_w) n(t) (JSBSim's eq. 32, stationary
variance σ_w²) — enters as an angle-of-attack disturbance α_g = w_g/V (w_g positive down): the
aerodynamic forces and moments, the vane and the accelerometer see α = α_i − α_g, the kinematics
the inertial α_i. The augmented system (α_i, q, α_g) is sampled exactly (matrix exponential for
the held inputs, Van Loan's integral for the noise), from zero gust at t = 0 as JSBSim starts.
JSBSim's pitch-rate gust q_g (∝ ẇ_g/b) and the lateral gusts are not modelled: the lateral model
flies in still air.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from estimators.state_space import (discretize, expm_small, lateral_matrices, propagate, short_period_dimensional,
                                    short_period_matrices, simulate_linear)
from harness.campaign import FlightKey
from maneuvers.recording import Recording
from models.constants import G0_FPS2, SURFACES
from models.axes import wind_axis_coefficients

LATERAL = ("CY", "Cl", "Cn")
LAT_VARS = ("beta", "phat", "rhat", "da", "dr")


# MIL-F-8785C Fig. 7 as JSBSim's FGWinds tabulates it: σ_w (ft/s) by probability-of-exceedance
# index (JSBSim's severity, 1..7) at these altitudes (ft), interpolated linearly, clamped at the ends.
POE_ALTITUDES_FT = (500.0, 1750.0, 3750.0, 7500.0, 15000.0, 25000.0, 35000.0, 45000.0, 55000.0, 65000.0,
                    75000.0, 80000.0)
POE_SIGMA_FPS = {
    1: (3.2, 2.2, 1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    2: (4.2, 3.6, 3.3, 1.6, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    3: (6.6, 6.9, 7.4, 6.7, 4.6, 2.7, 0.4, 0.0, 0.0, 0.0, 0.0, 0.0),
    4: (8.6, 9.6, 10.6, 10.1, 8.0, 6.6, 5.0, 4.2, 2.7, 0.0, 0.0, 0.0),
    5: (11.8, 13.0, 16.0, 15.1, 11.6, 9.7, 8.1, 8.2, 7.9, 4.9, 3.2, 2.1),
    6: (15.6, 17.6, 23.0, 23.6, 22.1, 20.0, 16.0, 15.1, 12.1, 7.9, 6.2, 5.1),
    7: (18.7, 21.5, 28.4, 30.2, 30.7, 31.0, 25.2, 23.1, 17.5, 10.7, 8.4, 7.2),
}


def vertical_gust_scales(turbulence, h_ft: float) -> tuple[float, float]:
    """σ_w (ft/s) and L_w (ft) of JSBSim's MIL-spec turbulence at altitude ``h_ft``."""
    if turbulence.severity == 0:
        return 0.0, 1750.0
    h = max(float(h_ft), 10.0)
    table = float(np.interp(h, POE_ALTITUDES_FT, POE_SIGMA_FPS[turbulence.severity]))
    low = 0.1 * turbulence.wind_20ft_fps
    if h <= 1000.0:
        return low, h
    if h <= 2000.0:
        return low + (h - 1000.0) / 1000.0 * (table - low), 1000.0 + (h - 1000.0) / 1000.0 * 750.0
    return table, 1750.0


def _noise_covariance(A: np.ndarray, Qc: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Φ = e^{A dt} and Q_d = ∫₀^dt e^{As} Q_c e^{Aᵀs} ds (Van Loan, 1978)."""
    n = len(A)
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n], M[:n, n:], M[n:, n:] = -A, Qc, A.T
    E = expm_small(M * dt)
    Phi = E[n:, n:].T
    Qd = Phi @ E[:n, n:]
    return Phi, (Qd + Qd.T) / 2


def gust_short_period(dim: dict, V: float, dt: float, de_cmd: np.ndarray, K: float, sigma_w: float,
                      L_w: float, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """α (aerodynamic), q and α_g of the short period flown through the vertical gust (module
    docstring), the pitch-rate loop sampled and held per sample."""
    tau = L_w / (2.0 * V)  # JSBSim's eq. 32: xi_w = (1 − 2T/τ_w) xi_w + …, τ_w = L_w/V
    Za, Ma = dim["Z_alpha"], dim["M_alpha"]
    A = np.array([[Za, 1.0 + dim["Z_q"], -Za], [Ma, dim["M_q"], -Ma], [0.0, 0.0, -1.0 / tau]])
    B = np.array([[dim["Z_de"]], [dim["M_de"]], [0.0]])
    Phi, G0, _ = discretize(A, B, dt)
    Qc = np.zeros((3, 3))
    Qc[2, 2] = (sigma_w / V) ** 2 * 2.0 / tau  # stationary variance (σ_w/V)²
    _, Qd = _noise_covariance(A, Qc, dt)
    lam, U = np.linalg.eigh(Qd)
    root = U * np.sqrt(np.clip(lam, 0.0, None))
    w = rng.standard_normal((len(de_cmd) - 1, 3)) @ root.T
    F = np.array([[0.0, K, 0.0]])
    x = propagate(Phi + G0 @ F, de_cmd[:-1, None] @ G0.T + w, np.zeros(3))
    return x[:, 0] - x[:, 2], x[:, 1], x[:, 2]


def linear_flight(key: FlightKey, fly_nominal, turbulence=None, turbulence_seed: int = 0) -> Recording:
    """Simulate the linear models for ``key`` (``fly_nominal(key)`` gives the JSBSim flight
    whose trim, truth and inputs they use), in still air or through ``turbulence``'s vertical
    gust (seeded by ``turbulence_seed``; module docstring)."""
    nominal = fly_nominal(dataclasses.replace(key, variant="nominal", loop="open"))
    meta = dict(nominal.meta)
    trim, truth = meta["trim"], {k: v["local"] for k, v in meta["truth"]["derivatives"].items()}
    g, m = nominal.geometry, nominal.mass_at(0)
    t, dt, n = nominal.t, nominal.dt, nominal.n
    V, qbar = trim["V_fps"], trim["qbar_psf"]
    S, b, c = g["S_ft2"], g["b_ft"], g["cbar_ft"]
    K = float(key.loop.split(":")[1]) if key.loop.startswith("closed") else 0.0
    signal = key.maneuver.build().deflections(t)
    zero = np.zeros(n)
    de_cmd, da, dr = (np.asarray(signal.get(s, zero), float) for s in SURFACES)

    dim = short_period_dimensional(truth["CZ_alpha"], truth["CZ_qhat"], truth["CZ_de"], truth["Cm_alpha"],
                                   truth["Cm_qhat"], truth["Cm_de"], qbar, S, c, m["mass_slug"], m["Iy_slugft2"], V)
    A, B, C, D = short_period_matrices(**dim, V_o=V)
    if turbulence is not None and turbulence.kind != "dryden":
        raise ValueError(f"the linear-model flight flies the MIL-spec Dryden vertical gust only, not "
                         f"{turbulence.kind!r} turbulence")
    sigma_w, L_w = vertical_gust_scales(turbulence, trim["h_ft"]) if turbulence is not None else (0.0, 0.0)
    gust = None
    if sigma_w > 0:
        alpha, q, gust = gust_short_period(dim, V, dt, de_cmd, K, sigma_w, L_w,
                                           np.random.default_rng(int(turbulence_seed)))
    else:
        # δs,k = δs,cmd,k + K q_k, held over each sample interval (a digital loop, as in the
        # JSBSim flights): x_{k+1} = (Φ + Γ F) x_k + Γ δs,cmd,k.
        Phi, G0, _ = discretize(A, B, dt)
        F = np.array([[0.0, K]])
        x = propagate(Phi + G0 @ F, de_cmd[:-1, None] @ G0.T, np.zeros(2))
        alpha, q = x[:, 0], x[:, 1]
    de = de_cmd + K * q
    qdot = dim["M_alpha"] * alpha + dim["M_q"] * q + dim["M_de"] * de
    alphadot = dim["Z_alpha"] * alpha + (1 + dim["Z_q"]) * q + dim["Z_de"] * de  # inertial (w/V) in a gust
    qhat = q * c / (2 * V)
    dCZ = truth["CZ_alpha"] * alpha + truth["CZ_qhat"] * qhat + truth["CZ_de"] * de
    dCm = truth["Cm_alpha"] * alpha + truth["Cm_qhat"] * qhat + truth["Cm_de"] * de

    lat = {f"{co}_{v}": truth[f"{co}_{v}"] for co in LATERAL for v in LAT_VARS}
    Al, Bl, Cl, Dl = lateral_matrices(lat, qbar=qbar, V=V, S=S, b=b, m=m["mass_slug"], Ix=m["Ix_slugft2"],
                                      Iz=m["Iz_slugft2"], Ixz=m["Ixz_slugft2"], alpha_o=trim["alpha_rad"],
                                      theta_o=trim["theta_rad"])
    ul = np.column_stack([da, dr])
    xl, _ = simulate_linear(Al, Bl, Cl, Dl, ul, dt)
    xdot = xl @ Al.T + ul @ Bl.T
    beta, p, r, phi = xl.T
    h = b / (2 * V)
    dC = {co: sum(truth[f"{co}_{v}"] * s for v, s in zip(LAT_VARS, (beta, p * h, r * h, da, dr))) for co in LATERAL}

    tc = meta["truth"]["trim_coefficients"]
    qS = qbar * S
    CZ = tc["CZ"] + dCZ
    CX = np.full(n, tc["CX"])
    Cm = tc["Cm"] + dCm
    alpha_abs = trim["alpha_rad"] + alpha
    data = {
        "t_s": t, "V_fps": np.full(n, V), "alpha_rad": alpha_abs, "beta_rad": beta,
        "p_rps": p, "q_rps": q, "r_rps": r, "phi_rad": phi,
        "theta_rad": trim["theta_rad"] + np.concatenate([[0.0], np.cumsum((q[1:] + q[:-1]) * dt / 2)]),
        "psi_rad": np.concatenate([[0.0], np.cumsum((r[1:] + r[:-1]) * dt / 2)]),
        "qbar_psf": np.full(n, qbar), "h_ft": np.full(n, trim["h_ft"]), "mach_1": np.full(n, trim["mach"]),
        "thrust_lbf": np.full(n, trim["thrust_lbf"]),
        "pdot_rps2": xdot[:, 1], "qdot_rps2": qdot, "rdot_rps2": xdot[:, 2],
        "de_rad": trim["de_rad"] + de, "da_rad": trim["da_rad"] + da, "dr_rad": trim["dr_rad"] + dr,
        # Eq. 1 read backwards: the accelerometers that give exactly these coefficients.
        "ax_g": (CX * qS + trim["thrust_lbf"]) / (m["mass_slug"] * G0_FPS2),
        "ay_g": (tc["CY"] + dC["CY"]) * qS / (m["mass_slug"] * G0_FPS2),
        "az_g": CZ * qS / (m["mass_slug"] * G0_FPS2),
        "truth_CX_1": CX, "truth_CY_1": tc["CY"] + dC["CY"], "truth_CZ_1": CZ,
        "truth_Cl_1": tc["Cl"] + dC["Cl"], "truth_Cm_1": Cm, "truth_Cn_1": tc["Cn"] + dC["Cn"],
        **{f"truth_{k}_1": v for k, v in wind_axis_coefficients(CX, CZ, alpha_abs).items()},
        "truth_alphadot_rps": alphadot,
    }
    if gust is not None:
        data["truth_alpha_gust_rad"] = gust
    # Only these derivatives are the linear models' own; their local and fit values coincide.
    own = {f"{co}_{v}" for co in ("CZ", "Cm") for v in ("alpha", "qhat", "de")} | set(lat)
    meta["truth"] = dict(meta["truth"])
    meta["truth"]["derivatives"] = {k: {"local": v["local"], "fit": v["local"]}
                                    for k, v in meta["truth"]["derivatives"].items() if k in own}
    meta["simulation"] = dict(meta["simulation"]) | {
        "variant": "linear", "loop": {"kind": "closed" if K else "open", "pitch_rate_gain": K},
        "turbulence": None if turbulence is None else {
            "kind": turbulence.kind, "severity": turbulence.severity, "wind_20ft_fps": turbulence.wind_20ft_fps,
            "seed": int(turbulence_seed), "sigma_w_fps": sigma_w, "L_w_ft": L_w,
            "model": "MIL-spec vertical gust as JSBSim flies it (first order, time constant L_w/2V), "
                     "entering as alpha_g = w_g/V; no pitch-rate or lateral gusts"},
        "linear_model": "seed Eq. 33 short period (Eq. 34 dimensional derivatives) and the linear "
                        "lateral-directional model, from the nominal aircraft's local truth derivatives; "
                        "rates normalised by the trim airspeed"}
    return Recording(data=pd.DataFrame(data), meta=meta, name="linear").validate("linear-model flight")
