"""Tracking tasks and task-priority control: the task Jacobians are the derivatives of the
task poses, the priorities hold, set-based tasks act only where they should, and with the
exact model the controllers track (still water, no noise, unlimited actuation)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT

from uvms_pin.control.pseudo_inverse import pseudo_inverse
from uvms_pin.control.tracking.task import TrackingTask, orientation_error
from uvms_pin.control.tracking.task_priority import (
    KinematicGains,
    KinematicLevel,
    prioritized_velocity,
)
from uvms_pin.control.tracking.trajectory import Hold
from uvms_pin.errors import ParameterError
from uvms_pin.model.urdf.load import load_uvms

UVMS_PATH = ROOT / "models" / "uvms_lbv150.urdf"


@pytest.fixture(scope="module")
def uvms():
    return load_uvms(UVMS_PATH)


def _q(uvms, rng):
    q = pin.randomConfiguration(uvms.model, uvms.model.lowerPositionLimit.clip(-2, 2),
                                uvms.model.upperPositionLimit.clip(-2, 2))  # fmt: skip
    q[7:] = rng.uniform(uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:])
    return q


def _task(uvms, target="end_effector", frame="world"):
    name = "" if target == "vehicle" else uvms.model.frames[uvms.ee_frame_id].name
    return TrackingTask("hold", target, frame, name, Hold(np.zeros(3)), np.eye(3))


@pytest.mark.parametrize(
    "target, frame", [("end_effector", "world"), ("end_effector", "vehicle"), ("vehicle", "world")]
)
def test_task_jacobian_is_the_derivative_of_the_pose(uvms, target, frame):
    task, model = _task(uvms, target, frame), uvms.model
    data = model.createData()
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = _q(uvms, rng)
        v = rng.normal(size=model.nv)
        _, _, jac = task.pose_and_jacobian(model, data, q)
        h = 1e-6
        p_plus, r_plus = task.pose(model, data, pin.integrate(model, q, h * v))
        p_minus, r_minus = task.pose(model, data, pin.integrate(model, q, -h * v))
        np.testing.assert_allclose((p_plus - p_minus) / (2 * h), jac[:3] @ v, atol=1e-6)
        omega = pin.log3(r_plus @ r_minus.T) / (2 * h)  # task-frame axes
        np.testing.assert_allclose(omega, jac[3:] @ v, atol=1e-6)
        if frame == "vehicle":
            assert not jac[:, :6].any()  # the vehicle's motion does not move it


def test_vehicle_frame_task_of_the_vehicle_is_refused(uvms):
    with pytest.raises(ParameterError, match="vehicle in the vehicle frame"):
        _task(uvms, "vehicle", "vehicle")


def test_orientation_error_is_the_rotation_to_the_reference():
    rotation = pin.utils.rpyToMatrix(0.1, -0.2, 0.3)
    error = orientation_error(np.eye(3), rotation)
    np.testing.assert_allclose(pin.exp3(error) @ rotation, np.eye(3), atol=1e-14)


def test_priorities_hold_and_a_single_task_is_the_weighted_pseudo_inverse():
    rng = np.random.default_rng(0)
    weights = rng.uniform(0.5, 5.0, 7)
    j1, x1 = rng.normal(size=(3, 7)), rng.normal(size=3)
    j2, x2 = rng.normal(size=(6, 7)), rng.normal(size=6)  # 3 + 6 > 7: they conflict
    single = prioritized_velocity([(j1, x1)], weights, 1e-9)
    np.testing.assert_allclose(single, pseudo_inverse(j1, 1e-12, weights) @ x1, atol=1e-9)
    both = prioritized_velocity([(j1, x1), (j2, x2)], weights, 1e-9)
    np.testing.assert_allclose(j1 @ both, x1, atol=1e-8)  # the first is exact
    swapped = prioritized_velocity([(j2, x2), (j1, x1)], weights, 1e-9)
    np.testing.assert_allclose(j2 @ swapped, x2, atol=1e-8)
    assert np.linalg.norm(j1 @ swapped - x1) > 1e-3  # the conflict is real
    # a lower task compatible with the upper one is met too
    j3 = rng.normal(size=(3, 7))
    x3 = rng.normal(size=3)
    three = prioritized_velocity([(j1, x1), (j3, x3)], weights, 1e-9)
    np.testing.assert_allclose(j3 @ three, x3, atol=1e-7)


def test_kinematic_level_meets_the_pose_task_and_the_limit_task(uvms):
    task = _task(uvms)
    model = uvms.model
    level = KinematicLevel(model, task, KinematicGains(attitude_gain_per_s=0.0, damping=1e-8))
    q = uvms.neutral_configuration()
    q[7:] = [-0.2, 1.0, -0.8, 0.2]
    zeta_r, errors = level.reference(0.0, q, np.zeros(model.nv))
    _, _, jac = task.pose_and_jacobian(model, model.createData(), q)
    rate = np.concatenate([errors["position_error"], errors["orientation_error"]])
    assert not errors["active_limits"].any()
    np.testing.assert_allclose(jac @ zeta_r, rate, atol=1e-6)
    # the rate bounds k_l (q_lo + m - q) <= q_dot <= k_l (q_hi - m - q) hold wherever the
    # joints are (inside a margin: driven back out), and only bounded joints are held
    rng = np.random.default_rng(5)
    lower, upper = model.lowerPositionLimit[7:], model.upperPositionLimit[7:]
    held_somewhere = 0
    for _ in range(40):
        q[7:] = rng.uniform(lower - 0.05, upper + 0.05)
        zeta_r, errors = level.reference(0.0, q, np.zeros(model.nv))
        rates = zeta_r[6:]
        assert np.all(rates >= 2.0 * (lower + 0.1 - q[7:]) - 1e-9)
        assert np.all(rates <= 2.0 * (upper - 0.1 - q[7:]) + 1e-9)
        held_somewhere += errors["active_limits"].sum()
    assert held_somewhere > 0


def test_a_lower_task_cannot_move_what_an_upper_task_holds_even_damped():
    # regression: with the projector built from the damped inverse, 1e-6 of a held joint's
    # direction stayed free and an arm-only task below used it at full size
    held = np.zeros((2, 10))
    held[0, 7] = held[1, 8] = 1.0
    arm = np.random.default_rng(0).normal(size=(6, 10))
    arm[:, :6] = 0.0
    zeta = prioritized_velocity(
        [(held, np.array([2.04, 2.2])), (arm, np.ones(6))], np.ones(10), 1e-3
    )
    np.testing.assert_allclose(zeta[7:9], [2.04, 2.2], rtol=1e-5)


def test_the_manipulability_task_climbs_its_gradient_in_the_pose_tasks_null_space(uvms):
    task, model = _task(uvms), uvms.model
    plain = KinematicLevel(model, task, KinematicGains(attitude_gain_per_s=0.0, damping=1e-9))
    q = uvms.neutral_configuration()
    q[7:] = [0.3, 0.4, -0.6, 0.5]
    w = plain.manipulability(q)
    gains_m = 2.5
    climbing = KinematicLevel(
        model,
        task,
        KinematicGains(
            attitude_gain_per_s=0.0,
            damping=1e-9,
            manipulability_threshold=2.0 * w,  # active here
            manipulability_gain=gains_m,
        ),
    )
    zero = np.zeros(model.nv)
    without, _ = plain.reference(0.0, q, zero)
    with_task, _ = climbing.reference(0.0, q, zero)
    _, _, jac = task.pose_and_jacobian(model, model.createData(), q)
    change = with_task - without
    np.testing.assert_allclose(jac @ change, 0.0, atol=1e-7)  # the pose task is untouched
    h = 1e-6
    gradient = np.array([
        (climbing.manipulability(q + h * np.eye(model.nq)[7 + j])
         - climbing.manipulability(q - h * np.eye(model.nq)[7 + j])) / (2 * h)
        for j in range(4)
    ])  # fmt: skip
    assert np.linalg.norm(change[6:]) > 1e-6 and change[6:] @ gradient > 0.0  # uphill
    # and exactly the gradient k_m grad w projected off the pose task's rows (unit weights)
    projector = np.eye(model.nv) - np.linalg.pinv(jac) @ jac
    np.testing.assert_allclose(
        change,
        projector @ np.r_[np.zeros(6), gains_m * gradient],
        atol=1e-6 * np.abs(gradient).max(),
    )
    # above the threshold the set-based task is absent
    relaxed = KinematicLevel(
        model, task, KinematicGains(attitude_gain_per_s=0.0, damping=1e-9,
                                    manipulability_threshold=0.5 * w)
    )  # fmt: skip
    np.testing.assert_allclose(relaxed.reference(0.0, q, zero)[0], without, atol=1e-12)


def test_a_vehicle_task_has_no_manipulability_task(uvms):
    """Manipulability is the arm's reach for its end-effector: a vehicle-tracking task
    gives the same reference with or without a manipulability threshold (w_min = 0.5,
    whatever w(q) is)."""
    task = _task(uvms, "vehicle")
    model = uvms.model
    rng = np.random.default_rng(8)
    plain = KinematicLevel(model, task, KinematicGains())
    asked = KinematicLevel(model, task, KinematicGains(manipulability_threshold=0.5))
    for _ in range(3):
        q, v = _q(uvms, rng), rng.normal(size=model.nv)
        np.testing.assert_array_equal(asked.reference(0.0, q, v)[0], plain.reference(0.0, q, v)[0])


@pytest.mark.parametrize("yaw", [0.0, 1.1])
@pytest.mark.parametrize("roll, pitch", [(0.2, 0.0), (0.0, -0.15)])
def test_the_attitude_task_levels_the_vehicle_at_its_rate_whatever_its_heading(
    uvms, roll, pitch, yaw
):
    """Second task: the vehicle's body roll and pitch rates (p, q) are k_a times the rotation
    from its attitude to the level one of the same heading: -k_a roll, -k_a pitch."""
    model, k_a = uvms.model, 0.7
    task = TrackingTask(
        "hold", "end_effector", "world", uvms.model.frames[uvms.ee_frame_id].name,
        Hold(np.zeros(3)), np.eye(3), track_orientation=False,
    )  # fmt: skip
    level = KinematicLevel(model, task, KinematicGains(attitude_gain_per_s=k_a, damping=1e-9))
    q = uvms.neutral_configuration()
    q[7:] = [0.3, 0.4, -0.6, 0.5]
    rotation = pin.utils.rpyToMatrix(0.0, 0.0, yaw) @ pin.utils.rpyToMatrix(roll, pitch, 0.0)
    q[3:7] = pin.Quaternion(rotation).coeffs()
    zeta_r, info = level.reference(0.0, q, np.zeros(model.nv))
    assert not info["active_limits"].any()
    np.testing.assert_allclose(zeta_r[3:5], [-k_a * roll, -k_a * pitch], atol=1e-9)
