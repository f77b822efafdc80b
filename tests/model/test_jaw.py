"""Jaw joints: the naming rule and the shipped Alpha 5 jaw (Reach Robotics' description)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.errors import ModelError
from uvms_pin.model.jaw import JawJoints, is_jaw_name, slice_if_consecutive

MODELS = Path(__file__).resolve().parents[2] / "models"
JAWS = MODELS / "uvms_bluerov2_alpha5_jaws.urdf"
FINGERS = ("alpha_jaw_finger_130_joint", "alpha_jaw_finger_139_joint")


@pytest.fixture(scope="module")
def uvms() -> up.UVMS:
    return up.load_uvms(JAWS)


def test_naming_rule():
    assert is_jaw_name("left_FINGER_joint") and is_jaw_name("gripper") and is_jaw_name("jaw_a")
    assert not is_jaw_name("alpha_axis_b") and not is_jaw_name("wrist_roll")


def test_consecutive_indices_read_as_a_slice_the_same_entries():
    values = np.arange(10.0) * 1.5
    for index in (np.array([3, 4, 5]), np.array([0]), np.array([8, 9])):
        at = slice_if_consecutive(index)
        assert isinstance(at, slice)
        np.testing.assert_array_equal(values[at], values[index])
    for index in (np.array([1, 3]), np.array([5, 4]), np.array([], dtype=int)):
        assert slice_if_consecutive(index) is index


def test_the_alpha5_jaw_as_reach_describes_it(uvms):
    jaw = JawJoints.of(uvms.model)
    assert jaw.names == FINGERS
    np.testing.assert_array_equal(jaw.lower, [0.0, 0.0])  # closed
    np.testing.assert_array_equal(jaw.upper, [0.5, 0.5])  # open [rad]
    np.testing.assert_array_equal(jaw.v_index, [10, 11])
    np.testing.assert_array_equal(jaw.arm_v_index, np.arange(10))
    model = uvms.model
    for name in FINGERS:
        inertia = model.inertias[model.getJointId(name)]
        assert inertia.mass == pytest.approx(0.055)
        assert model.effortLimit[model.joints[model.getJointId(name)].idx_v] == 10.0
    # the two pivots 31 mm apart across the jaw, the fingers' boxes (R26) 9 cm long
    data = model.createData()
    q = pin.neutral(model)
    pin.forwardKinematics(model, data, q)
    a, b = (data.oMi[model.getJointId(n)].translation for n in FINGERS)
    assert np.linalg.norm(a - b) == pytest.approx(0.031)


def test_opening_the_fingers_moves_their_tips_apart(uvms):
    model, data = uvms.model, uvms.model.createData()

    def tip_gap(angle: float) -> float:
        q = pin.neutral(model)
        q[-2:] = angle
        pin.forwardKinematics(model, data, q)
        tips = [
            data.oMi[model.getJointId(n)].act(np.array([0.0, s * 0.008, 0.09]))
            for n, s in zip(FINGERS, (-1.0, 1.0), strict=True)
        ]
        return float(np.linalg.norm(tips[0] - tips[1]))

    assert tip_gap(0.0) == pytest.approx(0.031 - 2 * 0.008, abs=1e-9)
    for angle in (0.25, 0.5):  # each tip swings out about its pivot, 15.5 mm off the centre
        expected = 2 * (0.0155 - 0.008 * np.cos(angle) + 0.09 * np.sin(angle))
        assert tip_gap(angle) == pytest.approx(expected, rel=1e-12)
    assert tip_gap(0.5) == pytest.approx(0.1032, abs=1e-4)  # the jaw fully open: 10.3 cm


def test_jaw_joints_by_name_and_bad_names(uvms):
    jaw = JawJoints.of(uvms.model, [FINGERS[1]])
    assert jaw.names == (FINGERS[1],)
    with pytest.raises(ModelError, match="not among the model's moving joints"):
        JawJoints.of(uvms.model, ["no_such_joint"])
    with pytest.raises(ModelError, match="moves below the jaw joint"):
        JawJoints.of(uvms.model, ["alpha_axis_c"])  # the wrist and the fingers move below it


def test_a_model_without_jaw_has_none():
    uvms = up.load_uvms(MODELS / "uvms_bluerov2_alpha5.urdf")
    assert JawJoints.of(uvms.model).count == 0


def test_a_continuous_jaw_joint_is_refused():
    """A continuous joint (one degree of freedom, but cos and sin in q: nq = 2) turns without
    an open and a closed end: refused as a jaw joint by its kind, before its limits."""
    text = JAWS.read_text().replace(
        f'<joint name="{FINGERS[0]}" type="revolute">',
        f'<joint name="{FINGERS[0]}" type="continuous">',
    )
    model = pin.buildModelFromXML(text, pin.JointModelFreeFlyer())
    assert model.joints[model.getJointId(FINGERS[0])].nq == 2
    with pytest.raises(ModelError, match=f"jaw joint '{FINGERS[0]}' .* must be revolute or"):
        JawJoints.of(model, [FINGERS[0]])
