"""The normalized action's scale: what the thrusters and joints can actually give."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.apps.gym.actions import action_scale, thruster_axis_capacity
from uvms_pin.errors import ParameterError
from uvms_pin.model.thruster import Thruster
from uvms_pin.sim.actuation import ThrustersAndJointLimits, Unlimited


def _actuation():
    thrusters = [
        Thruster("a", np.array([-0.3, 0.1, 0.0]), np.array([1.0, 0.0, 0.0]), 20.0, 10.0),
        Thruster("b", np.array([-0.3, -0.1, 0.0]), np.array([1.0, 0.0, 0.0]), 20.0, 10.0),
        Thruster("c", np.array([0.0, 0.0, 0.0]), np.array([0.0, 1.0, 1.0]), 5.0, 8.0),
    ]
    return ThrustersAndJointLimits(thrusters, np.array([3.0, 2.0]))


def test_capacity_is_the_largest_reachable_component():
    actuation = _actuation()
    capacity = thruster_axis_capacity(actuation)
    # surge: both aft thrusters forward, 2 x 20 N; yaw: 20 N x 0.1 m + 10 N x 0.1 m
    assert capacity[0] == pytest.approx(40.0)
    assert capacity[5] == pytest.approx(3.0)
    assert capacity[1] == pytest.approx(8.0 / np.sqrt(2))  # reverse is the stronger side
    # no thrust in the box exceeds it, and a vertex of the box attains it
    rng = np.random.default_rng(0)
    lower, upper = np.array([-10.0, -10.0, -8.0]), np.array([20.0, 20.0, 5.0])
    thrusts = rng.uniform(lower, upper, (20000, 3))
    wrenches = np.abs(thrusts @ actuation.allocation.T)
    assert np.all(wrenches <= capacity + 1e-12)
    corners = np.array(np.meshgrid(*zip(lower, upper, strict=True))).reshape(3, -1).T
    np.testing.assert_allclose(np.abs(corners @ actuation.allocation.T).max(axis=0), capacity)


def test_scale_is_capacity_then_joint_limits():
    scale = action_scale(_actuation(), 8)
    np.testing.assert_allclose(scale[6:], [3.0, 2.0])
    assert scale[3] == 1.0  # roll: no thruster reaches it, its command is dropped anyway


def test_unlimited_actuation_needs_an_explicit_scale():
    with pytest.raises(ParameterError, match="action_scale"):
        action_scale(Unlimited(), 8)
    np.testing.assert_array_equal(action_scale(Unlimited(), 2, [1.0, 2.0]), [1.0, 2.0])
    with pytest.raises(ParameterError, match="positive"):
        action_scale(Unlimited(), 2, [1.0, 0.0])


def test_a_scale_of_some_entries_is_their_part_and_an_override_has_their_count():
    driven = np.array([0, 1, 2, 3, 4, 5, 7])  # tau[6] (a servoed jaw joint) left out
    np.testing.assert_array_equal(
        action_scale(_actuation(), 8, driven=driven), action_scale(_actuation(), 8)[driven]
    )
    np.testing.assert_array_equal(action_scale(Unlimited(), 8, [1.0] * 7, driven), [1.0] * 7)
    for bad in ([1.0] * 8, None):  # nv numbers, or none, for 7 driven entries
        with pytest.raises(ParameterError, match=r"must be 7 positive|<7 numbers"):
            action_scale(Unlimited(), 8, bad, driven)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_capacity_is_the_best_corner_for_any_layout(seed):
    """Five thrusters at random places and directions, their forward and reverse limits
    unequal either way: each axis's capacity is the largest |component| over the corners
    of the thrust box (a linear function's maximum over a box is at a corner)."""
    rng = np.random.default_rng(seed)
    thrusters = [
        Thruster(f"t{k}", rng.uniform(-0.4, 0.4, 3), rng.normal(size=3), *rng.uniform(2, 30, 2))
        for k in range(5)
    ]
    actuation = ThrustersAndJointLimits(thrusters, np.array([1.0]))
    lower = -np.array([t.max_reverse_N for t in thrusters])
    upper = np.array([t.max_forward_N for t in thrusters])
    corners = np.array(np.meshgrid(*zip(lower, upper, strict=True))).reshape(5, -1).T
    best = np.abs(corners @ actuation.allocation.T).max(axis=0)
    np.testing.assert_allclose(thruster_axis_capacity(actuation), best, rtol=1e-12)
