"""Mounting an arm with its jaw: locked by default, moving with ``moving_jaw=True``."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from uvms_pin.model.mount.merge import merge_urdf

MODELS = Path(__file__).resolve().parents[3] / "models"
FINGERS = ["alpha_jaw_finger_130_joint", "alpha_jaw_finger_139_joint"]
MOUNT = ((0.25, -0.10965, 0.005), (0.0, 0.0, 0.0))


def _merge(**options):
    return merge_urdf(
        MODELS / "bluerov2_heavy.urdf", MODELS / "reach_alpha5_jaws.urdf", MOUNT, **options
    )


def _joint(merged, name: str) -> ET.Element:
    return next(j for j in merged.root.findall("joint") if j.get("name") == name)


def test_the_jaw_is_locked_by_default():
    merged = _merge(tool=None)
    assert merged.locked_joints == dict.fromkeys(FINGERS, 0.0)  # closed, 0 rad
    assert [_joint(merged, n).get("type") for n in FINGERS] == ["fixed", "fixed"]
    assert merged.arm_joints[-1] == "alpha_axis_b"


def test_a_moving_jaw_keeps_its_fingers_each_its_own_joint():
    merged = _merge(tool=None, moving_jaw=True)
    assert merged.locked_joints == {}
    assert merged.arm_joints[-2:] == FINGERS
    for name in FINGERS:
        joint = _joint(merged, name)
        assert joint.get("type") == "revolute"
        assert joint.find("mimic") is None  # the arm file couples them: dropped here
    assert _joint(merged, FINGERS[0]).find("limit").get("upper") == "0.5"
