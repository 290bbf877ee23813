"""The ICAO standard atmosphere (ISA), up to 20 km: pressure from pressure altitude, and the
altitude whose standard density a measured dynamic pressure and airspeed imply.

Constants: ICAO Doc 7488 (Manual of the ICAO Standard Atmosphere), SI.
"""
from __future__ import annotations

import numpy as np
import numpy.typing as npt

from models.constants import G0_MPS2
from models.errors import UserError

T0_K = 288.15
P0_PA = 101325.0
LAPSE_K_PER_M = 0.0065
R_J_PER_KG_K = 287.05287
TROPOPAUSE_M = 11000.0
TOP_M = 20000.0
FT_M = 0.3048
GAMMA_AIR = 1.4  # ratio of specific heats of air
SLUGFT3_PER_KGM3 = 0.0019403203  # 1 kg/m^3 in slug/ft^3
_EXPONENT = G0_MPS2 / (R_J_PER_KG_K * LAPSE_K_PER_M)  # g/(R L), about 5.256
_T11 = T0_K - LAPSE_K_PER_M * TROPOPAUSE_M
_RHO0 = P0_PA / (R_J_PER_KG_K * T0_K)
_RHO11 = _RHO0 * (_T11 / T0_K) ** (_EXPONENT - 1.0)


def pressure_pa(h_ft: npt.ArrayLike) -> np.ndarray:
    """Static pressure of the ISA at pressure altitude ``h_ft`` (ft), Pa.

    Raises
    ------
    ValueError
        Above 20 km (65,617 ft), beyond the two layers modelled.
    """
    h_m = np.asarray(h_ft, dtype=np.float64) * FT_M
    if np.any(h_m > TOP_M):
        raise UserError(f"altitude above {TOP_M / FT_M:.0f} ft is outside the ISA layers modelled")
    p11 = P0_PA * (_T11 / T0_K) ** _EXPONENT
    tropo = P0_PA * (1.0 - LAPSE_K_PER_M * np.minimum(h_m, TROPOPAUSE_M) / T0_K) ** _EXPONENT
    strato = p11 * np.exp(-G0_MPS2 * (h_m - TROPOPAUSE_M) / (R_J_PER_KG_K * _T11))
    return np.where(h_m <= TROPOPAUSE_M, tropo, strato)


def density_altitude_ft(rho_slugft3: npt.ArrayLike) -> np.ndarray:
    """The ISA altitude (ft) whose density is ``rho_slugft3``: the inverse of
    rho = rho0 (T/T0)^(g/(R L) - 1) in the troposphere and rho11 exp(-g (h - 11 km)/(R T11))
    above it. On a standard day it equals the pressure altitude."""
    rho = np.asarray(rho_slugft3, dtype=np.float64) / SLUGFT3_PER_KGM3
    if np.any(~(rho > 0)):
        raise UserError("density must be positive to give an altitude")
    tropo_m = (T0_K - T0_K * (rho / _RHO0) ** (1.0 / (_EXPONENT - 1.0))) / LAPSE_K_PER_M
    strato_m = TROPOPAUSE_M - np.log(rho / _RHO11) * R_J_PER_KG_K * _T11 / G0_MPS2
    return np.where(rho >= _RHO11, tropo_m, strato_m) / FT_M

