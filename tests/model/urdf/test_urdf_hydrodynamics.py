"""The <hydrodynamics> extension: elements found per link, coefficients parsed."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from uvms_pin.errors import ModelError
from uvms_pin.model.urdf.hydrodynamics import hydro_elements_by_link, parse_hydro


def links_of(root: ET.Element) -> dict[str, ET.Element]:
    return {link.get("name"): link for link in root.findall("link")}


def test_elements_inside_a_link_and_at_the_top_level():
    root = ET.fromstring(
        '<robot><link name="a"><hydrodynamics/></link><link name="b"/>'
        '<hydrodynamics link="b"/></robot>'
    )
    found = hydro_elements_by_link(root, links_of(root), "f.urdf")
    assert sorted(found) == ["a", "b"]
    assert found["b"] is root.find("hydrodynamics")


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('<link name="a"><hydrodynamics/><hydrodynamics/></link>', "more than one"),
        ('<link name="a"><hydrodynamics/></link><hydrodynamics link="a"/>', "more than one"),
        ('<link name="a"/><hydrodynamics link="z"/>', "names a link that does not exist"),
        ('<link name="a"/><hydrodynamics/>', 'needs a link="NAME" attribute'),
    ],
)
def test_misplaced_elements_are_named(text, match):
    root = ET.fromstring(f"<robot>{text}</robot>")
    with pytest.raises(ModelError, match=match):
        hydro_elements_by_link(root, links_of(root), "f.urdf")


def test_parse_hydro_diagonals_matrices_and_defaults():
    identity = " ".join("1" if i % 7 == 0 else "0" for i in range(36))
    params = parse_hydro(
        ET.fromstring(
            '<hydrodynamics><volume value="0.01"/><added_mass diagonal="1 2 3 4 5 6"/>'
            f'<linear_damping matrix="{identity}"/></hydrodynamics>'
        ),
        "f.urdf",
        "l",
    )
    assert params.volume_m3 == 0.01 and not params.derived and params.origin == "URDF"
    assert np.array_equal(params.center_of_buoyancy_m, np.zeros(3))
    assert np.array_equal(np.diag(params.added_mass), [1, 2, 3, 4, 5, 6])
    assert np.array_equal(params.linear_damping, np.eye(6))
    assert np.array_equal(params.quadratic_damping, np.zeros(6))


@pytest.mark.parametrize(
    ("inner", "match"),
    [
        ('<volume value="1"/><drag/>', "unknown tag <drag>"),
        ('<center_of_buoyancy xyz="0 0 0"/>', "has no <volume>"),
        ('<volume value="-1"/>', "negative volume"),
        ('<volume value="1"/><added_mass/>', "exactly one of diagonal"),
        ('<volume value="1"/><added_mass diagonal="1 1 -1 1 1 1"/>', "must be >= 0"),
    ],
)
def test_parse_hydro_names_what_is_wrong(inner, match):
    with pytest.raises(ModelError, match=match) as info:
        parse_hydro(ET.fromstring(f"<hydrodynamics>{inner}</hydrodynamics>"), "f.urdf", "l")
    assert "link 'l'" in str(info.value)
