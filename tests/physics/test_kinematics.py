"""End-effector kinematics: Euler angles, J'' and the analytical Jacobian vs finite differences.

Models: a small UVMS built in code (free-flyer + 4 revolute joints yaw/pitch/pitch/roll, an
``ee`` frame with a tilted mounting) and, once it exists, the reference URDF
``models/uvms_lbv150.urdf``.

Finite-difference tolerance: central differences with step h = 1e-6 along each velocity
direction (q ⊕ h e_k via pin.integrate) have truncation error h^2 |f'''| / 6 ~ 1e-13 for
arm lengths below 1 m and angles whose third derivatives are O(10) away from the Euler
singularity (we require |cos(pitch)| > 0.3), and round-off ~ 1e-16 |f| / h ~ 1e-10. An
absolute tolerance of 1e-7 is above both by three orders of magnitude and still far below
any real Jacobian error (entries are O(0.1-1)).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.physics.kinematics import (
    EULER_SINGULARITY_MIN_ABS_COS_PITCH,
    analytical_jacobian,
    angular_velocity_world_from_euler_rates,
    check_frame_id,
    end_effector_pose,
    euler_rate_matrix_body,
    euler_rpy_from_rotation,
    frame_id_from_name,
    frame_rotation_and_jacobian,
)

REFERENCE_URDF = Path(__file__).resolve().parents[2] / "models" / "uvms_lbv150.urdf"
FD_STEP = 1e-6
FD_ATOL = 1e-7


def build_test_uvms(n_joints: int = 4) -> pin.Model:
    """LBV150-sized free-flyer with an n-joint arm (axes cycle Z, Y, Y, X) and `ee` frame."""
    model = pin.Model()
    model.name = "test_uvms"
    root = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
    model.appendBodyToJoint(root, pin.Inertia.FromBox(11.0, 0.53, 0.25, 0.25), pin.SE3.Identity())
    joint_types = [pin.JointModelRZ, pin.JointModelRY, pin.JointModelRY, pin.JointModelRX]
    parent = root
    placement = pin.SE3(np.eye(3), np.array([0.25, 0.05, -0.1]))
    for i in range(n_joints):
        joint_id = model.addJoint(
            parent,
            joint_types[i % 4](),
            placement,
            f"joint{i + 1}",
            np.array([5.0]),
            np.array([2.0]),
            np.array([-2.5]),
            np.array([2.5]),
        )
        model.appendBodyToJoint(
            joint_id,
            pin.Inertia.FromCylinder(0.3, 0.02, 0.15),
            pin.SE3(np.eye(3), np.array([0.075, 0.0, 0.0])),
        )
        model.addJointFrame(joint_id)
        parent = joint_id
        placement = pin.SE3(np.eye(3), np.array([0.15, 0.0, 0.02]))
    tilt = pin.rpy.rpyToMatrix(0.1, -0.2, 0.3)
    model.addFrame(
        pin.Frame("ft_sensor", parent, pin.SE3(tilt, np.array([0.05, 0.0, 0.0])), pin.OP_FRAME)
    )
    model.addFrame(pin.Frame("ee", parent, pin.SE3(tilt, np.array([0.1, 0.01, 0.0])), pin.OP_FRAME))
    return model


@pytest.fixture(params=["programmatic", "reference_urdf"])
def model(request) -> pin.Model:
    if request.param == "programmatic":
        return build_test_uvms()
    return pin.buildModelFromUrdf(str(REFERENCE_URDF), pin.JointModelFreeFlyer())


def random_configuration(model: pin.Model, rng: np.random.Generator) -> np.ndarray:
    """Random q: position in a 2 m box, uniform random quaternion, joints within limits."""
    q = pin.neutral(model)
    q[:3] = rng.uniform(-1.0, 1.0, 3)
    quaternion_xyzw = rng.normal(size=4)
    q[3:7] = quaternion_xyzw / np.linalg.norm(quaternion_xyzw)
    for joint in model.joints[2:]:
        lower = model.lowerPositionLimit[joint.idx_q : joint.idx_q + joint.nq]
        upper = model.upperPositionLimit[joint.idx_q : joint.idx_q + joint.nq]
        if joint.nq == 1:
            lo = max(float(lower[0]), -np.pi)
            hi = min(float(upper[0]), np.pi)
            q[joint.idx_q] = rng.uniform(lo, hi)
        elif joint.nq == 2:  # continuous joint stored as (cos, sin)
            angle = rng.uniform(-np.pi, np.pi)
            q[joint.idx_q : joint.idx_q + 2] = [np.cos(angle), np.sin(angle)]
    return q


def well_conditioned_configurations(model, frame_id, count, seed):
    """Configurations away from the Euler singularity and from the +-pi wrap of roll/yaw."""
    rng = np.random.default_rng(seed)
    data = model.createData()
    found = []
    while len(found) < count:
        q = random_configuration(model, rng)
        _, rpy = end_effector_pose(model, data, q, frame_id)
        if abs(np.cos(rpy[1])) > 0.3 and abs(rpy[0]) < np.pi - 0.2 and abs(rpy[2]) < np.pi - 0.2:
            found.append(q)
    return found


def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_euler_rpy_round_trip_zyx():
    rng = np.random.default_rng(0)
    for _ in range(50):
        roll, yaw = rng.uniform(-np.pi + 1e-3, np.pi - 1e-3, 2)
        pitch = rng.uniform(-np.pi / 2 + 1e-3, np.pi / 2 - 1e-3)
        rotation = rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)
        np.testing.assert_allclose(euler_rpy_from_rotation(rotation), [roll, pitch, yaw], atol=1e-9)


def test_euler_rpy_rejects_bad_input():
    with pytest.raises(ParameterError):
        euler_rpy_from_rotation(np.eye(4))
    with pytest.raises(ParameterError):
        euler_rpy_from_rotation(np.full((3, 3), np.nan))


def test_euler_rate_matrix_gives_body_angular_velocity():
    """omega_body^ = R^T R_dot (central differences, h = 1e-6, error ~1e-10 -> atol 1e-7)."""
    rng = np.random.default_rng(1)
    for _ in range(20):
        rpy = rng.uniform([-3.0, -1.2, -3.0], [3.0, 1.2, 3.0])
        rpy_rate = rng.normal(size=3)
        rotation = pin.rpy.rpyToMatrix(rpy)
        rotation_dot = (
            pin.rpy.rpyToMatrix(rpy + FD_STEP * rpy_rate)
            - pin.rpy.rpyToMatrix(rpy - FD_STEP * rpy_rate)
        ) / (2 * FD_STEP)
        omega_hat = rotation.T @ rotation_dot
        omega_body = np.array([omega_hat[2, 1], omega_hat[0, 2], omega_hat[1, 0]])
        np.testing.assert_allclose(euler_rate_matrix_body(rpy) @ rpy_rate, omega_body, atol=FD_ATOL)
        assert np.linalg.det(euler_rate_matrix_body(rpy)) == pytest.approx(np.cos(rpy[1]))


def test_end_effector_pose_matches_pinocchio(model):
    data = model.createData()
    frame_id = frame_id_from_name(model, "ee")
    q = random_configuration(model, np.random.default_rng(2))
    position_world, rpy = end_effector_pose(model, data, q, frame_id)
    reference = model.createData()
    pin.framesForwardKinematics(model, reference, q)
    np.testing.assert_allclose(position_world, reference.oMf[frame_id].translation, atol=1e-12)
    np.testing.assert_allclose(
        pin.rpy.rpyToMatrix(rpy), reference.oMf[frame_id].rotation, atol=1e-12
    )


@pytest.mark.parametrize("frame_name", ["ee", "ft_sensor"])
def test_analytical_jacobian_matches_finite_differences(model, frame_name):
    """Column k of J = d/dh [p_world, rpy](q ⊕ h e_k) at h = 0, by central differences."""
    data = model.createData()
    frame_id = frame_id_from_name(model, frame_name)
    for q in well_conditioned_configurations(model, frame_id, count=8, seed=3):
        jacobian = analytical_jacobian(model, data, q, frame_id)
        assert jacobian.shape == (6, model.nv)
        fd = np.empty((6, model.nv))
        for k in range(model.nv):
            step = np.zeros(model.nv)
            step[k] = FD_STEP
            p_plus, rpy_plus = end_effector_pose(
                model, data, pin.integrate(model, q, step), frame_id
            )
            p_minus, rpy_minus = end_effector_pose(
                model, data, pin.integrate(model, q, -step), frame_id
            )
            fd[:3, k] = (p_plus - p_minus) / (2 * FD_STEP)
            fd[3:, k] = (rpy_plus - rpy_minus) / (2 * FD_STEP)
        np.testing.assert_allclose(jacobian, fd, atol=FD_ATOL, rtol=0)


def test_analytical_jacobian_vehicle_columns_analytic():
    """A body-frame vehicle translation moves the EE by world_R_body times it and does not
    change the EE orientation: J[:3, :3] = world_R_body, J[3:, :3] = 0."""
    model = build_test_uvms()
    data = model.createData()
    frame_id = frame_id_from_name(model, "ee")
    q = well_conditioned_configurations(model, frame_id, count=1, seed=4)[0]
    jacobian = analytical_jacobian(model, data, q, frame_id)
    rotation_body = pin.Quaternion(q[3:7]).matrix()  # quaternion xyzw -> world_R_body
    np.testing.assert_allclose(jacobian[:3, :3], rotation_body, atol=1e-12)
    np.testing.assert_allclose(jacobian[3:, :3], 0.0, atol=1e-12)


def test_analytical_jacobian_raises_at_euler_singularity(model):
    data = model.createData()
    frame_id = frame_id_from_name(model, "ee")
    q = pin.neutral(model)
    pin.framesForwardKinematics(model, data, q)
    rotation_ee_neutral = data.oMf[frame_id].rotation
    # Rotate the vehicle so that world_R_ee = Ry(pi/2): pitch = 90 deg exactly.
    rotation_body = rot_y(np.pi / 2) @ rotation_ee_neutral.T
    q[3:7] = pin.Quaternion(rotation_body).coeffs()
    _, rpy = end_effector_pose(model, data, q, frame_id)
    assert abs(np.cos(rpy[1])) < EULER_SINGULARITY_MIN_ABS_COS_PITCH
    with pytest.raises(ParameterError, match="singularity"):
        analytical_jacobian(model, data, q, frame_id)


def test_unknown_frame_lists_available_frames(model):
    with pytest.raises(ParameterError, match="'ee'") as info:
        frame_id_from_name(model, "gripper_tip")
    assert "gripper_tip" in str(info.value)
    assert "did you mean" not in str(info.value)  # nothing resembles it


def test_a_misspelt_frame_is_named_with_the_closest_frames_and_the_argument(model):
    with pytest.raises(ParameterError, match=r"^task frame 'e' is not a frame.*did you mean 'ee'"):
        frame_id_from_name(model, "e", "task frame")
    with pytest.raises(ParameterError, match=r"^frame None is not a frame"):
        frame_id_from_name(model, None)


def test_bad_q_raises():
    model = build_test_uvms()
    data = model.createData()
    frame_id = frame_id_from_name(model, "ee")
    with pytest.raises(ParameterError):
        end_effector_pose(model, data, np.zeros(model.nq + 1), frame_id)
    q = pin.neutral(model)
    q[0] = np.nan
    with pytest.raises(ParameterError):
        analytical_jacobian(model, data, q, frame_id)


def test_world_euler_rate_matrix_is_r_times_j_body_and_the_rotation_rate():
    """E rpy_dot = R J'' rpy_dot, and [omega_world]_x = R_dot R^T by central differences."""
    rng = np.random.default_rng(12)
    for _ in range(20):
        rpy = rng.uniform([-3.0, -1.4, -3.0], [3.0, 1.4, 3.0])
        rates = rng.normal(size=3)
        omega = np.array(angular_velocity_world_from_euler_rates(tuple(rpy), tuple(rates)))
        rotation = pin.rpy.rpyToMatrix(rpy)
        np.testing.assert_allclose(
            omega, rotation @ euler_rate_matrix_body(rpy) @ rates, rtol=0, atol=1e-14
        )
        h = 1e-6
        rotation_dot = (
            pin.rpy.rpyToMatrix(rpy + h * rates) - pin.rpy.rpyToMatrix(rpy - h * rates)
        ) / (2 * h)
        np.testing.assert_allclose(pin.skew(omega), rotation_dot @ rotation.T, atol=1e-8)


def test_one_pass_rotation_and_jacobian(model):
    """frame_rotation_and_jacobian = the frame rotation and LOCAL_WORLD_ALIGNED Jacobian of
    the full passes, and diag(I, E^-1) J^lwa is the analytical Jacobian."""
    frame_id = frame_id_from_name(model, "ee")
    data, reference = model.createData(), model.createData()
    for q in well_conditioned_configurations(model, frame_id, 10, seed=4):
        rotation, jacobian_lwa = frame_rotation_and_jacobian(model, data, q, frame_id)
        pin.computeJointJacobians(model, reference, q)
        pin.updateFramePlacements(model, reference)
        np.testing.assert_allclose(rotation, reference.oMf[frame_id].rotation, atol=1e-15)
        expected = pin.getFrameJacobian(
            model, reference, frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        )
        np.testing.assert_allclose(jacobian_lwa, expected, atol=1e-14)
        rpy = euler_rpy_from_rotation(rotation)
        world_rate_matrix = np.column_stack(
            [angular_velocity_world_from_euler_rates(tuple(rpy), tuple(e)) for e in np.eye(3)]
        )
        analytical = np.vstack(
            [jacobian_lwa[:3], np.linalg.solve(world_rate_matrix, jacobian_lwa[3:])]
        )
        np.testing.assert_allclose(
            analytical, analytical_jacobian(model, reference, q, frame_id), atol=1e-13
        )


def test_a_frame_id_is_one_of_the_models_frames():
    """0 (the universe) to nframes - 1: Pinocchio reads past its frames otherwise."""
    model = pin.buildModelFromUrdf(str(REFERENCE_URDF), pin.JointModelFreeFlyer())
    assert check_frame_id(model, 0) == 0
    assert check_frame_id(model, np.int64(model.nframes - 1)) == model.nframes - 1
    for bad in (model.nframes, -1):
        with pytest.raises(ParameterError, match=rf"frame_id {bad} out of range"):
            check_frame_id(model, bad)
    for bad in (True, 1.0, "ee"):
        with pytest.raises(ParameterError, match="frame_id must be an integer"):
            check_frame_id(model, bad)
