"""Origins in a URDF being mounted (uvms_pin.model.mount.origin): three finite numbers or a
ModelError naming the element and the file; an origin written first when there is none."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ModelError
from uvms_pin.model.mount.origin import origin_of, set_origin, vector_attribute

PATH = Path("arm.urdf")


@pytest.mark.parametrize("text", ["0 0", "0 0 0 1", "0 nan 0", "inf 0 0"])
def test_an_attribute_that_is_not_three_finite_numbers_is_refused(text):
    element = ET.fromstring(f'<origin xyz="{text}"/>')
    with pytest.raises(ModelError, match=r"arm.urdf: 'j': xyz needs 3 finite numbers"):
        vector_attribute(element, "xyz", "0 0 0", PATH, "j")


def test_a_missing_attribute_or_element_is_its_default_and_text_is_named():
    assert vector_attribute(None, "xyz", "1 2 3", PATH, "j").tolist() == [1.0, 2.0, 3.0]
    element = ET.fromstring('<origin rpy="0 0 1"/>')
    assert vector_attribute(element, "xyz", "0 0 0", PATH, "j").tolist() == [0.0, 0.0, 0.0]
    with pytest.raises(ModelError, match="'j': non-numeric xyz 'a b c'"):
        vector_attribute(ET.fromstring('<origin xyz="a b c"/>'), "xyz", "0 0 0", PATH, "j")


def test_an_origin_is_written_first_and_read_back():
    joint = ET.fromstring(
        '<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>'
    )
    assert origin_of(joint, PATH).isIdentity()
    placement = pin.SE3(pin.rpy.rpyToMatrix(0.1, -0.2, 0.3), np.array([0.5, 0.0, -0.25]))
    set_origin(joint, placement)
    assert [c.tag for c in joint] == ["origin", "parent", "child"]
    assert origin_of(joint, PATH).isApprox(placement, 1e-12)
