"""Performance functions and the error transformation of prescribed-performance control.

Reference values are computed by hand (to 8 significant digits) from
rho(t) = (rho0 - rho_inf) exp(-l t) + rho_inf, eps = ln((1 + xi)/(1 - xi)), r = 2/(1 - xi^2).
"""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.control.performance import (
    PerformanceFunction,
    barrier_extended,
    check_funnel,
    max_abs,
    normalized_error,
    transformation_gain,
    transformed_error,
    transformed_error_extended,
)
from uvms_pin.errors import FunnelViolation, ParameterError


def test_value_hand_computed():
    # The paper's force funnel: rho0 = 1 N, rho_inf = 0.2 N, l = 3 1/s.
    funnel = PerformanceFunction(1.0, 0.2, 3.0)
    assert funnel.size == 1
    assert funnel.value(0.0)[0] == pytest.approx(1.0, abs=1e-15)
    # 0.8 exp(-1.5) + 0.2 = 0.8 * 0.22313016 + 0.2
    assert funnel.value(0.5)[0] == pytest.approx(0.37850413, abs=1e-8)
    # 0.8 exp(-3) + 0.2 = 0.8 * 0.049787068 + 0.2
    assert funnel.value(1.0)[0] == pytest.approx(0.23982965, abs=1e-8)
    assert funnel.value(1e3)[0] == pytest.approx(0.2, abs=1e-15)
    # rho_dot = -l (rho0 - rho_inf) exp(-l t): -2.4 at t = 0, -3 * 0.8 * exp(-1.5) at 0.5 s
    assert funnel.derivative(0.0)[0] == pytest.approx(-2.4, abs=1e-15)
    assert funnel.derivative(0.5)[0] == pytest.approx(-0.53551238, abs=1e-8)


def test_vectorized_components_and_broadcasting():
    funnel = PerformanceFunction([1.0, 1.0, 1.0, 0.9, 0.9, 0.9], 0.2, 3.0)
    assert funnel.size == 6
    value = funnel.value(0.0)
    np.testing.assert_allclose(value, [1.0, 1.0, 1.0, 0.9, 0.9, 0.9], atol=1e-15)
    mixed = PerformanceFunction(1.0, [0.2, 0.4], [2.2, 1.0])
    np.testing.assert_allclose(
        mixed.value(1.0), [0.8 * np.exp(-2.2) + 0.2, 0.6 * np.exp(-1.0) + 0.4], atol=1e-15
    )


def test_derivative_matches_finite_difference():
    """Central differences with h = 1e-6: truncation h^2 |rho'''| / 6 < 1e-11, round-off
    ~1e-16 / 1e-6 = 1e-10; tolerance 1e-8."""
    funnel = PerformanceFunction([1.0, 0.9, 2.0], [0.2, 0.4, 0.1], [3.0, 2.2, 0.5])
    h = 1e-6
    for t in (0.0, 0.1, 0.7, 2.0, 5.0):
        fd = (funnel.value(t + h) - funnel.value(t - h)) / (2 * h)
        np.testing.assert_allclose(funnel.derivative(t), fd, atol=1e-8, rtol=0)


def test_funnel_is_decreasing_and_bounded():
    funnel = PerformanceFunction([1.0, 0.9], [0.2, 0.4], [3.0, 2.2])
    times = np.linspace(0.0, 10.0, 201)
    values = np.array([funnel.value(t) for t in times])
    assert np.all(np.diff(values, axis=0) < 0)
    assert np.all(values > funnel.rho_inf) and np.all(values <= funnel.rho0)


@pytest.mark.parametrize(
    ("rho0", "rho_inf", "rate", "match"),
    [
        ([1.0, 0.1], [0.2, 0.2], 3.0, "'pitch'.*rho0 = 0.1 must be > rho_inf"),
        ([1.0, 1.0], [0.2, 1.0], 3.0, "'pitch'.*rho0 = 1.0 must be > rho_inf = 1.0"),
        ([1.0, 1.0], [0.0, 0.2], 3.0, "'roll'.*rho_inf = 0.0 must be > 0"),
        ([1.0, 1.0], [-0.1, 0.2], 3.0, "'roll'.*rho_inf"),
        ([1.0, 1.0], 0.2, [3.0, 0.0], "'pitch'.*decay_rate_per_s = 0.0 must be > 0"),
        ([1.0, 1.0], 0.2, [-1.0, 3.0], "'roll'.*decay_rate_per_s"),
        ([1.0, np.nan], 0.2, 3.0, "non-finite"),
        ([1.0, 1.0, 1.0], [0.2, 0.2], 3.0, "broadcast"),
    ],
)
def test_bad_parameters_raise_naming_the_component(rho0, rho_inf, rate, match):
    with pytest.raises(ParameterError, match=match):
        PerformanceFunction(rho0, rho_inf, rate, names=["roll", "pitch"])


def test_bad_parameters_without_names_give_the_index():
    with pytest.raises(ParameterError, match="component 2"):
        PerformanceFunction([1.0, 1.0, 0.1], 0.2, 3.0)


def test_normalized_and_transformed_error_hand_computed():
    xi = normalized_error([0.5, -0.5, 0.0, 0.27], [1.0, 1.0, 0.7, 0.3])
    np.testing.assert_allclose(xi, [0.5, -0.5, 0.0, 0.9], atol=1e-15)
    # eps = ln(1.5 / 0.5) = ln 3, -ln 3, 0, ln(1.9 / 0.1) = ln 19
    np.testing.assert_allclose(
        transformed_error(xi), [1.0986123, -1.0986123, 0.0, 2.9444390], atol=1e-7
    )
    # r = 2 / (1 - xi^2) = 2 / 0.75, 2 / 0.75, 2, 2 / 0.19
    np.testing.assert_allclose(
        transformation_gain(xi), [2.6666667, 2.6666667, 2.0, 10.526316], atol=1e-6
    )


def test_transformation_gain_is_derivative_of_transformed_error():
    h = 1e-6
    for xi in (-0.95, -0.3, 0.0, 0.6, 0.99):
        fd = (transformed_error(xi + h) - transformed_error(xi - h)) / (2 * h)
        # truncation h^2 |eps'''| / 6 with |eps'''| < 1e7 at xi = 0.99: < 2e-6 relative
        assert transformation_gain(xi) == pytest.approx(fd, rel=1e-5)


@pytest.mark.parametrize("xi", [1.0, -1.0, 1.5, np.nan, np.inf])
def test_transformations_refuse_outside_the_funnel(xi):
    with pytest.raises(ParameterError):
        transformed_error([0.0, xi])
    with pytest.raises(ParameterError):
        transformation_gain([0.0, xi])


def test_normalized_error_rejects_non_positive_bound():
    with pytest.raises(ParameterError):
        normalized_error([0.1], [0.0])


def test_check_funnel_returns_xi_inside():
    xi = check_funnel(
        level="first", names=["f_x", "f_y"], time_s=0.5, error=[0.3, -0.1], bound=[0.6, 0.5]
    )
    np.testing.assert_allclose(xi, [0.5, -0.2], atol=1e-15)


@pytest.mark.parametrize("error_yaw", [0.9, -0.9, 1.2])
def test_check_funnel_raises_with_component_time_error_bound(error_yaw):
    names = ["f_x", "f_y", "f_z", "roll", "pitch", "yaw"]
    error = [0.1, 0.0, 0.0, 0.0, 0.0, error_yaw]
    bound = [1.0, 1.0, 1.0, 0.9, 0.9, 0.9]
    with pytest.raises(FunnelViolation) as info:
        check_funnel(level="first", names=names, time_s=1.25, error=error, bound=bound)
    violation = info.value
    assert violation.level == "first"
    assert violation.component == "yaw"
    assert violation.time_s == 1.25
    assert violation.error == error_yaw
    assert violation.bound == 0.9
    message = str(violation)
    assert "'yaw'" in message and "first" in message
    assert "t = 1.25" in message and f"{error_yaw:.6g}" in message and "rho = 0.9" in message


def test_check_funnel_reports_the_worst_component_and_nan():
    with pytest.raises(FunnelViolation) as info:
        check_funnel(
            level="second",
            names=["u", "v", "w"],
            time_s=0.0,
            error=[1.1, 0.5, -3.0],
            bound=[1, 1, 1],
        )
    assert info.value.component == "w"
    with pytest.raises(FunnelViolation) as info:
        check_funnel(
            level="second", names=["u", "v"], time_s=0.0, error=[2.0, np.nan], bound=[1, 1]
        )
    assert info.value.component == "v"


def test_check_funnel_rejects_mismatched_names():
    with pytest.raises(ParameterError):
        check_funnel(level="first", names=["a"], time_s=0.0, error=[0.1, 0.2], bound=[1, 1])


def test_max_abs_and_nan_anywhere():
    """max |x| of arrays and lists; a NaN in any position gives NaN (never passes < 1)."""
    assert max_abs(np.array([0.2, -0.7, 0.5])) == 0.7
    assert max_abs([0.1, -0.05]) == 0.1
    assert max_abs(np.array([-np.inf, 0.0])) == np.inf
    for position in range(4):
        values = np.array([0.1, -0.3, 0.2, 0.0])
        values[position] = np.nan
        assert np.isnan(max_abs(values))
        assert not max_abs(values) < 1.0


CLAMP = 0.9  # the extension's clamp here (the controller's is 1 - 1e-6)


@pytest.mark.parametrize("xi", [0.0, 0.3, -0.55, 0.9, -0.9])
def test_funnel_extension_is_eps_and_r_eps_inside_the_clamp(xi):
    """For |xi| <= clamp the extended transformation is eps(xi) and the extended barrier
    is r(xi) eps(xi) (the law's P^-1 r eps): the extension changes nothing inside."""
    eps = transformed_error(xi)
    assert transformed_error_extended(xi, CLAMP) == pytest.approx(eps, rel=1e-14, abs=1e-15)
    assert barrier_extended(xi, CLAMP) == pytest.approx(
        transformation_gain(xi) * eps, rel=1e-14, abs=1e-15
    )


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_funnel_extension_continues_linearly_with_the_clamp_slope(sign):
    """Beyond the clamp both are continued by their tangent at the clamp: eps by slope
    r(c) = 2 / (1 - c^2), r eps by b'(c) = 4 c eps / (1 - c^2)^2 + r^2 (the derivative of
    r eps, checked here by its central difference, h = 1e-6, 1e-6 relative); both are
    odd and keep growing outside (an implicit stage finds no rest beyond the funnel)."""
    c, h = CLAMP, 1e-6
    beyond = sign * np.array([c + 0.01, c + 0.5, c + 3.0])
    eps_c = transformed_error(sign * c)
    slope_eps = transformation_gain(c)
    np.testing.assert_allclose(
        transformed_error_extended(beyond, c), eps_c + slope_eps * (beyond - sign * c), rtol=1e-14
    )

    def barrier(x):
        return transformation_gain(x) * transformed_error(x)

    slope_barrier = (barrier(c + h) - barrier(c - h)) / (2 * h)  # r eps is smooth on (-1, 1)
    np.testing.assert_allclose(
        barrier_extended(beyond, c),
        barrier(sign * c) + slope_barrier * (beyond - sign * c),
        rtol=1e-6,
    )
    # C1 at the clamp: one-sided slopes agree
    right = (barrier_extended(sign * (c + h), c) - barrier_extended(sign * c, c)) / (sign * h)
    assert right == pytest.approx(slope_barrier, rel=1e-4)
    for f in (transformed_error_extended, barrier_extended):
        values = f(beyond, c)
        assert np.all(sign * np.diff(values) > 0.0)  # growing outward
        np.testing.assert_allclose(f(-beyond, c), -values, rtol=1e-14)  # odd
