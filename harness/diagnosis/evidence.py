"""The diagnosis's evidence records: a scored candidate effect (a row of the report's
candidate table) and one recording's analysis, everything the tests found."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from harness.diagnosis import candidates as cand
from harness.diagnosis.kinematics import KinematicResult
from harness.diagnosis.prepare import Prepared
from harness.diagnosis.spectra import AirShare
from models.replay import AeroAlong, InitialCondition


@dataclass
class Candidate:
    """A candidate effect with its test statistic (a row of the report's candidate table)."""

    effect: str
    axis: str | None
    channel: str | None
    parameter: str
    estimate: float
    std_error: float
    t: float
    explained_fraction: float
    units: str
    test: str
    selected: bool = False
    reason: str = ""
    details: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        d = {k: getattr(self, k) for k in ("effect", "axis", "channel", "parameter", "estimate", "std_error", "t",
                                           "explained_fraction", "units", "selected", "reason")}
        d["test"] = self.test
        return {k: (float(v) if isinstance(v, (np.floating,)) else v) for k, v in d.items()}


@dataclass
class Analysis:
    prepared: Prepared
    ic: InitialCondition
    aero: AeroAlong
    mismatch: dict[str, np.ndarray]
    noise: dict[str, float]          # per axis: the mismatch's noise level (high-frequency part)
    candidates: list[Candidate]
    selections: dict
    kinematic: KinematicResult
    delay: dict
    offset: cand.OffsetTest
    gust: object
    peak: object
    not_offered: dict = field(default_factory=dict)  # per axis: candidate parameters the maneuver did not excite
    applied: dict = field(default_factory=dict)      # sensor corrections applied before the model was evaluated
    gusty: str = ""  # why light gusts leave the kinematic (sensor) tests untrustworthy ('' when they do not)
    air: AirShare | None = None  # the air-share test, when the kinematics showed gusts
    nuisances: dict = field(default_factory=dict)  # per axis: the columns always in its stepwise fit
