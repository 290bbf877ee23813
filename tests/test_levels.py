"""The replay's surface levels as nuisance parameters (harness.diagnosis.levels) and the
start level they correct (models.replay.start_level, steady_start)."""
import math

import numpy as np
import pytest

from harness.diagnosis.levels import LEVEL_BOUND_SIGMAS, fit_levels, level_bound
from models.flight import FlightError
from models.replay import start_level, steady_start

T = np.arange(0.0, 20.0, 0.02)
INNER = slice(50, -50)


def _linear_plant(true_offsets: dict[str, float]):
    """A replay whose outputs respond linearly to each surface's level error: q to de, p to
    da; the recorded outputs are those at the true levels."""
    shapes = {"de": {"q": 1.0 - np.exp(-T), "V": -5.0 * T}, "da": {"p": np.sin(T)}}

    def fly(surfaces):
        out = {"q": np.zeros_like(T), "V": np.zeros_like(T), "p": np.zeros_like(T)}
        for s, x in surfaces.items():
            err = -(x[0] - 0.0)  # surfaces recorded with first sample 0: x0 - offset -> +offset
            for c, shape in shapes[s].items():
                out[c] = out[c] + err * shape
        return out

    measured = fly({s: np.array([-v, 0.0]) for s, v in true_offsets.items()})
    return fly, measured


def test_linear_levels_recovered_exactly():
    fly, measured = _linear_plant({"de": 0.003, "da": -0.002})
    surfaces = {"de": np.zeros(2), "da": np.zeros(2)}
    sim, offsets = fit_levels(fly, surfaces, {"de": 0.01, "da": 0.01}, measured,
                              {"q": 1e-6, "V": 1e-6, "p": 1e-6}, INNER)
    assert offsets["de"] == pytest.approx(0.003, rel=1e-9)
    assert offsets["da"] == pytest.approx(-0.002, rel=1e-9)
    np.testing.assert_allclose(sim["q"], measured["q"], atol=1e-12)


def test_levels_held_within_their_bound():
    fly, measured = _linear_plant({"de": 0.003})
    sim, offsets = fit_levels(fly, {"de": np.zeros(2)}, {"de": 0.001}, measured, {"q": 1e-6, "V": 1e-6}, INNER)
    assert offsets == {"de": pytest.approx(0.001)}


def test_no_bound_no_fit_and_unchanged_outputs():
    fly, measured = _linear_plant({"de": 0.003})
    base = fly({"de": np.zeros(2)})
    sim, offsets = fit_levels(fly, {"de": np.zeros(2)}, {"de": 0.0}, measured, {"q": 1e-6}, INNER)
    assert offsets == {}
    np.testing.assert_array_equal(sim["q"], base["q"])


def test_a_step_that_diverges_keeps_the_recorded_levels():
    fly0, measured = _linear_plant({"de": 0.003})

    def fly(surfaces):
        if surfaces["de"][0] != 0.0:
            raise FlightError("diverged")
        return fly0(surfaces)

    sim, offsets = fit_levels(fly, {"de": np.zeros(2)}, {"de": 0.01}, measured, {"q": 1e-6}, INNER)
    assert offsets == {}


def test_level_bound_from_noise_and_motion():
    t, sigma = np.arange(100) * 0.02, math.radians(0.05)
    quiet = np.zeros(100)
    assert level_bound(quiet, sigma, t) == pytest.approx(LEVEL_BOUND_SIGMAS * 1.25 * sigma / 5.0)
    assert level_bound(quiet, 0.0, t) == 0.0
    moving = np.linspace(0.0, 0.01, 100)
    assert level_bound(moving, 0.0, t) == pytest.approx(0.5 * moving[24])


def test_start_level_is_the_median_of_the_start_window():
    t = np.arange(0.0, 2.0, 0.02)
    x = np.where(t < 0.4, 1.0, 3.0)  # an input beginning inside the 0.5 s window
    x[0] = 7.0  # one wild first sample
    assert start_level(x, t) == 1.0
    y = steady_start(x, t)
    assert y[0] == 1.0 and np.array_equal(y[1:], x[1:])
    z = steady_start(np.zeros_like(t), t, level_of=x)  # a smoothed surface, its raw level
    assert z[0] == 1.0
