"""The joint drives' torque lag: exact first order over the periods."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.sim.actuation import Unlimited
from uvms_pin.sim.joint_drive import LaggedJointTorques


def test_63_percent_of_a_torque_step_at_the_time_constant():
    drives = LaggedJointTorques(Unlimited(), np.array([0.05, 0.2]))
    drives.start(0.005)
    command = np.r_[np.ones(6), 2.0, -3.0]
    for _ in range(10):  # 0.05 s
        out = drives.apply(command)
    np.testing.assert_array_equal(out[:6], 1.0)  # the vehicle's part is not lagged
    assert drives._torque[0] == pytest.approx(2.0 * (1 - math.exp(-1.0)), rel=1e-12)
    assert drives._torque[1] == pytest.approx(-3.0 * (1 - math.exp(-0.25)), rel=1e-12)


def test_a_lag_needs_a_sampled_loop_and_sane_constants():
    with pytest.raises(ParameterError, match="period_s"):
        LaggedJointTorques(Unlimited(), np.array([0.1])).start(None)
    with pytest.raises(ParameterError, match="time constants"):
        LaggedJointTorques(Unlimited(), np.array([-0.1]))


def test_a_zero_time_constant_passes_the_torque_at_once_beside_a_lagged_joint():
    """T_j = 0 is a drive without lag (not refused): its torque is the command from the
    first period on, while its neighbour's lags; all zero needs no sampled loop."""
    drives = LaggedJointTorques(Unlimited(), np.array([0.0, 0.1]))
    drives.start(0.01)
    out = drives.apply(np.r_[np.zeros(6), 2.0, 2.0])
    assert out[6] == 2.0
    assert 0.0 < out[7] < 2.0
    instant = LaggedJointTorques(Unlimited(), np.zeros(2))
    instant.start(None)
    np.testing.assert_array_equal(instant.apply(np.r_[np.zeros(6), 1.5, -0.5])[6:], [1.5, -0.5])


def test_a_command_of_another_arm_is_refused_with_both_counts():
    drives = LaggedJointTorques(Unlimited(), np.array([0.05, 0.05]))
    drives.start(0.01)
    with pytest.raises(ParameterError, match="3 joint torques for 2 time constants"):
        drives.apply(np.zeros(9))
