"""The errors a user can act on: printed as one line naming the cause, exit status 2."""
from __future__ import annotations

from estimators.least_squares import SingularRegressorsError
from estimators.regressors import EquationError
from harness.campaign import CampaignError
from harness.diagnosis.run import DiagnosisError
from maneuvers.base import InputSpecError
from maneuvers.recording import RecordingError
from models.flight import FlightError
from models.trim import TrimError

USER_ERRORS: tuple[type[BaseException], ...] = (
    RecordingError, TrimError, FlightError, InputSpecError, SingularRegressorsError, EquationError, CampaignError,
    DiagnosisError, FileNotFoundError, ValueError)
