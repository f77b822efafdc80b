"""The arm's model with its jaw locked: the same bodies, without the finger joints."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up
from uvms_pin.model.jaw import JawJoints
from uvms_pin.model.jaw_locked import jaw_locked

JAWS = Path(__file__).resolve().parents[2] / "models" / "uvms_bluerov2_alpha5_jaws.urdf"


@pytest.fixture(scope="module")
def uvms() -> up.UVMS:
    return up.load_uvms(JAWS)


def test_locked_jaw_is_the_same_body_without_the_finger_joints(uvms):
    jaw = JawJoints.of(uvms.model)
    locked = jaw_locked(uvms, jaw, jaw.lower)
    assert (locked.nq, locked.nv) == (uvms.nq - 2, uvms.nv - 2)
    assert locked.mass_kg == pytest.approx(uvms.mass_kg, rel=1e-12)
    assert locked.volume_m3 == pytest.approx(uvms.volume_m3, rel=1e-12)
    # same mass matrix on the vehicle and the arm at the locked position
    q = pin.neutral(uvms.model)
    q[7:11] = (0.1, 0.8, 2.2, -0.3)
    full = pin.crba(uvms.model, uvms.model.createData(), q)
    arm = pin.crba(locked.model, locked.model.createData(), q[jaw.arm_q_index])
    full, arm = np.triu(full) + np.triu(full, 1).T, np.triu(arm) + np.triu(arm, 1).T
    np.testing.assert_allclose(arm, full[np.ix_(jaw.arm_v_index, jaw.arm_v_index)], atol=1e-12)
    assert locked.model.frames[locked.ee_frame_id].name == "ee"


def test_locked_open_the_fingers_ride_open(uvms):
    jaw = JawJoints.of(uvms.model)
    locked = jaw_locked(uvms, jaw, jaw.upper)
    q = pin.neutral(uvms.model)
    q[jaw.q_index] = jaw.upper
    frames = []
    for model, config in ((uvms.model, q), (locked.model, q[jaw.arm_q_index])):
        data = model.createData()
        pin.framesForwardKinematics(model, data, config)
        frames.append(data.oMf[model.getFrameId("alpha_jaw_finger_130_link")])
    assert frames[0].isApprox(frames[1], 1e-12)  # the open finger, where the moving one is
    closed = jaw_locked(uvms, jaw, jaw.lower).model
    data = closed.createData()
    pin.framesForwardKinematics(closed, data, q[jaw.arm_q_index])
    assert not frames[0].isApprox(data.oMf[closed.getFrameId("alpha_jaw_finger_130_link")], 1e-3)
    com_full = pin.centerOfMass(uvms.model, uvms.model.createData(), q)
    com_locked = pin.centerOfMass(locked.model, locked.model.createData(), q[jaw.arm_q_index])
    np.testing.assert_allclose(com_locked, com_full, atol=1e-12)


def test_a_lock_position_outside_the_limits_is_refused(uvms):
    jaw = JawJoints.of(uvms.model)
    with pytest.raises(up.ParameterError, match="outside its limits"):
        jaw_locked(uvms, jaw, [0.0, 0.7])
