"""A URDF tree as file text, written atomically into a directory made if needed."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from uvms_pin.model.mount.text import urdf_text, write_text_file


def test_urdf_text_indents_a_copy():
    root = ET.fromstring('<robot name="r"><link name="a"/></robot>')
    text = urdf_text(root)
    assert text == '<?xml version="1.0"?>\n<robot name="r">\n  <link name="a" />\n</robot>\n'
    assert root.text is None  # the tree itself is not indented


def test_write_text_file_makes_the_directory(tmp_path):
    target = tmp_path / "new" / "dir" / "m.urdf"
    assert write_text_file(target, "text") == target
    assert target.read_text() == "text"
    assert sorted(p.name for p in target.parent.iterdir()) == ["m.urdf"]
