"""The environments' tasks (uvms_pin.apps.gym.tasks): their errors and rewards against an
independent computation, for goals that are not the identity."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.apps.gym.tasks import (
    StationKeepingTask,
    effort_penalties,
    effort_penalty,
    rotation_angle_from,
)


def _unit_quaternions(rng: np.random.Generator, n: int) -> np.ndarray:
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _angle(target_xyzw: np.ndarray, q_xyzw: np.ndarray) -> float:
    """|log3(R_d^T R)| from the rotation matrices."""
    r_d = pin.Quaternion(*np.roll(target_xyzw, 1)).toRotationMatrix()  # (w, x, y, z)
    r = pin.Quaternion(*np.roll(q_xyzw, 1)).toRotationMatrix()
    return float(np.linalg.norm(pin.log3(r_d.T @ r)))


@pytest.mark.parametrize("seed", range(5))
def test_the_rotation_angle_is_that_of_the_relative_rotation(seed):
    """Against random targets (not the identity, where the product's vector terms
    vanish): |log3(R_d^T R)| of each row; q and -q are the same rotation."""
    rng = np.random.default_rng(seed)
    target = _unit_quaternions(rng, 1)[0]
    q = _unit_quaternions(rng, 50)
    expected = [_angle(target, row) for row in q]
    np.testing.assert_allclose(rotation_angle_from(target, q), expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(rotation_angle_from(target, -q), expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(rotation_angle_from(target, target[None]), [0.0], atol=1e-12)


def test_the_effort_penalty_is_the_weighted_mean_square_action():
    rng = np.random.default_rng(3)
    actions = rng.uniform(-1.0, 1.0, size=(4, 10))
    expected = 0.3 * np.mean(actions**2, axis=1)
    np.testing.assert_allclose(effort_penalties(actions, 0.3), expected, rtol=1e-15)
    for row, value in zip(actions, expected, strict=True):
        assert effort_penalty(row, 0.3) == pytest.approx(value, rel=1e-15)


def test_station_keeping_about_a_turned_pose_scores_the_rotation_between_them():
    """A goal turned 0.4 rad about an oblique axis, the vehicle 0.05 m off and turned the
    other way: the angle error is |log3(R_d^T R)|, the reward -(e_p / 0.1)^2 -
    (e_R / 0.1)^2 - w mean(a^2)."""
    axis = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
    goal_rotation = pin.exp3(0.4 * axis)
    goal = np.r_[1.0, -2.0, -5.0, pin.Quaternion(goal_rotation).coeffs()]
    task = StationKeepingTask(goal, max_position_error_m=1.0, effort_weight=0.2)
    rotation = pin.exp3(-0.3 * np.array([0.0, 1.0, 0.0]))
    q = np.r_[1.03, -2.04, -5.0, pin.Quaternion(rotation).coeffs(), np.zeros(4)]
    action = np.full(10, 0.5)
    outcome = task.outcome(0.0, q, np.zeros(6), action)
    angle = float(np.linalg.norm(pin.log3(goal_rotation.T @ rotation)))
    assert outcome.terms["angle_error_rad"] == pytest.approx(angle, abs=1e-12)
    assert outcome.terms["position_error_m"] == pytest.approx(0.05, abs=1e-12)
    expected = -((0.05 / 0.1) ** 2) - (angle / 0.1) ** 2 - 0.2 * 0.25
    assert outcome.reward == pytest.approx(expected, rel=1e-12)
    assert not outcome.terminated
