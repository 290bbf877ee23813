"""Constants every package shares, defined once here, in the lowest package that needs them."""
from __future__ import annotations

G0_FPS2 = 32.17404855643
"""Standard gravity, ft/s² (9.80665 m/s² exactly)."""

G0_MPS2 = 9.80665
"""Standard gravity, m/s² (exact by definition)."""

SURFACES: tuple[str, ...] = ("de", "da", "dr")
"""The control surfaces, canonical quantity names: stabilator/elevator, aileron, rudder."""

BODY_COEFFICIENTS: tuple[str, ...] = ("CX", "CY", "CZ", "Cl", "Cm", "Cn")
"""The six body-axis force and moment coefficients (seed Eqs. 1-5)."""

COEFFICIENTS: tuple[str, ...] = BODY_COEFFICIENTS + ("CL", "CD")
"""The body-axis coefficients, then lift and drag."""
