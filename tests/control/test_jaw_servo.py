"""The jaw's force-limited servo and the arm's controller beside it."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.control.base import Controller
from uvms_pin.control.jaw_servo import JawSchedule, JawServo, WithJaw
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ParameterError
from uvms_pin.model.jaw import JawJoints

JAWS = Path(__file__).resolve().parents[2] / "models" / "uvms_bluerov2_alpha5_jaws.urdf"


@pytest.fixture(scope="module")
def uvms() -> up.UVMS:
    return up.load_uvms(JAWS)


@pytest.fixture(scope="module")
def servo(uvms) -> JawServo:
    return JawServo.for_model(uvms.model, JawJoints.of(uvms.model), 10.0, JawSchedule(1.0, 3.0))


def test_lever_is_the_fingers_centre_of_mass_off_its_axis(servo):
    # Reach's finger box centre (0, -8, 45) mm from the pivot, the axis along x
    np.testing.assert_allclose(servo.lever_m, np.hypot(0.008, 0.045), rtol=1e-12)


def test_schedule_closes_then_opens(servo):
    np.testing.assert_array_equal(servo.target(0.5), [0.5, 0.5])
    np.testing.assert_array_equal(servo.target(1.0), [0.0, 0.0])
    np.testing.assert_array_equal(servo.target(2.99), [0.0, 0.0])
    np.testing.assert_array_equal(servo.target(3.0), [0.5, 0.5])


def test_grip_saturates_at_max_force_times_lever(servo):
    # blocked by an object at 0.3 rad with the jaw closing: pressing with 10 N at the lever
    tau = servo.torque(2.0, np.array([0.3, 0.3]), np.zeros(2))
    np.testing.assert_allclose(tau, -10.0 * servo.lever_m, rtol=1e-12)
    # 5 % of the travel from the target: the linear range's edge
    near = servo.torque(2.0, np.array([0.025, 0.0125]), np.zeros(2))
    np.testing.assert_allclose(near, -10.0 * servo.lever_m * np.array([1.0, 0.5]), rtol=1e-12)
    assert np.all(servo.torque(2.0, np.zeros(2), np.zeros(2)) == 0.0)


@pytest.mark.parametrize(
    ("close", "reopen", "match"),
    [(-1.0, None, "close_at_s"), (2.0, 1.0, "must come after"), (np.inf, None, "close_at_s")],
)
def test_bad_schedules(close, reopen, match):
    with pytest.raises(ParameterError, match=match):
        JawSchedule(close, reopen)


def test_bad_force(uvms):
    with pytest.raises(ParameterError, match="max_force_N"):
        JawServo.for_model(uvms.model, JawJoints.of(uvms.model), 0.0, JawSchedule())


class _Recorder(Controller):
    def __init__(self):
        self.seen = None

    def compute(self, time_s, measurement):
        self.seen = measurement
        return np.arange(10.0)


def test_the_arm_controller_sees_and_commands_the_arm_only(uvms, servo):
    arm = _Recorder()
    both = WithJaw(arm, servo, uvms.nv, (False, False))
    q = np.zeros(uvms.nq)
    q[6] = 1.0
    q[11:] = (0.2, 0.4)
    v = np.arange(uvms.nv, dtype=float)
    tau = both.compute(2.0, Measurement(2.0, q, v, np.zeros(6)))
    assert arm.seen.q.shape == (11,) and arm.seen.v.shape == (10,)
    np.testing.assert_array_equal(arm.seen.v, np.arange(10.0))
    np.testing.assert_array_equal(tau[:10], np.arange(10.0))
    np.testing.assert_allclose(tau[10:], servo.torque(2.0, np.array([0.2, 0.4]), v[10:]))
    jaw = both.signals()["jaw"]
    assert jaw.components == (
        "alpha_jaw_finger_130_joint",
        "alpha_jaw_finger_139_joint",
        "alpha_jaw_finger_130_joint_grip",
        "alpha_jaw_finger_139_joint_grip",
    )
    assert jaw.units == ("rad", "rad", "N", "N")
    np.testing.assert_allclose(jaw.values[:2], [0.2, 0.4])
    np.testing.assert_allclose(jaw.values[2:], 10.0)  # both saturated


def test_a_sampled_servo_is_softened_for_light_fingers(uvms, servo):
    jaw = JawJoints.of(uvms.model)
    sampled = JawServo.for_model(uvms.model, jaw, 10.0, JawSchedule(), period_s=0.002)
    inertia = servo.damping**2 / (4.0 * servo.stiffness)  # d = 2 sqrt(k I)
    np.testing.assert_allclose(sampled.stiffness, inertia / (4.0 * 0.002**2), rtol=1e-12)
    assert np.all(sampled.stiffness < servo.stiffness)
    np.testing.assert_allclose(sampled.damping * 0.002 / inertia, 1.0, rtol=1e-12)
    fast = JawServo.for_model(uvms.model, jaw, 10.0, JawSchedule(), period_s=1e-4)
    np.testing.assert_array_equal(fast.stiffness, servo.stiffness)  # no cap needed


def test_servo_damping_opposes_the_fingers_velocity_critically(uvms, servo):
    """In the linear range the law is tau = k (q* - q) - d v: its velocity part is -d v, with
    d = 2 sqrt(k I) (critical damping of the finger's inertia I about its joint, from CRBA at
    the closed position, armature included)."""
    jaw = JawJoints.of(uvms.model)
    q = jaw.lower + np.array([0.001, 0.002])  # near the closed target, far from saturation
    v = np.array([0.05, -0.03])
    at_rest = servo.torque(2.0, q, np.zeros(2))
    moving = servo.torque(2.0, q, v)
    assert np.all(np.abs(moving) < servo.max_force_N * servo.lever_m)  # unsaturated
    np.testing.assert_allclose(moving - at_rest, -servo.damping * v, rtol=1e-12)
    q_closed = uvms.neutral_configuration()
    q_closed[jaw.q_index] = jaw.lower
    mass = pin.crba(uvms.model, uvms.model.createData(), q_closed)
    inertia = np.array([mass[i, i] for i in jaw.v_index])
    np.testing.assert_allclose(servo.damping, 2.0 * np.sqrt(servo.stiffness * inertia), rtol=1e-12)


def test_a_jaw_motors_armature_is_counted_once_in_the_fingers_inertia(uvms):
    """A motor's reflected inertia (the joint's armature A) adds to the finger's own once:
    I = M_ii(without A) + A, which sets the sampled servo's cap k = I / (4 T^2) and its
    critical damping d = 2 sqrt(k I)."""
    jaw = JawJoints.of(uvms.model)
    bare = JawServo.for_model(uvms.model, jaw, 10.0, JawSchedule(), period_s=0.005)
    bare_inertia = bare.damping**2 / (4.0 * bare.stiffness)
    model = uvms.model.copy()
    armature = np.array([3e-4, 5e-4])
    model.armature[jaw.v_index] = armature
    geared = JawServo.for_model(model, jaw, 10.0, JawSchedule(), period_s=0.005)
    inertia = bare_inertia + armature
    uncapped = 10.0 * geared.lever_m / (0.05 * (jaw.upper - jaw.lower))
    assert np.all(geared.stiffness < uncapped)  # the cap binds
    np.testing.assert_allclose(geared.stiffness, inertia / (4.0 * 0.005**2), rtol=1e-12)
    np.testing.assert_allclose(
        geared.damping, 2.0 * np.sqrt(geared.stiffness * inertia), rtol=1e-12
    )


def test_lever_ignores_the_centre_of_mass_offset_along_the_joint_axis(uvms):
    """r = |c - (c . a) a|: the finger's centre of mass slid along the joint axis a keeps its
    distance from the axis, hence its lever (the grip force F_max r)."""
    model = pin.Model(uvms.model)
    jaw = JawJoints.of(model)
    before = JawServo.for_model(model, jaw, 10.0, JawSchedule()).lever_m
    for j in jaw.joint_ids:
        joint_data = model.joints[j].createData()
        model.joints[j].calc(joint_data, pin.neutral(model))
        axis = np.array(joint_data.S).reshape(-1)[3:]  # the revolute axis, joint frame
        inertia = model.inertias[j]
        model.inertias[j] = pin.Inertia(inertia.mass, inertia.lever + 0.03 * axis, inertia.inertia)
    after = JawServo.for_model(model, jaw, 10.0, JawSchedule()).lever_m
    # 1e-9: the unaligned joint's axis and the 3 cm slide are rounded (the slide alone would
    # change the lever by 20 %)
    np.testing.assert_allclose(after, before, rtol=1e-9)


def test_a_prismatic_finger_s_servo_pushes_with_the_grip_force_itself(tmp_path):
    """A prismatic finger's tau is its force [N]: its lever is 1, and blocked while closing
    the servo presses with exactly -F_max."""
    from jaw_helpers import parallel_jaw_urdf

    model = up.load_uvms(parallel_jaw_urdf(tmp_path)).model
    jaw = JawJoints.of(model)
    servo = JawServo.for_model(model, jaw, 7.0, JawSchedule(0.0))
    np.testing.assert_array_equal(servo.lever_m, [1.0, 1.0])
    blocked = servo.torque(1.0, jaw.upper * 0.5, np.zeros(2))
    np.testing.assert_allclose(blocked, [-7.0, -7.0], rtol=1e-15)


def test_a_jaw_whose_joints_have_ros_namespaces_runs_and_logs_them_by_label(tmp_path):
    """Gazebo and ROS models name their links and joints ``robot/joint`` (uuv_simulator's
    Oberon 7: ``oberon7/finger_left_joint``): the jaw's log labels them (``bluerov_...``)
    instead of refusing the run at its first tick."""
    text = JAWS.read_text()
    names = set(re.findall(r'<(?:link|joint) name="([^"]+)"', text))
    for name in sorted(names, key=len, reverse=True):
        text = text.replace(f'"{name}"', f'"bluerov/{name}"')
    model = tmp_path / "namespaced.urdf"
    model.write_text(text)
    scenario = up.load_scenario(
        JAWS.parents[1] / "scenarios" / "gripper_close.toml",
        {"scenario.model": str(model), "scenario.duration_s": 0.4},
    )
    rollout = up.simulate(scenario, progress=False)
    assert rollout.metadata["status"] == "ok"
    finger = rollout.signals["jaw"][:, 0]
    assert finger[0] == pytest.approx(0.5) and finger[-1] < 0.45  # it closed at 0.2 s
    assert rollout.metadata["signal_units"]["jaw"]["components"][:2] == [
        "bluerov_alpha_jaw_finger_130_joint",
        "bluerov_alpha_jaw_finger_139_joint",
    ]
