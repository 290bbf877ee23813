"""Seed Eq. 2, the one place it is written: body-axis force coefficients to wind axes."""
from __future__ import annotations

import numpy as np


def wind_axis_coefficients(CX, CZ, alpha) -> dict[str, np.ndarray]:
    """Seed Eq. 2: CD = −CX cos α − CZ sin α, CL = −CZ cos α + CX sin α (arrays or scalars)."""
    ca, sa = np.cos(alpha), np.sin(alpha)
    return {"CD": -CX * ca - CZ * sa, "CL": -CZ * ca + CX * sa}
