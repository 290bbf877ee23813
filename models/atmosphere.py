"""Process noise: JSBSim's MIL-spec atmospheric turbulence, flown (not added afterwards)."""
from __future__ import annotations

from dataclasses import dataclass

import jsbsim

from models.errors import OptionError

# JSBSim's turb-type codes: the header comments say 4/5, the code uses 3/4 (../shared/jsbsim-notes.md).
TURB_TYPE = {"dryden": 3, "tustin": 4}


@dataclass(frozen=True)
class Turbulence:
    """MIL-spec turbulence for one flight.

    ``kind`` 'dryden' or 'tustin'; ``severity`` JSBSim's probability-of-exceedance index
    (1 light, 3 moderate, 5 severe); ``wind_20ft_fps`` the wind at 20 ft that sets the
    low-altitude intensity. The random seed is given per flight, so each realization of a
    campaign flies its own gusts.
    """

    kind: str = "dryden"
    severity: int = 1
    wind_20ft_fps: float = 15.0

    def __post_init__(self) -> None:
        if self.kind not in TURB_TYPE:
            raise OptionError(f"turbulence kind must be one of {sorted(TURB_TYPE)}, not {self.kind!r}")
        if not 0 <= self.severity <= 7:
            raise OptionError("turbulence severity must be 0..7 (JSBSim's MIL-spec index)")
        if self.wind_20ft_fps < 0:
            raise OptionError("wind at 20 ft must be non-negative")

    def describe(self) -> str:
        return f"{self.kind} turbulence, severity {self.severity}, wind at 20 ft {self.wind_20ft_fps:g} ft/s"


def start_turbulence(fdm: jsbsim.FGFDMExec, turbulence: Turbulence, seed: int) -> None:
    """Switch ``turbulence`` on in a trimmed instance, seeded with ``seed``."""
    fdm["atmosphere/randomseed"] = int(seed)
    fdm["atmosphere/turb-type"] = TURB_TYPE[turbulence.kind]
    fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = turbulence.wind_20ft_fps
    fdm["atmosphere/turbulence/milspec/severity"] = turbulence.severity
