"""Names in the merged file: clashes get the prefix arm_."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from uvms_pin.model.mount.names import (
    added_names,
    original_name,
    rename_clashes,
    unique_frame_names,
)
from uvms_pin.model.mount.tree import URDFTree

ARM = """<robot name="arm">
  <link name="base_link"/><link name="ee"/><link name="arm_ee"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="ee"/></joint>
  <joint name="j2" type="revolute"><parent link="ee"/><child link="arm_ee"/>
    <mimic joint="j1"/></joint>
</robot>"""


def test_added_frames_are_prefixed_while_the_vehicle_uses_their_names():
    frames = unique_frame_names({"ee", "arm_ee", "tool"})
    assert frames["ee"] == "arm_arm_ee"
    assert frames["tool"] == "arm_tool"
    assert frames["ft_sensor"] == "ft_sensor"


def test_reserved_names_follow_the_frames_that_will_be_added():
    assert {"ft_sensor", "tool", "ee"} <= added_names(sensor_link=None, with_tool=True, ee_link="x")
    no_tool = added_names(sensor_link="s", with_tool=False, ee_link="ee")
    assert not {"ft_sensor", "tool", "ee"} & no_tool
    assert "trim_foam" in no_tool and "arm_mount_joint" in no_tool


def test_clashing_names_and_every_reference_to_them_are_renamed():
    arm = URDFTree(ET.fromstring(ARM), Path("arm.urdf"))
    links = [ET.fromstring(ET.tostring(arm.links[n])) for n in arm.link_order]
    joints = [ET.fromstring(ET.tostring(arm.joints[n])) for n in arm.joint_order]
    renamed = rename_clashes(arm, links, joints, {"base_link", "j1"}, {"ee"})
    # arm_ee is taken in the arm file: the prefix repeats
    assert renamed == {"base_link": "arm_base_link", "ee": "arm_arm_ee", "j1": "arm_j1"}
    assert [link.get("name") for link in links] == ["arm_base_link", "arm_arm_ee", "arm_ee"]
    assert joints[0].find("parent").get("link") == "arm_base_link"
    assert joints[1].find("parent").get("link") == "arm_arm_ee"
    assert joints[1].find("mimic").get("joint") == "arm_j1"
    assert original_name("arm_arm_ee", renamed) == "ee"
    assert original_name("arm_ee", renamed) == "arm_ee"
