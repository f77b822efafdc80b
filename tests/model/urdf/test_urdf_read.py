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
    with pytest.raises(ModelError, match="root element is <sdf>, expected <robot>"):
        read_urdf_root(bad)
    bad.write_text('<robot name="r"/>')
    assert read_urdf_root(bad).get("name") == "r"
