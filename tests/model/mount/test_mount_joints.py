"""The arm's joints as a UVMS needs them: chain joints keep moving, the others are locked."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.mount.joints import CONTINUOUS_LIMIT_RAD, lock_joint, prepare_arm_joints
from uvms_pin.model.mount.origin import origin_of

PATH = Path("arm.urdf")


def joint(kind: str, limit: str = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'):
    return ET.fromstring(
        f'<joint name="j" type="{kind}"><parent link="a"/><child link="b"/>'
        f'<origin xyz="0.1 0 0" rpy="0 0 0.5"/><axis xyz="0 0 2"/>{limit}'
        '<mimic joint="k"/></joint>'
    )


def test_a_locked_revolute_joint_folds_its_rotation_into_the_origin():
    j = joint("revolute")
    assert lock_joint(j, 0.25, PATH) == 0.25
    assert j.get("type") == "fixed"
    assert [c.tag for c in j] == ["parent", "child", "origin"]
    expected = pin.SE3(pin.rpy.rpyToMatrix(0, 0, 0.5), np.array([0.1, 0, 0])) * pin.SE3(
        pin.rpy.rpyToMatrix(0, 0, 0.25), np.zeros(3)
    )
    assert origin_of(j, PATH).isApprox(expected, 1e-12)


def test_a_locked_prismatic_joint_moves_its_origin_along_the_axis():
    j = joint("prismatic", '<limit lower="0" upper="0.2" effort="1" velocity="1"/>')
    assert lock_joint(j, 0.05, PATH) == 0.05
    moved = origin_of(j, PATH).translation
    assert np.allclose(moved, [0.1, 0.0, 0.05])


def test_the_default_lock_position_is_zero_clipped_into_the_limits():
    j = joint("prismatic", '<limit lower="0.01" upper="0.2" effort="1" velocity="1"/>')
    assert lock_joint(j, None, PATH) == 0.01


def test_a_lock_position_outside_the_limits_is_refused():
    with pytest.raises(ParameterError, match=r"lock position 2.0 of joint 'j'.*\[-1.0, 1.0\]"):
        lock_joint(joint("revolute"), 2.0, PATH)
    assert lock_joint(joint("continuous", ""), 7.0, PATH) == 7.0  # no limits


def test_chain_joints_keep_moving_and_the_others_are_locked():
    chain, finger = joint("continuous"), joint("revolute")
    finger.set("name", "finger")
    locked = prepare_arm_joints([chain, finger], ["j"], {"finger": 0.5}, PATH)
    assert locked == {"finger": 0.5}
    assert chain.get("type") == "revolute" and chain.find("mimic") is None
    limit = chain.find("limit")
    assert float(limit.get("upper")) == CONTINUOUS_LIMIT_RAD == 2.0 * math.pi
    assert float(limit.get("lower")) == -CONTINUOUS_LIMIT_RAD
    assert finger.get("type") == "fixed"


@pytest.mark.parametrize(
    ("kind", "limit", "match"),
    [
        ("floating", "", "joint 'j' is floating: an arm may only have"),
        ("screw", "", "joint 'j' has unknown type 'screw'"),
        ("continuous", "", "continuous joint 'j' has no <limit effort velocity>"),
    ],
)
def test_joints_an_arm_cannot_have(kind, limit, match):
    with pytest.raises(ModelError, match=match):
        prepare_arm_joints([joint(kind, limit)], ["j"], {}, PATH)
