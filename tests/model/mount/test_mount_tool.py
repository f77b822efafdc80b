"""The tool on the wrist: the tool axis, the probe and the frames the mount adds."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.model.mount.names import unique_frame_names
from uvms_pin.model.mount.origin import origin_of
from uvms_pin.model.mount.tool import (
    ProbeTool,
    add_tool_frames,
    probe_link,
    rotation_with_x,
    tool_axis_in_link,
)
from uvms_pin.model.mount.tree import URDFTree

# base -j1 (about z)-> l1, 0.2 m along x -> l2 -j2 (about y, its frame turned)-> wrist
ARM = """<robot name="arm">
  <link name="base"/><link name="l1"/><link name="wrist"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="wrist"/>
    <origin xyz="0.2 0 0" rpy="0 -1.5707963267948966 0"/><axis xyz="0 0 -1"/></joint>
</robot>"""
PATH = Path("arm.urdf")


@pytest.fixture
def arm() -> URDFTree:
    return URDFTree(ET.fromstring(ARM), PATH)


def test_named_and_vector_tool_axes(arm):
    named = {"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1],
             "-x": [-1, 0, 0], "-y": [0, -1, 0], "-z": [0, 0, -1]}  # fmt: skip
    for name, axis in named.items():
        assert tool_axis_in_link(arm, name, ["j1", "j2"], "wrist", PATH).tolist() == axis
    axis = tool_axis_in_link(arm, [0.0, 3.0, 4.0], ["j1", "j2"], "wrist", PATH)
    assert np.allclose(axis, [0.0, 0.6, 0.8])
    with pytest.raises(ParameterError, match="tool_axis must be 'auto', one of x"):
        tool_axis_in_link(arm, "up", ["j1", "j2"], "wrist", PATH)
    with pytest.raises(ParameterError, match="non-zero finite 3-vector"):
        tool_axis_in_link(arm, [0.0, 0.0, 0.0], ["j1", "j2"], "wrist", PATH)


def test_the_auto_tool_axis_is_the_last_joint_axis_pointing_away_from_the_arm(arm):
    # j2's axis -z in the wrist frame is +x in l1 (the wrist frame is turned by -90 deg
    # about y), the way from l1 to the wrist: it is kept
    axis = tool_axis_in_link(arm, "auto", ["j1", "j2"], "wrist", PATH)
    assert np.allclose(axis, [0.0, 0.0, -1.0])


def test_rotation_with_x_is_a_rotation():
    for axis in ([1.0, 0, 0], [0, 1.0, 0], [0.3, -0.4, 0.866]):
        r = rotation_with_x(np.array(axis))
        assert np.allclose(r[:, 0], np.array(axis) / np.linalg.norm(axis))
        assert np.allclose(r.T @ r, np.eye(3)) and np.isclose(np.linalg.det(r), 1.0)


def test_probe_link_is_a_cylinder_along_x():
    link = probe_link("tool", ProbeTool(length_m=0.1, radius_m=0.01, mass_kg=0.2))
    assert link.find("inertial/origin").get("xyz") == "0.05 0.0 0.0"
    inertia = link.find("inertial/inertia")
    assert float(inertia.get("ixx")) == pytest.approx(0.5 * 0.2 * 0.01**2)
    assert float(inertia.get("iyy")) == pytest.approx(0.2 * (3 * 0.01**2 + 0.1**2) / 12)
    assert link.find("collision/geometry/cylinder").get("length") == "0.1"
    # a URDF cylinder lies along its z: turned onto the link's x, from the origin to the tip
    for tag in ("collision", "visual"):
        origin = origin_of(link.find(tag), PATH)
        np.testing.assert_allclose(np.abs(origin.rotation @ [0.0, 0.0, 1.0]), [1, 0, 0], atol=1e-12)
        np.testing.assert_allclose(origin.translation, [0.05, 0.0, 0.0], atol=1e-15)


def test_the_sensor_tool_and_ee_frames():
    out = ET.Element("robot")
    frames = unique_frame_names(set())
    sensor, ee = add_tool_frames(out, frames, "wrist", None, ProbeTool(), np.array([0, 0, 1.0]))
    assert (sensor, ee) == ("ft_sensor", "ee")
    assert [e.get("name") for e in out] == [
        "ft_sensor", "ft_sensor_joint", "tool", "tool_joint", "ee", "ee_joint",
    ]  # fmt: skip
    sensor_joint = out.find("joint[@name='ft_sensor_joint']")
    assert np.allclose(origin_of(sensor_joint, PATH).rotation[:, 0], [0, 0, 1])
    tip = origin_of(out.find("joint[@name='ee_joint']"), PATH)
    assert np.allclose(tip.translation, [ProbeTool().length_m, 0, 0])


def test_without_a_tool_the_ee_frame_is_the_sensor_frame_or_the_wrist():
    out = ET.Element("robot")
    frames = unique_frame_names(set())
    assert add_tool_frames(out, frames, "wrist", "flange", None, np.array([1.0, 0, 0])) == (
        "flange",
        "ee",
    )
    assert [e.get("name") for e in out] == ["ee", "ee_joint"]
    out = ET.Element("robot")
    assert add_tool_frames(out, frames, "ee", "ee", None, np.array([1.0, 0, 0])) == ("ee", "ee")
    assert len(out) == 0
