"""URDFTree: a URDF file as a checked kinematic tree."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from uvms_pin.errors import ModelError
from uvms_pin.model.mount.tree import URDFTree

# base -j1(revolute)-> a -fa(fixed)-> b -j2(prismatic)-> c ; a -j3(continuous)-> d
ARM = """<robot name="r">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/></joint>
  <joint name="fa" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="j2" type="prismatic"><parent link="b"/><child link="c"/></joint>
  <joint name="j3" type="continuous"><parent link="a"/><child link="d"/></joint>
</robot>"""


def tree(text: str = ARM) -> URDFTree:
    return URDFTree(ET.fromstring(text), Path("arm.urdf"))


def test_links_joints_parents_and_root():
    t = tree()
    assert t.link_order == ["base", "a", "b", "c", "d"]
    assert t.joint_order == ["j1", "fa", "j2", "j3"]
    assert t.root_link == "base"
    assert t.parent_joint == {"a": "j1", "b": "fa", "c": "j2", "d": "j3"}
    assert t.children["a"] == ["fa", "j3"]
    assert (t.parent_of("j2"), t.child_of("j2")) == ("b", "c")


def test_subtree_path_and_moving_joints():
    t = tree()
    assert sorted(t.subtree("a")) == ["a", "b", "c", "d"]
    assert t.path_joints("base", "c") == ["j1", "fa", "j2"]
    assert [t.is_moving(j) for j in t.joint_order] == [True, False, True, True]
    assert t.moving_below("a") == 2 and t.moving_below("c") == 0
    assert not t.moving_above("j1") and t.moving_above("j2")


def test_require_link_lists_the_links():
    with pytest.raises(ModelError, match=r"ee_link 'x' is not a link.*base, a, b, c, d"):
        tree().require_link("x", "ee_link")


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('<robot><link name="a"/><link name="a"/></robot>', "link 'a': is defined twice"),
        ("<robot><link/></robot>", "a <link> has no name"),
        ("<robot></robot>", "no <link> elements"),
        (
            '<robot><link name="a"/><link name="b"/>'
            '<joint name="j" type="fixed"><child link="b"/></joint></robot>',
            "joint 'j' needs <parent> and <child>",
        ),
        (
            '<robot><link name="a"/><link name="b"/>'
            '<joint name="j" type="fixed"><parent link="a"/><child link="q"/></joint></robot>',
            "joint 'j': unknown child link 'q'",
        ),
        ('<robot><link name="a"/><link name="b"/></robot>', "expected one root link, found 2"),
        (
            '<robot><link name="r"/><link name="a"/><link name="b"/>'
            '<joint name="j0" type="fixed"><parent link="a"/><child link="b"/></joint>'
            '<joint name="j1" type="fixed"><parent link="b"/><child link="a"/></joint></robot>',
            "the joints form a cycle",
        ),
    ],
)
def test_malformed_trees_are_named(text, match):
    with pytest.raises(ModelError, match=match) as info:
        tree(text)
    assert "arm.urdf" in str(info.value)
