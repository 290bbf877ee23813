"""Shared fixtures: flights are flown once per test session (each costs ~0.1 s)."""
from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # see harness.cli._single_threaded_blas

from pathlib import Path  # noqa: E402

import pytest

SHARED = Path(__file__).resolve().parents[2] / "shared"


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    if not SHARED.is_dir():
        pytest.skip(f"shared reference folder not found at {SHARED}")
    return SHARED


@pytest.fixture(scope="session")
def three_axis_f16():
    """Noise-free nominal F-16 flight exciting all three axes."""
    from maneuvers.fly import FlightSpec, fly_maneuver
    from maneuvers.inputs import default_three_axis_input
    return fly_maneuver(FlightSpec(input=default_three_axis_input()))


@pytest.fixture(scope="session")
def three_axis_exact():
    """Noise-free exact-truth F-16 flight exciting all three axes."""
    from maneuvers.fly import FlightSpec, fly_maneuver
    from maneuvers.inputs import default_three_axis_input
    from models.aircraft import Aircraft
    return fly_maneuver(FlightSpec(input=default_three_axis_input(), aircraft=Aircraft("f16", "exact-truth")))
