"""BlueROV2 Heavy thrusters: published geometry, full 6-DoF allocation, T200 limits."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.model.vehicles.bluerov2_heavy import T200_16V, thrusters
from uvms_pin.sim.actuation import ThrustersAndJointLimits


def test_geometry_matches_von_benzon_layout():
    ts = thrusters()
    assert len(ts) == 8
    horizontal = [t for t in ts if "horizontal" in t.name]
    vertical = [t for t in ts if "vertical" in t.name]
    np.testing.assert_allclose(
        sorted(np.abs(t.position_body_m).tolist() for t in horizontal), [[0.156, 0.111, 0.085]] * 4
    )
    np.testing.assert_allclose(
        sorted(np.abs(t.position_body_m).tolist() for t in vertical), [[0.120, 0.218, 0.0]] * 4
    )
    for t in horizontal:  # 45 deg off surge, in the horizontal plane
        assert t.direction_body[2] == 0.0
        assert abs(t.direction_body[0]) == pytest.approx(abs(t.direction_body[1]))
    for t in vertical:
        np.testing.assert_allclose(t.direction_body, [0, 0, 1])


def test_each_thruster_is_where_its_name_says_and_equal_thrusts_push_straight():
    """front/rear: x > 0 / x < 0; right/left: y < 0 / y > 0 (FLU). Equal thrust on the four
    horizontal thrusters is surge, with the pitch of their 8.5 cm below the origin and no
    sway, roll or yaw; on the four vertical pure heave (a thruster on the wrong side, or
    turned the wrong way, turns the vehicle)."""
    ts = thrusters()
    for t in ts:
        x, y, _ = t.position_body_m
        assert (x > 0) == ("front" in t.name) and (y < 0) == ("right" in t.name), t.name
    surge = 4.0 * np.sqrt(0.5)
    horizontal = sum(t.wrench_column for t in ts if "horizontal" in t.name)
    np.testing.assert_allclose(horizontal, [surge, 0, 0, 0, -0.085 * surge, 0], atol=1e-12)
    vertical = sum(t.wrench_column for t in ts if "vertical" in t.name)
    np.testing.assert_allclose(vertical, [0, 0, 4.0, 0, 0, 0], atol=1e-12)


def test_t200_limits_at_16_volts():
    assert T200_16V.max_forward_N == pytest.approx(5.25 * 9.80665)
    # the measured table's end at 1100 us (the technical details round it to 4.1 kgf)
    assert T200_16V.max_reverse_N == pytest.approx(4.07 * 9.80665, rel=1e-15)
    assert T200_16V.thrust_N(1.0) == pytest.approx(T200_16V.max_forward_N)
    assert T200_16V.thrust_N(-1.0) == pytest.approx(-T200_16V.max_reverse_N)
    assert T200_16V.thrust_N(0.5) == pytest.approx(0.25 * T200_16V.max_forward_N)
    with pytest.raises(ParameterError, match=r"\[-1, 1\]"):
        T200_16V.thrust_N(1.5)


def test_every_body_wrench_is_allocated_exactly_below_saturation():
    actuation = ThrustersAndJointLimits(thrusters(), None)
    assert np.linalg.matrix_rank(actuation.allocation) == 6
    rng = np.random.default_rng(8)
    for _ in range(20):
        wrench = rng.normal(scale=[10, 10, 10, 1, 1, 1])
        np.testing.assert_allclose(actuation.apply(wrench), wrench, atol=1e-9)
        assert not actuation.saturated(wrench)


def test_saturation_caps_each_thruster_at_its_t200_limit():
    actuation = ThrustersAndJointLimits(thrusters(), None)
    command = np.array([1000.0, 0, 0, 0, 0, 0])
    assert actuation.saturated(command)
    f = actuation.thrusts(command)
    assert np.all(f <= T200_16V.max_forward_N + 1e-12)
    assert np.all(f >= -T200_16V.max_reverse_N - 1e-12)
    # four horizontal thrusters at 45 deg: at most 4 F cos(45 deg) of surge
    assert actuation.apply(command)[0] <= 4 * T200_16V.max_forward_N * np.sqrt(0.5) + 1e-9


def test_a_command_on_the_bounds_is_not_saturated_by_the_allocations_rounding():
    """Thrusts planned on a limit (an MPC's box-constrained plan: here the eight thrusters'
    least-norm thrusts of a random wrench, scaled until one is on its limit) pass through
    B u and back through the allocation with ~1e-15 of rounding: not saturated; 1e-6 of
    the scale further is. Joint torques likewise against their effort limits."""
    effort = np.array([10.0, 10.0, 6.0, 3.0])
    actuation = ThrustersAndJointLimits(thrusters(), effort)
    rng = np.random.default_rng(4)
    lower, upper = actuation.lower_N, actuation.upper_N
    for _ in range(50):
        raw = actuation.allocation_pinv @ rng.normal(scale=[10, 10, 10, 1, 1, 1])
        limit = np.where(raw > 0.0, upper, -lower)
        on_bound = raw / np.max(np.abs(raw) / limit)  # one thrust on its limit, to rounding
        joints = effort * rng.choice([-1.0, 1.0], 4)
        assert not actuation.saturated(np.r_[actuation.allocation @ on_bound, joints])
        past = on_bound * (1.0 + 1e-6)
        assert actuation.saturated(np.r_[actuation.allocation @ past, np.zeros(4)])
        assert actuation.saturated(np.r_[np.zeros(6), joints * (1.0 + 1e-6)])
