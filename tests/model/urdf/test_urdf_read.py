"""Reading URDF text: numbers and origins of attributes, the <robot> root of a file."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ModelError
from uvms_pin.model.urdf.read import read_numbers, read_origin, read_urdf_root


def test_read_numbers():
    assert read_numbers(" 1 2e-3\n-4 ", 3, "<x>", "f.urdf", "l").tolist() == [1.0, 0.002, -4.0]


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (None, "<x> is missing its value"),
        ("1 a 3", "<x> has a non-numeric value '1 a 3'"),
        ("1 2", "<x> needs 3 numbers, got 2"),
        ("1 inf 3", "<x> has a non-finite value"),
    ],
)
def test_read_numbers_names_what_is_wrong(text, match):
    with pytest.raises(ModelError, match=match) as info:
        read_numbers(text, 3, "<x>", "f.urdf", "l")
    assert "f.urdf" in str(info.value) and "'l'" in str(info.value)


def test_read_origin():
    assert read_origin(None, "f.urdf", "l").isIdentity()
    origin = read_origin(ET.fromstring('<origin xyz="1 2 3" rpy="0 0 0.5"/>'), "f.urdf", "l")
    assert np.allclose(origin.translation, [1, 2, 3])
    assert np.allclose(origin.rotation, pin.rpy.rpyToMatrix(0, 0, 0.5))
    with pytest.raises(ModelError, match="<origin rpy> needs 3 numbers"):
        read_origin(ET.fromstring('<origin rpy="0 1"/>'), "f.urdf", "l")


def test_read_urdf_root(tmp_path):
    with pytest.raises(ModelError, match="file not found"):
        read_urdf_root(tmp_path / "none.urdf")
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot")
    with pytest.raises(ModelError, match="not well-formed XML"):
        read_urdf_root(bad)
    bad.write_text("<sdf/>")
    with pytest.raises(ModelError, match="root element is <sdf>, expected <robot>") as sdf:
        read_urdf_root(bad)
    assert "uvms-pin import FILE --out model.urdf" in str(sdf.value)  # the way to convert it
    bad.write_text("<launch/>")
    with pytest.raises(ModelError, match="root element is <launch>, expected <robot>") as other:
        read_urdf_root(bad)
    assert "import" not in str(other.value)  # no conversion to offer
    bad.write_text('<robot name="r"/>')
    assert read_urdf_root(bad).get("name") == "r"


@pytest.mark.parametrize("prefix", ["xacro", "gazebo_ext"])
def test_a_prefix_used_without_its_declaration_is_read(tmp_path, prefix):
    """Gazebo and xacro read elements of a prefix nobody declared; the URDF is read with the
    prefix declared (xacro's own namespace, or one of uvms-pin's for an unknown prefix)."""
    path = tmp_path / "prefixed.urdf"
    path.write_text(
        f'<robot name="r"><{prefix}:property name="x" value="1"/><link name="a"/></robot>'
    )
    root = read_urdf_root(path)
    assert root.get("name") == "r" and root.find("link").get("name") == "a"
    (element,) = [e for e in root if e.tag.endswith("}property")]
    assert element.tag.startswith("{") and element.get("value") == "1"
