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
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from estimators.state_space import (discretize, lateral_matrices, propagate, short_period_dimensional,
                                    short_period_matrices, simulate_linear)
from harness.campaign import FlightKey
from maneuvers.recording import G0_FPS2, Recording

LATERAL = ("CY", "Cl", "Cn")
LAT_VARS = ("beta", "phat", "rhat", "da", "dr")


def linear_flight(key: FlightKey, fly_nominal) -> Recording:
    """Simulate the linear models for ``key`` (``fly_nominal(key)`` gives the JSBSim flight
    whose trim, truth and inputs they use)."""
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
    de_cmd, da, dr = (np.asarray(signal.get(s, zero), float) for s in ("de", "da", "dr"))

    dim = short_period_dimensional(truth["CZ_alpha"], truth["CZ_qhat"], truth["CZ_de"], truth["Cm_alpha"],
                                   truth["Cm_qhat"], truth["Cm_de"], qbar, S, c, m["mass_slug"], m["Iy_slugft2"], V)
    A, B, C, D = short_period_matrices(**dim, V_o=V)
    # δs,k = δs,cmd,k + K q_k, held over each sample interval (a digital loop, as in the
    # JSBSim flights): x_{k+1} = (Φ + Γ F) x_k + Γ δs,cmd,k.
    Phi, G0, _ = discretize(A, B, dt)
    F = np.array([[0.0, K]])
    x = propagate(Phi + G0 @ F, de_cmd[:-1, None] @ G0.T, np.zeros(2))
    alpha, q = x[:, 0], x[:, 1]
    de = de_cmd + K * q
    qdot = dim["M_alpha"] * alpha + dim["M_q"] * q + dim["M_de"] * de
    alphadot = dim["Z_alpha"] * alpha + (1 + dim["Z_q"]) * q + dim["Z_de"] * de
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
        "truth_CD_1": -CX * np.cos(alpha_abs) - CZ * np.sin(alpha_abs),
        "truth_CL_1": -CZ * np.cos(alpha_abs) + CX * np.sin(alpha_abs),
        "truth_alphadot_rps": alphadot,
    }
    # Only these derivatives are the linear models' own; their local and fit values coincide.
    own = {f"{co}_{v}" for co in ("CZ", "Cm") for v in ("alpha", "qhat", "de")} | set(lat)
    meta["truth"] = dict(meta["truth"])
    meta["truth"]["derivatives"] = {k: {"local": v["local"], "fit": v["local"]}
                                    for k, v in meta["truth"]["derivatives"].items() if k in own}
    meta["simulation"] = dict(meta["simulation"]) | {
        "variant": "linear", "loop": {"kind": "closed" if K else "open", "pitch_rate_gain": K},
        "linear_model": "seed Eq. 33 short period (Eq. 34 dimensional derivatives) and the linear "
                        "lateral-directional model, from the nominal aircraft's local truth derivatives; "
                        "rates normalised by the trim airspeed"}
    return Recording(data=pd.DataFrame(data), meta=meta, name="linear").validate("linear-model flight")
