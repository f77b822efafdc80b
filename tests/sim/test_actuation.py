"""Thruster allocation and joint effort limits (`uvms_pin.sim.actuation`): the thrusters'
commands and the validation of the limits."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.model.thruster import Thruster
from uvms_pin.sim.actuation import ThrustersAndJointLimits


def _thrusters(forward_N: float, reverse_N: float) -> list[Thruster]:
    """Six thrusters along and about the body axes (they span every component)."""
    out = []
    for k in range(3):
        axis = np.eye(3)[k]
        out.append(Thruster(f"t{k}", np.zeros(3), axis, forward_N, reverse_N))
        arm = np.eye(3)[(k + 1) % 3] * 0.3
        direction = np.cross(axis, arm) / np.linalg.norm(np.cross(axis, arm))
        out.append(Thruster(f"r{k}", arm, direction, forward_N, reverse_N))
    return out


@pytest.mark.parametrize(
    ("forward_N", "reverse_N"), [(40.0, 30.0), (0.6, 0.25), (2.0, 0.0), (0.0, 2.0)]
)
def test_a_saturated_thruster_is_commanded_full_scale_whatever_its_size(forward_N, reverse_N):
    """The command of a linear drive is u = f / f_full, so a thrust on its bound is u = +1
    forward and u = -1 in reverse, for large and small thrusters alike (a limit below 1 N
    too); a thruster without reverse thrust (limit 0) is never commanded below 0, one without
    forward thrust never above 0 (its command at zero thrust is 0, not 0 / 0)."""
    actuation = ThrustersAndJointLimits(_thrusters(forward_N, reverse_N), None)
    actuation.start(0.01)
    for sign in (1.0, -1.0):
        actuation.apply(np.r_[sign * 1e4 * np.ones(6), np.zeros(0)])
        thrust = actuation.signals()["thrust"]
        command = actuation.signals()["thruster_command"]
        assert np.all(np.isfinite(command))
        full_forward = forward_N if forward_N > 0.0 else np.inf
        full = np.where(thrust >= 0.0, full_forward, reverse_N if reverse_N > 0.0 else np.inf)
        np.testing.assert_allclose(command, thrust / full, rtol=1e-12)
        assert np.all(np.abs(command) <= 1.0 + 1e-12)
        on_bound = np.isclose(thrust, forward_N) | np.isclose(thrust, -reverse_N)
        assert np.any(on_bound)
        np.testing.assert_allclose(np.abs(command[on_bound & (thrust != 0.0)]), 1.0, rtol=1e-12)


@pytest.mark.parametrize("limits", [[5.0, 0.0], [5.0, -1.0], [5.0, np.inf], [np.nan, 5.0]])
def test_joint_effort_limits_must_be_positive_and_finite(limits):
    """A joint's |tau| limit of 0, below 0, infinite or NaN is refused (None: unlimited)."""
    with pytest.raises(ParameterError, match="joint effort limits must be positive and finite"):
        ThrustersAndJointLimits(_thrusters(10.0, 10.0), np.array(limits))


def test_saturated_only_past_a_bound_by_more_than_the_rounding_tolerance():
    """`saturated` reports a thruster asked past its bound by more than PAST_LIMIT_N: a plan
    with thrusts on their bounds, or past them by less than the tolerance (the allocation's
    rounding), is not saturated; past by 1e-6 N it is, on either bound."""
    from uvms_pin.sim.actuation import PAST_LIMIT_N

    actuation = ThrustersAndJointLimits(_thrusters(40.0, 30.0), None)
    allocation = actuation.allocation
    assert np.linalg.matrix_rank(allocation) == 6  # B^+ B f = f: the plan is the thrust
    for k in range(6):
        for bound in (actuation.upper_N[k], actuation.lower_N[k]):
            outward = np.sign(bound)
            thrust = np.full(6, 1.0)
            thrust[k] = bound
            assert not actuation.saturated(allocation @ thrust)
            thrust[k] = bound + outward * 0.5 * PAST_LIMIT_N
            assert not actuation.saturated(allocation @ thrust)
            thrust[k] = bound + outward * 1e-6
            assert actuation.saturated(allocation @ thrust)
            thrust[k] = bound - outward * 0.5 * PAST_LIMIT_N
            assert not actuation.saturated(allocation @ thrust)


@pytest.mark.parametrize("components", [[], [6], [-1], [0, 0], [2, 7]])
def test_allocated_components_must_be_distinct_indices_of_the_body_wrench(components):
    """None, an index past 5 (the wrench has six components), a negative one or a repeated
    one is refused by name."""
    with pytest.raises(ParameterError, match="allocated_components must be distinct indices"):
        ThrustersAndJointLimits(_thrusters(10.0, 10.0), None, allocated_components=components)


@pytest.mark.parametrize("components", [[2], [0, 5], [5, 0, 3]])
def test_any_distinct_components_are_allocated_and_the_others_ignored(components):
    """One component alone (heave) or a few in any order: each allocated one is produced
    (the thrusters span all six), and what the command asks of the others changes nothing
    (f = B_s^+ tau_s reads the allocated rows only)."""
    actuation = ThrustersAndJointLimits(_thrusters(100.0, 100.0), None, components)
    actuation.start(0.01)
    command = np.array([3.0, -2.0, 5.0, 1.0, -1.5, 0.5])
    wrench = actuation.apply(command)
    np.testing.assert_allclose(wrench[components], command[components], atol=1e-12)
    others = np.setdiff1d(np.arange(6), components)
    changed = command.copy()
    changed[others] += 7.0
    np.testing.assert_array_equal(actuation.apply(changed), wrench)
