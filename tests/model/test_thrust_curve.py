"""Thrust curves: the T200's published points, the quadratic propeller law, their inverses."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.model.thrust_curve import QuadraticThrustCurve, TabulatedThrustCurve
from uvms_pin.model.vehicles.t200 import (
    STANDARD_GRAVITY_M_S2,
    T200_16V_PWM_US,
    T200_16V_THRUST_KGF,
    t200_16v_curve,
)


def test_t200_curve_reproduces_every_published_point():
    curve = t200_16v_curve()
    command = (T200_16V_PWM_US - 1500.0) / 400.0
    np.testing.assert_array_equal(
        curve.thrust_N(command), T200_16V_THRUST_KGF * STANDARD_GRAVITY_M_S2
    )
    # a few rows of the sheet, read independently
    for pwm, kgf in ((1100, -4.07), (1468, -0.04), (1500, 0.0), (1532, 0.04), (1900, 5.25)):
        assert curve.thrust_N(np.array([(pwm - 1500) / 400]))[0] == kgf * STANDARD_GRAVITY_M_S2


def test_t200_deadband_and_asymmetry():
    curve = t200_16v_curve()
    inside = (np.arange(1472, 1529, 4) - 1500.0) / 400.0
    assert not np.any(curve.thrust_N(inside))
    assert curve.max_forward_N == pytest.approx(51.48, abs=0.01)
    assert curve.max_reverse_N == pytest.approx(39.91, abs=0.01)
    # the least command for a small thrust lies just outside the deadband
    u = curve.command_for(np.array([1e-6, -1e-6]))
    assert u[0] == pytest.approx(0.07, abs=1e-6) and u[1] == pytest.approx(-0.07, abs=1e-6)


@pytest.mark.parametrize(
    "curve", [t200_16v_curve(), QuadraticThrustCurve(40.0, 25.0, 0.1), QuadraticThrustCurve(10, 10)]
)
def test_the_driver_command_gives_the_thrust_asked_within_the_limits(curve):
    wanted = np.linspace(-1.2 * curve.max_reverse_N, 1.2 * curve.max_forward_N, 4001)
    got = curve.thrust_N(curve.command_for(wanted))
    clipped = np.clip(wanted, -curve.max_reverse_N, curve.max_forward_N)
    np.testing.assert_allclose(got, clipped, rtol=0.0, atol=1e-12 * curve.max_forward_N)
    u = np.linspace(-1, 1, 2001)
    assert np.all(np.diff(curve.thrust_N(u)) >= 0.0)  # non-decreasing


def test_quadratic_law():
    curve = QuadraticThrustCurve(40.0, 25.0, deadband=0.2)
    np.testing.assert_array_equal(
        curve.thrust_N(np.array([1.0, -1.0, 0.2, -0.15])), [40, -25, 0, 0]
    )
    # half-way through the live range: a quarter of the thrust (T ~ n^2)
    assert curve.thrust_N(np.array([0.6]))[0] == pytest.approx(10.0, rel=1e-14)
    assert curve.thrust_N(np.array([-0.6]))[0] == pytest.approx(-6.25, rel=1e-14)
    # a command past full scale gives the full thrust, no more
    np.testing.assert_array_equal(curve.thrust_N(np.array([1.7, -1.3, -40.0])), [40, -25, -25])
    # without a deadband (the default) the live range is the whole range: T = u^2 T_max
    plain = QuadraticThrustCurve(40.0, 25.0)
    np.testing.assert_allclose(plain.thrust_N(np.array([0.5, -0.5, 0.1])), [10, -6.25, 0.4])


@pytest.mark.parametrize(
    ("command", "thrust", "match"),
    [
        ([-1, 0, 1], [0, 0, -1], "non-decreasing"),
        ([-1, 0.5, 0], [-1, 0, 1], "increase strictly"),
        ([-1, 0, 1], [-1, 0.5, 1], "zero thrust at zero"),
        ([-1, 0, 1], [-1, 0, np.nan], "finite command and thrust"),
        ([-1, 0, np.inf], [-1, 0, 1], "finite command and thrust"),
        ([-1, 0, 1], [-1, 0], "matching"),
    ],
)
def test_bad_tables_are_refused(command, thrust, match):
    with pytest.raises(ParameterError, match=match):
        TabulatedThrustCurve(np.array(command, float), np.array(thrust, float))


def test_bad_quadratic_is_refused():
    with pytest.raises(ParameterError, match="deadband"):
        QuadraticThrustCurve(1.0, 1.0, deadband=1.0)
    with pytest.raises(ParameterError, match="max_reverse_N"):
        QuadraticThrustCurve(1.0, -1.0)
