"""A nonlinear longitudinal model in the classic HFB-320 form (Jategaonkar, *Flight Vehicle
System Identification*, ch. 4), written as an sidbench model file.

    sidbench estimate --recording REC.csv --method oe --model-file estimators/model_files/hfb320_model.py

A model file is Python code that sidbench runs as it is: load only files you trust.

States V (m/s), α, θ (rad), q (rad/s); input δe (rad); outputs V, α, θ, q, q̇, a_x, a_z
(m/s²) — SI throughout: fit it to plain arrays (``ManeuverData``) in these units. Thrust
F_e is a constant along the body x axis. Coefficients are polynomials in Δα = α − α₀ and
ΔV = (V − V₀)/V₀ about the reference α₀, V₀:

    C_D = C_D0 + C_Dα Δα + C_DV ΔV
    C_L = C_L0 + C_Lα Δα + C_Lα2 Δα² + C_LV ΔV
    C_m = C_m0 + C_mα Δα + C_mq q c̄/(2V₀) + C_mδe δe + C_mV ΔV

    V̇ = −q̄S C_D/m + F_e cos α/m + g sin(α − θ)
    α̇ = −q̄S C_L/(mV) + q + g cos(α − θ)/V − F_e sin α/(mV)
    θ̇ = q
    q̇ = q̄S c̄ C_m/I_y,                     q̄ = ½ρV²
    a_x = (q̄S C_X + F_e)/m,  a_z = q̄S C_Z/m,  C_X = C_L sin α − C_D cos α,  C_Z = −C_L cos α − C_D sin α
"""
import numpy as np

from estimators.dynamic_models import Model, Parameter

CONSTANTS = {"m": 7472.0, "S": 30.0, "cbar": 2.2, "Iy": 51000.0, "rho": 0.8, "g": 9.80665, "thrust": 6000.0,
             "V0": 100.0, "alpha0": 0.05}


def _coefficients(x, u, p, c):
    V, alpha, theta, q = x
    de = u[0]
    da, dv = alpha - c["alpha0"], (V - c["V0"]) / c["V0"]
    CD = p["CD0"] + p["CDa"] * da + p["CDV"] * dv
    CL = p["CL0"] + p["CLa"] * da + p["CLa2"] * da ** 2 + p["CLV"] * dv
    Cm = (p["Cm0"] + p["Cma"] * da + p["Cmq"] * q * c["cbar"] / (2 * c["V0"]) + p["Cmde"] * de
          + p["CmV"] * dv)
    return 0.5 * c["rho"] * V ** 2, CD, CL, Cm


def dynamics(t, x, u, p, c):
    V, alpha, theta, q = x
    qbar, CD, CL, Cm = _coefficients(x, u, p, c)
    qS, m, F, g = qbar * c["S"], c["m"], c["thrust"], c["g"]
    Vdot = -qS * CD / m + F * np.cos(alpha) / m + g * np.sin(alpha - theta)
    alphadot = -qS * CL / (m * V) + q + g * np.cos(alpha - theta) / V - F * np.sin(alpha) / (m * V)
    qdot = qS * c["cbar"] * Cm / c["Iy"]
    return Vdot, alphadot, q, qdot


def observe(t, x, u, p, c):
    V, alpha, theta, q = x
    qbar, CD, CL, Cm = _coefficients(x, u, p, c)
    qS, m = qbar * c["S"], c["m"]
    CX = CL * np.sin(alpha) - CD * np.cos(alpha)
    CZ = -CL * np.cos(alpha) - CD * np.sin(alpha)
    qdot = qS * c["cbar"] * Cm / c["Iy"]
    return V, alpha, theta, q, qdot, (qS * CX + c["thrust"]) / m, qS * CZ / m


model = Model(
    name="hfb320-longitudinal",
    states=("V", "alpha", "theta", "q"),
    inputs=("de",),
    outputs=("V", "alpha", "theta", "q", "qdot", "ax", "az"),
    parameters=(
        Parameter("CD0", 0.04, lower=0.0), Parameter("CDa", 0.2), Parameter("CDV", 0.0, scale=0.01),
        Parameter("CL0", 0.55, lower=0.0), Parameter("CLa", 4.0, lower=0.0), Parameter("CLa2", 0.0, scale=1.0),
        Parameter("CLV", 0.0, scale=0.01),
        Parameter("Cm0", -0.05, scale=0.01), Parameter("Cma", -0.5), Parameter("Cmq", -12.0),
        Parameter("Cmde", -1.0), Parameter("CmV", 0.0, scale=0.01),
    ),
    dynamics=dynamics,
    observe=observe,
    constants=CONSTANTS,
)
