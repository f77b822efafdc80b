"""The estimator's settings (uvms_pin.sim.estimation.spec): a noise or an initial sigma
that is negative, infinite or NaN is refused by what it is; a zero sigma (certainty) too."""

from __future__ import annotations

import math

import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.sim.estimation.spec import EstimatorSpec


@pytest.mark.parametrize("key", ["dvl_noise_m_s", "depth_noise_m", "usbl_noise_m"])
@pytest.mark.parametrize("value", [-0.1, math.inf, math.nan])
def test_a_noise_that_is_negative_or_not_finite_is_refused(key, value):
    with pytest.raises(ParameterError, match="noise and sigma values must be >= 0"):
        EstimatorSpec(**{key: value})


@pytest.mark.parametrize("value", [-0.1, math.inf])
def test_an_initial_sigma_that_is_negative_or_infinite_is_refused(value):
    with pytest.raises(ParameterError, match="noise and sigma values must be >= 0"):
        EstimatorSpec(initial_sigma=(0.1, value, 0.02, 1e-3, 0.01))


@pytest.mark.parametrize("sigma", [(0.1, 0.05, 0.02, 1e-3), (0.1, 0.05, 0.02, 1e-3, 0.01, 0.1)])
def test_an_initial_sigma_of_other_than_five_values_is_refused(sigma):
    """Position, velocity, attitude, gyro and accelerometer bias: four or six values were
    accepted, and the run failed at its start on numpy's broadcasting error."""
    with pytest.raises(ParameterError, match="initial_sigma needs 5 values"):
        EstimatorSpec(initial_sigma=sigma)


def test_a_zero_noise_is_an_exact_sensor_and_a_zero_sigma_refused():
    assert EstimatorSpec(dvl_noise_m_s=0.0, depth_noise_m=0.0).dvl_noise_m_s == 0.0
    with pytest.raises(ParameterError, match="initial sigmas must be > 0"):
        EstimatorSpec(initial_sigma=(0.1, 0.05, 0.0, 1e-3, 0.01))
